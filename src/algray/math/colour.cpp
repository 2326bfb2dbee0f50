// Colour transfer functions: display (sRGB-encoded) values to the linear light the renderer works in.
#include "algray/math/colour.h"

#include <algorithm>
#include <cmath>

namespace algray {

double srgb_to_linear(double c) {
  c = std::clamp(c, 0.0, 1.0);
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

}  // namespace algray
