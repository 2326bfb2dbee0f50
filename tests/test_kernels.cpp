// Kernel specialisations of every DEGREE and precision (a seeded sample, all when exhaustive) build and find a root.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "algray/device/program_cache.h"
#include "algray/render/render_plan.h"
#include "algray/render/renderer.h"
#include "algray/scene/scene.h"
#include "sweep.h"
#include "temp_dir.h"
#include "test_support.h"

using namespace algray;

namespace {

// (z + x/10)^D = a: seen from above by an orthographic camera, the first root on the ray through (x, y) is
// z = a^(1/D) - x/10, a surface that needs every monomial x^i z^(D-i) of the degree.
Scene degree_scene(int degree, const char* precision, const std::vector<Override>& solver = {}, int pixels = 5) {
  std::ostringstream toml;
  toml << "[surface]\nequation = \"(z + x/10)^" << degree << " - a\"\n"
       << "[parameters]\na = 0.3\n"
       << "[extent]\nradius = 1.5\n"
       << "[camera]\nprojection = \"orthographic\"\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nheight = 2\n"
       << "[image]\nwidth = " << pixels << "\nheight = " << pixels << "\n"
       << "[render]\nprecision = \"" << precision << "\"\ntolerance = 1e-12\n";
  return load_scene_text(toml.str(), "degree" + std::to_string(degree) + ".toml", solver);
}

// Orthographic rays start on the plane z = 3 and run along -z with unit length, so the hit is at t = 3 - z.
// Every pixel inside the extent is checked; the failures are counted and the first is described.
void check_known_root(const RenderResult& result, int degree, const std::string& precision, int pixels = 5) {
  const double root = std::pow(0.3, 1.0 / degree);
  const double width = 2.0, pixel = width / pixels;
  // Float: the polynomial's coefficients carry about D * 2^-24 relative error, magnified by the flat D-th power
  // near its root. Double: the 1e-12 stopping width plus rounding.
  const double allowed = precision == "double" ? 1e-9 : 2e-4 * degree;
  int checked = 0, failed = 0;
  std::string first_failure;
  for (int py = 0; py < pixels; ++py) {
    for (int px = 0; px < pixels; ++px) {
      const HitRecord& h = result.hits.at(px, py);
      const double x = -width / 2 + (px + 0.5) * pixel;
      const double y = width / 2 - (py + 0.5) * pixel;
      const double z = root - x / 10;
      if (x * x + y * y + z * z >= 1.5 * 1.5) continue;  // outside the extent
      ++checked;
      const bool hit = (h.flags & ALGRAY_HIT_FOUND) != 0;
      const double t = static_cast<double>(h.t_hi) + static_cast<double>(h.t_lo);
      // The normal of (z + x/10)^D = a points along (1/10, 0, 1), towards the camera.
      const bool good = hit && std::fabs(t - (3 - z)) <= allowed && h.normal_z > 0.99f &&
                        std::fabs(h.normal_x - 0.1f / std::sqrt(1.01f)) < 1e-3f;
      if (good) continue;
      if (failed++ == 0) {
        std::ostringstream what;
        what << "pixel " << px << "," << py << ": " << (hit ? "hit" : "miss") << ", depth error "
             << std::fabs(t - (3 - z)) << " (allowed " << allowed << "), normal (" << h.normal_x << ", " << h.normal_z
             << ")";
        first_failure = what.str();
      }
    }
  }
  INFO(failed << " of " << checked << " pixels wrong; the first: " << first_failure);
  CHECK(checked > 0);
  CHECK(failed == 0);
}

}  // namespace

// Every specialisation under the `exhaustive` label; on other runs each precision's degree ends (1, 2, its
// largest) and a seeded sample of the degrees between. Degree 32 in double or float, drawn (both when exhaustive):
// its programs are the suite's costliest to compile (PoCL, cold: double's 6 s, float's 13 with its second pass),
// and test_kernel_portability compiles every configuration of it on every run.
TEST_CASE("every DEGREE from 1 to 32 builds and finds the smallest root, in float and double", "[kernels]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  const std::vector<Precision> top = testing::sampled_choices<Precision>(
      "test_kernels precision at degree 32 (0 double, 1 float)", {Precision::Double, Precision::Float}, 1);
  for (const NamedChoice<Precision>& choice : kPrecisions) {
    const char* const precision = choice.name;
    if (std::string(precision) == "double" && !session.info.fp64) FAIL("the test device lacks fp64");
    // Mixed precision, and adaptive, which escalates to it, exist up to degree 15 (kMaxMixedDegree); the scene
    // layer refuses them above.
    const bool compensated = choice.value == Precision::Mixed || choice.value == Precision::Adaptive;
    const int max_degree = compensated ? kMaxMixedDegree : 32;
    for (int degree : testing::sampled_degrees(std::string("test_kernels ") + precision + " degrees", max_degree, 2)) {
      if (degree == 32 && std::find(top.begin(), top.end(), choice.value) == top.end()) continue;
      INFO("DEGREE=" << degree << " precision=" << precision);
      const Scene scene = degree_scene(degree, precision);
      REQUIRE(scene.surface().polynomial.degree() == degree);
      RenderResult result;
      REQUIRE_NOTHROW(result = renderer.render_with_records(scene));  // a BuildError prints the options and the log
      // Adaptive, and float where it takes adaptive's kernels (float_measures_noise), with their second pass.
      const bool escalates =
          choice.value == Precision::Adaptive || (choice.value == Precision::Float && float_measures_noise(scene));
      // The camera rays' kernel (and the second pass's), then the shading kernel.
      REQUIRE(result.programs.size() == (escalates ? 3u : 2u));
      CHECK(result.programs.back().key.rfind("shade ", 0) == 0);
      // compiled from source in this process: now, or for an earlier case with the same program (adaptive's
      // lowest degrees run float's kernels)
      CHECK(result.programs[0].origin != "disk");
      check_known_root(result, degree, precision);
    }
  }
}

TEST_CASE("a program cache without a directory keeps programs in memory and writes no file", "[kernels][cache]") {
  ClSession& session = testing::device_session();
  // Entries would land in the working directory (an empty directory joined to a name), so work in an empty one.
  const testing::TempDir work("memory-cache");
  const std::filesystem::path was = std::filesystem::current_path();
  std::filesystem::current_path(work.path());
  ProgramCache memory_only(true, {});
  Renderer renderer(session, memory_only);
  const Scene scene = degree_scene(2, "double");
  const RenderResult first = renderer.render_with_records(scene);
  const RenderResult again = renderer.render_with_records(scene);
  int measured = 0;
  memory_only.remembered(session.info, "test-measurement", [&] { return ++measured, 1.0; });
  memory_only.remembered(session.info, "test-measurement", [&] { return ++measured, 2.0; });
  std::filesystem::current_path(was);
  REQUIRE(!first.programs.empty());
  CHECK(first.programs[0].origin == "built");
  REQUIRE(again.programs.size() == first.programs.size());
  for (const ProgramRecord& p : again.programs) CHECK(p.origin == "memory");
  CHECK(measured == 1);
  CHECK(work.entries().empty());
}

TEST_CASE("the paper's power-basis method and plain bisection build and find the same root", "[kernels]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  const std::vector<std::vector<Override>> solvers = {
      {{"render.isolation", "descartes"}, {"render.ray_origin", "eye"}},
      {{"render.isolation", "descartes"}},
      {{"render.refinement", "bisection"}},
  };
  // A spread of degrees: every specialisation of the default method is built by the test above. The power
  // basis loses about log10((|p| + |d|)^D) digits, p and d the expansion point and the segment in extent
  // units. Around the eye (the paper's construction, two radii out) that measured depth errors of 2e-8 at
  // degree 13 and missed roots from degree 21; around the entry point, errors of 1e-3 at degree 21. Each is
  // held to the range where it works: the eye to the paper's decic, the entry point to degree 16.
  for (const auto& solver : solvers) {
    const bool power = solver.front().value == "descartes", eye = solver.size() > 1;
    std::vector<int> degrees;
    for (int degree : {1, 2, 3, 5, 8, 10, 13, 16, 21, 32})
      if (!(eye && degree > 10) && !(power && degree > 16)) degrees.push_back(degree);
    const std::string name = solver.front().value + (eye ? " from the eye" : "");
    for (int degree : testing::sampled("test_kernels " + name + " degrees", degrees, {1, 2, degrees.back()}, 2)) {
      INFO("DEGREE=" << degree << " solver=" << solver.front().key << "=" << solver.front().value
                     << (eye ? " ray_origin=eye" : ""));
      const Scene scene = degree_scene(degree, "double", solver);
      RenderResult result;
      REQUIRE_NOTHROW(result = renderer.render_with_records(scene));
      check_known_root(result, degree, "double");
    }
  }
}

TEST_CASE("power-basis isolation refines a wide bracket to the stopping width at high degree", "[kernels]") {
  // On (z + x/10)^D = a the power-basis methods bracket the root on most of the segment, where the
  // coefficients are far larger than the terms near the root: a value stop scaled by the largest coefficient
  // stopped early there (refine.h), from degree 13 for the derivative chain in double. 64 x 64 rays per case.
  // Each method is held to the degrees where its power basis keeps enough digits (measured: above them, in
  // double, 4% to 20% of pixels 1.1e-9 to 1.8e-9 deep at degree 28 for Descartes and Sturm, and wrong roots
  // for the derivative chain; in float, wrong roots from degree 17, and from 13 for the derivative chain).
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  for (const char* precision : {"float", "double"}) {
    if (std::string(precision) == "double" && !session.info.fp64) FAIL("the test device lacks fp64");
    for (const NamedChoice<Isolation>& choice : kIsolations) {
      if (!isolates_in_power_basis(choice.value)) continue;
      const char* const isolation = choice.name;
      const bool is_double = std::string(precision) == "double", chain = std::string(isolation) == "derivative-chain";
      const int max_degree = is_double ? 24 : chain ? 9 : 13;
      std::vector<int> degrees;
      for (int degree : {5, 9, 13, 17, 21, 24})
        if (degree <= max_degree) degrees.push_back(degree);
      for (int degree : testing::sampled(std::string("test_kernels wide brackets ") + isolation + " " + precision,
                                         degrees, {degrees.front(), degrees.back()}, 1)) {
        INFO("DEGREE=" << degree << " isolation=" << isolation << " precision=" << precision);
        const Scene scene = degree_scene(degree, precision, {{"render.isolation", isolation}}, 64);
        RenderResult result;
        REQUIRE_NOTHROW(result = renderer.render_with_records(scene));
        check_known_root(result, degree, precision, 64);
      }
    }
  }
}
