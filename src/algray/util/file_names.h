// File-name helpers shared by the scene readers and the image writers.
#pragma once

#include <filesystem>
#include <string>

namespace algray {

// ".png" for "a/B.PNG": the extension, lower case, with its dot; "" without one.
std::string lowercase_extension(const std::filesystem::path& p);

}  // namespace algray
