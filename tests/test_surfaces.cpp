// Several surfaces in one scene: each traced by its own kernel, the nearest hit winning, each with its materials.
#include <catch2/catch.hpp>
#include <cmath>
#include <set>
#include <string>

#include "algray/device/program_cache.h"
#include "algray/render/renderer.h"
#include "algray/scene/scene.h"
#include "test_support.h"

using namespace algray;

namespace {

const std::string kCamera =
    "[extent]\nradius = 3.5\n[camera]\neye = [0.5, 4, 6]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nfov_y = 45\n"
    "[image]\nwidth = 80\nheight = 60\n[render]\nprecision = \"double\"\n";
const std::string kSphere = "x^2+y^2+z^2-1";
const std::string kTorus = "(x^2+y^2+z^2+2.25-0.16)^2-9*(x^2+z^2)";  // major radius 1.5, minor 0.4, around y

Scene two_surfaces(const std::string& lights = "") {
  return load_scene_text("[[surface]]\nname = \"ball\"\nequation = \"" + kSphere +
                             "\"\n[surface.material.front]\ncolour = [1, 0, 0]\n"
                             "[[surface]]\nname = \"ring\"\nequation = \"" + kTorus +
                             "\"\n[surface.material.front]\ncolour = [0, 1, 0]\n" + kCamera + lights,
                         "two.toml");
}

Scene one_surface(const std::string& equation) {
  return load_scene_text("[surface]\nequation = \"" + equation + "\"\n" + kCamera, "one.toml");
}

double t_of(const HitRecord& h) { return static_cast<double>(h.t_hi) + static_cast<double>(h.t_lo); }

}  // namespace

TEST_CASE("a scene's surfaces each get their own kernel, and the nearest hit wins", "[surfaces]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  const Scene scene = two_surfaces();
  REQUIRE(scene.surfaces.size() == 2);
  CHECK(scene.surfaces[0].materials.front.colour == glm::dvec3(1, 0, 0));
  CHECK(scene.surfaces[1].materials.front.colour == glm::dvec3(0, 1, 0));
  const RenderResult both = renderer.render_with_records(scene);
  const RenderResult ball = renderer.render_with_records(one_surface(kSphere));
  const RenderResult ring = renderer.render_with_records(one_surface(kTorus));

  // One primary kernel per surface, specialised by its degree.
  REQUIRE(both.passes.at(0).program_keys.size() == 2);
  CHECK(both.passes[0].program_keys[0].find("degree=2 ") != std::string::npos);
  CHECK(both.passes[0].program_keys[1].find("degree=4 ") != std::string::npos);

  // Each camera ray counts once in the statistics, and the solver work of both kernels is kept.
  CHECK(both.passes[0].rays == both.hits.records.size());
  std::uint64_t work_both = 0, work_apart = 0;
  for (std::size_t i = 0; i < both.hits.records.size(); ++i) {
    work_both += ALGRAY_WORK_ISOLATION_STEPS(both.hits.records[i].work);
    work_apart +=
        ALGRAY_WORK_ISOLATION_STEPS(ball.hits.records[i].work) + ALGRAY_WORK_ISOLATION_STEPS(ring.hits.records[i].work);
  }
  CHECK(work_both == work_apart);

  std::set<int> seen;
  for (std::size_t i = 0; i < both.hits.records.size(); ++i) {
    const HitRecord& h = both.hits.records[i];
    const HitRecord& a = ball.hits.records[i];
    const HitRecord& b = ring.hits.records[i];
    const bool ha = a.flags & ALGRAY_HIT_FOUND, hb = b.flags & ALGRAY_HIT_FOUND;
    INFO("pixel " << i % 80 << "," << i / 80);
    REQUIRE(((h.flags & ALGRAY_HIT_FOUND) != 0) == (ha || hb));
    if (!(ha || hb)) continue;
    const int expected = !hb || (ha && t_of(a) <= t_of(b)) ? 0 : 1;
    CHECK(both.hits.surface_of(i) == expected);
    CHECK(t_of(h) == t_of(expected == 0 ? a : b));
    seen.insert(both.hits.surface_of(i));
  }
  CHECK(seen == std::set<int>{0, 1});  // the view shows both
}

TEST_CASE("shadows and bounces see every surface", "[surfaces]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  // A low light on +x: the ball shades the far (-x) side of the ring, which alone would be lit there.
  const std::string light = "[[light]]\nposition = [4, 3, 0]\n";
  const RenderResult both = renderer.render_with_records(two_surfaces(light));
  Scene ring_alone = one_surface(kTorus);
  ring_alone.lights = two_surfaces(light).lights;
  const RenderResult ring = renderer.render_with_records(ring_alone);
  REQUIRE(both.passes.size() == 2);
  CHECK(both.passes[1].name == "shadow");
  CHECK(both.passes[1].program_keys.size() == 2);
  // Per camera pixel that shows the ring in both renders: the ball can only add shadow, and somewhere it does.
  auto hidden_by_pixel = [](const RenderResult& r) {
    std::vector<int> hidden(r.hits.records.size(), -1);  // -1: no shadow ray traced from this pixel
    for (std::size_t k = 0; k < r.shadows.points.size(); ++k)
      hidden[r.shadows.points[k]] = static_cast<int>(r.shadows.occlusion.at(0).masks[k] & 1u);
    return hidden;
  };
  const std::vector<int> with_ball = hidden_by_pixel(both), alone = hidden_by_pixel(ring);
  int compared = 0, newly_hidden = 0;
  for (std::size_t i = 0; i < with_ball.size(); ++i) {
    if (both.hits.surface_of(i) != 1 || with_ball[i] < 0 || alone[i] < 0) continue;
    ++compared;
    INFO("pixel " << i % 80 << "," << i / 80);
    CHECK(with_ball[i] >= alone[i]);
    newly_hidden += with_ball[i] > alone[i];
  }
  CHECK(compared > 100);
  CHECK(newly_hidden > 10);

  // Mirror rays from the ring that meet the ball find it: secondary rays are traced against every surface too.
  Scene mirrors = two_surfaces();
  mirrors.surfaces[1].materials.front.reflectivity = 0.5;
  mirrors.surfaces[1].materials.back.reflectivity = 0.5;
  const RenderResult bounced = renderer.render_with_records(mirrors);
  int ball_in_ring = 0, rays = 0;
  for (const SecondaryBatch& batch : bounced.secondary) {
    REQUIRE(batch.pass == PassKind::Reflection);
    rays += static_cast<int>(batch.rays.size());
    for (std::size_t i = 0; i < batch.hits.size(); ++i)
      ball_in_ring += (batch.hits[i].flags & ALGRAY_HIT_FOUND) && !batch.hit_surface.empty() && batch.hit_surface[i] == 0;
  }
  CHECK(rays > 100);
  CHECK(ball_in_ring > 10);
}
