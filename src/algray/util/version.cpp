// The version text, from the compile definition ALGRAY_VERSION and the generated revision header.
#include "algray/util/version.h"

#include <cstring>

#include "algray_git_revision.h"

namespace algray {

const char* version() { return ALGRAY_VERSION; }

const char* git_revision() { return ALGRAY_GIT_REVISION; }

std::string version_string() {
  std::string s = std::string("algray ") + version();
  if (std::strcmp(git_revision(), "unknown") != 0) s += std::string(" (git ") + git_revision() + ")";
  return s;
}

}  // namespace algray
