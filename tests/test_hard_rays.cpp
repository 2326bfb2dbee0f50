// Hard rays on real surfaces: nodes, tangent rays, the cusp, Fig. 8's torus case, high degrees (issue 3).
// Each ray is the single pixel of a 1x1 orthographic view, so the kernel and the reference see the same ray.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "algray/device/program_cache.h"
#include "algray/render/reference_render.h"
#include "algray/render/renderer.h"
#include "algray/scene/scene.h"
#include "solver_ref/solver_ref.h"
#include "test_support.h"

using namespace algray;

namespace {

std::string vec(const glm::dvec3& v) {
  std::ostringstream s;
  s.precision(17);
  s << "[" << v.x << ", " << v.y << ", " << v.z << "]";
  return s.str();
}

struct RaySolve {
  HitRecord kernel;
  ref::Answer reference;
  PixelRay ray;
  double t_in = 0, t_out = 0;
};

// The scene file's text without its perspective field of view, so the camera can become orthographic.
std::string scene_without_fov(const std::string& file) {
  std::ifstream in(std::string(ALGRAY_SOURCE_DIR) + "/scenes/" + file);
  std::string line, text;
  while (std::getline(in, line))
    if (line.rfind("fov_y", 0) != 0) text += line + "\n";
  return text;
}

// One renderer for the whole file: the rays below share a few programs.
Renderer& renderer() {
  static Renderer r(testing::device_session(), testing::program_cache());
  return r;
}

// The ray from `from` towards `to` as the only pixel of a 1x1 orthographic view, solved by the kernel and by
// the reference over the same extent interval the reference images use.
RaySolve solve(const std::string& file, const glm::dvec3& from, const glm::dvec3& to,
               const glm::dvec3& up = {0, 1, 0}) {
  const Scene scene = load_scene_text(scene_without_fov(file), file,
                                      {{"camera.projection", "\"orthographic\""},
                                       {"camera.height", "1"},
                                       {"camera.eye", vec(from)},
                                       {"camera.look_at", vec(to)},
                                       {"camera.up", vec(up)},
                                       {"image.width", "1"},
                                       {"image.height", "1"},
                                       {"antialias.samples", "1"},
                                       {"render.preview", "true"},
                                       {"render.precision", "\"double\""}});
  RaySolve r;
  const RenderResult result = renderer().render_with_records(scene);
  r.kernel = result.hits.records[0];
  r.ray = pixel_ray(result.basis, false, 0, 0);
  long double t_in = 0, t_out = 0;
  REQUIRE(extent_interval(scene.extent, r.ray, t_in, t_out));
  r.t_in = static_cast<double>(t_in);
  r.t_out = static_cast<double>(t_out);
  const glm::dvec3 o = r.ray.origin, d = r.ray.direction;
  r.reference = ref::smallest_root(scene.surface().polynomial, ref::ExactRay{{o.x, o.y, o.z}, {d.x, d.y, d.z}},
                                   exact_rational(r.t_in), exact_rational(r.t_out), mpq_class(1, 1000000000000L));
  return r;
}

double kernel_t(const HitRecord& h) { return static_cast<double>(h.t_hi) + static_cast<double>(h.t_lo); }

// The reference's answer for a ray that touches the surface: a double root, without a sign change, at t.
void check_double_root(const RaySolve& s, double t) {
  CHECK(s.reference.kind == ref::Classification::EvenRootNoSignChange);
  CHECK(s.reference.multiplicity == 2);
  CHECK(s.reference.t_nearest == Approx(t).margin(1e-12));
}

}  // namespace

TEST_CASE("rays through nodes meet a double root", "[hard-rays]") {
  // Axis-aligned rays are exact, so these pass exactly through the nodes. The Cayley cubic along z through its
  // node (1, 1, -1): P = (z + 1)^2, a double root without a sign change.
  const RaySolve cayley = solve("cayley_cubic.toml", glm::dvec3(1, 1, 1), glm::dvec3(1, 1, -3));
  INFO("Cayley: reference " << ref::to_string(cayley.reference.kind) << " at " << cayley.reference.t_nearest);
  check_double_root(cayley, 2);
  if (cayley.kernel.flags & ALGRAY_HIT_FOUND) CHECK(kernel_t(cayley.kernel) == Approx(2).margin(1e-6));
  // The lemniscate's node at the origin along x: P = x^2 (x^2 - 2 a^2), negative on both sides of 0; the
  // kernel goes on to the far lobe at x = -a sqrt 2 unless rounding noise stops it at the node.
  const RaySolve lemniscate = solve("lemniscate.toml", glm::dvec3(1, 0, 0), glm::dvec3(-4, 0, 0));
  INFO("lemniscate: reference " << ref::to_string(lemniscate.reference.kind) << " at "
                                << lemniscate.reference.t_nearest);
  CHECK(lemniscate.reference.kind == ref::Classification::EvenRootNoSignChange);
  CHECK(lemniscate.reference.t_nearest == Approx(1).margin(1e-12));
  REQUIRE((lemniscate.kernel.flags & ALGRAY_HIT_FOUND) != 0);
  const double x_hit = 1 - kernel_t(lemniscate.kernel);
  INFO("kernel at x = " << x_hit);
  CHECK((std::fabs(x_hit) < 1e-6 || std::fabs(x_hit + 2.7 * std::sqrt(2.0)) < 1e-8));
}

TEST_CASE("rays through a node of the Barth sextic and of the Kummer quartic", "[hard-rays]") {
  // Most of their nodes are irrational points, which the scenes' rounded constants move off any exact ray. These
  // two stay exact. Barth: (1, 0, 0) is a node for every value of phi (both terms vanish to second order), and
  // along the x axis P = -(1 + 2 phi)(x^2 - 1)^2, so the ray from x = 3 touches at x = 1 and x = -1 without
  // crossing. Kummer: on x = 0, z = 1 the planes p and q both vanish exactly, so along y P = (y^2 - 5/4)^2: a
  // double root at the node (0, sqrt(5)/2, 1), irrational but exactly double.
  const RaySolve barth = solve("barth_sextic.toml", glm::dvec3(3, 0, 0), glm::dvec3(-3, 0, 0));
  INFO("Barth: reference " << ref::to_string(barth.reference.kind) << " at " << barth.reference.t_nearest);
  check_double_root(barth, 2);
  // Invisible on the true surface; rounding noise may stop the kernel at one of the two touching points.
  if (barth.kernel.flags & ALGRAY_HIT_FOUND) {
    const double x_hit = 3 - kernel_t(barth.kernel);
    INFO("kernel at x = " << x_hit);
    CHECK((std::fabs(x_hit - 1) < 1e-6 || std::fabs(x_hit + 1) < 1e-6));
  }
  const RaySolve kummer = solve("kummer.toml", glm::dvec3(0, 2.5, 1), glm::dvec3(0, -2.5, 1), {0, 0, 1});
  INFO("Kummer: reference " << ref::to_string(kummer.reference.kind) << " at " << kummer.reference.t_nearest);
  check_double_root(kummer, 2.5 - std::sqrt(1.25));
  if (kummer.kernel.flags & ALGRAY_HIT_FOUND) {
    const double y_hit = 2.5 - kernel_t(kummer.kernel);
    INFO("kernel at y = " << y_hit);
    CHECK(std::fabs(std::fabs(y_hit) - std::sqrt(1.25)) < 1e-6);
  }
}

TEST_CASE("a ray through the tooth's isolated point touches without crossing and stays invisible", "[hard-rays]") {
  // x^4+y^4+z^4-(x^2+y^2+z^2) is negative all around the origin: along the z axis P* = z^4 - z^2. From
  // z = 1/2 down (an axis-aligned ray, so it is exact) the origin is the first root, of even multiplicity.
  const RaySolve s = solve("tooth.toml", glm::dvec3(0, 0, 0.5), glm::dvec3(0, 0, -0.5));
  INFO("reference " << ref::to_string(s.reference.kind) << " at " << s.reference.t_nearest);
  check_double_root(s, 0.5);
  // The kernel's rounded polynomial may dip across zero there by rounding noise; otherwise it passes through
  // to the far side of the tooth at z = -1.
  REQUIRE((s.kernel.flags & ALGRAY_HIT_FOUND) != 0);
  const double t = kernel_t(s.kernel);
  INFO("kernel at " << t);
  CHECK((std::fabs(t - 0.5) < 1e-6 || std::fabs(t - 1.5) < 1e-9));
}

TEST_CASE("a ray tangent to the torus along the top of its tube touches without crossing", "[hard-rays]") {
  // At z = r = 0.9 the torus equation is (x^2 + y^2 - a^2)^2: double roots at x = -2.5 and 2.5.
  const RaySolve s = solve("torus.toml", glm::dvec3(-3.4, 0, 0.9), glm::dvec3(3.4, 0, 0.9));
  INFO("reference " << ref::to_string(s.reference.kind) << " at " << s.reference.t_nearest);
  CHECK(s.reference.kind == ref::Classification::EvenRootNoSignChange);
  CHECK(s.reference.multiplicity == 2);
  CHECK(s.ray.origin.x + s.reference.t_nearest * s.ray.direction.x == Approx(-2.5).margin(1e-9));
  // Touching rays are invisible on the true surface; the kernel's rounded polynomial may dip across zero by
  // rounding noise, but only right at the touching point.
  if (s.kernel.flags & ALGRAY_HIT_FOUND)
    CHECK(s.ray.origin.x + kernel_t(s.kernel) * s.ray.direction.x == Approx(-2.5).margin(1e-6));
}

TEST_CASE("the cusp catastrophe: a double root on the fold and a triple root at the cusp", "[hard-rays]") {
  // Through the fold point z0 = 1/2 (x0 = -3 z0^2, y0 = 2 z0^3) along z: P = (z - 1/2)^2 (z + 1).
  const RaySolve fold = solve("cusp_catastrophe.toml", glm::dvec3(-0.75, 0.25, 2), glm::dvec3(-0.75, 0.25, -2));
  INFO("fold: reference " << ref::to_string(fold.reference.kind) << " at " << fold.reference.t_nearest);
  CHECK(fold.reference.kind == ref::Classification::EvenRootNoSignChange);
  CHECK(fold.ray.origin.z + fold.reference.t_nearest * fold.ray.direction.z == Approx(0.5).margin(1e-9));
  // The kernel sees through the touching point to the crossing at z = -1, or, by rounding noise, stops at it.
  REQUIRE((fold.kernel.flags & ALGRAY_HIT_FOUND) != 0);
  const double z_hit = fold.ray.origin.z + kernel_t(fold.kernel) * fold.ray.direction.z;
  INFO("kernel at z = " << z_hit);
  CHECK((std::fabs(z_hit - 0.5) < 1e-6 || std::fabs(z_hit + 1) < 1e-7));
  // Along z through the origin P = z^3: a triple root, which crosses and must be found.
  const RaySolve cusp = solve("cusp_catastrophe.toml", glm::dvec3(0, 0, 2), glm::dvec3(0, 0, -2));
  INFO("cusp: reference " << ref::to_string(cusp.reference.kind) << " at " << cusp.reference.t_nearest);
  CHECK(cusp.reference.kind == ref::Classification::MultipleRootOddSignChange);
  CHECK(cusp.reference.multiplicity == 3);
  REQUIRE((cusp.kernel.flags & ALGRAY_HIT_FOUND) != 0);
  CHECK(cusp.ray.origin.z + kernel_t(cusp.kernel) * cusp.ray.direction.z == Approx(0).margin(1e-4));
}

TEST_CASE("Fig. 8: where Newton from the left end catches the second root, the kernel keeps the first", "[hard-rays]") {
  // Rays from the camera sphere (radius 3R) whose P*(t) has the shape of the paper's Fig. 8(a): found by a
  // seeded scan of random rays, each confirmed below by running Newton's method.
  const std::vector<std::pair<glm::dvec3, glm::dvec3>> rays = {{{-1.316, 9.08, 5.106}, {-0.308, -1.21, -0.047}},
                                                               {{10.002, 1.496, -2.824}, {-0.538, -2.121, -0.704}},
                                                               {{-7.449, -4.452, -5.91}, {1.248, 1.979, 0.556}},
                                                               {{9.346, -0.73, -4.729}, {-2.242, 0.816, 0.056}},
                                                               {{-8.717, 0.4, 5.84}, {0.954, 1.011, 0.233}}};
  int found = 0;
  for (const auto& [from, to] : rays) {
    const RaySolve s = solve("torus.toml", from, to, {0, 0, 1});
    if (s.reference.kind != ref::Classification::SimpleRoot) continue;
    // Newton on the exact polynomial, in long double, from the left end of the interval.
    const glm::dvec3 o = s.ray.origin, d = s.ray.direction;
    const std::vector<mpq_class> p =
        ref::restrict_exact(load_scene_file(std::string(ALGRAY_SOURCE_DIR) + "/scenes/torus.toml").surface().polynomial,
                            ref::ExactRay{{o.x, o.y, o.z}, {d.x, d.y, d.z}});
    long double t = s.t_in;
    for (int it = 0; it < 100; ++it) {
      long double v = 0, dv = 0;
      for (std::size_t k = p.size(); k-- > 0;) {
        dv = dv * t + v;
        v = v * t + static_cast<long double>(p[k].get_d());
      }
      t -= v / dv;
    }
    if (!(std::fabs(static_cast<double>(t) - s.reference.t_nearest) > 1e-3)) continue;
    ++found;
    INFO("ray from " << vec(from) << ": Newton from t_in ends at " << double(t) << ", the smallest root is "
                     << s.reference.t_nearest);
    REQUIRE((s.kernel.flags & ALGRAY_HIT_FOUND) != 0);
    CHECK(kernel_t(s.kernel) == Approx(s.reference.t_nearest).epsilon(1e-9));
  }
  CHECK(found >= 3);  // the situation of Fig. 8 was met
}

TEST_CASE("high-degree rays agree with the reference", "[hard-rays]") {
  struct Case {
    const char* file;
    glm::dvec3 from, to;
  };
  const std::vector<Case> cases = {
      {"barth_decic.toml", {1.9, 0.7, 0.3}, {-0.2, 0.1, -0.05}},
      {"barth_decic.toml", {0.05, 2.0, 0.6}, {0.0, -0.5, -0.1}},
      {"chebyshev_nonic.toml", {1.5, 1.2, 0.9}, {-0.3, -0.2, -0.1}},
      {"endrass_octic.toml", {4.1, 0.9, 0.4}, {-1.0, 0.2, 0.1}},
      {"endrass_octic.toml", {0.2, 3.9, 1.5}, {0.1, -1.0, 0.2}},
  };
  for (const Case& c : cases) {
    const RaySolve s = solve(c.file, c.from, c.to);
    INFO(c.file << ": reference " << ref::to_string(s.reference.kind) << " at " << s.reference.t_nearest);
    REQUIRE((s.reference.kind == ref::Classification::SimpleRoot || s.reference.kind == ref::Classification::Miss));
    REQUIRE(((s.kernel.flags & ALGRAY_HIT_FOUND) != 0) == (s.reference.kind == ref::Classification::SimpleRoot));
    if (s.reference.kind == ref::Classification::SimpleRoot)
      CHECK(kernel_t(s.kernel) == Approx(s.reference.t_nearest).epsilon(1e-9));
  }
}
