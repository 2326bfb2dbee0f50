// Colour transfer functions: display (sRGB-encoded) values to the linear light the renderer works in.
#pragma once

namespace algray {

// An sRGB-encoded value in [0, 1] (a display colour, as other programs write them) as linear light.
double srgb_to_linear(double c);

}  // namespace algray
