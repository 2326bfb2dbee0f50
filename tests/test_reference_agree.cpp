// Every scene at 160x120, in double and float, against the certified reference (issue 3's image thresholds),
// adaptive's float line on every pixel of the cancelling octic and decic at 512x384, the cylinder extent, clipping
// planes and the extent as a ray gate.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "algray/device/program_cache.h"
#include "algray/render/reference_render.h"
#include "algray/render/renderer.h"
#include "algray/scene/scene.h"
#include "scene_fixtures.h"
#include "sweep.h"
#include "test_support.h"
#include "tolerances.h"

using namespace algray;

namespace {

constexpr int kWidth = 160, kHeight = 120;

// Plain float on the Barth decic and the Endrass octic does not reach its line: measured at 160x120, the decic
// has 3 disagreements (0.04%) but a hit on the wrong sheet (depth error 0.19), the octic 27 disagreements (0.33%)
// and a depth error of 0.24. Both expand to large cancelling monomials, whose rounding in float swamps P*(t).
// They need mixed precision (P*(t) built and isolated in float-float), which brings both within the line. The
// float cases stay in a test that is expected to fail, so the day they pass it says so.
const std::set<std::string> kFloatNotYet = {"barth_decic", "endrass_octic"};

struct SceneAgreement {
  ReferenceComparison c;
  testing::ImageThresholds limit;
  bool within() const {
    return static_cast<double>(c.disagreements) <= limit.disagreement_share * static_cast<double>(c.certified) &&
           c.worst_depth <= limit.depth_error;
  }
};

// The reference of a scene file at 160x120 for rays built in `ray_precision`, certified once a run: it depends on
// the rays, not on the precision the kernels solve them in (float, mixed and adaptive all trace float rays).
const ReferenceResult& scene_reference(const std::filesystem::path& file, const Scene& scene, Precision ray_precision) {
  static std::map<std::pair<std::string, Precision>, ReferenceResult> certified;
  const auto key = std::make_pair(file.string(), ray_precision);
  if (const auto it = certified.find(key); it != certified.end()) return it->second;
  return certified.emplace(key, render_reference(scene, ray_precision)).first->second;
}

// The scene at 160x120 in `precision` against the reference, printed as a row of the table (under `label`, the
// precision by default).
SceneAgreement agreement(Renderer& renderer, const std::filesystem::path& file, const char* precision,
                         const char* label = nullptr) {
  const Scene scene = load_scene_file(file.string(), {{"image.width", std::to_string(kWidth)},
                                                      {"image.height", std::to_string(kHeight)},
                                                      {"render.precision", precision},
                                                      {"antialias.samples", "1"},
                                                      {"render.preview", "true"}});
  const bool is_double = std::string(precision) == "double";
  const bool is_float = !is_double;  // float, mixed and adaptive all trace float rays
  const RenderResult kernel = renderer.render_with_records(scene);
  const ReferenceResult& ref = scene_reference(file, scene, is_float ? Precision::Float : Precision::Double);
  const ReferenceComparison c = compare_with_reference(kernel.hits, ref);
  std::printf("%-28s %-8s %9ld %9ld %9ld %12ld %9ld %12.3g at %d,%d\n", file.stem().string().c_str(),
              label ? label : precision, c.certified, c.ambiguous, c.ray_rounding, c.disagreements, c.simple_hits,
              c.worst_depth, c.worst_x, c.worst_y);
  return {c, is_double ? testing::kDoubleImage : testing::kFloatImage};
}

void check_scene(Renderer& renderer, const std::filesystem::path& file, const char* precision,
                 const char* label = nullptr) {
  const SceneAgreement a = agreement(renderer, file, precision, label);
  const ReferenceComparison& c = a.c;
  INFO(file.filename().string() << " " << (label ? label : precision) << ": " << c.disagreements << " of "
                                << c.certified << " certified pixels disagree on hit/miss (first at " << c.disagree_x
                                << "," << c.disagree_y << "); worst relative depth error " << c.worst_depth << " at "
                                << c.worst_x << "," << c.worst_y << "; " << c.ambiguous << " ambiguous ("
                                << c.ray_rounding << " of them within ray rounding)");
  CHECK(c.certified > kWidth * kHeight / 10);
  CHECK(static_cast<double>(c.disagreements) <= a.limit.disagreement_share * static_cast<double>(c.certified));
  CHECK(c.worst_depth <= a.limit.depth_error);
}

void print_header() {
  std::printf("%-28s %-8s %9s %9s %9s %12s %9s %12s\n", "scene", "prec", "certified", "ambiguous", "(rounding)",
              "disagree", "hits", "max depth err");
}

// Harder surfaces of degree 7 to 12 than the shipped scenes, made by the rules of ../shared/surfaces.md (nodes
// of Chebyshev cubes, close sheets, a singular curve): tests/data/hard_surfaces.
std::vector<std::filesystem::path> hard_surfaces() {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(ALGRAY_SOURCE_DIR "/tests/data/hard_surfaces"))
    if (e.path().extension() == ".toml") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

using testing::random_scene;
using testing::scene_files;

// Adaptive float as a device without fast fp64 runs it: the doubted rays go to mixed precision, and the float
// passes settle more of their doubts in float-float (KernelConfig::settle_doubts). Printed as "adapt-ff".
void check_adaptive_without_fp64(const std::vector<std::filesystem::path>& files) {
  const testing::HiddenFp64 hidden;
  ClSession session(select_device(""));
  REQUIRE_FALSE(session.info.fp64);
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  for (const auto& file : files) check_scene(renderer, file, "adaptive", "adapt-ff");
}

// A clipped scene against its reference: in double 0 disagreements, with one ray per work-item too (the scalar
// instance of the clipping in kernels/ray.h, 16 lanes the vector one: the same hits); otherwise the float line.
void check_clipped_agreement(Renderer& renderer, const Scene& scene, const ReferenceResult& ref,
                             const ReferenceComparison& c, bool is_double) {
  if (!is_double) {
    CHECK(static_cast<double>(c.disagreements) <=
          testing::kFloatImage.disagreement_share * static_cast<double>(c.certified));
    CHECK(c.worst_depth <= testing::kFloatImage.depth_error);
    return;
  }
  CHECK(c.disagreements == 0);
  CHECK(c.worst_depth <= testing::kDoubleImage.depth_error);
  Scene one_lane = scene;
  one_lane.render.lanes = 1;
  const ReferenceComparison c1 = compare_with_reference(renderer.render_with_records(one_lane).hits, ref);
  INFO("one lane: " << c1.disagreements << " of " << c1.certified << " disagree");
  CHECK(c1.disagreements == 0);
  CHECK(c1.simple_hits == c.simple_hits);
}

}  // namespace

TEST_CASE("the screen form meets the double line on seeded random surfaces of every degree", "[reference]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  // Every degree under the `exhaustive` label; otherwise the ends and a seeded sample (the reference costs ~1 s a
  // degree).
  for (int degree : testing::sampled_degrees("test_reference_agree random surface degrees", kMaxDegree, 3))
    for (unsigned seed : {1000u + static_cast<unsigned>(degree)}) {
      const Scene scene = load_scene_text(random_scene(degree, seed, Precision::Double), "random");
      const RenderResult kernel = renderer.render_with_records(scene);
      REQUIRE(kernel.config.ray_origin == RayOrigin::Screen);
      const ReferenceComparison c = compare_with_reference(kernel.hits, render_reference(scene, Precision::Double));
      INFO("degree " << degree << " seed " << seed << ": " << c.disagreements << " of " << c.certified
                     << " certified pixels disagree (first at " << c.disagree_x << "," << c.disagree_y
                     << "); worst relative depth error " << c.worst_depth << " at " << c.worst_x << "," << c.worst_y);
      CHECK(c.certified > 64 * 48 / 10);
      CHECK(static_cast<double>(c.disagreements) <=
            testing::kDoubleImage.disagreement_share * static_cast<double>(c.certified));
      CHECK(c.worst_depth <= testing::kDoubleImage.depth_error);
    }
}

TEST_CASE(
    "auto builds camera rays in the screen form in double, adaptive and float precision, and shadow rays in the "
    "point form",
    "[reference]") {
  const Scene base = load_scene_text(random_scene(6, 1006, Precision::Double), "random");
  // Plain float takes adaptive's float kernels first, its own (the extent form) for the rays they doubt.
  for (Precision p : {Precision::Double, Precision::Adaptive, Precision::Float}) {
    const RenderPlan plan = make_render_plan(base, p);
    CHECK(plan.find(PassKind::Primary)->kernels.at(0).ray_origin == RayOrigin::Screen);
    // adaptive's doubted camera rays go again through the extent construction (the trace kernel)
    for (const KernelConfig& again : plan.find(PassKind::Primary)->escalation)
      CHECK(again.ray_origin == RayOrigin::Extent);
  }
  CHECK(make_render_plan(base, Precision::Mixed).find(PassKind::Primary)->kernels.at(0).ray_origin ==
        RayOrigin::Extent);
  CHECK(make_render_plan(base, Precision::Float).find(PassKind::Primary)->escalation.at(0).precision ==
        Precision::Float);
  // Above adaptive's own limit of 15 too (its second pass is float's); with an isolation adaptive does not take,
  // plain float keeps its own kernels throughout.
  const Scene high = load_scene_text(random_scene(24, 1024, Precision::Float), "random");
  CHECK(make_render_plan(high, Precision::Float).find(PassKind::Primary)->kernels.at(0).ray_origin ==
        RayOrigin::Screen);
  CHECK(make_render_plan(high, Precision::Float).find(PassKind::Primary)->escalation.at(0).precision ==
        Precision::Float);
  const Scene sturm = load_scene_text(random_scene(6, 1006, Precision::Float), "random",
                                      {{"render.isolation", "\"sturm\""}});
  CHECK(make_render_plan(sturm, Precision::Float).find(PassKind::Primary)->kernels.at(0).ray_origin ==
        RayOrigin::Extent);
  CHECK(make_render_plan(sturm, Precision::Float).find(PassKind::Primary)->escalation.empty());
  // The eye inside the extent: expansion points would lie on both sides of it, far from some rays' segments.
  const Scene inside =
      load_scene_text(random_scene(6, 1006, Precision::Double), "random", {{"camera.eye", "[0.2, 0.1, 0.5]"}});
  CHECK(make_render_plan(inside, Precision::Double).find(PassKind::Primary)->kernels.at(0).ray_origin ==
        RayOrigin::Extent);
  const Scene full = load_scene_text(random_scene(6, 1006, Precision::Double) +
                                         "[[light]]\nposition = [3, 3, 3]\n[antialias]\nsamples = 2\nadaptive = true\n",
                                     "random", {{"render.preview", "false"}});
  const RenderPlan full_plan = make_render_plan(full, Precision::Double);
  REQUIRE(full_plan.passes.size() == 3);  // primary, shadow, antialias
  for (const PlannedPass& pass : full_plan.passes)
    CHECK(pass.kernels.at(0).ray_origin == (pass.kind == PassKind::Primary  ? RayOrigin::Screen
                                            : pass.kind == PassKind::Shadow ? RayOrigin::Point
                                                                            : RayOrigin::Extent));
  CHECK(make_render_plan(full, Precision::Mixed).find(PassKind::Shadow)->kernels.at(0).ray_origin == RayOrigin::Extent);
  // Adaptive's float shadow pass measures the point form's noise (kernels/shadow.h, PointTerms); plain float runs
  // the same kernel, its doubted rays through its own extent form.
  for (Precision p : {Precision::Float, Precision::Adaptive}) {
    const PlannedPass& shadow = *make_render_plan(full, p).find(PassKind::Shadow);
    CHECK(shadow.kernels.at(0).ray_origin == RayOrigin::Point);
    CHECK(shadow.kernels.at(0).precision == Precision::Adaptive);
    CHECK(shadow.escalation.at(0).ray_origin == RayOrigin::Extent);
  }
  // A scene that asks for the extent construction gets it for every kernel.
  const Scene extent = load_scene_text(random_scene(6, 1006, Precision::Double) + "[[light]]\nposition = [3, 3, 3]\n",
                                       "random", {{"render.preview", "false"}, {"render.ray_origin", "\"extent\""}});
  for (const PlannedPass& pass : make_render_plan(extent, Precision::Double).passes)
    CHECK(pass.kernels.at(0).ray_origin == RayOrigin::Extent);
}

TEST_CASE("every scene agrees with the certified reference within issue 3's thresholds", "[reference]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  const auto files = scene_files();
  REQUIRE(files.size() >= 12);
  print_header();
  for (const auto& file : files) {
    check_scene(renderer, file, "double");
    check_scene(renderer, file, "mixed");
    check_scene(renderer, file, "adaptive");
    if (!kFloatNotYet.count(file.stem().string())) check_scene(renderer, file, "float");
  }
  check_adaptive_without_fp64(files);
}

TEST_CASE("a cylinder extent about each axis clips as the certified reference does: 0 disagreements in double",
          "[reference][extent]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  // Small images (64x48): each cylinder cuts its surface open, so many rays end on the cylinder's side or caps.
  struct Case {
    const char* scene;
    const char* axis;
    const char* radius;
    const char* half_height;
  };
  const Case cases[] = {{"kummer", "z", "1.6", "1.2"}, {"torus", "x", "3", "1.2"}, {"cayley_cubic", "y", "2", "1.5"}};
  print_header();
  const auto hit = [](const HitRecord& r) { return (r.flags & ALGRAY_HIT_FOUND) != 0; };
  for (const Case& k : cases) {
    const std::filesystem::path file =
        std::filesystem::path(ALGRAY_SOURCE_DIR "/scenes") / (std::string(k.scene) + ".toml");
    // The scene in its own sphere, to see that the cylinder cuts some of it away.
    const RenderResult uncut =
        renderer.render_with_records(load_scene_file(file.string(), {{"image.width", "64"},
                                                                     {"image.height", "48"},
                                                                     {"render.precision", "double"},
                                                                     {"antialias.samples", "1"},
                                                                     {"render.preview", "true"}}));
    for (const char* precision : {"double", "float"}) {
      const Scene scene = load_scene_file(file.string(), {{"image.width", "64"},
                                                          {"image.height", "48"},
                                                          {"render.precision", precision},
                                                          {"antialias.samples", "1"},
                                                          {"render.preview", "true"},
                                                          {"extent.type", "cylinder"},
                                                          {"extent.axis", k.axis},
                                                          {"extent.radius", k.radius},
                                                          {"extent.half_height", k.half_height}});
      REQUIRE(scene.extent.kind == ExtentKind::Cylinder);
      const bool is_double = std::string(precision) == "double";
      const RenderResult kernel = renderer.render_with_records(scene);
      const ReferenceResult ref = render_reference(scene, is_double ? Precision::Double : Precision::Float);
      const ReferenceComparison c = compare_with_reference(kernel.hits, ref);
      long cut = 0;
      for (std::size_t i = 0; i < uncut.hits.records.size(); ++i)
        cut += hit(uncut.hits.records[i]) && !hit(kernel.hits.records[i]);
      const long outside =
          std::count(ref.classes.begin(), ref.classes.end(), static_cast<std::uint32_t>(PixelClass::OutsideExtent));
      std::printf(
          "%-28s %-8s %9ld %9ld %9ld %12ld %9ld %12.3g at %d,%d  (cylinder about %s; %ld outside, %ld cut away)\n",
          k.scene, precision, c.certified, c.ambiguous, c.ray_rounding, c.disagreements, c.simple_hits, c.worst_depth,
          c.worst_x, c.worst_y, k.axis, outside, cut);
      INFO(k.scene << " in a cylinder about " << k.axis << ", " << precision << ": " << c.disagreements << " of "
                   << c.certified << " certified pixels disagree (first at " << c.disagree_x << "," << c.disagree_y
                   << "); worst depth " << c.worst_depth);
      CHECK(c.certified > 64 * 48 / 8);
      CHECK(c.simple_hits > 64 * 48 / 16);
      CHECK(outside > 0);          // rays that miss the cylinder
      CHECK(cut > 64 * 48 / 100);  // pixels of the surface that the cylinder cut away
      check_clipped_agreement(renderer, scene, ref, c, is_double);
    }
  }
}

TEST_CASE("clipping planes cut each surface as the certified reference does: 0 disagreements in double",
          "[reference][extent][clip]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  // Seeded planes: one to three per scene, their normals uniform on the sphere, each through a point 0.05 to 0.5
  // of the extent's radius from its centre along the normal, keeping the centre's side: every plane cuts the
  // surface open, and together they leave enough of it to see. One case in a box, one in a cylinder, the others
  // in the scene's own sphere.
  std::mt19937 rng(46);
  std::normal_distribution<double> normal(0, 1);
  std::uniform_real_distribution<double> offset(0.05, 0.5);
  struct Case {
    const char* scene;
    int planes;
    std::vector<Override> extent;
  };
  const Case cases[] = {{"kummer", 1, {}},
                        {"torus", 2, {}},
                        {"cayley_cubic", 3, {{"extent.type", "box"}}},
                        {"barth_sextic", 2, {{"extent.type", "cylinder"}, {"extent.axis", "x"}}}};
  print_header();
  const auto hit = [](const HitRecord& r) { return (r.flags & ALGRAY_HIT_FOUND) != 0; };
  for (const Case& k : cases) {
    const std::filesystem::path file =
        std::filesystem::path(ALGRAY_SOURCE_DIR "/scenes") / (std::string(k.scene) + ".toml");
    std::vector<Override> base = {
        {"image.width", "64"}, {"image.height", "48"}, {"antialias.samples", "1"}, {"render.preview", "true"}};
    base.insert(base.end(), k.extent.begin(), k.extent.end());
    std::vector<Override> uncut_overrides = base;
    uncut_overrides.push_back({"render.precision", "double"});
    const Scene uncut_scene = load_scene_file(file.string(), uncut_overrides);
    const RenderResult uncut = renderer.render_with_records(uncut_scene);
    // The planes, a.x + d <= 0 kept, written as [[clip]] tables by --set clip=[...].
    const glm::dvec3 centre = uncut_scene.extent.unit_centre();
    const double radius = uncut_scene.extent.unit_scale();
    std::string list;
    for (int i = 0; i < k.planes; ++i) {
      const glm::dvec3 n = glm::normalize(glm::dvec3(normal(rng), normal(rng), normal(rng)));
      const glm::dvec3 through = centre + offset(rng) * radius * n;
      char plane[160];
      std::snprintf(plane, sizeof plane, "%s{plane = [%.17g, %.17g, %.17g, %.17g]}", i ? ", " : "", n.x, n.y, n.z,
                    -glm::dot(n, through));
      list += plane;
    }
    for (const char* precision : {"double", "float"}) {
      std::vector<Override> overrides = base;
      overrides.push_back({"render.precision", precision});
      overrides.push_back({"clip", "[" + list + "]"});
      const Scene scene = load_scene_file(file.string(), overrides);
      REQUIRE(scene.extent.clips.size() == static_cast<std::size_t>(k.planes));
      const bool is_double = std::string(precision) == "double";
      const RenderResult kernel = renderer.render_with_records(scene);
      const ReferenceResult ref = render_reference(scene, is_double ? Precision::Double : Precision::Float);
      const ReferenceComparison c = compare_with_reference(kernel.hits, ref);
      long cut = 0, added = 0;
      for (std::size_t i = 0; i < uncut.hits.records.size(); ++i) {
        cut += hit(uncut.hits.records[i]) && !hit(kernel.hits.records[i]);
        added += !hit(uncut.hits.records[i]) && hit(kernel.hits.records[i]);
      }
      std::printf("%-28s %-8s %9ld %9ld %9ld %12ld %9ld %12.3g at %d,%d  (%d plane%s; %ld cut away, %ld added)\n",
                  k.scene, precision, c.certified, c.ambiguous, c.ray_rounding, c.disagreements, c.simple_hits,
                  c.worst_depth, c.worst_x, c.worst_y, k.planes, k.planes == 1 ? "" : "s", cut, added);
      INFO(k.scene << " cut by " << list << ", " << precision << ": " << c.disagreements << " of " << c.certified
                   << " certified pixels disagree (first at " << c.disagree_x << "," << c.disagree_y
                   << "); worst depth " << c.worst_depth);
      CHECK(c.certified > 64 * 48 / 8);
      CHECK(c.simple_hits > 64 * 48 / 32);
      CHECK(cut > 64 * 48 / 100);        // pixels of the surface that the planes cut away
      if (is_double) CHECK(added == 0);  // a cut takes surface away, never adds any
      check_clipped_agreement(renderer, scene, ref, c, is_double);
    }
  }
}

TEST_CASE("a gate passes the rays that meet it, which see the surface beyond it, as the certified reference does",
          "[reference][extent][gate]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  // Two quartics (one degree: the same kernels) at 64x48, each gated by a shape smaller than the surface: the
  // Kummer surface's arms, which run to infinity, through a sphere; the torus through a box, cut by a plane too.
  // Rays that miss the gate must miss; those that pass it see the surface out to the far sphere.
  struct Case {
    const char* scene;
    std::vector<Override> gate;
    bool float_too;
  };
  const Case cases[] = {{"kummer", {{"extent.radius", "1.2"}, {"extent.gate", "true"}}, true},
                        {"torus",
                         {{"extent.type", "box"},
                          {"extent.min", "[-2.8, -2.8, -0.3]"},
                          {"extent.max", "[2.8, 2.8, 0.3]"},
                          {"extent.gate", "true"},
                          {"extent.reach", "3"},
                          {"clip", "[{plane = [0.3, 1, 0, -1]}]"}},
                         false}};
  print_header();
  const auto hit = [](const HitRecord& r) { return (r.flags & ALGRAY_HIT_FOUND) != 0; };
  for (const Case& k : cases) {
    const std::filesystem::path file =
        std::filesystem::path(ALGRAY_SOURCE_DIR "/scenes") / (std::string(k.scene) + ".toml");
    std::vector<Override> base = {
        {"image.width", "64"}, {"image.height", "48"}, {"antialias.samples", "1"}, {"render.preview", "true"}};
    base.insert(base.end(), k.gate.begin(), k.gate.end());
    for (const char* precision : {"double", "float"}) {
      const bool is_double = std::string(precision) == "double";
      if (!is_double && !k.float_too) continue;
      std::vector<Override> overrides = base;
      overrides.push_back({"render.precision", precision});
      const Scene scene = load_scene_file(file.string(), overrides);
      REQUIRE(scene.extent.gate);
      // The same shape as a cut: what the gate shows beyond it is what the cut takes away.
      Scene cut_scene = scene;
      cut_scene.extent.gate = false;
      const RenderResult kernel = renderer.render_with_records(scene);
      const RenderResult cut = renderer.render_with_records(cut_scene);
      const ReferenceResult ref = render_reference(scene, is_double ? Precision::Double : Precision::Float);
      const ReferenceComparison c = compare_with_reference(kernel.hits, ref);
      long beyond = 0, lost = 0;
      for (std::size_t i = 0; i < kernel.hits.records.size(); ++i) {
        beyond += hit(kernel.hits.records[i]) && !hit(cut.hits.records[i]);
        lost += !hit(kernel.hits.records[i]) && hit(cut.hits.records[i]);
      }
      const long outside =
          std::count(ref.classes.begin(), ref.classes.end(), static_cast<std::uint32_t>(PixelClass::OutsideExtent));
      std::printf("%-28s %-8s %9ld %9ld %9ld %12ld %9ld %12.3g at %d,%d  (gate; %ld outside it, %ld seen beyond it)\n",
                  k.scene, precision, c.certified, c.ambiguous, c.ray_rounding, c.disagreements, c.simple_hits,
                  c.worst_depth, c.worst_x, c.worst_y, outside, beyond);
      INFO(k.scene << " gated, " << precision << ": " << c.disagreements << " of " << c.certified
                   << " certified pixels disagree (first at " << c.disagree_x << "," << c.disagree_y
                   << "); worst depth " << c.worst_depth);
      CHECK(c.certified > 64 * 48 / 8);
      CHECK(outside > 64 * 48 / 8);     // rays that miss the gate
      CHECK(beyond > 64 * 48 / 50);     // surface seen through the gate beyond it, which a cut would not show
      if (is_double) CHECK(lost == 0);  // a gate shows all that the same shape as a cut shows
      check_clipped_agreement(renderer, scene, ref, c, is_double);
    }
  }
}

TEST_CASE("plain float on the cancelling degree-8 and degree-10 surfaces (known to miss the line)",
          "[reference][!shouldfail]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  for (const auto& file : scene_files())
    if (kFloatNotYet.count(file.stem().string())) check_scene(renderer, file, "float");
}

TEST_CASE("adaptive float holds the float line on harder surfaces of degree 7 to 12, where plain float fails",
          "[reference]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  const auto files = hard_surfaces();
  REQUIRE(files.size() >= 5);
  print_header();
  int float_fails = 0;
  for (const auto& file : files) {
    const int degree = load_scene_file(file.string()).surface().polynomial.degree();
    CHECK(degree >= 7);
    CHECK(degree <= 12);
    check_scene(renderer, file, "adaptive");
    check_scene(renderer, file, "mixed");
    float_fails += !agreement(renderer, file, "float").within();
  }
  check_adaptive_without_fp64(files);
  // They are hard: plain float misses its line on most of them.
  INFO(float_fails << " of " << files.size() << " miss the float line in plain float");
  CHECK(float_fails * 2 > static_cast<int>(files.size()));
}

TEST_CASE("adaptive float agrees with the certified reference wherever it differs from double, at 512x384",
          "[reference]") {
  // The full-size check of the float line's hardest cases: every pixel of the cancelling octic and decic, not a
  // 160x120 sample. Where adaptive and double differ on hit/miss or by more than the float line in depth, the
  // reference decides, on the ray as adaptive's float kernel built it; a certified pixel must agree with it.
  // (A trial that held camera rays to the noise local to an interval, as shadow rays are, at ALGRAY_LOCAL_FACTOR
  // 1, left two certified Endrass octic pixels without their close pair of roots here.)
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  for (const char* name : {"endrass_octic", "barth_decic"}) {
    auto scene_in = [&](const char* precision) {
      return load_scene_file(std::string(ALGRAY_SOURCE_DIR) + "/scenes/" + name + ".toml",
                             {{"image.width", "512"},
                              {"image.height", "384"},
                              {"render.precision", precision},
                              {"antialias.samples", "1"},
                              {"render.preview", "true"}});
    };
    const Scene scene = scene_in("\"adaptive\"");
    const RenderResult adaptive = renderer.render_with_records(scene);
    const RenderResult exact = renderer.render_with_records(scene_in("\"double\""));
    const std::vector<Monomial> monomials = scene.surface().polynomial.monomials();
    int differing = 0, certified = 0, escalated = 0;
    for (int y = 0; y < 384; ++y)
      for (int x = 0; x < 512; ++x) {
        const HitRecord& a = adaptive.hits.at(x, y);
        const HitRecord& d = exact.hits.at(x, y);
        escalated += (a.flags & ALGRAY_HIT_ESCALATED) != 0;
        const bool a_hit = (a.flags & ALGRAY_HIT_FOUND) != 0, d_hit = (d.flags & ALGRAY_HIT_FOUND) != 0;
        const double t_a = double(a.t_hi) + a.t_lo, t_d = double(d.t_hi) + d.t_lo;
        if (a_hit == d_hit && (!a_hit || std::fabs(t_a - t_d) <= testing::kFloatImage.depth_error * t_d)) continue;
        ++differing;
        const PixelRay ray = pixel_ray(adaptive.basis, true, x, y);
        const RayCertificate c =
            certify_ray(scene.surface().polynomial, monomials, scene.extent, ray, Precision::Float);
        if (c.cls != PixelClass::Miss && c.cls != PixelClass::SimpleRoot) continue;
        ++certified;
        INFO(name << " pixel " << x << "," << y << ": adaptive " << (a_hit ? "hit" : "miss") << " t " << t_a
                  << ", double " << (d_hit ? "hit" : "miss") << " t " << t_d << ", reference "
                  << pixel_class_name(c.cls) << " t " << static_cast<double>(c.answer.t_nearest));
        CHECK(a_hit == (c.cls == PixelClass::SimpleRoot));
        if (a_hit && c.cls == PixelClass::SimpleRoot)
          CHECK(std::fabs(t_a - static_cast<double>(c.answer.t_nearest)) <=
                testing::kFloatImage.depth_error * static_cast<double>(c.answer.t_nearest));
      }
    std::printf(
        "%s at 512x384: adaptive escalated %d rays; it differs from double at %d pixels, %d of them "
        "certified\n",
        name, escalated, differing, certified);
    CHECK(escalated > 0);  // these surfaces do exercise the escalation
  }
}
