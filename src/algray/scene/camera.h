// Camera conventions: how a scene's camera turns into the per-pixel ray formula the kernels evaluate.
#pragma once

#include <array>
#include <glm/glm.hpp>

namespace algray {

enum class Projection { Perspective, Orthographic };

struct CameraSpec {
  Projection projection = Projection::Perspective;
  glm::dvec3 eye{0, 0, 5};
  glm::dvec3 look_at{0, 0, 0};
  glm::dvec3 up{0, 1, 0};
  double fov_y_degrees = 45;  // perspective: full vertical field of view
  double ortho_height = 2;    // orthographic: height of the view in world units
};

// Pixel (px, py), py = 0 at the top, gets o = o00 + (px+0.5)*ou + (py+0.5)*ov and d = d00 + (px+0.5)*du + (py+0.5)*dv.
// Perspective: ou = ov = 0 and o00 = eye; orthographic: du = dv = 0 and d00 = the unit view direction.
struct RayBasis {
  glm::dvec3 o00, ou, ov;
  glm::dvec3 d00, du, dv;
  glm::dvec3 right, true_up, forward;  // orthonormal camera frame
};

RayBasis make_ray_basis(const CameraSpec& camera, int width, int height);

// The ray of pixel (px, py) exactly as a kernel of the given precision computes it: the basis rounded to that
// precision, then each product and sum rounded in docs/outputs.md's order. The result is that ray's exact value.
struct PixelRay {
  glm::dvec3 origin, direction;
};
PixelRay pixel_ray(const RayBasis& basis, bool single_precision, int px, int py);

// Row-major 4x4 matrices for the row-vector convention (p' = p * M) that OpenEXR's Imath uses.
// Camera space: x right, y up, looking down -z. NDC: x, y in [-1, 1] across the image, y up; the
// homogeneous w is -z for perspective cameras (1 for orthographic), and z is left as camera-space z.
std::array<float, 16> world_to_camera_matrix(const RayBasis& basis, const glm::dvec3& eye);
std::array<float, 16> world_to_ndc_matrix(const CameraSpec& camera, const RayBasis& basis, int width, int height);

}  // namespace algray
