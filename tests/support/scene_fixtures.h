// Scenes the tests share: a small valid scene that error tests vary line by line, and seeded random surfaces.
#pragma once

#include <algorithm>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "algray/device/kernel_config.h"
#include "algray/scene/scene.h"

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

// A seeded random surface of exactly `degree` in the unit sphere, seen from outside: x^n + y^n + z^n fixes the
// degree, then 3n random monomials of lower degrees with coefficients in [-1, 1] (the bench's family).
inline std::string random_scene(int degree, unsigned seed, Precision precision) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coefficient(-1, 1);
  std::ostringstream s;
  s.precision(17);
  s << "[surface]\nterms = [[" << degree << ", 0, 0, 1], [0, " << degree << ", 0, 1], [0, 0, " << degree
    << ", 1], [0, 0, 0, -0.25]";
  for (int m = 0; m < 3 * degree; ++m) {
    const int total = std::uniform_int_distribution<int>(1, std::max(1, degree - 1))(rng);
    const int i = std::uniform_int_distribution<int>(0, total)(rng);
    const int j = std::uniform_int_distribution<int>(0, total - i)(rng);
    s << ", [" << i << ", " << j << ", " << total - i - j << ", " << coefficient(rng) << "]";
  }
  s << "]\n[extent]\ntype = \"sphere\"\nradius = 1\n[camera]\neye = [1.2, 0.9, 2.6]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\n"
    << "fov_y = 45\n[image]\nwidth = 64\nheight = 48\n[render]\nprecision = \"" << to_string(precision) << "\"\npreview = true\n"
    << "ray_origin = \"auto\"\n";
  return s.str();
}

// The example scene with everything that crosses a tile's border or fills a batch: two surfaces, a reflective
// ball and a transparent ring, an area light; small.
inline Scene ball_and_ring(const std::vector<Override>& overrides) {
  std::vector<Override> all = {{"image.width", "72"}, {"image.height", "54"}};
  all.insert(all.end(), overrides.begin(), overrides.end());
  return load_scene_file(std::string(ALGRAY_SOURCE_DIR) + "/scenes/examples/ball_and_ring.toml", all);
}

}  // namespace algray::testing
