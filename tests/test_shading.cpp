// The film's colours against Phong written out one ray and one light point at a time, bit for bit, the plane
// sections drawn over them, and the device's shading kernel against the host's shading of the same records.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "algray/device/program_cache.h"
#include "algray/render/renderer.h"
#include "algray/scene/scene.h"
#include "algray/render/shade.h"
#include "algray/render/trace_records.h"
#include "film_compare.h"
#include "scene_fixtures.h"
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
  ProgramCache& cache = testing::program_cache();
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

TEST_CASE("a section plane through the unit sphere marks the ring where it cuts the sphere, closed and one pixel wide",
          "[shading][section]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  // The plane z = 0.5, seen from +z: a circle of radius sqrt(0.75) on the near half of the sphere.
  const std::string base =
      "[surface]\nequation = \"x^2+y^2+z^2-1\"\n[extent]\nradius = 1.5\n"
      "[camera]\neye = [0, 0, 4.5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nfov_y = 45\n"
      "[image]\nwidth = 96\nheight = 96\n[antialias]\nsamples = 1\n[render]\nprecision = \"double\"\npreview = true\n";
  const std::string section = "[[section]]\nplane = [0, 0, 2, -1]\ncolour = [0, 1, 0]\n";
  const auto marked = [](const RenderResult& r, std::size_t k) {
    return r.image.rgba[4 * k] == 0.0f && r.image.rgba[4 * k + 1] == 1.0f && r.image.rgba[4 * k + 2] == 0.0f;
  };
  const RenderResult plain = renderer.render_with_records(load_scene_text(base, "plain.toml"));
  const RenderResult cut = renderer.render_with_records(load_scene_text(base + section, "cut.toml"));
  const double ring = std::sqrt(0.75);
  std::size_t count = 0, unmarked_elsewhere = 0;
  bool sectors[16] = {};
  for (int y = 0; y < cut.hits.height; ++y)
    for (int x = 0; x < cut.hits.width; ++x) {
      const std::size_t k = static_cast<std::size_t>(y) * cut.hits.width + x;
      INFO("pixel " << x << "," << y);
      CHECK_FALSE(marked(plain, k));
      if (!marked(cut, k)) {
        // Elsewhere the colour is the plain render's.
        for (int c = 0; c < 4; ++c) unmarked_elsewhere += cut.image.rgba[4 * k + c] != plain.image.rgba[4 * k + c];
        continue;
      }
      const HitRecord& h = cut.hits.records[k];
      REQUIRE((h.flags & ALGRAY_HIT_FOUND) != 0);
      const PixelRay ray = pixel_ray(cut.basis, false, x, y);
      const glm::dvec3 p = ray.origin + (static_cast<double>(h.t_hi) + static_cast<double>(h.t_lo)) * ray.direction;
      // There the rays meet the sphere 72 degrees off its normal, so one pixel outwards moves the hit by about
      // 0.096 in z and 0.055 in sqrt(x^2 + y^2): the ring's pixels lie within half a pixel of the circle, and a
      // little more for the sphere's curving away over that pixel.
      CHECK(std::fabs(p.z - 0.5) < 0.065);
      CHECK(std::fabs(std::hypot(p.x, p.y) - ring) < 0.037);
      ++count;
      const double angle = std::atan2(y + 0.5 - 48, x + 0.5 - 48);
      sectors[static_cast<int>(std::floor((angle + M_PI) / (2 * M_PI) * 16)) & 15] = true;
    }
  CHECK(unmarked_elsewhere == 0);
  // Closed: some of it in each of 16 sectors about the image centre; and one pixel wide: a digital circle of
  // radius 22.3 pixels (the projected ring) has about 4 sqrt(2) 22.3 = 126 pixels.
  for (int i = 0; i < 16; ++i) {
    INFO("sector " << i);
    CHECK(sectors[i]);
  }
  CHECK(count >= 100);
  CHECK(count <= 160);
  // And it reads back from the scene's TOML.
  const Scene again = load_scene_text(scene_to_toml(load_scene_text(base + section, "cut.toml")), "again.toml");
  REQUIRE(again.sections.size() == 1);
  CHECK(again.sections[0].plane == glm::dvec4(0, 0, 2, -1));
  CHECK(again.sections[0].colour == glm::dvec3(0, 1, 0));
}

TEST_CASE("a section of one surface marks that surface only, and a section `width` pixels wide that many times as "
          "many pixels",
          "[shading][section]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  // Two unit balls side by side, seen from +z; the plane z = 0.5 cuts both in a ring of radius sqrt(0.75).
  const std::string base =
      "[[surface]]\nequation = \"(x+1.2)^2+y^2+z^2-1\"\n[[surface]]\nequation = \"(x-1.2)^2+y^2+z^2-1\"\n"
      "[extent]\nradius = 2.5\n"
      "[camera]\neye = [0, 0, 8]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nfov_y = 40\n"
      "[image]\nwidth = 128\nheight = 96\n[antialias]\nsamples = 1\n[render]\nprecision = \"double\"\npreview = true\n";
  const auto marked_on = [&](const std::string& section, long& left, long& right) {
    const RenderResult r = renderer.render_with_records(load_scene_text(base + section, "cut.toml"));
    left = right = 0;
    for (std::size_t k = 0; k < r.hits.records.size(); ++k) {
      const bool marked =
          r.image.rgba[4 * k] == 0.0f && r.image.rgba[4 * k + 1] == 1.0f && r.image.rgba[4 * k + 2] == 0.0f;
      if (!marked) continue;
      REQUIRE((r.hits.records[k].flags & ALGRAY_HIT_FOUND) != 0);
      (r.hits.surface_of(k) == 0 ? left : right) += 1;
    }
  };
  long every_left = 0, every_right = 0, one_left = 0, one_right = 0, wide_left = 0, wide_right = 0;
  marked_on("[[section]]\nplane = [0, 0, 1, -0.5]\ncolour = [0, 1, 0]\n", every_left, every_right);
  marked_on("[[section]]\nplane = [0, 0, 1, -0.5]\ncolour = [0, 1, 0]\nsurface = 1\n", one_left, one_right);
  marked_on("[[section]]\nplane = [0, 0, 1, -0.5]\ncolour = [0, 1, 0]\nsurface = 1\nwidth = 3\n", wide_left,
            wide_right);
  // Both rings alike (the scene is symmetric), each a closed digital circle of radius about 12 pixels.
  CHECK(every_left >= 50);
  CHECK(std::labs(every_left - every_right) <= every_left / 10);
  CHECK(one_left == 0);
  CHECK(one_right == every_right);
  CHECK(wide_left == 0);
  CHECK(static_cast<double>(wide_right) == Approx(3.0 * static_cast<double>(one_right)).epsilon(0.25));
  // Both keys read back from the scene's TOML; a surface index past the list is a located error.
  const Scene again = load_scene_text(
      scene_to_toml(load_scene_text(base + "[[section]]\nplane = [0, 0, 1, 0]\nsurface = 1\nwidth = 2.5\n", "a.toml")),
      "again.toml");
  REQUIRE(again.sections.size() == 1);
  CHECK(again.sections[0].surface == 1);
  CHECK(again.sections[0].width == 2.5);
  CHECK(load_scene_text(base + "[[section]]\nplane = [0, 0, 1, 0]\n", "b.toml").sections[0].surface == -1);
  for (const char* bad : {"surface = 2", "surface = -1", "width = 0", "width = 65", "surface = 0.5"}) {
    CAPTURE(bad);
    try {
      load_scene_text(base + "[[section]]\nplane = [0, 0, 1, 0]\n" + bad + "\n", "bad.toml");
      FAIL("accepted");
    } catch (const SceneError& e) {
      // The value's line (the base's 19 lines, the table's header and plane before it) and column.
      CHECK(e.where == "bad.toml:22:" + std::to_string(std::strchr(bad, '=') - bad + 3));
    }
  }
}

TEST_CASE("a section seen through a transparent surface is as wide as one seen directly", "[shading][section]") {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  // The ring where z = 0.5 cuts the unit ball, seen from +z, directly and through the clear plane z = 1.5: the
  // transmitted ray starts at the plane, and its pixel's footprint still grows with the distance from the eye.
  const std::string ball = "[[surface]]\nequation = \"x^2+y^2+z^2-1\"\n";
  const std::string pane =
      "[[surface]]\nequation = \"z-1.5\"\n[surface.material.front]\ntransparency = 1\nspecular = 0\n"
      "[surface.material.back]\ntransparency = 1\nspecular = 0\n";
  const std::string rest =
      "[extent]\nradius = 2\n[camera]\neye = [0, 0, 8]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nfov_y = 30\n"
      "[image]\nwidth = 96\nheight = 96\n[antialias]\nsamples = 1\n[render]\nprecision = \"double\"\n"
      "[[section]]\nplane = [0, 0, 1, -0.5]\ncolour = [0, 1, 0]\nsurface = 0\n";
  const auto marked = [&](const std::string& text) {
    const RenderResult r = renderer.render_with_records(load_scene_text(text, "t.toml"));
    long n = 0;
    for (std::size_t k = 0; k < r.hits.records.size(); ++k)
      n += r.image.rgba[4 * k] < 0.1f && r.image.rgba[4 * k + 1] > 0.9f && r.image.rgba[4 * k + 2] < 0.1f;
    return n;
  };
  const long direct = marked(ball + rest), through = marked(ball + pane + rest);
  CHECK(direct >= 80);
  CHECK(static_cast<double>(through) == Approx(static_cast<double>(direct)).epsilon(0.1));
}

TEST_CASE("the shading kernel's film and totals are the host's shading of the same records: bit for bit in double, "
          "within 1/255 in float", "[shading][device]") {
  ClSession& session = testing::device_session();
  REQUIRE(session.info.fp64);  // the double half of the check needs it; the float half hides it below
  DeviceInfo without_fp64 = session.info;
  without_fp64.fp64 = false;
  without_fp64.fp64_hidden = true;
  ClSession float_session(without_fp64);
  ProgramCache& cache = testing::program_cache();
  // Full mode and preview (lights, shadows, both sides; 2x2 samples per pixel), the headlight, and sections of two
  // surfaces with bounces and adaptive antialiasing, each in an image whose width is no multiple of the kernel's
  // lanes and work-groups.
  Scene supersampled = two_sided_scene(false);
  supersampled.antialias.samples = 2;
  std::vector<std::pair<std::string, Scene>> scenes = {{"two-sided, full, 2x2", supersampled},
                                                       {"two-sided, preview", two_sided_scene(true)}};
  Scene headlight = two_sided_scene(true);
  headlight.lights.clear();
  scenes.emplace_back("headlight", headlight);
  Scene sections = testing::ball_and_ring({{"antialias.adaptive", "true"}, {"antialias.samples", "2"}});
  sections.sections.push_back({{0, 0, 1, -0.1}, {0.9, 0.1, 0.1}, -1, 2});
  sections.sections.push_back({{1, 0, 0, 0}, {0.1, 0.9, 0.1}, 1, 1});
  scenes.emplace_back("ball and ring, sections, adaptive antialiasing", sections);
  for (auto& [what, scene] : scenes) {
    for (ClSession* on : {&session, &float_session}) {
      const bool in_double = on->info.fp64;
      scene.render.precision = in_double ? Precision::Double : Precision::Adaptive;
      Renderer renderer(*on, cache);
      const RenderResult r = renderer.render_with_records(scene);
      const FrameImage host = shade_frame(scene, r);
      INFO(what << (in_double ? ", double" : ", without fp64") << ": first difference "
                << testing::first_difference(r.image, host));
      CHECK(testing::same_bits(r.image.depth, host.depth));
      CHECK(testing::same_bits(r.image.normal, host.normal));
      if (in_double) {
        CHECK(testing::same_bits(r.image.rgba, host.rgba));
      } else {
        REQUIRE(r.image.rgba.size() == host.rgba.size());
        float largest = 0;
        for (std::size_t i = 0; i < host.rgba.size(); ++i)
          largest = std::max(largest, std::fabs(r.image.rgba[i] - host.rgba[i]));
        INFO("largest colour difference " << largest * 255 << "/255");
        CHECK(largest <= 1.0f / 255);
      }
      // The kernel's totals of the camera rays are the records' own.
      const PrimarySummary want = summarise_hits(r.hits, r.plan.samples), got = r.primary;
      CHECK(got.rays == want.rays);
      CHECK(got.hits == want.hits);
      CHECK(got.depth_limited == want.depth_limited);
      CHECK(got.isolation_steps == want.isolation_steps);
      CHECK(got.refine_iterations == want.refine_iterations);
      CHECK(got.pixels == want.pixels);
      CHECK(got.pixels_hit == want.pixels_hit);
      CHECK(want.hits > 100);
    }
  }
}
