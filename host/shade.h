// Turning hit records into colours: the paper's preview mode (no lights, a headlight on the normal).
#pragma once

#include "camera.h"
#include "image_io.h"
#include "renderer.h"
#include "scene.h"

namespace algray {

// Share of the colour that does not depend on the angle, so surfaces seen edge-on stay visible.
inline constexpr double kPreviewAmbient = 0.2;

// RGBA, depth, normals and the solver-statistics channels of a frame.
FrameImage shade_preview(const Scene& scene, const RenderResult& result);

// Unit direction of pixel (px, py)'s ray, in double (the kernels compute the same ray in their own precision).
glm::dvec3 pixel_direction(const RayBasis& basis, int px, int py);

}  // namespace algray
