// The screen form of the camera rays' P*(t): Taylor coefficients along each ray, as polynomials in its column.
#pragma once

#include <cstdint>
#include <vector>

#include "algray/scene/camera.h"
#include "algray/scene/scene.h"

namespace algray {

// Camera rays in the extent's unit coordinates as affine functions of the image position (xi, eta) in [-1, 1]:
// pixel (px, py) of a width x height image has xi = (px + 1/2) * 2/width - 1 and eta = (py + 1/2) * 2/height - 1,
// origin o = oc + xi ox + eta oy and direction d = dc + xi dx + eta dy. Every ray is expanded about its point at
// t = t0, where the middle ray passes closest to the extent's centre: near the extent for every ray that meets it,
// so the Taylor coefficients are as well conditioned as the extent construction's (measured, bench/RESULTS.md).
struct ScreenGeometry {
  glm::dvec3 oc, ox, oy;
  glm::dvec3 dc, dx, dy;
  double t0 = 0;
  double xi_scale = 0, xi_offset = -1;  // xi = (px + 1/2) * xi_scale + xi_offset, as the kernel computes it
  // False when the eye is inside the extent or the extent's centre is behind the camera: then the expansion
  // points may lie far from the surface, and RayOrigin::Auto keeps the extent construction.
  bool well_placed = false;
};

ScreenGeometry screen_geometry(const RayBasis& basis, int width, int height, const Extent& extent);

// F(tau, xi, eta) = P(o + (t0 + tau) d) for P in unit coordinates, expanded once per image in long double.
class ScreenForm {
 public:
  // exponents: i | j << 8 | k << 16, as SurfaceData holds them.
  ScreenForm(const std::vector<std::uint32_t>& exponents, const std::vector<double>& coefficients, int degree,
             const ScreenGeometry& geometry);

  // Rows row0 .. row0 + count - 1 of a `height`-row image: out[(r * n1 + j) * n1 + k] is the xi^j coefficient of
  // the row's tau^k coefficient (n1 = degree + 1), followed by 16 zeros so that a kernel may read any power's
  // coefficients as one 16-wide vector.
  std::vector<double> rows(int row0, int count, int height) const;
  int degree() const { return degree_; }

 private:
  int degree_;
  std::vector<long double> f_;  // [k][j][i]: coefficient of tau^k xi^j eta^i, each index 0 .. degree
};

}  // namespace algray
