// Every scene in scenes/, rendered small in float and double, agrees with an independent CPU check in long double.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "algray/device/program_cache.h"
#include "algray/render/renderer.h"
#include "algray/scene/scene.h"
#include "test_support.h"

using namespace algray;

namespace {

using Real = long double;

// Named tolerances of this check. The kernels' rounding errors scale with the size of P along the whole ray
// segment, since P*(t) is built for the segment at once: ray_scale = max over [t_in, t_out] of sum |monomials|
// (for the paper's construction around the eye, the size of its power-basis terms instead).
// A hit may miss the root by the stopping width w = 4 tol max(t, 1), which moves P by about w |dP/dt|.
//   residual:     |P(hit)| <= factor * (degree * eps * ray_scale + w * sum |d monomial / dt|)
//   significance: a sample's sign counts only where |P| > factor * degree * eps * ray_scale
constexpr Real kResidualFactor = 16;
constexpr Real kSignificanceFactor = 16;
constexpr Real kEndMarginFactor = 256;  // scans stay this many eps * max(t, 1) inside [t_in, t_out]
constexpr int kScanSamples = 2000;
constexpr int kSampledHits = 80, kSampledMisses = 80;
constexpr int kWidth = 80, kHeight = 60;
constexpr unsigned kSeed = 20261122;
const std::set<std::string> kPaperSurfaces = {"barth_sextic", "cusp_catastrophe", "torus",     "tooth",
                                              "lemniscate",   "barth_decic",      "tanglecube"};

struct Vec {
  Real x, y, z;
};
Vec at(const Vec& o, const Vec& d, Real t) { return {o.x + t * d.x, o.y + t * d.y, o.z + t * d.z}; }

// docs/outputs.md's ray convention, evaluated in the kernel's precision R, each operation rounded, no fused ops.
template <typename R>
void rebuild_ray(const RayBasis& b, int px, int py, Vec& o, Vec& d) {
  const R fx = static_cast<R>(px) + R(0.5), fy = static_cast<R>(py) + R(0.5);
  auto axis = [&](const glm::dvec3& a00, const glm::dvec3& au, const glm::dvec3& av, int i) {
    const volatile R x_part = fx * static_cast<R>(au[i]);  // volatile: keep each product rounded on its own
    const volatile R y_part = fy * static_cast<R>(av[i]);
    const volatile R sum = static_cast<R>(a00[i]) + x_part;
    return static_cast<Real>(static_cast<R>(sum + y_part));
  };
  o = {axis(b.o00, b.ou, b.ov, 0), axis(b.o00, b.ou, b.ov, 1), axis(b.o00, b.ou, b.ov, 2)};
  d = {axis(b.d00, b.du, b.dv, 0), axis(b.d00, b.du, b.dv, 1), axis(b.d00, b.du, b.dv, 2)};
}

// [t_in, t_out] of the ray in the extent, in world coordinates, independently of the kernels' unit coordinates.
bool clip(const Extent& e, const Vec& o, const Vec& d, Real& t_in, Real& t_out) {
  if (e.kind == ExtentKind::Sphere) {
    const Vec oc{o.x - e.centre.x, o.y - e.centre.y, o.z - e.centre.z};
    const Real a = d.x * d.x + d.y * d.y + d.z * d.z;
    const Real b = oc.x * d.x + oc.y * d.y + oc.z * d.z;
    const Real c = oc.x * oc.x + oc.y * oc.y + oc.z * oc.z - Real(e.radius) * e.radius;
    const Real disc = b * b - a * c;
    if (disc <= 0) return false;
    t_in = std::max<Real>(0, (-b - std::sqrt(disc)) / a);
    t_out = (-b + std::sqrt(disc)) / a;
  } else {
    t_in = 0;
    t_out = std::numeric_limits<Real>::max();
    const Real os[3] = {o.x, o.y, o.z}, ds[3] = {d.x, d.y, d.z};
    for (int i = 0; i < 3; ++i) {
      const Real t0 = (e.min[i] - os[i]) / ds[i], t1 = (e.max[i] - os[i]) / ds[i];
      t_in = std::max(t_in, std::min(t0, t1));
      t_out = std::min(t_out, std::max(t0, t1));
    }
  }
  return t_out > t_in;
}

struct Evaluation {
  Real value;      // P(p)
  Real magnitude;  // sum of |monomials| at p
  Real slope;      // sum of |d monomial / dt| along direction d
};

Evaluation evaluate(const std::vector<Monomial>& poly, const Vec& p, const Vec& d) {
  Real px[kMaxDegree + 1], py[kMaxDegree + 1], pz[kMaxDegree + 1];
  px[0] = py[0] = pz[0] = 1;
  for (int n = 1; n <= kMaxDegree; ++n) {
    px[n] = px[n - 1] * p.x;
    py[n] = py[n - 1] * p.y;
    pz[n] = pz[n - 1] * p.z;
  }
  Evaluation e{0, 0, 0};
  for (const Monomial& m : poly) {
    const Real term = m.coef * px[m.i] * py[m.j] * pz[m.k];
    e.value += term;
    e.magnitude += std::fabs(term);
    const Real dx = m.i ? m.i * px[m.i - 1] * d.x * py[m.j] * pz[m.k] : 0;
    const Real dy = m.j ? m.j * px[m.i] * py[m.j - 1] * d.y * pz[m.k] : 0;
    const Real dz = m.k ? m.k * px[m.i] * py[m.j] * pz[m.k - 1] * d.z : 0;
    e.slope += std::fabs(m.coef) * (std::fabs(dx) + std::fabs(dy) + std::fabs(dz));
  }
  return e;
}

// P sampled densely along the ray segment [a, b].
struct Scan {
  std::vector<Real> t, value;
  Real scale = 0;  // largest sum of |monomials| met
};

Scan scan(const std::vector<Monomial>& poly, const Vec& o, const Vec& d, Real a, Real b) {
  Scan s;
  for (int i = 0; i <= kScanSamples; ++i) {
    const Real t = a + (b - a) * i / kScanSamples;
    const Evaluation e = evaluate(poly, at(o, d, t), d);
    s.t.push_back(t);
    s.value.push_back(e.value);
    s.scale = std::max(s.scale, e.magnitude);
  }
  return s;
}

// The size of P*(t) = P(o + t d) built in the power basis around the ray origin, as the paper does:
// sum |c_k| t_out^k. Rounding errors of that construction scale with it, not with |P| along the segment.
Real origin_power_scale(const std::vector<Monomial>& poly, const Vec& o, const Vec& d, Real t_out) {
  std::vector<Real> c(kMaxDegree + 1, 0);
  for (const Monomial& m : poly) {
    std::vector<Real> term(kMaxDegree + 1, 0);
    term[0] = m.coef;
    int degree = 0;
    const Real o3[3] = {o.x, o.y, o.z}, d3[3] = {d.x, d.y, d.z};
    const int e3[3] = {m.i, m.j, m.k};
    for (int axis = 0; axis < 3; ++axis)
      for (int r = 0; r < e3[axis]; ++r, ++degree)
        for (int k = degree + 1; k >= 0; --k) term[k] = o3[axis] * term[k] + (k ? d3[axis] * term[k - 1] : 0);
    for (int k = 0; k <= degree; ++k) c[k] += term[k];
  }
  Real scale = 0, power = 1;
  for (int k = 0; k <= kMaxDegree; ++k, power *= t_out) scale += std::fabs(c[k]) * power;
  return scale;
}

// Sign changes of P before t_limit, between samples whose |P| exceeds `noise`.
int significant_sign_changes(const Scan& s, Real t_limit, Real noise) {
  int changes = 0, last = 0;
  for (std::size_t i = 0; i < s.t.size() && s.t[i] < t_limit; ++i) {
    if (std::fabs(s.value[i]) <= noise) continue;
    const int sign = s.value[i] > 0 ? 1 : -1;
    if (last != 0 && sign != last) ++changes;
    last = sign;
  }
  return changes;
}

}  // namespace

TEST_CASE("each scene agrees with an independent CPU check on a seeded sample of pixels", "[scenes]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  const std::vector<std::filesystem::path> files = testing::scene_files();
  REQUIRE(files.size() >= 12);

  for (const auto& file : files) {
    // The default method in both precisions; the paper's own (power basis around the eye) in double on the
    // paper's surfaces, the range it was made for.
    std::vector<std::pair<std::string, std::vector<Override>>> configurations = {
        {"default double", {{"render.precision", "double"}}}, {"default float", {{"render.precision", "float"}}}};
    if (kPaperSurfaces.count(file.stem().string()))
      configurations.push_back(
          {"paper double",
           {{"render.precision", "double"}, {"render.isolation", "descartes"}, {"render.ray_origin", "eye"}}});
    for (const auto& [label, solver] : configurations) {
      const char* precision = label.c_str();
      const bool around_eye = label == "paper double";
      // One primary ray per pixel, as the checks below assume; no shadow pass, which they do not look at.
      std::vector<Override> overrides = {{"image.width", std::to_string(kWidth)},
                                         {"image.height", std::to_string(kHeight)},
                                         {"antialias.samples", "1"},
                                         {"render.preview", "true"}};
      overrides.insert(overrides.end(), solver.begin(), solver.end());
      const Scene scene = load_scene_file(file.string(), overrides);
      const RenderResult result = renderer.render_with_records(scene);
      const bool is_double = result.config.precision == Precision::Double;
      const Real eps = is_double ? std::numeric_limits<double>::epsilon() : std::numeric_limits<float>::epsilon();
      const Real degree = scene.surface().polynomial.degree();
      const Real tol = std::max<Real>(result.config.tolerance, eps);
      const std::vector<Monomial> poly = scene.surface().polynomial.monomials();

      // A seeded sample of hit pixels and of pixels whose ray crosses the extent without a hit.
      std::vector<int> hits, misses;
      for (int i = 0; i < kWidth * kHeight; ++i) {
        const HitRecord& h = result.hits.records[static_cast<std::size_t>(i)];
        if (h.flags & ALGRAY_HIT_FOUND)
          hits.push_back(i);
        else if (h.flags & ALGRAY_HIT_IN_EXTENT)
          misses.push_back(i);
      }
      std::mt19937 rng(kSeed);
      std::shuffle(hits.begin(), hits.end(), rng);
      std::shuffle(misses.begin(), misses.end(), rng);
      hits.resize(std::min<std::size_t>(hits.size(), kSampledHits));
      misses.resize(std::min<std::size_t>(misses.size(), kSampledMisses));
      CHECK(hits.size() >= 10);  // every scene shows its surface

      int checked = 0;
      for (const std::vector<int>* set : {&hits, &misses}) {
        for (std::size_t n = 0; n < set->size(); ++n) {
          const int index = (*set)[n];
          const int px = index % kWidth, py = index / kWidth;
          const HitRecord& h = result.hits.records[static_cast<std::size_t>(index)];
          Vec o, d;
          if (is_double)
            rebuild_ray<double>(result.basis, px, py, o, d);
          else
            rebuild_ray<float>(result.basis, px, py, o, d);
          Real t_in = 0, t_out = 0;
          const bool crosses = clip(scene.extent, o, d, t_in, t_out);
          INFO(file.filename().string() << " precision=" << precision << " seed=" << kSeed << " case "
                                        << (set == &hits ? "hit" : "miss") << " #" << n << " pixel (" << px << "," << py
                                        << ") t_in=" << double(t_in) << " t_out=" << double(t_out));
          REQUIRE(crosses);
          const Real end_margin = kEndMarginFactor * eps * std::max<Real>(t_out, 1);
          const Scan samples = scan(poly, o, d, t_in + end_margin, t_out - end_margin);
          const Real size = around_eye ? origin_power_scale(poly, o, d, t_out) : samples.scale;
          const Real noise = kSignificanceFactor * degree * eps * size;
          if (set == &hits) {
            const Real t = static_cast<Real>(h.t_hi) + static_cast<Real>(h.t_lo);
            INFO("t=" << double(t));
            CHECK(t >= t_in - end_margin);
            CHECK(t <= t_out + end_margin);
            const Evaluation e = evaluate(poly, at(o, d, t), d);
            const Real stop_width = 4 * tol * std::max<Real>(t, 1);
            INFO("P(hit)=" << double(e.value) << " noise=" << double(noise) << " slope=" << double(e.slope));
            CHECK(std::fabs(e.value) <= noise + kResidualFactor * stop_width * e.slope);
            // The root may sit a stopping width either side of t.
            const Real root_margin = 4 * stop_width + end_margin;
            CHECK(significant_sign_changes(samples, t - root_margin, noise) == 0);
          } else {
            CHECK(significant_sign_changes(samples, t_out, noise) == 0);
          }
          ++checked;
        }
      }
      CHECK(checked > 0);
    }
  }
}
