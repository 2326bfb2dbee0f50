// Host pieces that need no device: kernel configuration keys, precision choice, tiles, cameras, unit coordinates.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "algray/device/kernel_config.h"
#include "algray/device/kernel_sources.h"
#include "algray/render/precision_race.h"
#include "algray/render/renderer.h"
#include "algray/scene/camera.h"
#include "algray/scene/expression.h"
#include "algray/scene/scene.h"

using namespace algray;

namespace {

const char* kSphereScene = R"(
[surface]
equation = "(x-1)^2 + y^2 + z^2 - 0.25"
[extent]
type = "box"
min = [0, -1, -1]
max = [3, 1, 1]
[camera]
eye = [1, 0, 5]
look_at = [1, 0, 0]
up = [0, 1, 0]
)";

}  // namespace

TEST_CASE("every choice that changes the kernel changes both the build options and the cache key", "[config]") {
  KernelConfig base;
  base.degree = 6;
  std::vector<KernelConfig> variants(8, base);
  variants[1].degree = 7;
  variants[2].precision = Precision::Float;
  variants[3].isolation = Isolation::PowerDescartes;
  variants[4].refinement = Refinement::Bisection;
  variants[5].ray_origin = RayOrigin::Eye;
  variants[6].tolerance = 1e-8;
  variants[7].max_iterations = 1000;
  std::set<std::string> keys, options;
  for (const KernelConfig& c : variants) {
    keys.insert(c.key());
    options.insert(c.build_options());
  }
  CHECK(keys.size() == variants.size());
  CHECK(options.size() == variants.size());
  // The tolerance travels bit for bit, as a hexadecimal literal.
  KernelConfig odd = base;
  odd.tolerance = 1.0 / 3.0;
  CHECK(odd.build_options().find("-D TOLERANCE=0x1.5555555555555p-2") != std::string::npos);
  odd.precision = Precision::Float;
  CHECK(odd.build_options().find("-D TOLERANCE=0x1.555556p-2f") != std::string::npos);
}

TEST_CASE("solver names round-trip and unknown names are refused", "[config]") {
  for (const NamedChoice<Precision>& p : kPrecisions) {
    Precision back{};
    REQUIRE(parse_precision(to_string(p.value), back));
    CHECK(back == p.value);
  }
  for (const NamedChoice<Isolation>& i : kIsolations) {
    Isolation back{};
    REQUIRE(parse_isolation(to_string(i.value), back));
    CHECK(back == i.value);
  }
  for (const NamedChoice<Refinement>& r : kRefinements) {
    Refinement back{};
    REQUIRE(parse_refinement(to_string(r.value), back));
    CHECK(back == r.value);
  }
  for (const NamedChoice<RayOrigin>& o : kRayOrigins) {
    RayOrigin back{};
    REQUIRE(parse_ray_origin(to_string(o.value), back));
    CHECK(back == o.value);
  }
  Precision p{};
  CHECK_FALSE(parse_precision("quad", p));
  CHECK(precision_choices() == "float, double, mixed, adaptive");
  // Mixed precision stops at degree 15, with the scene's position in the message.
  CHECK_THROWS_WITH(
      load_scene_text(kSphereScene, "t.toml", {{"surface.equation", "\"x^16 - 1\""}, {"render.precision", "mixed"}}),
      Catch::Contains("mixed precision supports degrees up to 15"));
  KernelConfig mixed;
  mixed.precision = Precision::Mixed;
  CHECK(mixed.build_options().find("-D ALGRAY_DOUBLE=0 -D ALGRAY_COMPENSATED=1") != std::string::npos);
}

TEST_CASE("precision follows the device: double refused without fp64, auto takes fast fp64 or adaptive float",
          "[config]") {
  Scene scene = load_scene_text(kSphereScene, "t.toml");
  DeviceInfo no_fp64;
  no_fp64.name = "toy device";
  no_fp64.fp64 = false;
  DeviceInfo with_fp64 = no_fp64;
  with_fp64.fp64 = true;
  CHECK(resolve_precision(scene, no_fp64, std::nullopt) == Precision::Adaptive);
  CHECK(resolve_precision(scene, with_fp64, 1.02) == Precision::Double);
  CHECK(resolve_precision(scene, with_fp64, kFastFp64Slowdown) == Precision::Double);
  // a datacenter GPU (the H200 measured 1.83-1.86) stays in double when a measurement jitters past 2
  CHECK(resolve_precision(scene, with_fp64, 2.3) == Precision::Double);
  CHECK(resolve_precision(scene, with_fp64, 32.0) == Precision::Adaptive);  // a consumer GPU's fp64
  // Where adaptive cannot go (mixed precision's degree limit, another isolation), float.
  scene.render.isolation = Isolation::Sturm;
  CHECK(resolve_precision(scene, no_fp64, std::nullopt) == Precision::Float);
  CHECK(resolve_precision(scene, with_fp64, 32.0) == Precision::Float);
  scene.render.isolation = Isolation::Bernstein;
  scene.render.precision = Precision::Double;
  CHECK_THROWS_WITH(resolve_precision(scene, no_fp64, std::nullopt), Catch::Contains("has no double precision"));
  CHECK(resolve_precision(scene, with_fp64, 32.0) == Precision::Double);  // asked for: slow or not
  scene.render.precision = Precision::Adaptive;
  CHECK(resolve_precision(scene, with_fp64, 1.0) == Precision::Adaptive);
}

// PrecisionRace's schedule and decision (the frames themselves: test_public_api).
TEST_CASE("a precision race alternates double and adaptive, then keeps the faster, adaptive on a tie", "[config]") {
  PrecisionRace race;
  const std::string slow_double = "a", tie = "b";
  std::vector<Precision> order;
  const double double_ms[] = {9.0, 8.0}, adaptive_ms[] = {7.5, 8.5};
  for (int frame = 0; frame < 2 * PrecisionRace::kRounds; ++frame) {
    const Precision p = race.next(slow_double);
    order.push_back(p);
    race.record(slow_double, p, p == Precision::Double ? double_ms[frame / 2] : adaptive_ms[frame / 2]);
  }
  CHECK(order ==
        std::vector<Precision>{Precision::Double, Precision::Adaptive, Precision::Double, Precision::Adaptive});
  CHECK(race.next(slow_double) == Precision::Adaptive);  // fastest frames: adaptive 7.5 against double 8.0
  CHECK_THAT(race.reason(slow_double),
             Catch::Contains("adaptive: its fastest of 2 frames took 7.5 ms") && Catch::Contains("double's 8 ms"));
  // Decided: a frame slower than kReopen times double's fastest (8 ms), or several not in a row, keep it; kRounds
  // in a row race the key again, from double.
  race.record(slow_double, Precision::Adaptive, 100.0);
  race.record(slow_double, Precision::Double, 100.0);  // not the chosen precision's: ignored
  race.record(slow_double, Precision::Adaptive, 9.0);   // within 1.25 x 8 ms: the count starts over
  for (int frame = 0; frame + 1 < PrecisionRace::kRounds; ++frame) race.record(slow_double, Precision::Adaptive, 10.5);
  CHECK(race.next(slow_double) == Precision::Adaptive);
  race.record(slow_double, Precision::Adaptive, 10.5);
  CHECK(race.next(slow_double) == Precision::Double);
  CHECK_THAT(race.reason(slow_double), Catch::Contains("racing double against adaptive"));
  CHECK(race.next(tie) == Precision::Double);  // a key of its own, racing from its first frame
  CHECK_THAT(race.reason(tie), Catch::Contains("first frame"));
  for (int frame = 0; frame < 2 * PrecisionRace::kRounds; ++frame) race.record(tie, race.next(tie), 5.0);
  CHECK(race.next(tie) == Precision::Adaptive);
  PrecisionRace faster_double;
  for (int frame = 0; frame < 2 * PrecisionRace::kRounds; ++frame) {
    const Precision p = faster_double.next("c");
    faster_double.record("c", p, p == Precision::Double ? 4.0 : 6.0);
  }
  CHECK(faster_double.next("c") == Precision::Double);
  CHECK_THAT(faster_double.reason("c"), Catch::StartsWith("double: ") && Catch::Contains("adaptive's 6 ms"));
  // Float and mixed frames are not the race's.
  PrecisionRace other;
  other.record("d", Precision::Float, 1.0);
  CHECK(other.next("d") == Precision::Double);
  CHECK_THAT(other.reason("d"), Catch::Contains("first frame"));
  // The oldest key is forgotten past kKeys and races again.
  PrecisionRace many;
  for (int frame = 0; frame < 2 * PrecisionRace::kRounds; ++frame) many.record("first", many.next("first"), 1.0);
  REQUIRE(many.next("first") == Precision::Adaptive);
  for (std::size_t k = 0; k < PrecisionRace::kKeys; ++k) many.record("key " + std::to_string(k), Precision::Double, 1);
  CHECK(many.next("first") == Precision::Double);
}

TEST_CASE("a precision race's key keeps a surface's race while its coefficients move, not its size or shape",
          "[config]") {
  const Scene base = load_scene_text(kSphereScene, "t.toml");
  const auto key = [](const std::string& text, const std::vector<Override>& overrides) {
    return PrecisionRace::key_of(load_scene_text(text, "t.toml", overrides));
  };
  const std::string k = PrecisionRace::key_of(base);
  CHECK(key(kSphereScene, {{"camera.eye", "[0, 1, 7]"}}) == k);
  CHECK(key(kSphereScene, {{"image.width", "333"}}) != k);
  CHECK(key(kSphereScene, {{"surface.equation", "\"(x-1)^2 + y^2 + z^2 - 0.3\""}}) == k);  // a parameter moved
  CHECK(key(kSphereScene, {{"surface.equation", "\"x^4 + y^2 + z^2 - 1\""}}) != k);        // another surface
  CHECK(key(kSphereScene, {{"render.isolation", "\"sturm\""}}) != k);
}

TEST_CASE("adaptive precision is refused, naming the line, where it cannot escalate", "[config]") {
  CHECK_THROWS_WITH(
      load_scene_text(kSphereScene, "t.toml", {{"render.precision", "adaptive"}, {"render.isolation", "sturm"}}),
      Catch::Contains("adaptive precision needs render.isolation = \"bernstein\"") &&
          Catch::Contains("--set render.precision=adaptive"));  // where the choice was made
  CHECK_THROWS_WITH(
      load_scene_text(kSphereScene, "t.toml", {{"surface.equation", "\"x^16 - 1\""}, {"render.precision", "adaptive"}}),
      Catch::Contains("escalates to mixed, which supports degrees up to 15"));
  KernelConfig adaptive;
  adaptive.precision = Precision::Adaptive;
  CHECK(adaptive.build_options().find("-D ALGRAY_DOUBLE=0 -D ALGRAY_COMPENSATED=0 -D ALGRAY_ESCALATE=1") !=
        std::string::npos);
}

TEST_CASE("tolerances below the working precision are raised to it", "[config]") {
  Scene scene = load_scene_text(kSphereScene, "t.toml", {{"render.tolerance", "1e-15"}});
  CHECK(primary_config(scene, Precision::Double).tolerance == Approx(1e-15));
  CHECK(primary_config(scene, Precision::Float).tolerance >= 1e-7);
}

TEST_CASE("GPUs get launches that fill them, CPUs few large ones, and the plan says which", "[config]") {
  DeviceInfo gpu, cpu;
  gpu.type = "GPU";
  cpu.type = "CPU";
  // A 1920x1080 preview is one launch per pass on a GPU.
  CHECK(default_tile_size(gpu) >= 1920);
  CHECK(default_tile_size(cpu) >= 1024);
  Scene scene = load_scene_text(kSphereScene, "t.toml", {{"image.width", "1920"}, {"image.height", "1080"}});
  scene.render.preview = true;
  const RenderPlan on_gpu = make_render_plan(scene, Precision::Float, std::vector<PlanDevice>{{gpu}});
  CHECK(on_gpu.tile_rays() == 1920u * 1080u);
  CHECK(on_gpu.tile_choice.find("GPU") != std::string::npos);
  CHECK(on_gpu.json()["tile"]["choice"] == on_gpu.tile_choice);
  const RenderPlan on_cpus = make_render_plan(scene, Precision::Float, std::vector<PlanDevice>{{cpu}, {cpu}});
  CHECK(on_cpus.tile_choice.find("halved") != std::string::npos);
  scene.render.tile_size = 64;
  CHECK(make_render_plan(scene, Precision::Float, std::vector<PlanDevice>{{gpu}}).tile_choice ==
        "the scene's render.tile_size");
}

TEST_CASE("the float shadow kernel takes as many lanes as a vector register holds floats", "[config]") {
  // A light that casts shadows and full mode: the shadow pass, in the point form (degree 2).
  Scene scene = load_scene_text(std::string(kSphereScene) + "[[light]]\nposition = [3, 3, 3]\n", "t.toml",
                                {{"render.preview", "false"}});
  const auto shadow_lanes_on = [&](Precision precision, std::vector<unsigned> widths) {
    std::vector<PlanDevice> devices;
    for (unsigned width : widths) {
      DeviceInfo cpu;
      cpu.type = "CPU";
      cpu.native_float_width = width;
      devices.push_back({cpu});
    }
    const RenderPlan plan = make_render_plan(scene, precision, devices);
    const KernelConfig& shadow = plan.find(PassKind::Shadow)->kernels.at(0);
    REQUIRE(shadow.ray_origin == RayOrigin::Point);
    return shadow.lanes;
  };
  for (Precision precision : {Precision::Float, Precision::Adaptive}) {
    INFO(to_string(precision));
    CHECK(shadow_lanes_on(precision, {8}) == 8);    // AVX2
    CHECK(shadow_lanes_on(precision, {16}) == 16);  // AVX-512
    CHECK(shadow_lanes_on(precision, {4}) == 8);    // SSE: no fewer than 8
    CHECK(shadow_lanes_on(precision, {0}) == kMaxFloatShadowLanes);
    CHECK(shadow_lanes_on(precision, {16, 8}) == 8);  // what every device holds
  }
  CHECK(shadow_lanes_on(Precision::Double, {16}) == kMaxShadowLanes);
  CHECK(shadow_lanes_on(Precision::Double, {8}) == kMaxShadowLanes);
  // The camera rays keep theirs.
  DeviceInfo cpu;
  cpu.type = "CPU";
  cpu.native_float_width = 8;
  CHECK(make_render_plan(scene, Precision::Float, std::vector<PlanDevice>{{cpu}}).find(PassKind::Primary)->kernels.at(0).lanes ==
        default_lanes("CPU"));
}

TEST_CASE("the rays traced again take as many lanes as a vector register holds in their precision", "[config]") {
  const Scene scene = load_scene_text(kSphereScene, "t.toml");
  const auto trace_lanes = [&](Precision precision, Precision escalation,
                               std::vector<std::pair<unsigned, unsigned>> widths) {
    std::vector<PlanDevice> devices;
    for (const auto& [floats, doubles] : widths) {
      DeviceInfo cpu;
      cpu.type = "CPU";
      cpu.native_float_width = floats;
      cpu.native_double_width = doubles;
      devices.push_back({cpu, escalation});
    }
    const RenderPlan plan = make_render_plan(scene, precision, devices);
    const PlannedPass& primary = *plan.find(PassKind::Primary);
    REQUIRE(primary.escalation.size() == 1);
    CHECK(primary.escalation[0].entry == "trace");
    CHECK(primary.kernels.at(0).lanes == default_lanes("CPU"));  // the first pass keeps its lanes
    return primary.escalation[0].lanes;
  };
  CHECK(trace_lanes(Precision::Adaptive, Precision::Double, {{8, 4}}) == 4);           // AVX2: four doubles
  CHECK(trace_lanes(Precision::Adaptive, Precision::Mixed, {{8, 4}}) == 8);            // float-float in floats
  CHECK(trace_lanes(Precision::Float, Precision::Double, {{8, 4}}) == 8);              // plain float's second pass
  CHECK(trace_lanes(Precision::Adaptive, Precision::Double, {{16, 8}}) == 8);          // AVX-512
  CHECK(trace_lanes(Precision::Adaptive, Precision::Double, {{16, 8}, {8, 4}}) == 4);  // what every device holds
  CHECK(trace_lanes(Precision::Adaptive, Precision::Double, {{0, 0}}) == default_lanes("CPU"));  // not known
}

TEST_CASE("the extent form's shadow rays are restricted a vector register's rays at a time where it fuses",
          "[config]") {
  CHECK(shadow_batch_width(8, true) == 8);    // AVX2 floats
  CHECK(shadow_batch_width(4, true) == 4);    // AVX2 doubles
  CHECK(shadow_batch_width(16, true) == 16);  // AVX-512 floats
  CHECK(shadow_batch_width(1, true) == 0);    // a GPU's one lane
  CHECK(shadow_batch_width(0, true) == 0);    // not known
  CHECK(shadow_batch_width(3, true) == 0);    // no such vector type
  CHECK(shadow_batch_width(8, false) == 0);   // fma() would not match the vector steps' unfused multiply-adds
  KernelConfig c;
  c.entry = "shadow";
  c.shadow_batch = 8;
  CHECK(c.key().find(" batch=8") != std::string::npos);
  CHECK(c.build_options().find("-D ALGRAY_SHADOW_BATCH=8") != std::string::npos);
  c.shadow_batch = 0;
  CHECK(c.key().find("batch") == std::string::npos);

  // Degree 16 (the point form stops at 15): every shadow kernel is the extent form's.
  const Scene scene = load_scene_text(std::string(kSphereScene) + "[[light]]\nposition = [3, 3, 3]\n", "t.toml",
                                      {{"render.preview", "false"}, {"surface.equation", "\"x^16 + y^2 + z^2 - 1\""}});
  const auto batches = [&](Precision precision, std::vector<std::pair<unsigned, bool>> float_widths) {
    std::vector<PlanDevice> devices;
    for (const auto& [width, fma] : float_widths) {
      DeviceInfo cpu;
      cpu.type = "CPU";
      cpu.native_float_width = width;
      cpu.native_double_width = width / 2;
      cpu.float_fma = cpu.double_fma = fma;
      devices.push_back({cpu, Precision::Double});
    }
    const PlannedPass shadow = *make_render_plan(scene, precision, devices).find(PassKind::Shadow);
    REQUIRE(shadow.kernels.at(0).ray_origin == RayOrigin::Extent);
    std::vector<int> out{shadow.kernels.at(0).shadow_batch};
    for (const KernelConfig& e : shadow.escalation) out.push_back(e.shadow_batch);
    return out;
  };
  CHECK(batches(Precision::Double, {{8, true}}) == std::vector<int>{4});
  CHECK(batches(Precision::Float, {{8, true}}) == std::vector<int>{8, 8});              // the first pass and its second
  CHECK(batches(Precision::Float, {{16, true}, {8, true}}) == std::vector<int>{8, 8});  // what every device holds
  CHECK(batches(Precision::Float, {{8, true}, {8, false}}) == std::vector<int>{0, 0});  // one device without fma
  CHECK(batches(Precision::Double, {{1, true}}) == std::vector<int>{0});                // GPUs: one accumulator per ray
}

TEST_CASE("the point form's doubted shadow rays go through float's extent form before float-float", "[config]") {
  // Full mode with a shadow-casting light: adaptive's shadow pass is the float point form (degree 2).
  Scene scene = load_scene_text(std::string(kSphereScene) + "[[light]]\nposition = [3, 3, 3]\n", "t.toml",
                                {{"render.preview", "false"}});
  DeviceInfo cpu;
  cpu.type = "CPU";
  const auto shadow_pass = [&](Precision escalation) {
    const RenderPlan plan = make_render_plan(scene, Precision::Adaptive, std::vector<PlanDevice>{{cpu, escalation}});
    return *plan.find(PassKind::Shadow);
  };
  // A float-float second pass: a float tier in the extent construction first, which settles what it can (its
  // doubts go on); the point form settles doubts only by searching its doubted rays again (kernels/shadow.h).
  const PlannedPass mixed = shadow_pass(Precision::Mixed);
  REQUIRE(mixed.kernels.at(0).ray_origin == RayOrigin::Point);
  CHECK(mixed.kernels.at(0).settle_doubts);
  REQUIRE(mixed.float_escalation.size() == 1);
  REQUIRE(mixed.float_escalation[0].has_value());
  CHECK(mixed.float_escalation[0]->ray_origin == RayOrigin::Extent);
  CHECK(mixed.float_escalation[0]->precision == Precision::Adaptive);
  CHECK(mixed.float_escalation[0]->settle_doubts);
  CHECK(mixed.escalation.at(0).precision == Precision::Mixed);
  CHECK(make_render_plan(scene, Precision::Adaptive, std::vector<PlanDevice>{{cpu, Precision::Mixed}})
            .json()["passes"][1]["float_escalation"][0] == mixed.float_escalation[0]->key());
  // A double second pass costs about what float's extent form does: no tier between, and the point form's search
  // again saves less than it costs.
  const PlannedPass in_double = shadow_pass(Precision::Double);
  CHECK(in_double.float_escalation.empty());
  CHECK(in_double.escalation.at(0).precision == Precision::Double);
  CHECK_FALSE(in_double.kernels.at(0).settle_doubts);
  // Plain float's doubted rays go to float's extent form already, after the point form's search again.
  const RenderPlan plain = make_render_plan(scene, Precision::Float, std::vector<PlanDevice>{{cpu}});
  CHECK(plain.find(PassKind::Shadow)->float_escalation.empty());
  CHECK(plain.find(PassKind::Shadow)->kernels.at(0).settle_doubts);
  CHECK_FALSE(plain.find(PassKind::Primary)->kernels.at(0).settle_doubts);
  // Where the first pass is the extent form already (a scene that asks for it), there is nothing to add.
  scene.render.ray_origin = RayOrigin::Extent;
  const RenderPlan extent = make_render_plan(scene, Precision::Adaptive, std::vector<PlanDevice>{{cpu}});
  const PlannedPass& extent_shadow = *extent.find(PassKind::Shadow);
  CHECK(std::none_of(extent_shadow.float_escalation.begin(), extent_shadow.float_escalation.end(),
                     [](const std::optional<KernelConfig>& c) { return c.has_value(); }));
}

TEST_CASE("the surface in unit coordinates vanishes where the world surface does", "[config]") {
  const Scene scene = load_scene_text(kSphereScene, "t.toml");
  const SurfaceData data = prepare_surface(scene);
  REQUIRE(data.degree == 2);
  CHECK(data.even_axes == 6);  // y and z appear squared only; x - 1 brings in odd powers of x
  double largest = 0;
  for (double c : data.coefficients) largest = std::max(largest, std::fabs(c));
  CHECK(largest == 1.0);
  // Points of the world sphere (centre (1,0,0), radius 0.5) map to zeros of the unit polynomial.
  const glm::dvec3 c = scene.extent.unit_centre();
  const double s = scene.extent.unit_scale();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(0, 6.283185307179586);
  for (int n = 0; n < 20; ++n) {
    const double a = angle(rng), b = angle(rng);
    const glm::dvec3 p{1 + 0.5 * std::cos(a) * std::cos(b), 0.5 * std::sin(a) * std::cos(b), 0.5 * std::sin(b)};
    const glm::dvec3 u = (p - c) / s;
    double value = 0;
    for (std::size_t m = 0; m < data.coefficients.size(); ++m) {
      const cl_uint e = data.exponents[m];
      value += data.coefficients[m] * std::pow(u.x, e & 0xff) * std::pow(u.y, (e >> 8) & 0xff) *
               std::pow(u.z, (e >> 16) & 0xff);
    }
    INFO("case " << n);
    CHECK(std::fabs(value) < 1e-14);
  }
  // The box becomes a box inside the unit sphere.
  const glm::dvec3 half = scene.extent.unit_box_half();
  CHECK(glm::length(half) == Approx(1.0));
}

TEST_CASE("the ray basis follows docs/outputs.md's convention", "[config]") {
  CameraSpec cam;
  cam.eye = {0, 0, 5};
  cam.look_at = {0, 0, 0};
  cam.up = {0, 1, 0};
  cam.fov_y_degrees = 90;
  const RayBasis b = make_ray_basis(cam, 4, 2);
  // The centre of the image looks straight at look_at; the top-left corner pixel up and to the left.
  const glm::dvec3 centre = b.d00 + 2.0 * b.du + 1.0 * b.dv;
  CHECK(centre.x == Approx(0).margin(1e-15));
  CHECK(centre.y == Approx(0).margin(1e-15));
  CHECK(centre.z == Approx(-1));
  const glm::dvec3 corner = b.d00 + 0.5 * b.du + 0.5 * b.dv;
  CHECK(corner.x < 0);
  CHECK(corner.y > 0);
  // With a 90 degree field of view the top edge of the image is at 45 degrees.
  const glm::dvec3 top = b.d00 + 2.0 * b.du;
  CHECK(top.y / -top.z == Approx(1.0));
  cam.projection = Projection::Orthographic;
  cam.ortho_height = 2;
  const RayBasis o = make_ray_basis(cam, 4, 2);
  CHECK(o.du == glm::dvec3(0));
  CHECK(o.dv == glm::dvec3(0));
  const glm::dvec3 first = o.o00 + 0.5 * o.ou + 0.5 * o.ov;
  CHECK(first.x == Approx(-1.5));
  CHECK(first.y == Approx(0.5));
}

TEST_CASE("kernel sources resolve their includes from the embedded files", "[config]") {
  const std::string source = assemble_kernel_source("primary.cl");
  CHECK(source.find("__kernel void primary(") != std::string::npos);
  CHECK(source.find("typedef struct {") != std::string::npos);  // algray_shared.h's HitRecord came in
  CHECK(source.find("#include \"") == std::string::npos);       // every include was resolved
  CHECK_THROWS(assemble_kernel_source("no_such_kernel.cl"));
  // A header included in one #if branch must come again in the next: the preprocessor drops the first copy
  // (methods/power_basis.h, under both the Descartes and the Sturm method).
  const auto sturm_branch = source.find("#elif ISOLATION == ALGRAY_ISOLATION_STURM");
  REQUIRE(sturm_branch != std::string::npos);
  const auto power_basis_at = source.find("static void taylor_shift(");
  REQUIRE(power_basis_at != std::string::npos);
  CHECK(power_basis_at < sturm_branch);
  CHECK(source.find("static void taylor_shift(", sturm_branch) != std::string::npos);
  // A header once outside every #if is not written again: its guard is set (each include of it was written out
  // where it stood, megabytes, until 2026-12-07).
  const auto copies = [&source](const std::string& text) {
    std::size_t n = 0;
    for (auto at = source.find(text); at != std::string::npos; at = source.find(text, at + 1)) ++n;
    return n;
  };
  CHECK(copies("#define ALGRAY_REAL_H") == 1);
  CHECK(copies("#define ALGRAY_SHARED_H") == 1);
  CHECK(source.size() < 400000);
}

// The -D switches: declared once, in kernels/build_switches.h, and the host writes exactly those of its host part.
TEST_CASE("every build switch is declared once, and the host writes each one it owns", "[config]") {
  const auto read = [](const std::filesystem::path& p) {
    std::ifstream in(p);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  };
  // `#ifndef NAME` followed by `#define NAME`: a default (include guards, ALGRAY_*_H, define no value after).
  const std::regex default_of(R"(#ifndef ([A-Z_][A-Z0-9_]*)\s*\n#define \1 \S)");
  const std::string header = read(ALGRAY_SOURCE_DIR "/kernels/build_switches.h");
  const auto host_end = header.find("---- From the entry file");
  REQUIRE(host_end != std::string::npos);
  std::set<std::string> host_declared;
  for (auto it = std::sregex_iterator(header.begin(), header.end(), default_of); it != std::sregex_iterator(); ++it)
    if (static_cast<std::size_t>(it->position()) < host_end) host_declared.insert((*it)[1]);
  // DEGREE and the method's abilities have no default, only a required value.
  CHECK(header.find("#ifndef DEGREE\n#error") != std::string::npos);
  host_declared.insert("DEGREE");
  for (const char* ability : {"ISOLATION_POWER_BASIS", "ISOLATION_ADAPTIVE", "ISOLATION_POINT_FORM", "SOLVER_LANES"}) {
    CHECK(header.find(std::string("!defined(") + ability + ")") != std::string::npos);
    host_declared.insert(ability);
  }
  const std::vector<std::string> written = build_switch_names();
  CHECK(std::set<std::string>(written.begin(), written.end()) == host_declared);
  KernelConfig config;
  config.degree = 7;
  for (const std::string& name : written) {
    INFO(name);
    CHECK(config.build_options().find(" -D " + name + "=") != std::string::npos);
  }
  // No other kernel file defaults a switch, declared there or not.
  for (const auto& entry : std::filesystem::directory_iterator(ALGRAY_SOURCE_DIR "/kernels")) {
    if (entry.path().filename() == "build_switches.h") continue;
    const std::string text = read(entry.path());
    for (auto it = std::sregex_iterator(text.begin(), text.end(), default_of); it != std::sregex_iterator(); ++it)
      FAIL_CHECK(entry.path().filename().string() << " defaults " << (*it)[1] << " outside build_switches.h");
  }
}

// What each method can do is one table (solver_options.h): every method has its row, and the scene's check, the
// plan's lanes and the messages all follow it.
TEST_CASE("every method has its row of abilities, and lanes follow the rows", "[config]") {
  for (const NamedChoice<Isolation>& i : kIsolations) {
    INFO(i.name);
    CHECK(abilities(i.value).method == i.value);
    CHECK(isolates_in_power_basis(i.value) == abilities(i.value).power_basis);
    CHECK(adaptive_unsupported(6, i.value).empty() == abilities(i.value).adaptive);
    for (const NamedChoice<Refinement>& r : kRefinements) {
      INFO(r.name);
      CHECK(abilities(r.value).method == r.value);
      KernelConfig config;
      config.isolation = i.value;
      config.refinement = r.value;
      CHECK(lanes_apply(config) == (abilities(i.value).lanes && abilities(r.value).lanes));
      const std::string lanes = "[render]\nlanes = 8\nisolation = \"" + std::string(i.name) + "\"\nrefinement = \"" +
                                r.name + "\"\n";
      if (lanes_supported(i.value, r.value))
        CHECK_NOTHROW(load_scene_text(kSphereScene + lanes, "lanes.toml"));
      else
        CHECK_THROWS_WITH(load_scene_text(kSphereScene + lanes, "lanes.toml"), Catch::Contains(lanes_methods()));
    }
  }
  CHECK(lanes_methods() == "isolation = \"bernstein\" and refinement = \"brent\"");
}
