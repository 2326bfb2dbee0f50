// Reflection and transmission rays against spheres, whose hits are known in closed form.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "program_cache.h"
#include "renderer.h"
#include "scene.h"
#include "shade.h"
#include "test_support.h"

using namespace algray;

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
void check_batches(const RenderResult& r, const std::vector<Sphere>& spheres, const std::string& pass,
                   std::size_t& checked) {
  for (const SecondaryBatch& batch : r.secondary) {
    if (batch.pass != pass) continue;
    for (std::size_t i = 0; i < batch.rays.size(); ++i) {
      double expected = INFINITY;
      for (const Sphere& s : spheres) expected = std::min(expected, sphere_hit(batch.rays[i], s.centre, s.radius));
      const HitRecord& h = batch.hits[i];
      const bool hit = (h.flags & ALGRAY_HIT_FOUND) != 0;
      const double t = static_cast<double>(h.t_hi) + static_cast<double>(h.t_lo);
      INFO(pass << " depth " << batch.depth << " ray " << i << ": expected t " << expected << ", kernel "
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
      if (pass == "reflection") {
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
  ProgramCache cache(false);
  Renderer renderer(session, cache);
  // Radii 1 and 2 around the origin; both sides of both transparent, so rays pass through up to four sheets.
  const Scene scene = sphere_scene("(x^2+y^2+z^2-1)*(x^2+y^2+z^2-4)",
                                   {"[material.front]", "transparency = 0.5", "[material.back]", "transparency = 0.5",
                                    "[render]", "precision = \"double\""});
  const RenderResult r = renderer.render(scene, false);
  std::size_t checked = 0;
  check_batches(r, {{{0, 0, 0}, 1}, {{0, 0, 0}, 2}}, "transmission", checked);
  int deepest = 0;
  for (const SecondaryBatch& b : r.secondary) deepest = std::max(deepest, b.depth);
  CHECK(deepest >= 3);  // through the outer sphere, the inner one, and out again
  CHECK(checked > 1000);
}

TEST_CASE("reflection rays leave by the mirror direction and find the other sphere", "[secondary]") {
  ClSession& session = testing::device_session();
  ProgramCache cache(false);
  Renderer renderer(session, cache);
  const Scene scene = sphere_scene("((x-1.3)^2+y^2+z^2-1)*((x+1.3)^2+y^2+z^2-1)",
                                   {"[material.front]", "reflectivity = 0.5", "[render]", "precision = \"double\""});
  const RenderResult r = renderer.render(scene, false);
  std::size_t checked = 0, hits = 0;
  check_batches(r, {{{1.3, 0, 0}, 1}, {{-1.3, 0, 0}, 1}}, "reflection", checked);
  for (const SecondaryBatch& b : r.secondary)
    for (const HitRecord& h : b.hits) hits += (h.flags & ALGRAY_HIT_FOUND) != 0;
  CHECK(checked > 1000);
  CHECK(hits > 50);  // the spheres see each other in their inner flanks
}

TEST_CASE("a transparent side without a transmission pass shows opaque, not darkened", "[secondary]") {
  ClSession& session = testing::device_session();
  ProgramCache cache(false);
  Renderer renderer(session, cache);
  for (const char* how : {"preview = true", "max_depth = 0"}) {
    INFO(how);
    const Scene clear = sphere_scene("x^2+y^2+z^2-1", {"[material.front]", "transparency = 1", "[render]", how});
    Scene opaque = clear;
    opaque.surfaces[0].materials.front.transparency = 0;
    const RenderResult r = renderer.render(clear, false);
    CHECK(r.plan.find("transmission") == nullptr);
    const FrameImage a = shade_frame(clear, r), b = shade_frame(opaque, renderer.render(opaque, false));
    const std::size_t centre = 4 * (static_cast<std::size_t>(a.height / 2) * a.width + a.width / 2);
    CHECK(a.rgba[centre] > 0.1f);
    CHECK(a.rgba[centre] == b.rgba[centre]);
  }
}
