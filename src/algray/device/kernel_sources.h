// The OpenCL C sources embedded at build time, and their assembly into one program text.
#pragma once

#include <string>

#include "algray/util/embedded_files.h"

namespace algray {

// The text of `main_file` with its #include "..." lines replaced by the embedded files, each included once.
// With the environment variable ALGRAY_KERNEL_DIR set, files are read from that directory instead, so kernels
// can be edited without rebuilding the host.
std::string assemble_kernel_source(const std::string& main_file);

}  // namespace algray
