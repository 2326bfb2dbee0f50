// A small valid scene, line by line, that error tests vary one line at a time (shared by scene and CLI tests).
#pragma once

#include <map>
#include <string>
#include <vector>

namespace algray::testing {

// Line 1 is a comment so that a test can put top-level keys before the first table.
inline const std::vector<std::string> kUnitSphere = {
    "# unit sphere seen from +z",    // 1
    "[surface]",                     // 2
    "equation = \"x^2+y^2+z^2-1\"",  // 3
    "[extent]",                      // 4
    "radius = 2",                    // 5
    "[camera]",                      // 6
    "eye = [0, 0, 5]",               // 7
    "look_at = [0, 0, 0]",           // 8
    "up = [0, 1, 0]",                // 9
    "fov_y = 45",                    // 10
};

// The unit sphere scene with some lines replaced (a replacement may span several lines) and lines appended.
inline std::string sphere_with(const std::map<int, std::string>& replaced,
                               const std::vector<std::string>& appended = {}) {
  std::string text;
  for (std::size_t i = 0; i < kUnitSphere.size(); ++i) {
    const auto it = replaced.find(static_cast<int>(i + 1));
    text += (it == replaced.end() ? kUnitSphere[i] : it->second) + "\n";
  }
  for (const std::string& line : appended) text += line + "\n";
  return text;
}

}  // namespace algray::testing
