// Turning hit records into colours: Phong lighting with the shadow pass's answers, or a headlight without lights.
#pragma once

#include "camera.h"
#include "image_io.h"
#include "renderer.h"
#include "scene.h"

namespace algray {

// Without lights, the share of the colour that does not depend on the angle, so surfaces seen edge-on stay
// visible.
inline constexpr double kPreviewAmbient = 0.2;

// RGBA, depth, normals and the solver-statistics channels of the output image: every traced ray shaded, then
// the antialiasing samples of each pixel averaged (a box filter). Depth and normal are those of the pixel's
// nearest sample; the solver channels add up the work of all its samples.
FrameImage shade_frame(const Scene& scene, const RenderResult& result);

// Unit direction of pixel (px, py)'s ray, in double (the kernels compute the same ray in their own precision).
glm::dvec3 pixel_direction(const RayBasis& basis, int px, int py);

}  // namespace algray
