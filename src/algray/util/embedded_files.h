// Files compiled into the binary by cmake/EmbedFiles.cmake: the OpenCL kernels and the default scene.
#pragma once

#include <vector>

namespace algray {

struct EmbeddedFile {
  const char* name;  // file name without directory, e.g. "primary.cl"
  const char* text;
};

const std::vector<EmbeddedFile>& embedded_kernel_files();
const std::vector<EmbeddedFile>& embedded_scene_files();

}  // namespace algray
