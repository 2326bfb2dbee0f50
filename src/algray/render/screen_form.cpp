// The screen form: P restricted to the camera's rays once per image, then to each row, in long double.
#include "algray/render/screen_form.h"

#include <cmath>

namespace algray {
namespace {

using Real = long double;

// A polynomial in (tau, xi, eta), dense over [k][j][i] with k, j, i <= n; tau_degree and plane_degree bound
// the degree in tau and the total degree in (xi, eta) of the coefficients that may be non-zero.
struct Trivariate {
  int n = 0;
  int tau_degree = 0, plane_degree = 0;
  std::vector<Real> c;
  explicit Trivariate(int n_) : n(n_), c(static_cast<std::size_t>((n_ + 1) * (n_ + 1) * (n_ + 1)), 0) {}
  std::size_t at(int k, int j, int i) const { return (static_cast<std::size_t>(k) * (n + 1) + j) * (n + 1) + i; }
  void set_constant(Real a) {
    std::fill(c.begin(), c.end(), Real(0));
    c[0] = a;
    tau_degree = plane_degree = 0;
  }
  void add(const Trivariate& o) {
    for (int k = 0; k <= o.tau_degree; ++k)
      for (int j = 0; j <= o.plane_degree; ++j)
        for (int i = 0; i + j <= o.plane_degree; ++i) c[at(k, j, i)] += o.c[o.at(k, j, i)];
    tau_degree = std::max(tau_degree, o.tau_degree);
    plane_degree = std::max(plane_degree, o.plane_degree);
  }
};

// One coordinate along the rays: q + xi qx + eta qy + tau (d + xi dx + eta dy).
struct Coordinate {
  Real q, qx, qy, d, dx, dy;
};

// p *= coordinate, `times` times; scratch is reused between calls.
void multiply(Trivariate& p, const Coordinate& f, int times, Trivariate& scratch) {
  for (int r = 0; r < times; ++r) {
    std::fill(scratch.c.begin(), scratch.c.end(), Real(0));
    for (int k = 0; k <= p.tau_degree; ++k)
      for (int j = 0; j <= p.plane_degree; ++j)
        for (int i = 0; i + j <= p.plane_degree; ++i) {
          const Real v = p.c[p.at(k, j, i)];
          if (v == 0) continue;
          scratch.c[p.at(k, j, i)] += v * f.q;
          scratch.c[p.at(k, j + 1, i)] += v * f.qx;
          scratch.c[p.at(k, j, i + 1)] += v * f.qy;
          scratch.c[p.at(k + 1, j, i)] += v * f.d;
          scratch.c[p.at(k + 1, j + 1, i)] += v * f.dx;
          scratch.c[p.at(k + 1, j, i + 1)] += v * f.dy;
        }
    std::swap(p.c, scratch.c);
    ++p.tau_degree;
    ++p.plane_degree;
  }
}

bool inside_extent(const glm::dvec3& u, const Extent& extent) {
  if (extent.kind == ExtentKind::Sphere || extent.gate) return glm::dot(u, u) <= 1;  // a gate's rays: its far sphere
  const glm::dvec3 half = extent.unit_box_half();
  if (extent.kind == ExtentKind::Cylinder) {
    const int a = extent.axis, i = a == 0 ? 1 : 0, j = a == 2 ? 1 : 2;
    return u[i] * u[i] + u[j] * u[j] <= half[i] * half[i] && std::abs(u[a]) <= half[a];
  }
  return std::abs(u.x) <= half.x && std::abs(u.y) <= half.y && std::abs(u.z) <= half.z;
}

}  // namespace

ScreenGeometry screen_geometry(const RayBasis& b, int width, int height, const Extent& extent) {
  const glm::dvec3 centre = extent.unit_centre();
  const double inv = 1 / extent.unit_scale();
  const double half_w = 0.5 * width, half_h = 0.5 * height;
  ScreenGeometry g;
  g.oc = (b.o00 + half_w * b.ou + half_h * b.ov - centre) * inv;
  g.ox = half_w * b.ou * inv;
  g.oy = half_h * b.ov * inv;
  g.dc = (b.d00 + half_w * b.du + half_h * b.dv) * inv;
  g.dx = half_w * b.du * inv;
  g.dy = half_h * b.dv * inv;
  g.xi_scale = 2.0 / width;
  g.xi_offset = -1;
  const double dd = glm::dot(g.dc, g.dc);
  g.t0 = dd > 0 ? -glm::dot(g.oc, g.dc) / dd : 0;
  g.well_placed = g.t0 > 0 && !inside_extent(g.oc, extent);
  return g;
}

ScreenForm::ScreenForm(const std::vector<std::uint32_t>& exponents, const std::vector<double>& coefficients,
                       int degree, const ScreenGeometry& g)
    : degree_(degree) {
  // The expansion point moves with the pixel: q = o + t0 d, affine in (xi, eta) like o and d.
  const glm::dvec3 q = g.oc + g.t0 * g.dc, qx = g.ox + g.t0 * g.dx, qy = g.oy + g.t0 * g.dy;
  Coordinate axes[3];
  for (int a = 0; a < 3; ++a)
    axes[a] = {q[a], qx[a], qy[a], g.dc[a], g.dx[a], g.dy[a]};
  // Nested Horner in x, then y, then z over the monomials sorted by i, j, k descending, as the kernels do it.
  Trivariate total(degree), level_y(degree), level_z(degree), scratch(degree);
  bool have_total = false;
  int prev_i = -1;
  std::size_t m = 0;
  while (m < exponents.size()) {
    const int i = static_cast<int>(exponents[m] & 0xffu);
    bool have_y = false;
    int prev_j = -1;
    while (m < exponents.size() && static_cast<int>(exponents[m] & 0xffu) == i) {
      const int j = static_cast<int>((exponents[m] >> 8) & 0xffu);
      int prev_k = -1;
      while (m < exponents.size() && static_cast<int>(exponents[m] & 0xffu) == i &&
             static_cast<int>((exponents[m] >> 8) & 0xffu) == j) {
        const int k = static_cast<int>((exponents[m] >> 16) & 0xffu);
        if (prev_k < 0) {
          level_z.set_constant(coefficients[m]);
        } else {
          multiply(level_z, axes[2], prev_k - k, scratch);
          level_z.c[0] += coefficients[m];
        }
        prev_k = k;
        ++m;
      }
      multiply(level_z, axes[2], prev_k, scratch);
      if (!have_y) {
        std::swap(level_y, level_z);
        have_y = true;
      } else {
        multiply(level_y, axes[1], prev_j - j, scratch);
        level_y.add(level_z);
      }
      prev_j = j;
    }
    multiply(level_y, axes[1], prev_j, scratch);
    if (!have_total) {
      std::swap(total, level_y);
      have_total = true;
    } else {
      multiply(total, axes[0], prev_i - i, scratch);
      total.add(level_y);
    }
    prev_i = i;
  }
  if (have_total) multiply(total, axes[0], prev_i, scratch);
  f_ = std::move(total.c);
}

std::vector<double> ScreenForm::rows(int row0, int count, int height) const {
  const int n1 = degree_ + 1;
  const auto at = [n1](int k, int j, int i) { return (static_cast<std::size_t>(k) * n1 + j) * n1 + i; };
  std::vector<double> out(static_cast<std::size_t>(count) * n1 * n1 + 16, 0.0);
  for (int r = 0; r < count; ++r) {
    const Real eta = (static_cast<Real>(row0 + r) + Real(0.5)) * Real(2) / height - 1;
    for (int k = 0; k <= degree_; ++k)
      for (int j = 0; j <= degree_; ++j) {
        Real h = 0;
        for (int i = degree_ - j; i >= 0; --i) h = h * eta + f_[at(k, j, i)];
        out[(static_cast<std::size_t>(r) * n1 + j) * n1 + k] = static_cast<double>(h);
      }
  }
  return out;
}

}  // namespace algray
