// Reflection and transmission rays against spheres, whose hits are known in closed form; tiled renders against one
// tile.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "algray/device/program_cache.h"
#include "algray/render/renderer.h"
#include "algray/render/shade.h"
#include "algray/render/solver_aov.h"
#include "algray/scene/scene.h"
#include "film_compare.h"
#include "scene_fixtures.h"
#include "test_support.h"

using namespace algray;
using testing::ball_and_ring;
using testing::first_difference;
using testing::same_bits;

namespace {

// Smallest t > 0 where o + t d meets the sphere |p - c| = r, or +inf.
double sphere_hit(const PixelRay& ray, const glm::dvec3& c, double r) {
  const glm::dvec3 oc = ray.origin - c;
  const double a = glm::dot(ray.direction, ray.direction), b = glm::dot(oc, ray.direction);
  const double disc = b * b - a * (glm::dot(oc, oc) - r * r);
  if (disc < 0) return INFINITY;
  const double s = std::sqrt(disc);
  for (double t : {(-b - s) / a, (-b + s) / a})
    if (t > 0) return t;
  return INFINITY;
}

Scene sphere_scene(const std::string& equation, const std::vector<std::string>& material) {
  std::string text = "[surface]\nequation = \"" + equation +
                     "\"\n[extent]\nradius = 3.5\n[camera]\neye = [0.3, 0.4, 8]\nlook_at = [0, 0, 0]\n"
                     "up = [0, 1, 0]\nfov_y = 40\n[image]\nwidth = 128\nheight = 96\n"
                     "[[light]]\nposition = [4, 5, 6]\n";
  for (const std::string& line : material) text += line + "\n";
  return load_scene_text(text, "spheres.toml");
}

struct Sphere {
  glm::dvec3 centre;
  double radius;
};

// Every ray of every secondary batch against the closed form: hit or miss, and t to 1e-7 of the ray's length.
void check_batches(const RenderResult& r, const std::vector<Sphere>& spheres, PassKind pass, std::size_t& checked) {
  for (const SecondaryBatch& batch : r.secondary) {
    if (batch.pass != pass) continue;
    for (std::size_t i = 0; i < batch.rays.size(); ++i) {
      double expected = INFINITY;
      for (const Sphere& s : spheres) expected = std::min(expected, sphere_hit(batch.rays[i], s.centre, s.radius));
      const HitRecord& h = batch.hits[i];
      const bool hit = (h.flags & ALGRAY_HIT_FOUND) != 0;
      const double t = static_cast<double>(h.t_hi) + static_cast<double>(h.t_lo);
      INFO(to_string(pass) << " depth " << batch.depth << " ray " << i << ": expected t " << expected << ", kernel "
                           << (hit ? std::to_string(t) : std::string("miss")));
      // A ray grazing a sphere may go either way; elsewhere the answer is certain.
      const bool grazing = std::isfinite(expected) && std::fabs(t - expected) > 1e-3 && !hit;
      if (grazing) continue;
      REQUIRE(hit == std::isfinite(expected));
      if (hit) CHECK(std::fabs(t - expected) <= 1e-7 * std::max(1.0, expected));
      // The ray starts off the surface it leaves: never a hit right at its origin.
      if (hit) CHECK(expected * glm::length(batch.rays[i].direction) > 1e-4);
      // It starts on one of the spheres (within the offset) and a mirror ray leaves it outwards.
      const Sphere* from = nullptr;
      for (const Sphere& s : spheres)
        if (std::fabs(glm::length(batch.rays[i].origin - s.centre) - s.radius) < 1e-4) from = &s;
      REQUIRE(from != nullptr);
      if (pass == PassKind::Reflection) {
        const glm::dvec3 outward = batch.rays[i].origin - from->centre;
        CHECK(glm::dot(outward, batch.rays[i].direction) >= 0);
      }
      ++checked;
    }
  }
}

}  // namespace

TEST_CASE("transmission rays continue to the next root: nested spheres", "[secondary]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  // Radii 1 and 2 around the origin; both sides of both transparent, so rays pass through up to four sheets.
  const Scene scene =
      sphere_scene("(x^2+y^2+z^2-1)*(x^2+y^2+z^2-4)", {"[material.front]", "transparency = 0.5", "[material.back]",
                                                       "transparency = 0.5", "[render]", "precision = \"double\""});
  const RenderResult r = renderer.render_with_records(scene);
  std::size_t checked = 0;
  check_batches(r, {{{0, 0, 0}, 1}, {{0, 0, 0}, 2}}, PassKind::Transmission, checked);
  int deepest = 0;
  for (const SecondaryBatch& b : r.secondary) deepest = std::max(deepest, b.depth);
  CHECK(deepest >= 3);  // through the outer sphere, the inner one, and out again
  CHECK(checked > 1000);
}

TEST_CASE("reflection rays leave by the mirror direction and find the other sphere", "[secondary]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  const Scene scene = sphere_scene("((x-1.3)^2+y^2+z^2-1)*((x+1.3)^2+y^2+z^2-1)",
                                   {"[material.front]", "reflectivity = 0.5", "[render]", "precision = \"double\""});
  const RenderResult r = renderer.render_with_records(scene);
  std::size_t checked = 0, hits = 0;
  check_batches(r, {{{1.3, 0, 0}, 1}, {{-1.3, 0, 0}, 1}}, PassKind::Reflection, checked);
  for (const SecondaryBatch& b : r.secondary)
    for (const HitRecord& h : b.hits) hits += (h.flags & ALGRAY_HIT_FOUND) != 0;
  CHECK(checked > 1000);
  CHECK(hits > 50);  // the spheres see each other in their inner flanks
}

TEST_CASE("a transparent side without a transmission pass shows opaque, not darkened", "[secondary]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  for (const char* how : {"preview = true", "max_depth = 0"}) {
    INFO(how);
    const Scene clear = sphere_scene("x^2+y^2+z^2-1", {"[material.front]", "transparency = 1", "[render]", how});
    Scene opaque = clear;
    opaque.surfaces[0].materials.front.transparency = 0;
    const RenderResult r = renderer.render_with_records(clear);
    CHECK(r.plan.find(PassKind::Transmission) == nullptr);
    const FrameImage a = shade_frame(clear, r), b = shade_frame(opaque, renderer.render_with_records(opaque));
    const std::size_t centre = 4 * (static_cast<std::size_t>(a.height / 2) * a.width + a.width / 2);
    CHECK(a.rgba[centre] > 0.1f);
    CHECK(a.rgba[centre] == b.rgba[centre]);
  }
}

TEST_CASE("tiles and batches change no pixel: small ones render the one-tile image bit for bit", "[secondary][tiles]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  // Full mode with everything that crosses a tile's border or fills a batch: two surfaces, a reflective ball
  // and a transparent ring (bounces), an area light's shadows, and adaptive antialiasing, whose choice at a
  // tile's edge depends on the neighbouring tile's first colours; then the same with uniform 2x2 supersampling.
  for (const char* adaptive : {"true", "false"}) {
    Scene scene =
        ball_and_ring({{"antialias.adaptive", adaptive}, {"antialias.samples", adaptive[0] == 't' ? "3" : "2"}});
    scene.render.tile_size = 4096;  // one tile
    RenderOptions whole;
    whole.keep_records = true;
    const RenderResult one = renderer.render(scene, whole);
    std::vector<std::string> passes;
    for (const PassStats& p : one.passes) {
      passes.push_back(p.name);
      CHECK(p.rays > 0);
    }
    CHECK(passes == (adaptive[0] == 't'
                         ? std::vector<std::string>{"primary", "shadow", "reflection", "transmission", "antialias"}
                         : std::vector<std::string>{"primary", "shadow", "reflection", "transmission"}));
    CHECK(one.passes[0].launches == 2);  // one tile, one kernel per surface
    // The film is what shade_frame makes of the records.
    const FrameImage from_records = shade_frame(scene, one);
    INFO("adaptive " << adaptive << ": film against shade_frame, first difference "
                     << first_difference(one.image, from_records));
    CHECK(same_bits(one.image.rgba, from_records.rgba));
    CHECK(same_bits(one.image.depth, from_records.depth));
    CHECK(same_bits(one.image.normal, from_records.normal));

    // Tiles of 8 and 13 traced rays a side (not dividing the image), batches of 1000 and of 37 rays, so that
    // shadow points, antialias rays and bounces are split into groups.
    const struct {
      int tile;
      std::size_t batch;
    } splits[] = {{8, 1000}, {13, 37}, {4096, 37}};
    for (const auto& split : splits) {
      scene.render.tile_size = split.tile;
      RenderOptions options;
      options.keep_records = true;
      options.batch_rays = split.batch;
      const RenderResult tiled = renderer.render(scene, options);
      INFO("adaptive " << adaptive << ", tile " << split.tile << ", batches of " << split.batch
                       << " rays: first difference " << first_difference(one.image, tiled.image));
      CHECK(tiled.passes[0].launches > (split.tile < 4096 ? 2 * 20 : 1));
      CHECK(same_bits(one.image.rgba, tiled.image.rgba));
      CHECK(same_bits(one.image.depth, tiled.image.depth));
      CHECK(same_bits(one.image.normal, tiled.image.normal));
      CHECK(same_bits(one.hits.records, tiled.hits.records));
      CHECK(same_bits(one.hits.surface, tiled.hits.surface));
      CHECK(same_bits(one.refined, tiled.refined));
      REQUIRE(tiled.passes.size() == one.passes.size());
      for (std::size_t p = 0; p < one.passes.size(); ++p) {
        INFO("pass " << one.passes[p].name);
        CHECK(tiled.passes[p].rays == one.passes[p].rays);
      }
      std::size_t largest = 0;
      for (const SecondaryBatch& b : tiled.secondary) largest = std::max(largest, b.rays.size());
      CHECK(largest <= std::max<std::size_t>(split.batch, 9));  // whole pixels: a refined one has 9 rays
    }
  }
}

TEST_CASE("without records a render keeps the film and the totals, not every ray", "[secondary][tiles]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  Scene scene = ball_and_ring({});
  scene.render.tile_size = 16;
  RenderOptions options;
  std::size_t tiles = 0, camera_rays = 0;
  SolverWork work = empty_solver_work(scene.image.width, scene.image.height, 1);
  options.on_primary_tile = [&](const PrimaryTile& tile) {
    add_tile_work(work, tile);
    ++tiles;
    camera_rays += static_cast<std::size_t>(tile.width) * tile.height;
    CHECK(tile.width <= 16);
    CHECK(tile.height <= 16);
  };
  const RenderResult lean = renderer.render(scene, options);
  CHECK(lean.hits.records.empty());
  CHECK(lean.secondary.empty());
  CHECK(lean.shadows.points.empty());
  CHECK(tiles == 5 * 4);
  CHECK(camera_rays == 72u * 54u);
  CHECK(lean.primary.rays == 72u * 54u);
  CHECK(lean.primary.pixels == 72u * 54u);
  CHECK(lean.primary.hits > 0);
  const RenderResult full = renderer.render_with_records(scene);
  CHECK(same_bits(lean.image.rgba, full.image.rgba));
  const PrimarySummary from_records = summarise_hits(full.hits, full.plan.samples);
  CHECK(lean.primary.hits == from_records.hits);
  CHECK(lean.primary.isolation_steps == from_records.isolation_steps);
  CHECK(lean.primary.pixels_hit == from_records.pixels_hit);
  // The solver channels gathered tile by tile are those of the whole records.
  const SolverWork whole = solver_work(full);
  CHECK(work.isolation_steps == whole.isolation_steps);
  CHECK(work.refine_iterations == whole.refine_iterations);
  CHECK(work.flags == whole.flags);
  CHECK(work.classification == whole.classification);
}

TEST_CASE("adaptive precision escalates camera, shadow, reflected and transmitted rays alike, counted per pass",
          "[secondary][adaptive]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  std::ifstream in(std::string(ALGRAY_SOURCE_DIR) + "/tests/data/hard_surfaces/kummer_shell.toml");
  std::stringstream text;
  text << in.rdbuf() << "\n[[light]]\nposition = [4, 5, 6]\n";
  const Scene scene = load_scene_text(text.str(), "kummer_shell.toml",
                                      {{"image.width", "48"},
                                       {"image.height", "36"},
                                       {"render.preview", "false"},
                                       {"render.precision", "\"adaptive\""},
                                       {"render.max_depth", "2"},
                                       {"material.front.reflectivity", "0.4"},
                                       {"material.front.transparency", "0.4"}});
  const RenderResult r = renderer.render_with_records(scene);
  for (const PassKind kind : {PassKind::Primary, PassKind::Shadow, PassKind::Reflection, PassKind::Transmission}) {
    const PlannedPass* planned = r.plan.find(kind);
    REQUIRE(planned != nullptr);
    REQUIRE(planned->escalation.size() == 1);
    const PassStats* stats = nullptr;
    for (const PassStats& p : r.passes)
      if (p.name == to_string(kind)) stats = &p;
    REQUIRE(stats != nullptr);
    INFO(stats->name << ": " << stats->escalated << " of " << stats->rays << " rays escalated");
    CHECK(stats->escalated > 0);
    CHECK(stats->escalated < stats->rays);
    CHECK(stats->escalation_ms > 0);
    CHECK(stats->escalation_ms <= stats->kernel_ms);
    // The pass lists its escalation kernel after its own, with its device time.
    REQUIRE(stats->program_keys.size() == 2);
    CHECK(stats->program_keys[1] == planned->escalation[0].key());
    CHECK(stats->program_ms[1] == Approx(stats->escalation_ms));
  }
  // No record keeps the float kernel's doubt: each doubted ray's answer is the second pass's.
  std::size_t escalated_camera = 0;
  for (const HitRecord& h : r.hits.records) {
    CHECK_FALSE(h.flags & ALGRAY_HIT_DOUBT);
    escalated_camera += (h.flags & ALGRAY_HIT_ESCALATED) != 0;
  }
  std::size_t escalated_secondary = 0, secondary = 0;
  for (const SecondaryBatch& b : r.secondary)
    for (const HitRecord& h : b.hits) {
      CHECK_FALSE(h.flags & ALGRAY_HIT_DOUBT);
      escalated_secondary += (h.flags & ALGRAY_HIT_ESCALATED) != 0;
      ++secondary;
    }
  CHECK(escalated_camera == r.passes.at(0).escalated);
  CHECK(escalated_secondary > 0);
  CHECK(escalated_secondary < secondary);
}
