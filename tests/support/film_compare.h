// Films and records compared bit for bit, with the first differing pixel for a failure message.
#pragma once

#include <cstring>
#include <string>
#include <vector>

#include "algray/io/image_io.h"

namespace algray::testing {

// Bit for bit: the same floats, NaNs and signed zeros included.
template <typename T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// The first pixel where two films differ, for the failure message.
inline std::string first_difference(const FrameImage& a, const FrameImage& b) {
  for (std::size_t i = 0; i < a.depth.size() && i < b.depth.size(); ++i) {
    const bool differs = std::memcmp(&a.rgba[4 * i], &b.rgba[4 * i], 4 * sizeof(float)) != 0 ||
                         std::memcmp(&a.depth[i], &b.depth[i], sizeof(float)) != 0 ||
                         std::memcmp(&a.normal[3 * i], &b.normal[3 * i], 3 * sizeof(float)) != 0;
    if (differs)
      return "pixel " + std::to_string(i % a.width) + "," + std::to_string(i / a.width) + ": red " +
             std::to_string(a.rgba[4 * i]) + " against " + std::to_string(b.rgba[4 * i]);
  }
  return "none";
}

// Every channel of the film alike.
inline bool same_film(const FrameImage& a, const FrameImage& b) {
  return a.width == b.width && a.height == b.height && same_bits(a.rgba, b.rgba) && same_bits(a.depth, b.depth) &&
         same_bits(a.normal, b.normal);
}

}  // namespace algray::testing
