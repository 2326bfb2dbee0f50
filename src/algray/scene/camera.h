// Camera conventions: how a scene's camera turns into the per-pixel ray formula the kernels evaluate.
#pragma once

#include <array>
#include <glm/glm.hpp>
#include <optional>

namespace algray {

enum class Projection { Perspective, Orthographic };

// The camera as angles about its look-at point (the scene keys camera.azimuth, .elevation and .distance, which
// the view page and the Python explorer set too). Azimuth turns about `up` from the reference direction (+z, or
// +x when up is along z, made normal to up) towards up x reference (+x when up is +y); elevation rises above the
// plane through look_at normal to up, from -90 to 90 degrees.
struct CameraAngles {
  double azimuth = 30;    // degrees
  double elevation = 20;  // degrees
  double distance = 1;    // from look_at to the eye, world units
};

// A scene that gives no eye is seen from these angles, from kFramingDistance times its extent's radius R (a box's
// half-diagonal) through the default 45 degrees: the shipped scenes' framing, which shows all of the extent.
inline constexpr double kFramingDistance = 3;
// camera.shift's bound, in image widths and heights.
inline constexpr double kMaxCameraShift = 100;

struct CameraSpec {
  Projection projection = Projection::Perspective;
  glm::dvec3 eye{0, 0, 5};
  glm::dvec3 look_at{0, 0, 0};
  glm::dvec3 up{0, 1, 0};
  double fov_y_degrees = 45;  // perspective: full vertical field of view
  double ortho_height = 2;    // orthographic: height of the view in world units
  // The image's centre moved across the image plane by shift.x image widths to the right and shift.y heights up:
  // an off-axis view (a shifted lens, or POV-Ray's direction not normal to its right and up). Zero: on axis.
  glm::dvec2 shift{0, 0};
  // Set when the scene placed the camera by angles: those angles, and the up vector as written. `eye` and `up`
  // above are then the placed eye and the image's up direction (camera_from_angles).
  std::optional<CameraAngles> angles;
  glm::dvec3 written_up{0, 1, 0};
};

// The eye and the image's up direction of a camera given by angles about look_at, with `up` the scene's up; the
// image's up is normal to the view, so that elevations of +-90 degrees (looking along up) are well defined.
void place_camera_by_angles(CameraSpec& camera, const CameraAngles& angles, const glm::dvec3& up);
// The angles of a camera's eye about its look-at point, as place_camera_by_angles takes them.
CameraAngles camera_angles(const CameraSpec& camera);

// The camera's own frame (x right, y up, z towards the viewer, origin at the eye; OpenGL's eye space, as the EXR's
// worldToCamera): a point or a direction of that frame in world coordinates.
glm::dvec3 camera_point_to_world(const CameraSpec& camera, const glm::dvec3& p);
glm::dvec3 camera_vector_to_world(const CameraSpec& camera, const glm::dvec3& v);

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
