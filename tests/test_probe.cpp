// The probe: the Fig. 8 torus ray, the plot and JSON from the command, and the traced path against the render.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

#include "algray/api/probe_report.h"
#include "algray/device/kernel_sources.h"
#include "algray/io/image_io.h"
#include "algray/render/escalation.h"
#include "algray/render/render_plan.h"
#include "algray/render/renderer.h"
#include "cli_sandbox.h"
#include "temp_dir.h"
#include "test_support.h"

using namespace algray;
using algray::testing::device_session;

namespace {

Scene torus_scene(std::vector<Override> extra = {}) {
  std::vector<Override> overrides = {{"antialias.samples", "1"}, {"render.preview", "true"}};
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  return load_scene_file(ALGRAY_SOURCE_DIR "/scenes/torus.toml", overrides);
}

// A TOML string value.
std::string toml_string(const std::string& s) {
  std::string q = "\"";
  q += s;
  return q += '"';
}

KernelConfig solver(const Scene& scene, Precision precision, Isolation isolation, Refinement refinement) {
  KernelConfig c = primary_config(scene, precision);
  c.isolation = isolation;
  c.refinement = refinement;
  c.max_iterations = default_max_iterations(refinement);
  return c;
}

// The paper's Fig. 8: a ray that grazes the near side of the tube (two close roots, x1 < x2) and then crosses
// the far side (x3 < x4). P* has a shallow hump between x1 and x2; Newton started left of it can jump to x2.
// Torus a = 2.5, r = 0.9 around the z axis; the ray runs along x at height z = 0.85, from x = -5.
constexpr double kHeight = 0.85;
double fig8_root(int i) {
  const double half = std::sqrt(0.9 * 0.9 - kHeight * kHeight);  // half the chord through the tube
  const double xs[4] = {-2.5 - half, -2.5 + half, 2.5 - half, 2.5 + half};
  return xs[i] + 5.0;
}

// The Fig. 8 ray itself: along x at height kHeight, from x = -5.
ProbeTarget fig8_ray() {
  ProbeTarget target;
  target.given_ray = true;
  target.origin = {-5, 0, kHeight};
  target.direction = {1, 0, 0};
  return target;
}

}  // namespace

TEST_CASE("the probe names the smallest root of the Fig. 8 torus ray and the isolation that found it", "[probe]") {
  ClSession& session = device_session();
  const Scene scene = torus_scene();
  const ProbeTarget target = fig8_ray();
  const double x1 = fig8_root(0), x2 = fig8_root(1);

  const ProbeReference ref = probe_reference(scene, 0, {target.origin, target.direction}, Precision::Double);
  REQUIRE(ref.roots.size() == 4);
  for (int i = 0; i < 4; ++i) {
    INFO("root " << i);
    CHECK(ref.roots[i].t == Approx(fig8_root(i)).epsilon(1e-12));
    CHECK(ref.roots[i].multiplicity == 1);
  }
  CHECK(ref.certificate.cls == PixelClass::SimpleRoot);

  struct Case {
    Isolation isolation;
    Refinement refinement;
  };
  // Newton is the method the paper saw jump to x2; the bracket must keep it on x1.
  const Case cases[] = {{Isolation::Bernstein, Refinement::Brent},
                        {Isolation::Bernstein, Refinement::Newton},
                        {Isolation::PowerDescartes, Refinement::Brent},
                        {Isolation::Sturm, Refinement::Newton}};
  for (const Case& c : cases) {
    const KernelConfig config = solver(scene, Precision::Double, c.isolation, c.refinement);
    INFO(to_string(c.isolation) << " + " << to_string(c.refinement));
    const SolverTrace tr = trace_probe(session, testing::program_cache(), scene, 0, config, target);
    REQUIRE(tr.in_extent);
    const double t_in = 5 - std::sqrt(3.5 * 3.5 - kHeight * kHeight);
    CHECK(tr.t_in == Approx(t_in).epsilon(1e-12));
    CHECK(tr.t_out == Approx(10 - t_in).epsilon(1e-12));
    REQUIRE(tr.coefficients.size() == 5);
    CHECK(tr.basis == (c.isolation == Isolation::Bernstein ? ALGRAY_BASIS_BERNSTEIN : ALGRAY_BASIS_POWER_SEGMENT));

    // The root: x1, within the tolerance, and solver_ref's smallest.
    REQUIRE(tr.found());
    CHECK(std::fabs(tr.t - x1) <= 4e-9 * x1);
    CHECK(std::fabs(tr.t - ref.certificate.answer.t_nearest) <= 4e-9 * x1);

    // The isolation: it starts on the whole segment, which holds all four roots, and must split it; it ends
    // on one interval around x1 that leaves x2 out. Every step in between splits or drops an interval.
    REQUIRE(tr.steps.size() >= 2);
    const ProbeStep& first = tr.steps.front();
    CHECK(first.decision == ALGRAY_STEP_SPLIT);
    CHECK(first.lo == 0);
    CHECK(first.hi == 1);
    if (c.isolation == Isolation::Sturm)
      CHECK(first.count == 4);  // Sturm counts distinct real roots exactly
    else
      CHECK(first.count >= 4);  // Descartes' rule bounds them from above
    const ProbeStep& last = tr.steps.back();
    CHECK(last.decision == ALGRAY_STEP_ISOLATED);
    CHECK(last.count == 1);
    CHECK(tr.t_at(last.lo) < x1);
    CHECK(x1 < tr.t_at(last.hi));
    CHECK(tr.t_at(last.hi) < x2);
    for (std::size_t i = 1; i + 1 < tr.steps.size(); ++i) {
      INFO("step " << i);
      CHECK((tr.steps[i].decision == ALGRAY_STEP_SPLIT || tr.steps[i].decision == ALGRAY_STEP_NO_ROOT));
    }
    CHECK(tr.steps.size() == tr.isolation_steps());
    CHECK(tr.isolation_status == ALGRAY_ISOLATED_BRACKET);
    CHECK(tr.iso_lo == last.lo);
    CHECK(tr.iso_hi == last.hi);

    // The refinement: one event per counted iteration, every iterate inside the isolating interval, the
    // last one the root.
    REQUIRE(!tr.iterates.empty());
    CHECK(tr.iterates.size() == tr.refine_iterations());
    for (const ProbeIterate& it : tr.iterates) {
      INFO("iterate " << it.number);
      CHECK(it.y >= 0);
      CHECK(it.y <= 1);
      CHECK(it.lo <= it.hi);
    }
    CHECK(std::fabs(tr.iterates.back().t - tr.t) <= 8e-9 * x1);
    CHECK(tr.events_offered == tr.events_recorded);
  }
}

TEST_CASE("a log too short for the ray keeps its first events and says how many it lost", "[probe]") {
  ClSession& session = device_session();
  const Scene scene = torus_scene();
  const ProbeTarget target = fig8_ray();
  const KernelConfig config = primary_config(scene, Precision::Double);
  const SolverTrace full = trace_probe(session, testing::program_cache(), scene, 0, config, target);
  const SolverTrace cut = trace_probe(session, testing::program_cache(), scene, 0, config, target, 8);
  REQUIRE(full.events_offered == full.events_recorded);
  CHECK(cut.events_offered == full.events_offered);
  CHECK(cut.events_recorded == 8);
  // The first events are the same: the segment and the 5 coefficients, then the first steps.
  CHECK(cut.t_in == full.t_in);
  CHECK(cut.coefficients == full.coefficients);
  CHECK(cut.steps.size() == 2);
  CHECK(cut.iterates.empty());
  // The hit record does not depend on the log.
  CHECK(std::memcmp(&cut.hit, &full.hit, sizeof(HitRecord)) == 0);
  std::ostringstream report;
  print_probe(report, scene, target, {SurfaceProbe{0, {cut}, probe_reference(scene, 0, cut.ray, Precision::Double)}});
  CHECK_THAT(report.str(), Catch::Contains("kept the first 8 of " + std::to_string(full.events_offered)));
}

TEST_CASE("a probed pixel gets the render's hit record bit for bit", "[probe]") {
  ClSession& session = device_session();
  struct Case {
    Precision precision;
    Isolation isolation;
    Refinement refinement;
  };
  const Case cases[] = {{Precision::Double, Isolation::Bernstein, Refinement::Brent},
                        {Precision::Float, Isolation::Bernstein, Refinement::Brent},
                        {Precision::Mixed, Isolation::Bernstein, Refinement::Illinois},
                        {Precision::Double, Isolation::PowerDescartes, Refinement::RegulaFalsi},
                        {Precision::Double, Isolation::Sturm, Refinement::Newton},
                        {Precision::Double, Isolation::DerivativeChain, Refinement::Bisection}};
  for (const Case& c : cases) {
    const Scene scene = torus_scene({{"image.width", "48"},
                                     {"image.height", "36"},
                                     {"render.precision", toml_string(to_string(c.precision))},
                                     {"render.isolation", toml_string(to_string(c.isolation))},
                                     {"render.refinement", toml_string(to_string(c.refinement))}});
    INFO(to_string(c.precision) << " " << to_string(c.isolation) << " + " << to_string(c.refinement));
    Renderer renderer(session, testing::program_cache());
    const RenderResult render = renderer.render_with_records(scene);
    REQUIRE(render.hits.width == 48);
    // The render's first kernel (plain float's is adaptive's float kernel: float_measures_noise); a pixel it
    // doubted holds the second pass's answer, which the test of doubted rays below follows.
    const KernelConfig config = make_render_plan(scene, c.precision).find(PassKind::Primary)->kernels.at(0);
    int hits = 0, misses_in_extent = 0, compared = 0;
    // Every third pixel: a few hundred rays, hits and misses, grazing ones at the silhouette included.
    for (int py = 0; py < 36; ++py) {
      for (int px = (py % 3); px < 48; px += 3) {
        ProbeTarget target;
        target.px = px;
        target.py = py;
        const SolverTrace tr = trace_probe(session, testing::program_cache(), scene, 0, config, target);
        const HitRecord& rendered = render.hits.at(px, py);
        INFO("pixel (" << px << ", " << py << ")");
        if (rendered.flags & ALGRAY_HIT_ESCALATED) {
          ++compared;
          continue;
        }
        REQUIRE(std::memcmp(&tr.hit, &rendered, sizeof(HitRecord)) == 0);
        ++compared;
        hits += tr.found();
        misses_in_extent += tr.in_extent && !tr.found();
      }
    }
    CHECK(compared == 576);
    CHECK(hits > 50);
    CHECK(misses_in_extent > 10);
  }
}

TEST_CASE("probe --plot writes a valid SVG and PNG, and --json the same story", "[probe][cli]") {
  using namespace algray::testing;
  Sandbox box;
  const std::string scene = quoted(ALGRAY_SOURCE_DIR "/scenes/torus.toml");
  const std::string ray = " --ray -5,0,0.85,1,0,0";

  const Result svg = box.run("probe " + scene + ray + " --plot fig8.svg");
  INFO(svg.err);
  REQUIRE(svg.exit_code == 0);
  CHECK(svg.out.find("one root: isolated") != std::string::npos);
  CHECK(svg.out.find("solver_ref: simple root") != std::string::npos);
  const std::string text = read_text(box.work / "fig8.svg");
  CHECK(text.rfind("<?xml", 0) == 0);
  CHECK(text.find("<svg") != std::string::npos);
  CHECK(text.find("</svg>") != std::string::npos);
  CHECK(text.find("solver_ref") != std::string::npos);

  // --no-cache: every solver's probe program would go to the disk cache, and on PoCL storing one compiles it once
  // more (program_cache.h); no later process here reads them.
  const Result png = box.run("probe " + scene + ray + " --all-solvers --no-cache --plot fig8.png");
  INFO(png.err);
  REQUIRE(png.exit_code == 0);
  CHECK(png.out.find("side by side") != std::string::npos);
  const std::string bytes = read_text(box.work / "fig8.png");
  REQUIRE(bytes.size() > 1000);
  CHECK(bytes.compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)) == 0);

  // Zoomed on the isolating interval, x1 is inside the plot and the other three roots are not.
  const Result zoom = box.run("probe " + scene + ray + " --plot zoom.svg --plot-range isolating");
  REQUIRE(zoom.exit_code == 0);
  const std::string zoomed = read_text(box.work / "zoom.svg");
  std::size_t left_out = 0;
  for (std::size_t at = zoomed.find("outside the plot"); at != std::string::npos;
       at = zoomed.find("outside the plot", at + 1))
    ++left_out;
  CHECK(left_out == 3);
  CHECK(box.run("probe " + scene + ray + " --plot z.svg --plot-range 3,1").exit_code == 2);
  CHECK(box.run("probe " + scene + ray + " --plot z.svg --plot-range 0,inf").exit_code == 2);
  CHECK(box.run("probe " + scene + ray + " --plot-range isolating").exit_code == 2);
  CHECK(!fs::exists(box.work / "z.svg"));
  CHECK(box.run("probe " + scene + " --ray 0,nan,10,0,0,-1").exit_code == 2);
  CHECK(box.run("probe " + scene + " --pixel 1e30,2").exit_code == 2);

  const Result json = box.run("probe " + scene + ray + " --json");
  REQUIRE(json.exit_code == 0);
  const nlohmann::json j = nlohmann::json::parse(json.out);
  const nlohmann::json& s = j["surfaces"][0];
  REQUIRE(s["solvers"].size() == 1);
  CHECK(s["reference"]["roots"].size() == 4);
  CHECK(s["solvers"][0]["t"].get<double>() == Approx(fig8_root(0)).epsilon(1e-8));
  CHECK(s["solvers"][0]["steps"].back()["decision_code"] == ALGRAY_STEP_ISOLATED);

  // Bad input: no ray, a pixel outside the image, a plot format it cannot write. Nothing is written.
  CHECK(box.run("probe " + scene).exit_code == 2);
  const Result outside = box.run("probe " + scene + " --pixel 5000,1");
  CHECK(outside.exit_code == 2);
  CHECK(outside.err.find("outside") != std::string::npos);
  CHECK(box.run("probe " + scene + ray + " --plot fig8.gif").exit_code == 2);
  CHECK(!fs::exists(box.work / "fig8.gif"));
}

TEST_CASE("render --aov adds the solver channels asked for and --heatmap draws the work", "[probe][cli]") {
  using namespace algray::testing;
  Sandbox box;
  const std::string scene =
      quoted(ALGRAY_SOURCE_DIR "/scenes/torus.toml") + " --width 64 --height 48 --preview --set antialias.samples=1";
  const Result r =
      box.run("render " + scene + " -o out.exr --aov classification,isolation,iterations --heatmap work.png");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const FrameImage img = read_exr(box.work / "out.exr");
  // read_exr returns extra channels sorted by name.
  REQUIRE(img.uint_channels.size() == 3);
  CHECK(img.uint_channels[0].name == "solver.class");
  CHECK(img.uint_channels[1].name == "solver.isolationSteps");
  CHECK(img.uint_channels[2].name == "solver.refineIterations");
  const auto& cls = img.uint_channels[0].values;
  const auto& steps = img.uint_channels[1].values;
  const auto& iterations = img.uint_channels[2].values;
  int counts[6] = {0, 0, 0, 0, 0, 0};
  for (std::size_t i = 0; i < cls.size(); ++i) {
    INFO("pixel " << i);
    REQUIRE(cls[i] <= 5);
    ++counts[cls[i]];
    const bool hit = std::isfinite(img.depth[i]);
    if (cls[i] != 5) CHECK(hit == (cls[i] >= 2));  // at the depth limit it may be either
    if (cls[i] == 0) CHECK(steps[i] == 0);         // nothing solved outside the extent
    if (cls[i] == 2) CHECK(iterations[i] > 0);
    if (cls[i] >= 1) CHECK(steps[i] > 0);
  }
  CHECK(counts[0] > 0);
  CHECK(counts[1] > 0);
  CHECK(counts[2] > 100);

  // The channel agrees with the probe of the same pixel.
  const int px = 32, py = 24;
  const Result probe = box.run("probe " + scene + " --pixel 32,24 --json");
  REQUIRE(probe.exit_code == 0);
  const nlohmann::json s = nlohmann::json::parse(probe.out)["surfaces"][0]["solvers"][0];
  CHECK(s["isolation_steps"].get<std::uint32_t>() == steps[py * 64 + px]);
  CHECK(s["refine_iterations"].get<std::uint32_t>() == iterations[py * 64 + px]);

  // The heat map: a PNG at least as large as the image (it adds a colour bar and caption).
  const std::string png = read_text(box.work / "work.png");
  REQUIRE(png.size() > 24);
  const auto be32 = [&](std::size_t at) {
    return (std::uint32_t(std::uint8_t(png[at])) << 24) | (std::uint32_t(std::uint8_t(png[at + 1])) << 16) |
           (std::uint32_t(std::uint8_t(png[at + 2])) << 8) | std::uint32_t(std::uint8_t(png[at + 3]));
  };
  CHECK(be32(16) >= 64);
  CHECK(be32(20) >= 48);

  // A plane of multiplicity 3 seen square on: every root lands exactly on the midpoint of the segment, a
  // subdivision point, so every hit is an exact zero (class 3). A double plane at z = 0.1 is mostly invisible
  // (class 1); where rounding splits its double root into two real ones, it shows.
  const auto classes_of = [&](const std::string& equation) {
    write_text(box.in / "plane.toml", "[surface]\nequation = \"" + equation +
                                          "\"\n[extent]\nradius = 1\n[camera]\nprojection = \"orthographic\"\n"
                                          "eye = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nheight = 2.5\n"
                                          "[image]\nwidth = 32\nheight = 32\n");
    REQUIRE(box.run("render " + quoted((box.in / "plane.toml").string()) + " -o plane.exr --aov classification")
                .exit_code == 0);
    const FrameImage image = read_exr(box.work / "plane.exr");  // kept: a loop over a temporary's member dangles
    std::map<std::uint32_t, int> count;
    for (std::uint32_t c : image.uint_channels.at(0).values) ++count[c];
    return count;
  };
  const auto triple = classes_of("z^3");
  CHECK(triple.count(0) == 1);
  CHECK(triple.count(3) == 1);
  CHECK(triple.size() == 2);  // outside the extent, or an exact zero
  auto twice = classes_of("(z-0.1)^2");
  CHECK(twice[1] > twice[2] + twice[3]);
  CHECK(twice[1] > 400);

  // Without --aov there are no solver channels; an unknown name is bad input.
  REQUIRE(box.run("render " + scene + " -o plain.exr").exit_code == 0);
  CHECK(read_exr(box.work / "plain.exr").uint_channels.empty());
  const Result bad = box.run("render " + scene + " -o bad.exr --aov iterations,colour");
  CHECK(bad.exit_code == 2);
  CHECK(bad.err.find("colour") != std::string::npos);
  CHECK(!fs::exists(box.work / "bad.exr"));
}

TEST_CASE("render builds contain no probe code: the hooks compile to nothing unless ALGRAY_PROBE", "[probe]") {
  // The C preprocessor stands in for the OpenCL compiler's: the kernels are C99 to it. Every kernel a render
  // builds, with every isolation method; the probe kernel itself must show the hooks, or the test proves nothing.
  // The log is a parameter every solver function takes (kernels/probe_log.h): render builds pass NO_PROBE, and
  // their hooks are `((void)probe_log)`, so nothing is recorded, read or written through it.
  algray::testing::TempDir dir("preprocess");
  const auto preprocessed = [&](const std::string& file, const KernelConfig& config) {
    const std::filesystem::path source = dir / "kernel.c", out = dir / "kernel.i";
    {
      std::ofstream s(source);
      s << assemble_kernel_source(file);
    }
    std::string defines;
    std::istringstream options(config.build_options());
    for (std::string word; options >> word;)
      if (word == "-D" && options >> word) defines += " -D" + word;
    const std::string cmd = "cpp -P" + defines + " " + source.string() + " -o " + out.string() + " 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
    return algray::testing::read_text(out);
  };
  for (const NamedChoice<Isolation>& choice : kIsolations) {
    const Isolation isolation = choice.value;
    KernelConfig config;
    config.degree = 6;
    config.isolation = isolation;
    INFO(to_string(isolation));
    const std::string probe = preprocessed("probe.cl", config);
    CHECK(probe.find("probe_record(") != std::string::npos);
    for (const char* file : {"primary.cl", "shadow.cl", "trace.cl"}) {
      INFO(file);
      const std::string render = preprocessed(file, config);
      REQUIRE(render.find("__kernel") != std::string::npos);
      CHECK(render.find("probe_record") == std::string::npos);
      CHECK(render.find("probe_log->") == std::string::npos);
      CHECK(render.find("log->") == std::string::npos);
    }
  }
}

TEST_CASE("a ray adaptive precision doubts: the probe says why, and the second pass's trace is the render's answer",
          "[probe]") {
  RenderContext context("", true);
  // Adaptive, and plain float, which takes adaptive's float kernels and its own for the rays they doubt.
  for (const Precision precision : {Precision::Adaptive, Precision::Float}) {
    INFO(to_string(precision));
    const Scene scene = load_scene_file(
        std::string(ALGRAY_SOURCE_DIR) + "/tests/data/hard_surfaces/kummer_shell.toml",
        {{"image.width", "64"}, {"image.height", "48"}, {"render.precision", toml_string(to_string(precision))}});
    Renderer renderer(context.session(), context.cache());
    const RenderResult render = renderer.render_with_records(scene);
    int probed = 0, plain = 0;
    for (int py = 0; py < 48 && probed < 12; ++py)
      for (int px = 0; px < 64 && probed < 12; ++px) {
        const HitRecord& rendered = render.hits.at(px, py);
        if (!(rendered.flags & ALGRAY_HIT_ESCALATED)) {
          // A ray the float kernel decided: one trace, and no doubt but a flat one it confirmed.
          if (plain++ % 97 != 0) continue;
          ProbeTarget target{false, px, py, {}, {}};
          const std::vector<SurfaceProbe> probes = probe_scene(scene, target, false, context);
          REQUIRE(probes.at(0).traces.size() == 1);
          CHECK(probes[0].traces[0].doubt.has_value() == probes[0].traces[0].confirmed.has_value());
          continue;
        }
        ++probed;
        ProbeTarget target{false, px, py, {}, {}};
        const std::vector<SurfaceProbe> probes = probe_scene(scene, target, false, context);
        INFO("pixel (" << px << ", " << py << ")");
        REQUIRE(probes.at(0).traces.size() == 2);
        const SolverTrace& first = probes[0].traces[0];
        const SolverTrace& again = probes[0].traces[1];
        CHECK(first.config.precision == Precision::Adaptive);
        REQUIRE(first.doubt.has_value());
        CHECK(doubt_reason(static_cast<unsigned>(first.doubt->reason)) != nullptr);
        CHECK(std::fabs(first.doubt->value) <= first.doubt->noise);
        CHECK((first.hit.flags & ALGRAY_HIT_DOUBT) != 0);
        CHECK(again.config.precision == (precision == Precision::Float
                                             ? Precision::Float
                                             : escalation_precision(context.session().info, context.cache())));
        CHECK_FALSE(again.doubt.has_value());
        // The render kept the second pass's answer.
        CHECK(again.found() == ((rendered.flags & ALGRAY_HIT_FOUND) != 0));
        if (again.found()) CHECK(std::memcmp(&again.hit, &rendered, offsetof(HitRecord, flags)) == 0);
      }
    CHECK(probed == 12);
  }
}

namespace {

// An adaptive preview of `file` (in the source tree), width x height.
Scene adaptive_preview(const char* file, int width, int height) {
  return load_scene_file(std::string(ALGRAY_SOURCE_DIR) + "/" + file, {{"image.width", std::to_string(width)},
                                                                       {"image.height", std::to_string(height)},
                                                                       {"render.precision", "\"adaptive\""},
                                                                       {"render.preview", "true"}});
}

// A root the float kernel doubted and kept after all, as the probe traces it (probe: the pixel's surface probe, whose
// first trace settled the doubt; rendered: the render's record of that pixel): a flat root P's values confirmed, or
// with `brackets` an isolating interval P's values at its ends settled.
void check_kept_doubt(const SurfaceProbe& probe, const HitRecord& rendered, bool brackets) {
  const SolverTrace& trace = probe.traces.at(0);
  REQUIRE(trace.confirmed.has_value());
  CHECK(trace.confirmed->bracket == brackets);
  REQUIRE(trace.doubt.has_value());
  CHECK(doubt_reason(static_cast<unsigned>(trace.doubt->reason))->id ==
        (brackets ? ALGRAY_DOUBT_ACCEPT : ALGRAY_DOUBT_FLAT));
  CHECK(probe.traces.size() == 1);
  CHECK((trace.hit.flags & ALGRAY_HIT_DOUBT) == 0);
  // P changes sign across the root (or the bracket), each value beyond its rounding.
  CHECK(std::fabs(trace.confirmed->before) > trace.confirmed->before_rounding);
  CHECK(std::fabs(trace.confirmed->after) > trace.confirmed->after_rounding);
  CHECK((trace.confirmed->before > 0) != (trace.confirmed->after > 0));
  // The render kept this very root,
  CHECK(std::memcmp(&trace.hit, &rendered, offsetof(HitRecord, flags)) == 0);
  // which lies within ALGRAY_DOUBT_POSITION of its t from the certified smallest root, where there is one.
  const PixelClass cls = probe.reference.certificate.cls;
  if (cls == PixelClass::SimpleRoot || cls == PixelClass::OddMultipleRoot) {
    const double t_ref = probe.reference.roots.at(0).t;
    CHECK(std::fabs(trace.t - t_ref) <= ALGRAY_DOUBT_POSITION * std::fabs(t_ref) * 1.01);
  }
}

// Scans a 96x72 adaptive preview of `file` for the first four roots the float kernel doubted and kept after all
// (check_kept_doubt). Returns how many of them were decided in float-float.
int check_confirmed_roots(const char* file, bool brackets, RenderContext& context) {
  const Scene scene = adaptive_preview(file, 96, 72);
  Renderer renderer(context.session(), context.cache());
  const RenderResult render = renderer.render_with_records(scene);
  int confirmed = 0, in_float_float = 0;
  for (int py = 0; py < 72 && confirmed < 4; py += 2)
    for (int px = 0; px < 96 && confirmed < 4; px += 2) {
      const HitRecord& rendered = render.hits.at(px, py);
      if (!(rendered.flags & ALGRAY_HIT_FOUND) || (rendered.flags & ALGRAY_HIT_ESCALATED)) continue;
      ProbeTarget target{false, px, py, {}, {}};
      const std::vector<SurfaceProbe> probes = probe_scene(scene, target, false, context);
      const SolverTrace& trace = probes.at(0).traces.at(0);
      if (!trace.confirmed || trace.confirmed->bracket != brackets) continue;
      ++confirmed;
      in_float_float += trace.confirmed->float_float;
      INFO(file << ", pixel (" << px << ", " << py << ")");
      check_kept_doubt(probes.at(0), rendered, brackets);
    }
  CHECK(confirmed == 4);
  return in_float_float;
}

}  // namespace

TEST_CASE("a flat-doubted root that P's values confirm is kept: one trace, the render's record", "[probe]") {
  RenderContext context("", true);
  // The Barth decic's doubted roots are confirmed (most in float at 1024x768; the first four of this scan in
  // float-float); the cubed tooth's, every root nearly triple and its monomials cancelling, need float-float.
  check_confirmed_roots("scenes/barth_decic.toml", false, context);
  CHECK(check_confirmed_roots("tests/data/hard_surfaces/tooth_cubed.toml", false, context) > 0);
}

TEST_CASE("a bracket doubted for its end values that P's values settle is kept: one trace, the render's record",
          "[probe]") {
  RenderContext context("", true);
  // The Kummer shell's two sheets lie within float's noise of each other: its brackets' end values often do too,
  // and float's rounding of P from the monomials is too large there: float-float settles them. The Barth decic's
  // brackets are settled in float.
  CHECK(check_confirmed_roots("tests/data/hard_surfaces/kummer_shell.toml", true, context) == 4);
}

TEST_CASE("a bracket float's own evaluation of P settles needs no float-float: one trace, the render's record",
          "[probe]") {
  // One of the three brackets of the Barth decic at 160x120 that P from the monomials settles in float
  // (kernels/point_values.h, bracket_ends_proven: found by rendering with those brackets left unsettled).
  RenderContext context("", true);
  const Scene scene = adaptive_preview("scenes/barth_decic.toml", 160, 120);
  Renderer renderer(context.session(), context.cache());
  const RenderResult render = renderer.render_with_records(scene);
  ProbeTarget target{false, 68, 81, {}, {}};
  const std::vector<SurfaceProbe> probes = probe_scene(scene, target, false, context);
  check_kept_doubt(probes.at(0), render.hits.at(68, 81), true);
  CHECK_FALSE(probes.at(0).traces.at(0).confirmed->float_float);
  CHECK(probes.at(0).reference.certificate.cls == PixelClass::SimpleRoot);
}

TEST_CASE(
    "where the second pass is float-float, discard doubts settled in float-float let the search go on: "
    "root-free intervals, the render's record, the reference's answer",
    "[probe]") {
  // The plan settles these only where the second pass would run in float-float, as without fp64.
  const testing::HiddenFp64 hidden;
  RenderContext context("", true);
  REQUIRE(escalation_precision(context.session().info, context.cache()) == Precision::Mixed);
  const Scene scene = load_scene_file(std::string(ALGRAY_SOURCE_DIR) + "/tests/data/hard_surfaces/kummer_shell.toml",
                                      {{"image.width", "96"},
                                       {"image.height", "72"},
                                       {"render.precision", "\"adaptive\""},
                                       {"render.preview", "true"}});
  Renderer renderer(context.session(), context.cache());
  const RenderResult render = renderer.render_with_records(scene);
  int rays = 0, decided = 0;
  for (int py = 1; py < 72 && decided < 4; py += 2)
    for (int px = 1; px < 96 && decided < 4; px += 2) {
      ProbeTarget target{false, px, py, {}, {}};
      const std::vector<SurfaceProbe> probes = probe_scene(scene, target, false, context);
      const SolverTrace& trace = probes.at(0).traces.at(0);
      if (trace.settled_discards.empty()) continue;
      ++rays;
      INFO("pixel (" << px << ", " << py << ")");
      for (const auto& [doubt, ends] : trace.settled_discards) {
        CHECK(doubt.reason == ALGRAY_DOUBT_DISCARD);
        CHECK(std::fabs(doubt.value) <= doubt.noise);
        // P at both ends beyond its bound and of one sign: with the coefficients inside clear of the noise, the
        // interval is root-free.
        CHECK(std::fabs(ends.before) > ends.before_rounding);
        CHECK(std::fabs(ends.after) > ends.after_rounding);
        CHECK((ends.before > 0) == (ends.after > 0));
        // and so it is for the reference: no certified root inside
        for (const auto& root : probes[0].reference.roots)
          CHECK_FALSE((root.t > trace.t_at(doubt.lo) && root.t < trace.t_at(doubt.hi)));
      }
      if (trace.hit.flags & ALGRAY_HIT_DOUBT) continue;  // doubted again later: the second pass answers
      ++decided;
      const HitRecord& rendered = render.hits.at(px, py);
      CHECK(probes[0].traces.size() == 1);
      CHECK((rendered.flags & ALGRAY_HIT_ESCALATED) == 0);
      CHECK(trace.found() == ((rendered.flags & ALGRAY_HIT_FOUND) != 0));
      if (trace.found()) CHECK(std::memcmp(&trace.hit, &rendered, offsetof(HitRecord, flags)) == 0);
      // The float line against the certified answer.
      const PixelClass cls = probes[0].reference.certificate.cls;
      if (cls == PixelClass::Miss) CHECK_FALSE(trace.found());
      if (cls == PixelClass::SimpleRoot) {
        REQUIRE(trace.found());
        const double t_ref = probes[0].reference.roots.at(0).t;
        CHECK(std::fabs(trace.t - t_ref) <= 1e-3 * std::fabs(t_ref));
      }
    }
  INFO(rays << " rays with settled discard doubts");
  CHECK(decided == 4);
}
