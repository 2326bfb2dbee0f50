// The algray version: the CMake project version and the git revision the binary was built from.
#pragma once

#include <string>

namespace algray {

// "0.1.0", from project(algray VERSION ...) in the top-level CMakeLists.txt.
const char* version();

// The short commit hash of the source tree at build time, "91078e7"; "91078e7-dirty" when tracked files
// differed from that commit; "unknown" when it was not built from a git checkout. Refreshed on every build.
const char* git_revision();

// "algray 0.1.0 (git 91078e7)", or "algray 0.1.0" when the revision is unknown: what --version prints and what
// images, stats and logs carry.
std::string version_string();

}  // namespace algray
