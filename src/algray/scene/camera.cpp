// Camera frame, per-pixel ray coefficients and the EXR camera matrices.
#include "algray/scene/camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace algray {

RayBasis make_ray_basis(const CameraSpec& camera, int width, int height) {
  RayBasis b{};
  b.forward = glm::normalize(camera.look_at - camera.eye);
  b.right = glm::normalize(glm::cross(b.forward, camera.up));
  b.true_up = glm::cross(b.right, b.forward);
  const double w = width, h = height, aspect = w / h;
  if (camera.projection == Projection::Perspective) {
    const double half_tan = std::tan(glm::radians(camera.fov_y_degrees) / 2);
    b.o00 = camera.eye;
    b.ou = b.ov = glm::dvec3(0);
    b.d00 = b.forward + half_tan * aspect * (2 * camera.shift.x - 1) * b.right +
            half_tan * (2 * camera.shift.y + 1) * b.true_up;
    b.du = (2 * half_tan * aspect / w) * b.right;
    b.dv = (-2 * half_tan / h) * b.true_up;
  } else {
    const double half_h = camera.ortho_height / 2, half_w = half_h * aspect;
    b.o00 = camera.eye + half_w * (2 * camera.shift.x - 1) * b.right + half_h * (2 * camera.shift.y + 1) * b.true_up;
    b.ou = (2 * half_w / w) * b.right;
    b.ov = (-2 * half_h / h) * b.true_up;
    b.d00 = b.forward;
    b.du = b.dv = glm::dvec3(0);
  }
  return b;
}

namespace {

double radians(double degrees) { return degrees * std::numbers::pi / 180; }
double degrees(double radians) { return radians * 180 / std::numbers::pi; }

// The horizontal frame azimuths are measured in: the reference direction (azimuth 0) and the one at +90 degrees.
void azimuth_frame(const glm::dvec3& unit_up, glm::dvec3& reference, glm::dvec3& side) {
  glm::dvec3 r = glm::dvec3(0, 0, 1) - unit_up.z * unit_up;
  if (glm::length(r) < 1e-6) r = glm::dvec3(1, 0, 0) - unit_up.x * unit_up;
  reference = glm::normalize(r);
  side = glm::cross(unit_up, reference);
}

}  // namespace

void place_camera_by_angles(CameraSpec& camera, const CameraAngles& angles, const glm::dvec3& given_up) {
  const glm::dvec3 up = given_up;  // a copy: `given_up` may be camera.up, which is set below
  const glm::dvec3 u = glm::normalize(up);
  glm::dvec3 reference, side;
  azimuth_frame(u, reference, side);
  const double a = radians(angles.azimuth), e = radians(angles.elevation);
  const glm::dvec3 horizontal = std::cos(a) * reference + std::sin(a) * side;
  const glm::dvec3 towards_eye = std::cos(e) * horizontal + std::sin(e) * u;
  camera.eye = camera.look_at + angles.distance * towards_eye;
  camera.up = std::cos(e) * u - std::sin(e) * horizontal;  // normal to the view, in the plane of up and the view
  camera.angles = angles;
  camera.written_up = up;
}

CameraAngles camera_angles(const CameraSpec& camera) {
  if (camera.angles) return *camera.angles;
  const glm::dvec3 u = glm::normalize(camera.up);
  glm::dvec3 reference, side;
  azimuth_frame(u, reference, side);
  const glm::dvec3 offset = camera.eye - camera.look_at;
  CameraAngles out;
  out.distance = glm::length(offset);
  out.elevation = degrees(std::asin(std::clamp(glm::dot(offset, u) / out.distance, -1.0, 1.0)));
  const glm::dvec3 horizontal = offset - glm::dot(offset, u) * u;
  out.azimuth = glm::length(horizontal) > 1e-12 * out.distance
                    ? degrees(std::atan2(glm::dot(horizontal, side), glm::dot(horizontal, reference)))
                    : 0;
  return out;
}

glm::dvec3 camera_vector_to_world(const CameraSpec& camera, const glm::dvec3& v) {
  const glm::dvec3 forward = glm::normalize(camera.look_at - camera.eye);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::dvec3 up = glm::cross(right, forward);
  return v.x * right + v.y * up - v.z * forward;
}

glm::dvec3 camera_point_to_world(const CameraSpec& camera, const glm::dvec3& p) {
  return camera.eye + camera_vector_to_world(camera, p);
}

namespace {

template <typename R>
glm::dvec3 convention_sum(const glm::dvec3& v00, const glm::dvec3& vx, const glm::dvec3& vy, int px, int py) {
  const R fx = static_cast<R>(px) + R(0.5), fy = static_cast<R>(py) + R(0.5);
  glm::dvec3 out;
  for (int i = 0; i < 3; ++i) {
    const R x_part = fx * static_cast<R>(vx[i]);
    const R y_part = fy * static_cast<R>(vy[i]);
    const R partial = static_cast<R>(v00[i]) + x_part;
    out[i] = static_cast<double>(static_cast<R>(partial + y_part));
  }
  return out;
}

}  // namespace

PixelRay pixel_ray(const RayBasis& b, bool single_precision, int px, int py) {
  if (single_precision)
    return {convention_sum<float>(b.o00, b.ou, b.ov, px, py), convention_sum<float>(b.d00, b.du, b.dv, px, py)};
  return {convention_sum<double>(b.o00, b.ou, b.ov, px, py), convention_sum<double>(b.d00, b.du, b.dv, px, py)};
}

std::array<float, 16> world_to_camera_matrix(const RayBasis& basis, const glm::dvec3& eye) {
  // Rows of the rotation are the camera axes (right, up, -forward) as columns for p * M.
  const glm::dvec3 axes[3] = {basis.right, basis.true_up, -basis.forward};
  std::array<float, 16> m{};
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) m[r * 4 + c] = static_cast<float>(axes[c][r]);
    m[12 + c] = static_cast<float>(-glm::dot(axes[c], eye));
  }
  m[15] = 1;
  return m;
}

std::array<float, 16> world_to_ndc_matrix(const CameraSpec& camera, const RayBasis& basis, int width, int height) {
  const std::array<float, 16> view = world_to_camera_matrix(basis, camera.eye);
  const double aspect = static_cast<double>(width) / height;
  // Projection for row vectors: x_ndc = x / (-z * tan*aspect), y_ndc = y / (-z * tan) for perspective.
  std::array<double, 16> proj{};
  if (camera.projection == Projection::Perspective) {
    const double half_tan = std::tan(glm::radians(camera.fov_y_degrees) / 2);
    proj[0] = 1 / (half_tan * aspect);
    proj[5] = 1 / half_tan;
    proj[10] = 1;  // z passes through; w = -z
    proj[11] = -1;
    proj[8] = 2 * camera.shift.x;  // the shifted centre is NDC (0, 0)
    proj[9] = 2 * camera.shift.y;
  } else {
    const double half_h = camera.ortho_height / 2;
    proj[0] = 1 / (half_h * aspect);
    proj[5] = 1 / half_h;
    proj[10] = 1;
    proj[15] = 1;
    proj[12] = -2 * camera.shift.x;
    proj[13] = -2 * camera.shift.y;
  }
  std::array<float, 16> out{};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += static_cast<double>(view[r * 4 + k]) * proj[k * 4 + c];
      out[r * 4 + c] = static_cast<float>(s);
    }
  return out;
}

}  // namespace algray
