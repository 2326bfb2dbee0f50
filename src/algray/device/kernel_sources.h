// The OpenCL C sources embedded at build time, and their assembly into one program text.
#pragma once

#include <string>

#include "algray/util/embedded_files.h"

namespace algray {

// The text of `main_file` with its #include "..." lines replaced by the embedded files: a file again where it is
// included again, unless a copy before stands outside every #if (then its include guard is set).
// With the environment variable ALGRAY_KERNEL_DIR set, files are read from that directory instead, so kernels
// can be edited without rebuilding the host.
std::string assemble_kernel_source(const std::string& main_file);

// A compiler's build log with each location it gives in the assembled program text (NVIDIA's compiler writes
// "<kernel>:9756:1:", ignoring #line) rewritten as the kernel file and line it came from, so that every
// device's errors point into kernels/; locations that already name a kernel file (PoCL honours #line) stay.
std::string locate_in_kernel_files(const std::string& log, const std::string& source);

}  // namespace algray
