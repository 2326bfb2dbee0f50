// The render plan, seen through --stats: each effect's pass, kernel and rays exist only when asked; its memory.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "cli_sandbox.h"
#include "algray/io/image_io.h"
#include "algray/render/render_plan.h"
#include "algray/scene/scene.h"
#include "scene_fixtures.h"

using namespace algray::testing;

namespace {

// A rectangle light above and to the right of the unit sphere's camera, with `extra` lines added to it.
std::vector<std::string> light_lines(const std::string& extra = "") {
  std::vector<std::string> lines = {"[[light]]",        "type = \"rectangle\"", "position = [3, 4, 5]",
                                    "edge_u = [1, 0, 0]", "edge_v = [0, 1, 0]", "samples = 3"};
  if (!extra.empty()) lines.push_back(extra);
  return lines;
}

std::vector<std::string> names_of(const nlohmann::json& list) {
  std::vector<std::string> names;
  for (const auto& item : list) names.push_back(item.at("name").get<std::string>());
  return names;
}

// Renders the unit sphere with `tail` appended at 40x30 and returns its --stats.
nlohmann::json stats_of_unit_sphere(const std::vector<std::string>& tail, const std::string& flags) {
  Sandbox box;
  const auto scene = box.scene("s.toml", sphere_with({}, tail));
  const Result r =
      box.run("render " + quoted(scene.string()) + " -o out.exr --width 40 --height 30 --stats s.json " + flags);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  return box.stats();
}

struct PlanCase {
  const char* what;
  std::vector<std::string> scene_tail;
  const char* flags;
  bool shadows;
};

}  // namespace

TEST_CASE("only the passes a scene calls for are built, launched and counted", "[plan]") {
  require_device();
  const std::vector<PlanCase> cases = {
      {"no lights: a headlight, no shadows", {}, "", false},
      {"a light that casts no shadows", light_lines("shadows = false"), "", false},
      {"a shadow-casting light in preview mode", light_lines(), "--preview", false},
      {"a shadow-casting light", light_lines(), "", true},
      {"two lights, one casting shadows", [] {
         std::vector<std::string> l = light_lines("shadows = false");
         for (const std::string& line : light_lines()) l.push_back(line);
         return l;
       }(),
       "", true},
  };
  for (const PlanCase& c : cases) {
    INFO(c.what);
    const nlohmann::json s = stats_of_unit_sphere(c.scene_tail, c.flags);
    const std::vector<std::string> passes = names_of(s.at("passes"));
    // What ran is what the plan says, in its order.
    CHECK(passes == names_of(s.at("plan").at("passes")));
    const std::vector<std::string> expected =
        c.shadows ? std::vector<std::string>{"primary", "shadow"} : std::vector<std::string>{"primary"};
    CHECK(passes == expected);
    bool shadow_program = false;
    for (const auto& p : s.at("programs")) shadow_program |= p.at("key").get<std::string>().rfind("shadow ", 0) == 0;
    CHECK(shadow_program == c.shadows);
    std::uint64_t shadow_rays = 0;
    for (const auto& p : s.at("passes"))
      if (p.at("name") == "shadow") shadow_rays = p.at("rays").get<std::uint64_t>();
    if (c.shadows)
      CHECK(shadow_rays > 0);
    else
      CHECK(shadow_rays == 0);
    // No buffer of a pass that does not run.
    for (const auto& b : s.at("plan").at("buffers")) {
      const std::string name = b.at("name");
      if (!c.shadows) CHECK(name == "primary hits");
    }
    CHECK(s.at("plan").at("skipped").size() >= (c.shadows ? 2u : 3u));
  }
}

TEST_CASE("the paper's ray origin (eye) builds camera rays about the eye and shadow rays on their segments",
          "[plan]") {
  // The shadow kernel has no eye construction: a plan that asked for one failed to build it (found 2026-12-06).
  const nlohmann::json stats =
      stats_of_unit_sphere(light_lines(), "--isolation sturm --set render.ray_origin=\"eye\"");
  std::set<std::string> origins;  // pass name and the origin= of its kernels' keys
  for (const auto& pass : stats.at("plan").at("passes"))
    for (const auto& kernel : pass.at("kernels")) {
      const std::string key = kernel.get<std::string>(), at = key.substr(key.find(" origin=") + 8);
      origins.insert(pass.at("name").get<std::string>() + " " + at.substr(0, at.find(' ')));
    }
  CHECK(origins == std::set<std::string>{"primary eye", "shadow extent"});
}

TEST_CASE("antialiasing traces samples x samples camera rays per pixel, and no more", "[plan]") {
  require_device();
  for (int samples : {1, 3}) {
    INFO("antialias.samples = " << samples);
    Sandbox box;
    const auto scene =
        box.scene("s.toml", sphere_with({}, {"[antialias]", "samples = " + std::to_string(samples)}));
    const Result r = box.run("render " + quoted(scene.string()) + " -o out.exr --width 40 --height 30 --stats s.json");
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const nlohmann::json s = box.stats();
    REQUIRE(s.at("passes").size() == 1);
    CHECK(s.at("passes")[0].at("rays").get<long>() == 40L * 30 * samples * samples);
    CHECK(s.at("plan").at("traced").at("width").get<int>() == 40 * samples);
  }
}

TEST_CASE("preview mode traces one camera ray per pixel whatever the scene's antialiasing", "[plan]") {
  require_device();
  for (const char* adaptive : {"false", "true"}) {
    INFO("antialias.adaptive = " << adaptive);
    const nlohmann::json s =
        stats_of_unit_sphere({"[antialias]", "samples = 3", std::string("adaptive = ") + adaptive}, "--preview");
    REQUIRE(names_of(s.at("passes")) == std::vector<std::string>{"primary"});
    CHECK(s.at("passes")[0].at("rays").get<long>() == 40L * 30);
    CHECK(s.at("plan").at("traced").at("width").get<int>() == 40);
    const std::string skipped = s.at("plan").at("skipped").dump();
    CHECK(skipped.find("antialias: preview mode traces one camera ray per pixel") != std::string::npos);
  }
}

TEST_CASE("reflection and transmission passes run only for materials that ask, and never in preview", "[plan]") {
  require_device();
  struct EffectCase {
    const char* what;
    std::vector<std::string> tail;
    const char* flags;
    std::set<std::string> passes;  // besides primary
  };
  const std::vector<EffectCase> cases = {
      {"ordinary materials", {"[material.front]", "reflectivity = 0", "transparency = 0"}, "", {}},
      {"a reflective side", {"[material.front]", "reflectivity = 0.4"}, "", {"reflection"}},
      {"a transparent side", {"[material.front]", "transparency = 0.5"}, "", {"transmission"}},
      {"both", {"[material.front]", "reflectivity = 0.3", "transparency = 0.5"}, "", {"reflection", "transmission"}},
      {"both, in preview mode", {"[material.front]", "reflectivity = 0.3", "transparency = 0.5"}, "--preview", {}},
      {"both, with no bounces allowed",
       {"[material.front]", "reflectivity = 0.3", "transparency = 0.5", "[render]", "max_depth = 0"},
       "",
       {}},
  };
  for (const EffectCase& c : cases) {
    INFO(c.what);
    const nlohmann::json s = stats_of_unit_sphere(c.tail, c.flags);
    CHECK(names_of(s.at("passes")) == names_of(s.at("plan").at("passes")));
    std::set<std::string> secondary;
    for (const auto& p : s.at("passes")) {
      const std::string name = p.at("name");
      if (name == "primary") continue;
      secondary.insert(name);
      // The unit sphere fills the middle of the view: every bounce pass has camera hits to start from.
      CHECK(p.at("rays").get<std::uint64_t>() > 0);
      for (const auto& k : p.at("kernels")) CHECK(k.at("key").get<std::string>().rfind("trace ", 0) == 0);
    }
    CHECK(secondary == c.passes);
    bool trace_program = false;
    for (const auto& p : s.at("programs")) trace_program |= p.at("key").get<std::string>().rfind("trace ", 0) == 0;
    CHECK(trace_program == !c.passes.empty());
  }
}

TEST_CASE("adaptive antialiasing traces n x n rays only where neighbours differ, and looks like uniform", "[plan]") {
  require_device();
  Sandbox box;
  const std::string scene = quoted(std::string(ALGRAY_SOURCE_DIR) + "/scenes/tanglecube.toml");
  const std::string common = " --width 96 --height 72 --set antialias.samples=3 --set render.precision=double";
  const Result uniform = box.run("render " + scene + " -o uniform.exr --stats u.json" + common);
  const Result adaptive =
      box.run("render " + scene + " -o adaptive.exr --stats a.json --set antialias.adaptive=true" + common);
  INFO(uniform.err << adaptive.err);
  REQUIRE(uniform.exit_code == 0);
  REQUIRE(adaptive.exit_code == 0);
  const nlohmann::json u = box.stats("u.json"), a = box.stats("a.json");
  CHECK(names_of(u.at("passes")) == std::vector<std::string>{"primary", "shadow"});
  CHECK(names_of(a.at("passes")) == std::vector<std::string>{"primary", "shadow", "antialias"});
  // One camera ray per pixel first; then 9 per refined pixel, some but not all of them.
  CHECK(a.at("passes")[0].at("rays").get<long>() == 96 * 72);
  const long refined_rays = a.at("passes")[2].at("rays").get<long>();
  CHECK(refined_rays % 9 == 0);
  CHECK(refined_rays > 0);
  CHECK(refined_rays / 9 < 96 * 72 / 2);
  CHECK(a.at("passes")[1].at("rays").get<long>() < u.at("passes")[1].at("rays").get<long>());

  const algray::FrameImage ui = algray::read_exr(box.work / "uniform.exr");
  const algray::FrameImage ai = algray::read_exr(box.work / "adaptive.exr");
  REQUIRE(ui.rgba.size() == ai.rgba.size());
  double total = 0;
  int far = 0;
  for (std::size_t p = 0; p < ui.rgba.size() / 4; ++p) {
    double worst = 0;
    for (int c = 0; c < 4; ++c) worst = std::max(worst, std::fabs(double(ui.rgba[4 * p + c]) - ai.rgba[4 * p + c]));
    total += worst;
    far += worst > 0.1;  // the default threshold
  }
  const double mean = total / static_cast<double>(ui.rgba.size() / 4);
  INFO("mean difference " << mean << ", " << far << " pixels off by more than the threshold");
  CHECK(mean < 0.005);
  CHECK(far <= 96 * 72 / 200);  // a feature thinner than a pixel can fall between the first rays
}

TEST_CASE("a plan's memory grows with the pixels, not with the samples, the lights or the bounces", "[plan][memory]") {
  // No device: the plan alone. The bound is 40 bytes per output pixel plus 300 MB, whatever the
  // antialiasing, the lights and the bounces; the film is 32 bytes a pixel, the rest is one tile's work.
  using algray::Override;
  const std::vector<std::vector<Override>> settings = {
      {},  // the scene as shipped: 2x2 antialiasing, two 5x5 area lights with shadows
      {{"antialias.samples", "1"}},
      {{"antialias.samples", "16"}},
      {{"antialias.samples", "8"}, {"antialias.adaptive", "true"}},
      {{"light.0.samples", "8"}, {"light.1.samples", "8"}},
      {{"material.front.reflectivity", "0.5"}, {"material.back.transparency", "0.5"}, {"render.max_depth", "8"}},
  };
  for (const auto& extra : settings) {
    std::string what = "the scene as shipped";
    for (const Override& o : extra) what += ", " + o.key + " = " + o.value;
    INFO(what);
    auto plan_at = [&](int side) {
      std::vector<Override> all = {{"image.width", std::to_string(side)}, {"image.height", std::to_string(side)}};
      all.insert(all.end(), extra.begin(), extra.end());
      const algray::Scene scene =
          algray::load_scene_file(std::string(ALGRAY_SOURCE_DIR) + "/scenes/barth_sextic.toml", all);
      return algray::make_render_plan(scene, algray::Precision::Double, 1024);
    };
    const algray::RenderPlan small = plan_at(1024), poster = plan_at(8192);
    // One tile's buffers and host work, whatever the image.
    CHECK(poster.buffer_bytes() == small.buffer_bytes());
    CHECK(poster.tile_host_bytes == small.tile_host_bytes);
    CHECK(poster.buffer_bytes() + poster.tile_host_bytes < (200ull << 20));
    const std::uint64_t pixels = 8192ull * 8192, small_pixels = 1024ull * 1024;
    const std::uint64_t per_pixel = poster.refine_samples > 1 ? 33 : 32;
    CHECK(poster.estimated_memory_bytes() - small.estimated_memory_bytes() == per_pixel * (pixels - small_pixels));
    CHECK(poster.estimated_memory_bytes() <= 40 * pixels + 300'000'000ull);
  }
  // A render the machine cannot hold is still refused on the estimate (test_reliability).
  const algray::Scene huge = algray::load_scene_file(std::string(ALGRAY_SOURCE_DIR) + "/scenes/barth_sextic.toml",
                                                     {{"image.width", "32768"}, {"image.height", "32768"}});
  CHECK(algray::make_render_plan(huge, algray::Precision::Double).estimated_memory_bytes() > (32ull << 30));
}
