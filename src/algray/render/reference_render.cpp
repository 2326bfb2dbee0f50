// Reference rendering: solver_ref on every pixel's exact ray, rows spread over threads, results as hit records.
#include "algray/render/reference_render.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>
#include <thread>
#include <vector>

#include "kernels/algray_shared.h"
#include "solver_ref/solver_ref.h"

namespace algray {
namespace {

mpq_class evaluate(const std::vector<mpq_class>& poly, const mpq_class& t) {
  mpq_class v = 0;
  for (auto it = poly.rbegin(); it != poly.rend(); ++it) v = v * t + *it;
  return v;
}

PixelClass classify(ref::Classification kind) {
  switch (kind) {
    case ref::Classification::Miss:
      return PixelClass::Miss;
    case ref::Classification::SimpleRoot:
      return PixelClass::SimpleRoot;
    case ref::Classification::MultipleRootOddSignChange:
      return PixelClass::OddMultipleRoot;
    case ref::Classification::EvenRootNoSignChange:
      return PixelClass::EvenRoot;
    case ref::Classification::IdenticallyZero:
      return PixelClass::OnSurface;
  }
  return PixelClass::Miss;
}

// grad P at o + t d, in long double from the exact polynomial's monomials.
std::array<long double, 3> gradient_at(const std::vector<Monomial>& monomials, const PixelRay& ray, long double t) {
  const long double p[3] = {ray.origin.x + t * ray.direction.x, ray.origin.y + t * ray.direction.y,
                            ray.origin.z + t * ray.direction.z};
  // Power tables, not std::pow on long double (powl), which was a tenth of a certified render's time. The
  // gradient only shades and sizes a loose enclosure, so an ulp's difference is of no account.
  int top = 0;
  for (const Monomial& m : monomials) top = std::max({top, m.i, m.j, m.k});
  const std::array<std::vector<long double>, 3> powers = axis_powers(p[0], p[1], p[2], top);
  std::array<long double, 3> g = {0, 0, 0};
  for (const Monomial& m : monomials) {
    const int e[3] = {m.i, m.j, m.k};
    for (int axis = 0; axis < 3; ++axis) {
      if (e[axis] == 0) continue;
      long double term = m.coef * e[axis];
      for (int other = 0; other < 3; ++other) term *= powers[other][e[other] - (other == axis)];
      g[axis] += term;
    }
  }
  return g;
}

}  // namespace

const char* pixel_class_name(PixelClass c) {
  switch (c) {
    case PixelClass::OutsideExtent:
      return "outside extent";
    case PixelClass::Miss:
      return "miss";
    case PixelClass::SimpleRoot:
      return "simple root";
    case PixelClass::OddMultipleRoot:
      return "odd multiple root";
    case PixelClass::EvenRoot:
      return "even root";
    case PixelClass::OnSurface:
      return "on surface";
    case PixelClass::NearEnd:
      return "root near a clipping end";
    case PixelClass::RayRounding:
      return "ray rounding could change the answer";
  }
  return "?";
}

namespace {

// [t_in, t_out] of the ray inside the sphere of `radius` about `centre`, from t = 0 on; false where it misses.
bool sphere_interval(const glm::dvec3& centre, double radius, const PixelRay& ray, long double& t_in,
                     long double& t_out) {
  using R = long double;
  const R o[3] = {ray.origin.x, ray.origin.y, ray.origin.z}, d[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
  R a = 0, b = 0, c = -R(radius) * R(radius);
  for (int i = 0; i < 3; ++i) {
    const R oc = o[i] - R(centre[i]);
    a += d[i] * d[i];
    b += oc * d[i];
    c += oc * oc;
  }
  const R disc = b * b - a * c;
  if (!(disc > 0)) return false;
  t_in = std::max<R>(0, (-b - std::sqrt(disc)) / a);
  t_out = (-b + std::sqrt(disc)) / a;
  return true;
}

// [t_in, t_out] of the ray inside the extent's shape (sphere, box or cylinder), from t = 0 on, not yet cut by its
// planes; false where it misses the sphere or the cylinder's side (a box's miss is t_out <= t_in).
bool shape_interval(const Extent& e, const PixelRay& ray, long double& t_in, long double& t_out) {
  using R = long double;
  const R o[3] = {ray.origin.x, ray.origin.y, ray.origin.z}, d[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
  if (e.kind == ExtentKind::Sphere) return sphere_interval(e.centre, e.radius, ray, t_in, t_out);
  if (e.kind == ExtentKind::Cylinder) {
    // The slab between the caps, then the infinite cylinder's quadratic across the axis.
    const int a = e.axis, i = a == 0 ? 1 : 0, j = a == 2 ? 1 : 2;
    const R t0 = (R(e.centre[a]) - R(e.half_height) - o[a]) / d[a],
            t1 = (R(e.centre[a]) + R(e.half_height) - o[a]) / d[a];
    t_in = std::max<R>(0, std::min(t0, t1));
    t_out = std::min(std::numeric_limits<R>::max(), std::max(t0, t1));
    const R pi = o[i] - R(e.centre[i]), pj = o[j] - R(e.centre[j]);
    const R qa = d[i] * d[i] + d[j] * d[j], qb = pi * d[i] + pj * d[j];
    const R qc = pi * pi + pj * pj - R(e.radius) * R(e.radius);
    if (qa == 0) return qc <= 0;  // along the axis: inside it or not
    const R disc = qb * qb - qa * qc;
    if (!(disc > 0)) return false;
    t_in = std::max(t_in, (-qb - std::sqrt(disc)) / qa);
    t_out = std::min(t_out, (-qb + std::sqrt(disc)) / qa);
    return true;
  }
  t_in = 0;
  t_out = std::numeric_limits<R>::max();
  for (int i = 0; i < 3; ++i) {
    const R t0 = (R(e.min[i]) - o[i]) / d[i], t1 = (R(e.max[i]) - o[i]) / d[i];
    t_in = std::max(t_in, std::min(t0, t1));
    t_out = std::min(t_out, std::max(t0, t1));
  }
  return true;
}

}  // namespace

bool extent_interval(const Extent& e, const PixelRay& ray, long double& t_in, long double& t_out) {
  using R = long double;
  const R o[3] = {ray.origin.x, ray.origin.y, ray.origin.z}, d[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
  if (!shape_interval(e, ray, t_in, t_out)) return false;
  // A gate passes the rays that meet it, each along its far sphere (the unit sphere of the kernels' coordinates).
  if (e.gate && !(t_out > t_in && sphere_interval(e.unit_centre(), e.unit_scale(), ray, t_in, t_out))) return false;
  // The clipping planes, in world coordinates: where the ray crosses a plane, the part beyond it is cut away; a
  // ray along a plane keeps all or nothing.
  for (const glm::dvec4& p : e.clips) {
    const R s = R(p.x) * o[0] + R(p.y) * o[1] + R(p.z) * o[2] + R(p.w);
    const R v = R(p.x) * d[0] + R(p.y) * d[1] + R(p.z) * d[2];
    if (v > 0)
      t_out = std::min(t_out, -s / v);
    else if (v < 0)
      t_in = std::max(t_in, -s / v);
    else if (s > 0)
      return false;
  }
  return t_out > t_in;
}

// Critical points are the roots of P*', found exactly; P* is flat at them, so a loose enclosure will do.
bool flips_under_ray_rounding(const std::vector<mpq_class>& restricted, const std::vector<Monomial>& monomials,
                              const PixelRay& ray, const mpq_class& lo, const mpq_class& limit, long double eps) {
  std::vector<mpq_class> derivative;
  for (std::size_t k = 1; k < restricted.size(); ++k) derivative.push_back(restricted[k] * static_cast<long>(k));
  while (!derivative.empty() && derivative.back() == 0) derivative.pop_back();
  if (derivative.size() < 2 || limit < lo) return false;  // P* linear or constant: no critical point
  const mpq_class width = abs(limit) / 1000000000 + mpq_class(1, 1000000000);
  const double o[3] = {ray.origin.x, ray.origin.y, ray.origin.z},
               d[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
  // Each critical point's value against what rounding the ray's components could move it by.
  bool flips = false;
  ref::for_each_root(derivative, lo, limit, width, [&](const ref::Answer& c) {
    const long double t = c.t_nearest;
    const long double value = std::fabs(evaluate(restricted, exact_rational(c.t_nearest)).get_d());
    const std::array<long double, 3> g = gradient_at(monomials, ray, t);
    long double change = 0;
    for (int axis = 0; axis < 3; ++axis) change += std::fabs(g[axis]) * (std::fabs(o[axis]) + std::fabs(t * d[axis]));
    flips = value <= kReferenceRayRoundings * eps * change;
    return !flips;
  });
  return flips;
}

RayCertificate certify_ray(const Polynomial& polynomial, const std::vector<Monomial>& monomials, const Extent& extent,
                           const PixelRay& ray, Precision ray_precision) {
  RayCertificate c;
  if (!extent_interval(extent, ray, c.t_in, c.t_out)) return c;
  const long double eps = ray_precision != Precision::Double ? std::numeric_limits<float>::epsilon()
                                                             : std::numeric_limits<double>::epsilon();
  // Solve on the interval widened by the clipping margin, so a root the kernels' own clipping may just
  // include or exclude shows up as ambiguous instead of as a certified answer.
  const long double margin = kReferenceEndMargin * eps * std::max<long double>(c.t_out, 1);
  const ref::ExactRay exact{{ray.origin.x, ray.origin.y, ray.origin.z},
                            {ray.direction.x, ray.direction.y, ray.direction.z}};
  c.lo = exact_rational(static_cast<double>(std::max<long double>(0, c.t_in - margin)));
  c.hi = exact_rational(static_cast<double>(c.t_out + margin));
  c.width = exact_rational(kReferenceWidth * static_cast<double>(std::max<long double>(c.t_out, 1)));
  c.restricted = ref::restrict_exact(polynomial, exact);
  // The smallest root, and past a simple one the second: P* keeps its shape up to it, so beyond it nothing a small
  // move does changes the answer. One walk finds both.
  bool found = false;
  std::optional<ref::Answer> second;
  ref::for_each_root(c.restricted, c.lo, c.hi, c.width, [&](const ref::Answer& root) {
    if (found) {
      second = root;
      return false;
    }
    c.answer = root;
    found = true;
    return root.kind == ref::Classification::SimpleRoot;
  });
  c.cls = classify(c.answer.kind);
  if (c.answer.kind == ref::Classification::Miss) {
    if (flips_under_ray_rounding(c.restricted, monomials, ray, c.lo, c.hi, eps)) c.cls = PixelClass::RayRounding;
    return c;
  }
  const long double t = c.answer.t_nearest;
  if (t < c.t_in + margin || t > c.t_out - margin) c.cls = PixelClass::NearEnd;
  if (c.cls == PixelClass::SimpleRoot) {
    const mpq_class limit = second ? second->hi : c.hi;
    if (flips_under_ray_rounding(c.restricted, monomials, ray, c.lo, limit, eps)) c.cls = PixelClass::RayRounding;
  }
  return c;
}

ReferenceResult render_reference(const Scene& scene, Precision ray_precision, unsigned threads) {
  const int width = scene.image.width, height = scene.image.height;
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  ReferenceResult out;
  RenderResult& r = out.render;
  r.config = primary_config(scene, ray_precision);
  r.basis = make_ray_basis(scene.camera, width, height);
  // Primary rays only, one per pixel: the reference neither supersamples nor traces shadows.
  r.plan.width = width;
  r.plan.height = height;
  r.hits.width = width;
  r.hits.height = height;
  r.hits.records.assign(pixels, HitRecord{});
  out.classes.assign(pixels, static_cast<std::uint32_t>(PixelClass::OutsideExtent));
  out.t.assign(pixels, std::numeric_limits<double>::infinity());

  const bool single = ray_precision != Precision::Double;
  const std::vector<Monomial> monomials = scene.surface().polynomial.monomials();

  auto solve_pixel = [&](int px, int py) {
    const std::size_t i = static_cast<std::size_t>(py) * width + px;
    HitRecord& h = r.hits.records[i];
    h.t_hi = h.depth = std::numeric_limits<float>::infinity();
    const PixelRay ray = pixel_ray(r.basis, single, px, py);
    const RayCertificate c = certify_ray(scene.surface().polynomial, monomials, scene.extent, ray, ray_precision);
    out.classes[i] = static_cast<std::uint32_t>(c.cls);
    if (c.cls == PixelClass::OutsideExtent) return;
    h.flags = ALGRAY_HIT_IN_EXTENT;
    if (c.answer.kind == ref::Classification::Miss) return;
    const ref::Answer& a = c.answer;
    const long double t = a.t_nearest;
    out.t[i] = a.t_nearest;
    h.flags |= ALGRAY_HIT_FOUND;
    if (c.cls == PixelClass::EvenRoot) h.flags |= ALGRAY_HIT_TANGENT;
    h.t_hi = static_cast<float>(a.t_nearest);
    h.t_lo = static_cast<float>(a.t_nearest - static_cast<double>(h.t_hi));
    h.depth = static_cast<float>(a.t_nearest * glm::length(ray.direction));
    // Normal from the gradient of the exact polynomial, facing the viewer.
    const std::array<long double, 3> g = gradient_at(monomials, ray, t);
    const long double len = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    glm::dvec3 n = len > 0 ? glm::dvec3(double(g[0] / len), double(g[1] / len), double(g[2] / len))
                           : -glm::normalize(ray.direction);
    if (glm::dot(n, ray.direction) > 0) n = -n;
    h.normal_x = static_cast<float>(n.x);
    h.normal_y = static_cast<float>(n.y);
    h.normal_z = static_cast<float>(n.z);
    // The side: P has one sign on [t_in, root), the sign at the start (or, for a root there, of P' there).
    const mpq_class start = exact_rational(static_cast<double>(c.t_in));
    int before = sgn(evaluate(c.restricted, start));
    if (before == 0) {
      std::vector<mpq_class> derivative;
      for (std::size_t k = 1; k < c.restricted.size(); ++k)
        derivative.push_back(c.restricted[k] * static_cast<long>(k));
      before = -sgn(evaluate(derivative, start));
    }
    if (before < 0) h.flags |= ALGRAY_HIT_BACK;
  };

  const unsigned workers = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
  std::atomic<int> next_row{0};
  auto work = [&] {
    for (int py = next_row++; py < height; py = next_row++)
      for (int px = 0; px < width; ++px) solve_pixel(px, py);
  };
  std::vector<std::thread> pool;
  for (unsigned w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();

  PassStats pass;
  pass.name = "reference";
  pass.rays = pixels;
  r.passes.push_back(pass);
  return out;
}

ReferenceComparison compare_with_reference(const HitBuffer& kernel, const ReferenceResult& reference) {
  ReferenceComparison c;
  std::vector<double> errors;
  const int width = kernel.width, height = kernel.height;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width + x;
      const auto cls = static_cast<PixelClass>(reference.classes[i]);
      if (cls == PixelClass::OutsideExtent) continue;
      if (cls != PixelClass::Miss && cls != PixelClass::SimpleRoot) {
        ++c.ambiguous;
        c.ray_rounding += cls == PixelClass::RayRounding;
        continue;
      }
      ++c.certified;
      const HitRecord& h = kernel.records[i];
      const bool kernel_hit = (h.flags & ALGRAY_HIT_FOUND) != 0;
      if (kernel_hit != (cls == PixelClass::SimpleRoot)) {
        if (c.disagreements++ == 0) c.disagree_x = x, c.disagree_y = y;
        continue;
      }
      if (!kernel_hit) continue;
      const double t = static_cast<double>(h.t_hi) + static_cast<double>(h.t_lo);
      const double error = std::fabs(t - reference.t[i]) / std::fabs(reference.t[i]);
      errors.push_back(error);
      if (error > c.worst_depth || c.worst_x < 0) {
        c.worst_depth = error;
        c.worst_x = x;
        c.worst_y = y;
      }
    }
  }
  c.simple_hits = static_cast<long>(errors.size());
  if (!errors.empty()) {
    auto middle = errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2);
    std::nth_element(errors.begin(), middle, errors.end());
    c.median_depth = *middle;
  }
  return c;
}

}  // namespace algray
