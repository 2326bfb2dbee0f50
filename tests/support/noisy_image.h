// The noise image the image_io tests write and check: incompressible, so writes are slow and outgrow small limits.
#pragma once

#include <random>

#include "algray/io/image_io.h"

namespace algray::testing {

// rgba, then depth (times 100), drawn as uniform noise from one mt19937(seed).
inline FrameImage noisy_image(int side, std::mt19937::result_type seed) {
  FrameImage im;
  im.width = im.height = side;
  const std::size_t n = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  im.rgba.resize(4 * n);
  for (float& v : im.rgba) v = uniform(rng);
  im.depth.resize(n);
  for (float& v : im.depth) v = uniform(rng) * 100.0f;
  return im;
}

}  // namespace algray::testing
