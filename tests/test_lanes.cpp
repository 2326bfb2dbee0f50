// The primary and trace kernels at lane widths 2 to 16 (render.lanes, kernels/lanes.h) against width 1, the one-ray
// build of the same code: the same hit records bit for bit, on seeded random surfaces, in every precision and with
// partial lane groups.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstring>
#include <string>
#include <vector>

#include "algray/device/program_cache.h"
#include "algray/render/renderer.h"
#include "algray/scene/scene.h"
#include "scene_fixtures.h"
#include "sweep.h"
#include "test_support.h"

using namespace algray;

namespace {

// The random surface at 61 x 37 pixels in tiles of 24: widths 24 and 13, so every tile ends in a partial group
// of lanes, and rows that start mid-image.
Scene lanes_scene(int degree, unsigned seed, Precision precision, int lanes, const std::string& origin) {
  return load_scene_text(testing::random_scene(degree, seed, precision), "random",
                         {{"image.width", "61"},
                          {"image.height", "37"},
                          {"render.tile_size", "24"},
                          {"render.ray_origin", "\"" + origin + "\""},
                          {"render.lanes", std::to_string(lanes)}});
}

// Index of the first record whose bytes differ, or -1.
long first_difference(const std::vector<HitRecord>& a, const std::vector<HitRecord>& b) {
  if (a.size() != b.size()) return 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(HitRecord)) != 0) return static_cast<long>(i);
  return -1;
}

}  // namespace

TEST_CASE("lanes give the one-ray kernel's hit records bit for bit", "[lanes]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  struct Case {
    int degree;
    Precision precision;
    std::string origin;
    std::vector<int> lanes;
  };
  std::vector<Case> cases;
  // Degrees on each side of the vector widths' limits (3 and 7 coefficients fill a float4 and float8, 15 a
  // float16): the ends and the last mixed degree on every run, a seeded sample of the others. At degree 32 one
  // precision a run, drawn (both when exhaustive): the lanes above degree 15 are the same code over LREAL in both,
  // and each degree-32 pair of programs takes PoCL some 20 s of a cold suite to compile (float's 40, with its
  // second pass).
  const std::vector<Precision> top = testing::sampled_choices<Precision>(
      "test_lanes precisions at degree 32 (0 double, 1 float)", {Precision::Double, Precision::Float}, 1);
  const auto tested = [&](int degree, Precision precision) {
    return degree < 32 || std::find(top.begin(), top.end(), precision) != top.end();
  };
  // The sweep compares the lanes renders take on this device (default_lanes) with one lane: the same programs as
  // the other tests' renders of those degrees, which a cold suite then compiles once (each is about a second of
  // PoCL's time). Widths 2, 4 and 8 are the cases below.
  const int renders = default_lanes(session.info.type);
  for (int degree : testing::sampled("test_lanes degrees", {1, 2, 3, 5, 6, 9, 12, 15, 20, 32}, {1, 2, 15, 32}, 1)) {
    if (tested(degree, Precision::Double)) cases.push_back({degree, Precision::Double, "auto", {renders}});  // screen form
    if (tested(degree, Precision::Float)) cases.push_back({degree, Precision::Float, "auto", {renders}});  // extent construction
    if (degree <= kMaxMixedDegree) cases.push_back({degree, Precision::Mixed, "auto", {renders}});
  }
  cases.push_back({6, Precision::Double, "extent", {2, 4, 8, 16}});
  cases.push_back({10, Precision::Float, "auto", {2, 4, 16}});
  cases.push_back({9, Precision::Double, "auto", {2, 4, 16}});  // the screen form's lanes (screen_coefficients)
  cases.push_back({9, Precision::Adaptive, "auto", {16}});      // with adaptive's noise (screen_terms)
  std::size_t hits = 0;
  for (std::size_t index = 0; index < cases.size(); ++index) {
    const Case& c = cases[index];
    const unsigned seed = 2000u + static_cast<unsigned>(c.degree);
    const RenderResult one = renderer.render_with_records(lanes_scene(c.degree, seed, c.precision, 1, c.origin));
    REQUIRE(one.plan.find(PassKind::Primary)->kernels.at(0).lanes == 1);
    for (const HitRecord& h : one.hits.records) hits += (h.flags & ALGRAY_HIT_FOUND) != 0;
    for (int lanes : c.lanes) {
      const RenderResult many = renderer.render_with_records(lanes_scene(c.degree, seed, c.precision, lanes, c.origin));
      REQUIRE(many.plan.find(PassKind::Primary)->kernels.at(0).lanes == lanes);
      const long at = first_difference(one.hits.records, many.hits.records);
      INFO("case " << index << ": degree " << c.degree << ", seed " << seed << ", " << to_string(c.precision) << ", "
                   << c.origin << ", " << lanes << " lanes: first differing record " << at << " of "
                   << one.hits.records.size());
      CHECK(at == -1);
    }
  }
  CHECK(hits > cases.size() * 100);  // the surfaces are in view: the comparison covers refined roots
}

// Adaptive precision's checks of P from the monomials (kernels/point_values.h, float_float.h): flat-doubted roots
// confirmed lane by lane in float, then the lanes still in doubt together in float-float (surface.h,
// confirmed_in_float_float); brackets doubted for their end values settled after the search likewise (bernstein
// method, bracket_ends_proven). The one-ray kernel does both one ray at a time. On
// the first two hard surfaces most doubted roots go through float-float (tests/test_probe); the torus shell's
// doubts are mostly brackets.
TEST_CASE("lanes settle doubts in float-float as the one-ray kernel does, bit for bit", "[lanes]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  for (const char* name : {"tooth_cubed", "chebyshev_decic", "torus_shell"}) {
    const std::string file = std::string(ALGRAY_SOURCE_DIR) + "/tests/data/hard_surfaces/" + name + ".toml";
    const auto render = [&](int lanes) {
      return renderer.render_with_records(load_scene_file(file, {{"image.width", "61"},
                                                                 {"image.height", "37"},
                                                                 {"render.tile_size", "24"},
                                                                 {"render.precision", "\"adaptive\""},
                                                                 {"render.lanes", std::to_string(lanes)}}));
    };
    const RenderResult one = render(1);
    std::size_t found = 0;
    for (const HitRecord& h : one.hits.records) found += (h.flags & ALGRAY_HIT_FOUND) != 0;
    CHECK(found > 300);
    for (int lanes : {8, 16}) {
      const long at = first_difference(one.hits.records, render(lanes).hits.records);
      INFO(name << ", " << lanes << " lanes: first differing record " << at);
      CHECK(at == -1);
    }
  }
}

// Where the second pass runs in float-float (no fp64), the float pass also settles discard doubts in float-float
// (discard_settled) and its search goes on: lanes evaluate P for the lanes that need it together, in
// the step that doubted. The Kummer and BC6 shells doubt most rays so; settled, fewer go to the second pass.
TEST_CASE("lanes settle discard doubts in float-float as the one-ray kernel does, bit for bit", "[lanes]") {
  const auto escalated = [](const RenderResult& r) {
    std::size_t n = 0;
    for (const HitRecord& h : r.hits.records) n += (h.flags & ALGRAY_HIT_ESCALATED) != 0;
    return n;
  };
  ProgramCache& cache = testing::program_cache();
  Renderer with_fp64(testing::device_session(), cache);
  const testing::HiddenFp64 hidden;
  ClSession session(select_device(""));
  REQUIRE_FALSE(session.info.fp64);
  Renderer renderer(session, cache);
  for (const char* name : {"kummer_shell", "bc6_shell"}) {
    const std::string file = std::string(ALGRAY_SOURCE_DIR) + "/tests/data/hard_surfaces/" + name + ".toml";
    const auto scene = [&](int lanes) {
      return load_scene_file(file, {{"image.width", "61"},
                                    {"image.height", "37"},
                                    {"render.tile_size", "24"},
                                    {"render.precision", "\"adaptive\""},
                                    {"render.lanes", std::to_string(lanes)}});
    };
    const RenderResult one = renderer.render_with_records(scene(1));
    const RenderResult lanes = renderer.render_with_records(scene(8));
    const long at = first_difference(one.hits.records, lanes.hits.records);
    INFO(name << ": first differing record " << at);
    CHECK(at == -1);
    const std::size_t settling = escalated(lanes), not_settling = escalated(with_fp64.render_with_records(scene(8)));
    INFO("rays escalated: " << settling << " settling discard doubts, " << not_settling << " not");
    CHECK(settling < not_settling);
  }
}

// Surfaces whose lane groups take the search's rarer exits together: on z^3 seen square on every root is an
// exact zero at a subdivision point, so whole groups have nothing to refine; a double plane gives clusters
// with and without a sign change; x y z has singular lines; the sphere's rim has tangent rays.
TEST_CASE("lanes give the one-ray kernel's hit records where groups settle without refining", "[lanes]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  const char* const equations[] = {"z^3", "(z-0.1)^2", "x*y*z", "x^2+y^2+z^2-0.5"};
  for (const std::string equation : equations) {
    std::string text = "[surface]\nequation = \"";
    text += equation;
    text += "\"\n[extent]\nradius = 1\n[camera]\nprojection = \"orthographic\"\neye = [0, 0, 5]\n";
    text += "look_at = [0, 0, 0]\nup = [0, 1, 0]\nheight = 2.5\n[image]\nwidth = 45\nheight = 32\n";
    // The double plane is mostly invisible by design (a double root has no sign change): few hits there.
    const std::size_t least_hits = equation == "(z-0.1)^2" ? 1 : 100;
    for (const NamedChoice<Precision>& choice : kPrecisions) {
      const Precision precision = choice.value;
      const std::string quoted_precision = '"' + std::string(to_string(precision)) + '"';
      const auto render = [&](int lanes) {
        return renderer.render_with_records(load_scene_text(
            text, "plane", {{"render.precision", quoted_precision}, {"render.lanes", std::to_string(lanes)}}));
      };
      const RenderResult one = render(1), many = render(8);
      REQUIRE(many.plan.find(PassKind::Primary)->kernels.at(0).lanes == 8);
      std::size_t found = 0;
      for (const HitRecord& h : one.hits.records) found += (h.flags & ALGRAY_HIT_FOUND) != 0;
      const long at = first_difference(one.hits.records, many.hits.records);
      INFO(equation << ", " << to_string(precision) << ": first differing record " << at << " of "
                    << one.hits.records.size() << ", " << found << " hits");
      // Adaptive precision doubts the double plane's float hits and escalates them: none need be left, as on the
      // surface itself; every other surface keeps its hits.
      const bool double_plane = equation == "(z-0.1)^2";
      CHECK(found >= (precision == Precision::Adaptive && double_plane ? std::size_t{0} : least_hits));
      CHECK(at == -1);
    }
  }
}

// Reflection and transmission rays of a random surface, traced by the trace kernel: its lanes against one ray
// per work-item, in every precision. In adaptive precision the camera rays' doubts go to the trace kernel too.
// No light casts shadows (the headlight shades): the shadow kernel's lanes are test_shadows_batched's.
TEST_CASE("secondary rays in lanes give the one-ray kernel's hit records bit for bit", "[lanes]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  std::size_t rays = 0, partial_groups = 0;
  for (int degree : {3, 10}) {  // coefficients filling a float4, and 11 of a float16
    const unsigned seed = 2100u + static_cast<unsigned>(degree);
    for (const NamedChoice<Precision>& choice : kPrecisions) {
      if (choice.value == Precision::Mixed && degree > kMaxMixedDegree) continue;
      const auto render = [&](int lanes) {
        return renderer.render_with_records(load_scene_text(testing::random_scene(degree, seed, choice.value), "random",
                                                            {{"render.preview", "false"},
                                                             {"image.width", "96"},
                                                             {"image.height", "72"},
                                                             {"render.lanes", std::to_string(lanes)},
                                                             {"material.front.reflectivity", "0.5"},
                                                             {"material.back.transparency", "0.5"}}));
      };
      const RenderResult one = render(1), many = render(8);
      REQUIRE(many.plan.find(PassKind::Reflection)->kernels.at(0).lanes == 8);
      REQUIRE(one.secondary.size() == many.secondary.size());
      INFO("degree " << degree << ", seed " << seed << ", " << choice.name);
      CHECK(first_difference(one.hits.records, many.hits.records) == -1);
      for (std::size_t b = 0; b < one.secondary.size(); ++b) {
        const std::vector<HitRecord>& hits = one.secondary[b].hits;
        INFO("batch " << b << " of " << one.secondary.size() << ", " << hits.size() << " rays");
        CHECK(first_difference(hits, many.secondary[b].hits) == -1);
        rays += hits.size();
        partial_groups += hits.size() % 8 != 0;
      }
    }
  }
  CHECK(rays > 5000);         // the surfaces are in view and spawn secondary rays
  CHECK(partial_groups > 0);  // and some batch ends in a partial group of lanes
}

TEST_CASE("the plan gives lanes to the camera and secondary rays' kernels, where they apply", "[lanes]") {
  const std::string text = testing::random_scene(6, 2006, Precision::Double);
  const Scene full = load_scene_text(text + "[[light]]\nposition = [3, 3, 3]\n", "random",
                                     {{"render.preview", "false"}, {"material.front.reflectivity", "0.5"}});
  const RenderPlan plan = make_render_plan(full, Precision::Double, 0, 8);
  CHECK(plan.find(PassKind::Primary)->kernels.at(0).lanes == 8);
  CHECK(plan.find(PassKind::Primary)->kernels.at(0).key().find(" lanes=8") != std::string::npos);
  CHECK(plan.find(PassKind::Reflection)->kernels.at(0).lanes == 8);
  // The shadow kernel's point form (double) runs lanes too; the extent form batches rays its own way.
  CHECK(plan.find(PassKind::Shadow)->kernels.at(0).ray_origin == RayOrigin::Point);
  CHECK(plan.find(PassKind::Shadow)->kernels.at(0).lanes == 8);
  // Plain float runs adaptive's float kernels (float_measures_noise): its shadow pass is the float point form,
  // its doubted rays float's extent form (one ray per work-item: the extent form batches its own way), and its
  // doubted camera rays float's trace kernel, in lanes.
  const RenderPlan float_plan = make_render_plan(full, Precision::Float, 0, 8);
  CHECK(float_plan.find(PassKind::Shadow)->kernels.at(0).ray_origin == RayOrigin::Point);
  CHECK(float_plan.find(PassKind::Shadow)->kernels.at(0).precision == Precision::Adaptive);
  CHECK(float_plan.find(PassKind::Shadow)->kernels.at(0).lanes == 8);
  CHECK(float_plan.find(PassKind::Shadow)->escalation.at(0).ray_origin == RayOrigin::Extent);
  CHECK(float_plan.find(PassKind::Shadow)->escalation.at(0).precision == Precision::Float);
  CHECK(float_plan.find(PassKind::Shadow)->escalation.at(0).lanes == 1);
  CHECK(float_plan.find(PassKind::Primary)->escalation.at(0).entry == "trace");
  CHECK(float_plan.find(PassKind::Primary)->escalation.at(0).precision == Precision::Float);
  CHECK(float_plan.find(PassKind::Primary)->escalation.at(0).lanes == 8);
  // Adaptive precision's second pass for camera rays is the trace kernel: in lanes too.
  const RenderPlan adaptive = make_render_plan(full, Precision::Adaptive, 0, 8);
  CHECK(adaptive.find(PassKind::Primary)->escalation.at(0).entry == "trace");
  CHECK(adaptive.find(PassKind::Primary)->escalation.at(0).lanes == 8);
  // Adaptive's float shadow pass is the point form in lanes; mixed precision's second pass the extent form.
  CHECK(adaptive.find(PassKind::Shadow)->kernels.at(0).ray_origin == RayOrigin::Point);
  CHECK(adaptive.find(PassKind::Shadow)->kernels.at(0).lanes == 8);
  CHECK(adaptive.find(PassKind::Shadow)->escalation.at(0).ray_origin == RayOrigin::Extent);
  CHECK(adaptive.find(PassKind::Shadow)->escalation.at(0).lanes == 1);
  // Where double's fp64 is fast the doubted shadow rays go again in double, in the point form and its lanes; in
  // mixed precision through the extent form.
  RenderPlan in_double = adaptive;
  escalate_in(in_double, Precision::Double);
  CHECK(in_double.find(PassKind::Shadow)->escalation.at(0).ray_origin == RayOrigin::Point);
  CHECK(in_double.find(PassKind::Shadow)->escalation.at(0).lanes == 8);
  CHECK(in_double.find(PassKind::Primary)->escalation.at(0).ray_origin == RayOrigin::Extent);
  // Camera and secondary rays take 16 lanes where asked; the shadow kernel's point form in double at most
  // kMaxShadowLanes.
  const RenderPlan wide = make_render_plan(full, Precision::Double, 0, 16);
  CHECK(wide.find(PassKind::Primary)->kernels.at(0).lanes == 16);
  CHECK(wide.find(PassKind::Reflection)->kernels.at(0).lanes == 16);
  CHECK(wide.find(PassKind::Shadow)->kernels.at(0).lanes == kMaxShadowLanes);
  RenderPlan wide_adaptive = make_render_plan(full, Precision::Adaptive, 0, 16);
  escalate_in(wide_adaptive, Precision::Double);
  CHECK(wide_adaptive.find(PassKind::Primary)->escalation.at(0).lanes == 16);
  CHECK(wide_adaptive.find(PassKind::Shadow)->escalation.at(0).lanes == kMaxShadowLanes);
  // Float vectors hold twice the lanes: adaptive's float point form takes 16.
  CHECK(wide_adaptive.find(PassKind::Shadow)->kernels.at(0).lanes == kMaxFloatShadowLanes);
  RenderPlan in_mixed = adaptive;
  escalate_in(in_mixed, Precision::Mixed);
  CHECK(in_mixed.find(PassKind::Shadow)->escalation.at(0).ray_origin == RayOrigin::Extent);
  // A refinement without a lane version keeps one ray per work-item; the scene's setting overrides the device's.
  const Scene bisection = load_scene_text(text, "random", {{"render.refinement", "\"bisection\""}});
  CHECK(make_render_plan(bisection, Precision::Double, 0, 8).find(PassKind::Primary)->kernels.at(0).lanes == 1);
  const Scene four = load_scene_text(text, "random", {{"render.lanes", "4"}});
  CHECK(make_render_plan(four, Precision::Double, 0, 8).find(PassKind::Primary)->kernels.at(0).lanes == 4);
  CHECK_THROWS_WITH(load_scene_text(text, "random", {{"render.lanes", "3"}}),
                    Catch::Contains("render.lanes must be 1, 2, 4, 8 or 16"));
  CHECK_THROWS_WITH(load_scene_text(text, "random", {{"render.lanes", "8"}, {"render.isolation", "\"sturm\""}}),
                    Catch::Contains("render.lanes > 1 needs isolation = \"bernstein\" and refinement = \"brent\""));
}
