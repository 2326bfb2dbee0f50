// The film's colours against Phong written out one ray and one light point at a time, bit for bit.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "algray/device/program_cache.h"
#include "algray/render/renderer.h"
#include "algray/scene/scene.h"
#include "algray/render/shade.h"
#include "test_support.h"

using namespace algray;

namespace {

// Both sides in view (a hyperboloid of one sheet cut by the extent), different materials on each, an area light
// that casts shadows and a point light that does not.
Scene two_sided_scene(bool preview) {
  const std::string text =
      "[surface]\nequation = \"x^2 + y^2 - z^2 - 0.3\"\n"
      "[surface.material.front]\ncolour = [0.9, 0.5, 0.2]\nexponent = 25\nspecular = 0.5\n"
      "[surface.material.back]\ncolour = [0.2, 0.6, 0.9]\nexponent = 60\ndiffuse = 0.6\nambient = 0.2\n"
      "[extent]\nradius = 1.6\n[camera]\neye = [2.5, 3.2, 4.1]\nlook_at = [0, 0, 0]\nup = [0, 0, 1]\nfov_y = 42\n"
      "[image]\nwidth = 83\nheight = 61\n"
      "[[light]]\ntype = \"rectangle\"\nposition = [3, 1, 5]\nedge_u = [1.5, 0, 0]\nedge_v = [0, 1.5, 0]\n"
      "samples = 3\n"
      "[[light]]\nposition = [-4, 3, 2]\nintensity = 0.6\ncolour = [1, 0.9, 0.8]\nshadows = false\n" +
      std::string(preview ? "[render]\npreview = true\n" : "");
  return load_scene_text(text, "two_sided.toml");
}

// Phong of one hit, one light point after another, as the shading model defines it (shade.h).
// `highlit` becomes true where some point adds a highlight.
glm::dvec3 phong(const Scene& scene, const HitRecord& h, const PixelRay& ray, const ShadowLookup& shadows,
                 std::size_t k, bool& highlit) {
  const Materials& sides = scene.surfaces[0].materials;
  const Material& m = (h.flags & ALGRAY_HIT_BACK) ? sides.back : sides.front;
  const glm::dvec3 n(h.normal_x, h.normal_y, h.normal_z);
  const glm::dvec3 to_eye = -glm::normalize(ray.direction);
  const glm::dvec3 point = hit_point(ray, h);
  const double cutoff = std::pow(1.0 / 4096, 1 / m.exponent);
  glm::dvec3 c = m.ambient * m.colour;
  for (std::size_t li = 0; li < scene.lights.size(); ++li) {
    const Light& light = scene.lights[li];
    const std::vector<glm::dvec3> points =
        scene.render.preview ? std::vector<glm::dvec3>{light.position} : light.sample_points();
    const std::uint64_t hidden = shadows.hidden(li, k);
    double diffuse = 0, specular = 0;
    for (std::size_t s = 0; s < points.size(); ++s) {
      if (hidden >> s & 1u) continue;
      const glm::dvec3 l = glm::normalize(points[s] - point);
      const double n_dot_l = glm::dot(n, l);
      if (n_dot_l <= 0) continue;
      diffuse += n_dot_l;
      const double r_dot_v = glm::dot(2 * n_dot_l * n - l, to_eye);
      if (r_dot_v > cutoff) {
        specular += std::pow(r_dot_v, m.exponent);
        highlit = true;
      }
    }
    const double share = 1.0 / static_cast<double>(points.size());
    c += light.intensity * light.colour * (m.diffuse * diffuse * share * m.colour + m.specular * specular * share);
  }
  return c;
}

}  // namespace

TEST_CASE("every hit's colour is Phong over the light points the shadow pass left, bit for bit", "[shading]") {
  ClSession& session = testing::device_session();
  ProgramCache cache(false);
  Renderer renderer(session, cache);
  for (bool preview : {false, true}) {
    for (const char* precision : {"double", "float"}) {
      Scene scene = two_sided_scene(preview);
      scene.render.precision = std::string(precision) == "double" ? Precision::Double : Precision::Float;
      const RenderResult r = renderer.render_with_records(scene);
      const ShadowLookup shadows(r.shadows, r.hits.records.size(), scene.lights.size());
      const bool single = scene.render.precision != Precision::Double;
      // The shader itself on every hit at once (whole groups of lanes and a remainder) and one at a time.
      const Shader shader(scene, r.plan, r.basis, *scene.render.precision);
      std::vector<Shader::HitToShade> all;
      for (int y = 0; y < r.hits.height; ++y)
        for (int x = 0; x < r.hits.width; ++x) {
          const std::size_t k = static_cast<std::size_t>(y) * r.hits.width + x;
          if (r.hits.records[k].flags & ALGRAY_HIT_FOUND)
            all.push_back({&r.hits.records[k], 0, pixel_ray(r.basis, single, x, y), k});
        }
      REQUIRE(all.size() % kShadeLanes != 0);
      std::vector<glm::dvec3> together(all.size()), alone(all.size());
      shader.shade_hits(all.data(), all.size(), shadows, together.data());
      for (std::size_t i = 0; i < all.size(); ++i) shader.shade_hits(&all[i], 1, shadows, &alone[i]);
      std::size_t front = 0, back = 0, shadowed = 0, highlights = 0, next = 0;
      for (int y = 0; y < r.hits.height; ++y)
        for (int x = 0; x < r.hits.width; ++x) {
          const std::size_t k = static_cast<std::size_t>(y) * r.hits.width + x;
          const HitRecord& h = r.hits.records[k];
          if (!(h.flags & ALGRAY_HIT_FOUND)) continue;
          bool highlit = false;
          const glm::dvec3 expected = phong(scene, h, pixel_ray(r.basis, single, x, y), shadows, k, highlit);
          INFO((preview ? "preview" : "full") << ", " << precision << ", pixel " << x << "," << y);
          REQUIRE(all[next].hit_index == k);
          CHECK(std::memcmp(&together[next], &expected, sizeof expected) == 0);
          CHECK(std::memcmp(&alone[next], &expected, sizeof expected) == 0);
          ++next;
          for (int c = 0; c < 3; ++c) {
            const float want = static_cast<float>(expected[c]), got = r.image.rgba[4 * k + c];
            CHECK(std::memcmp(&want, &got, sizeof want) == 0);
          }
          CHECK(r.image.rgba[4 * k + 3] == 1.0f);
          ++((h.flags & ALGRAY_HIT_BACK) ? back : front);
          shadowed += shadows.hidden(0, k) != 0;
          highlights += highlit;
        }
      // The scene shows what the check is for: both sides, shadows in full mode, and highlights.
      INFO((preview ? "preview" : "full") << ", " << precision);
      CHECK(front > 200);
      CHECK(back > 200);
      CHECK((shadowed > 20) == !preview);
      CHECK(highlights > 5);
    }
  }
}
