// File-name helpers shared by the scene readers and the image writers.
#include "algray/util/file_names.h"

#include <algorithm>
#include <cctype>

namespace algray {

std::string lowercase_extension(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext;
}

}  // namespace algray
