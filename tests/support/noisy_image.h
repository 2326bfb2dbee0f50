// The noise image the image_io tests write and check: incompressible, so writes are slow and outgrow small limits.
#pragma once

#include <random>

#include "algray/io/image_io.h"

namespace algray::testing {

// rgba, then depth (times 100), drawn as uniform noise from one mt19937(seed).
// A float in [0, 1) from the top 24 bits of one draw: std::uniform_real_distribution computes a logarithm per value,
// which in the sanitizer tree (-O0) was half of test_image_io's time.
inline float unit_float(std::mt19937& rng) { return static_cast<float>(rng() >> 8) * 0x1p-24f; }

inline FrameImage noisy_image(int side, std::mt19937::result_type seed) {
  FrameImage im;
  im.width = im.height = side;
  const std::size_t n = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
  std::mt19937 rng(seed);
  im.rgba.resize(4 * n);
  for (float& v : im.rgba) v = unit_float(rng);
  im.depth.resize(n);
  for (float& v : im.depth) v = unit_float(rng) * 100.0f;
  return im;
}

}  // namespace algray::testing
