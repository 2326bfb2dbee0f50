// .jsurf import: jsurf's framing (clip sphere, scale, rotation, camera), lights, values and errors.
#include <catch2/catch.hpp>
#include <cmath>

#include "cli_sandbox.h"
#include "algray/render/render_plan.h"
#include "algray/render/renderer.h"
#include "algray/scene/scene.h"
#include "test_support.h"

using namespace algray;
using algray::testing::device_session;

namespace {

// A file in the style SURFER writes: orthographic camera one unit behind the clip sphere's centre, three
// lights in camera space. `body` adds or replaces keys (a later key wins, as in Java properties).
std::string jsurf_file(const std::string& body) {
  return "#SURFER surface description\n"
         "camera_type=ORTHOGRAPHIC_CAMERA\n"
         "camera_height=2.0\n"
         "camera_fov_y=60.0\n"
         "camera_transform=1.0 0.0 0.0 -0.0  0.0 1.0 0.0 -0.0  0.0 0.0 1.0 -1.0  0.0 0.0 0.0 1.0\n"
         "background_color=1.0 1.0 1.0\n"
         "front_material_color=0.9 0.5 0.2\n"
         "back_material_color=0.2 0.4 0.9\n"
         "light_status_0=ON\nlight_position_0=-100.0 100.0 100.0\nlight_intensity_0=0.7\n"
         "light_status_1=ON\nlight_position_1=100.0 100.0 100.0\nlight_intensity_1=0.5\n"
         "light_status_2=ON\nlight_position_2=0.0 -100.0 100.0\nlight_intensity_2=0.3\n" +
         body;
}

Scene jsurf_scene(const std::string& body, int size = 101) {
  return load_jsurf_text(jsurf_file(body), "test.jsurf",
                         {{"image.width", std::to_string(size)},
                          {"image.height", std::to_string(size)},
                          {"antialias.samples", "1"},
                          {"antialias.adaptive", "false"}});
}

HitBuffer render_hits(const Scene& scene) {
  Renderer renderer(device_session(), testing::program_cache());
  return renderer.render_with_records(scene).hits;
}

struct Coverage {
  int left = 1 << 30, right = -1, top = 1 << 30, bottom = -1;
  long count = 0;
  double centre_x = 0, centre_y = 0;
};
Coverage coverage(const HitBuffer& hits) {
  Coverage c;
  for (int y = 0; y < hits.height; ++y)
    for (int x = 0; x < hits.width; ++x)
      if (hits.at(x, y).flags & ALGRAY_HIT_FOUND) {
        c.left = std::min(c.left, x);
        c.right = std::max(c.right, x);
        c.top = std::min(c.top, y);
        c.bottom = std::max(c.bottom, y);
        ++c.count;
        c.centre_x += x;
        c.centre_y += y;
      }
  if (c.count) {
    c.centre_x /= static_cast<double>(c.count);
    c.centre_y /= static_cast<double>(c.count);
  }
  return c;
}

}  // namespace

TEST_CASE("the clip sphere fills the image as in jsurf, at any scale factor and rotation", "[jsurf]") {
  // The plane facing the camera, cut by the clip sphere: a disc whose diameter is the image height, as in
  // jsurf (camera_height 2 across a clip sphere of radius 1). Rotated and scaled, the disc stays the same.
  struct Case {
    const char* body;
  };
  const Case cases[] = {
      {"surface_equation=z\nscale_factor=0.0\n"},
      {"surface_equation=z\nscale_factor=0.7\n"},
      {"surface_equation=z\nscale_factor=-0.4\n"},
      // z = 0 in equation space, seen along the equation's x axis after this rotation: the plane x = 0 faces us.
      {"surface_equation=x\nscale_factor=0.3\n"
       "rotation_matrix=0.0 0.0 1.0 0.0  0.0 1.0 0.0 0.0  -1.0 0.0 0.0 0.0  0.0 0.0 0.0 1.0\n"},
  };
  for (const Case& c : cases) {
    INFO(c.body);
    const Scene scene = jsurf_scene(c.body);
    CHECK(scene.camera.projection == Projection::Orthographic);
    const Coverage cov = coverage(render_hits(scene));
    CHECK(cov.left <= 1);
    CHECK(cov.right >= 99);
    CHECK(cov.top <= 1);
    CHECK(cov.bottom >= 99);
    const double disc = 3.14159265358979 / 4 * 101 * 101;
    CHECK(cov.count == Approx(disc).epsilon(0.02));
    CHECK(cov.centre_x == Approx(50).margin(0.5));
    CHECK(cov.centre_y == Approx(50).margin(0.5));
  }
}

TEST_CASE("jsurf's scale factor and rotation place a surface as jsurf does", "[jsurf]") {
  // A unit sphere at scale_factor 0.3 is 10^-0.3 of the clip sphere: jsurf draws it 51 pixels wide of 101.
  const Coverage sphere = coverage(render_hits(jsurf_scene("surface_equation=x^2+y^2+z^2-1\nscale_factor=0.3\n")));
  CHECK(sphere.right - sphere.left + 1 == Approx(101 * std::pow(10.0, -0.3)).margin(1.5));
  // Wholly outside the clip sphere at scale_factor -0.3: nothing to see.
  CHECK(coverage(render_hits(jsurf_scene("surface_equation=x^2+y^2+z^2-1\nscale_factor=-0.3\n"))).count == 0);

  // A small ball at equation +x shows on the right; the row-major rotation 0 -1 0 / 1 0 0 moves it to the bottom.
  const std::string blob = "surface_equation=(x-0.6)^2+y^2+z^2-0.04\nscale_factor=0.0\n";
  const Coverage right = coverage(render_hits(jsurf_scene(blob)));
  REQUIRE(right.count > 0);
  CHECK(right.centre_x > 70);
  CHECK(right.centre_y == Approx(50).margin(2));
  const Coverage bottom = coverage(render_hits(
      jsurf_scene(blob + "rotation_matrix=0.0 -1.0 0.0 0.0  1.0 0.0 0.0 0.0  0.0 0.0 1.0 0.0  0.0 0.0 0.0 1.0\n")));
  REQUIRE(bottom.count > 0);
  CHECK(bottom.centre_y > 70);
  CHECK(bottom.centre_x == Approx(50).margin(2));
}

TEST_CASE("jsurf lights stay in camera space and values map to algray's scene", "[jsurf]") {
  const Scene scene = jsurf_scene(
      "surface_equation=x^2+y^2+z^2-a^2\nsurface_parameter_a=0.5\nscale_factor=0.2\n"
      "rotation_matrix=0.0 0.0 1.0 0.0  0.0 1.0 0.0 0.0  -1.0 0.0 0.0 0.0  0.0 0.0 0.0 1.0\n"
      "front_material_shininess=40.0\nfront_material_specular_iIntensity=0.5\nlight_status_2=OFF\n");
  CHECK(scene.parameters.at("a") == 0.5);
  CHECK(scene.extent.radius == Approx(std::pow(10.0, 0.2)));
  REQUIRE(scene.lights.size() == 2);
  for (const Light& l : scene.lights) CHECK(!l.shadows);
  // Light 1 sits at camera-space (100, 100, 100): to the viewer's right, above, behind the eye.
  const RayBasis basis = make_ray_basis(scene.camera, 101, 101);
  const glm::dvec3 to_light = scene.lights[1].position - scene.camera.eye;
  CHECK(glm::dot(to_light, basis.right) > 0);
  CHECK(glm::dot(to_light, basis.true_up) > 0);
  CHECK(glm::dot(to_light, basis.forward) < 0);
  CHECK(scene.surface().materials.front.exponent == Approx(10));   // Blinn 40 is about Phong 10
  CHECK(scene.surface().materials.front.specular == Approx(0.5));  // the 2011 spelling counts
  // Display colours become linear ones.
  CHECK(scene.surface().materials.front.colour.r == Approx(std::pow((0.9 + 0.055) / 1.055, 2.4)));
}

TEST_CASE("bad .jsurf files get located errors; unsupported or ignored features get warnings", "[jsurf][errors]") {
  const auto error_of = [](const std::string& text) -> SceneError {
    try {
      load_jsurf_text(text, "bad.jsurf");
    } catch (const SceneError& e) {
      return e;
    }
    FAIL("no error for:\n" << text);
    throw std::logic_error("unreachable");
  };
  CHECK_THAT(error_of("background_color=1 1 1\n").message, Catch::Contains("surface_equation"));
  // Line 3: the value starts at column 20, and "qq" 6 characters into it.
  const SceneError eq = error_of("# a comment\nscale_factor=0.1\nsurface_equation = x^2 + qq\n");
  CHECK(eq.where == "bad.jsurf:3:26");
  CHECK_THAT(eq.message, Catch::Contains("qq"));
  // The same on a continued line, and after an escape: positions are the file's, not the joined line's.
  CHECK(error_of("surface_equation = x^2 + \\\n    y^2 + qq\n").where == "bad.jsurf:2:11");
  CHECK(error_of("surface_equation = \\u0078 + qq\n").where == "bad.jsurf:1:29");
  CHECK_THAT(error_of(jsurf_file("surface_equation=x\nscale_factor=400\n")).message, Catch::Contains("finite"));
  CHECK_THAT(error_of(jsurf_file("surface_equation=x\nsurface_parameter_a.b=1\n")).message,
             Catch::Contains("not a parameter name"));
  CHECK_THAT(error_of(jsurf_file("surface_equation=x\nsurface_parameter_log=1\n")).message,
             Catch::Contains("reserved"));
  const SceneError number = error_of(jsurf_file("surface_equation=x\nscale_factor=big\n"));
  CHECK_THAT(number.where, Catch::Contains("bad.jsurf:"));
  CHECK_THAT(number.message, Catch::Contains("'big' is not a number"));
  CHECK_THAT(error_of(jsurf_file("surface_equation=x\nrotation_matrix=2 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n")).message,
             Catch::Contains("pure rotation"));
  CHECK_THAT(error_of(jsurf_file("surface_equation=x\ncamera_transform=1 0 0\n")).message,
             Catch::Contains("expected 16 numbers, found 3"));
  CHECK_THAT(error_of(jsurf_file("surface_equation=x\ncamera_type=FISHEYE\n")).message,
             Catch::Contains("ORTHOGRAPHIC_CAMERA"));

  // Java properties syntax: ':' and blank separators, '!' comments, continued lines.
  const Scene s = load_jsurf_text(jsurf_file("! comment\nsurface_equation : x^2+y^2\\\n    +z^2-1\n"
                                             "scale_factor 0.1\nsurface_parameter_b=2\nfoo_bar=1\n"
                                             "transform_matrix=1 0 0 0 0 0 -1 0 0 1 0 0 0 0 0 1\n"),
                                  "ok.jsurf");
  CHECK(s.surface().polynomial.degree() == 2);
  CHECK(s.extent.radius == Approx(std::pow(10.0, 0.1)));
  CHECK(s.parameters.at("b") == 2);
  bool unknown = false, ignored = false;
  for (const std::string& w : s.warnings) {
    unknown |= w.find("foo_bar") != std::string::npos;
    ignored |= w.find("transform_matrix is ignored") != std::string::npos;
  }
  CHECK(unknown);
  CHECK(ignored);
}

TEST_CASE("algray render takes .jsurf files and jsurf text on standard input", "[jsurf][cli]") {
  using namespace algray::testing;
  Sandbox box;
  write_text(box.in / "ball.jsurf", jsurf_file("surface_equation=x^2+y^2+z^2-1\nscale_factor=0.3\nmystery=1\n"));
  const Result r =
      box.run("render " + quoted((box.in / "ball.jsurf").string()) + " --width 64 --height 64 -o ball.png");
  INFO(r.err);
  CHECK(r.exit_code == 0);
  CHECK(fs::exists(box.work / "ball.png"));
  CHECK(r.err.find("warning") != std::string::npos);
  CHECK(r.err.find("mystery") != std::string::npos);
  const Result piped = box.run("render - --width 32 --height 32 -o piped.png", box.in / "ball.jsurf");
  INFO(piped.err);
  CHECK(piped.exit_code == 0);
  CHECK(fs::exists(box.work / "piped.png"));
}
