// Tests of the TOML scene reader: the shipped scenes, parameters, overrides and every error's file:line:column.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "algray/scene/camera.h"
#include "algray/scene/expression.h"
#include "algray/scene/scene.h"
#include "scene_fixtures.h"

using algray::Override;
using algray::Scene;
using algray::SceneError;

namespace {

using algray::testing::sphere_with;

// Loads `text` expecting a SceneError and returns it; fails the test if the scene loads.
SceneError error_of(const std::string& text, const std::vector<Override>& overrides = {}) {
  try {
    algray::load_scene_text(text, "t.toml", overrides);
  } catch (const SceneError& e) {
    return e;
  }
  FAIL("the scene loaded, but an error was expected:\n" << text);
  throw std::logic_error("unreachable");
}

void check_error(const std::string& text, const std::string& where, const std::string& phrase) {
  const SceneError e = error_of(text);
  INFO("scene:\n" << text << "error: " << e.what());
  CHECK(e.where == where);
  CHECK_THAT(e.message, Catch::Contains(phrase));
}

algray::Polynomial equation(const std::string& text, const std::map<std::string, double>& params = {}) {
  return algray::parse_equation(text, params);
}

}  // namespace

TEST_CASE("every shipped scene loads with a supported degree and a non-empty extent", "[scene]") {
  const std::filesystem::path dir = std::filesystem::path(ALGRAY_SOURCE_DIR) / "scenes";
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".toml") continue;
    ++count;
    INFO(entry.path());
    Scene s;
    REQUIRE_NOTHROW(s = algray::load_scene_file(entry.path().string()));
    CHECK(s.surface().polynomial.degree() >= 1);
    CHECK(s.surface().polynomial.degree() <= 32);
    CHECK_FALSE(s.name.empty());
    if (s.extent.kind == algray::ExtentKind::Sphere) {
      CHECK(s.extent.radius > 0);
    } else {
      for (int i = 0; i < 3; ++i) CHECK(s.extent.min[i] < s.extent.max[i]);
    }
  }
  // A wrong path would make the loop vacuous.
  CHECK(count >= 10);
}

TEST_CASE("the default scene is the Barth sextic", "[scene]") {
  const Scene s = algray::default_scene();
  CHECK(s.surface().polynomial.degree() == 6);
  CHECK(s.surface().polynomial.terms().size() == 17);
  CHECK(s.name == "Barth sextic");
  CHECK(s.source == "<built-in default scene>");
  // The embedded copy must be the file in scenes/, not a stale one.
  const Scene file = algray::load_scene_file(std::string(ALGRAY_SOURCE_DIR) + "/scenes/barth_sextic.toml");
  CHECK(s.surface().polynomial == file.surface().polynomial);
}

TEST_CASE("a scene without surface.name is named after its file", "[scene]") {
  const Scene s = algray::load_scene_text(sphere_with({}), "some/dir/ball.toml");
  CHECK(s.name == "ball");
}

TEST_CASE("parameters are substituted into the equation as their double values", "[scene]") {
  const std::string text = sphere_with({{3, "equation = \"x^2+y^2+z^2-a\""}}, {"[parameters]", "a = 2.7"});
  const Scene s = algray::load_scene_text(text, "t.toml");
  CHECK(s.parameters.at("a") == 2.7);
  CHECK(s.surface().polynomial == equation("x^2+y^2+z^2-a", {{"a", 2.7}}));
  CHECK_FALSE(s.surface().polynomial == equation("x^2+y^2+z^2-3"));

  SECTION("a bare override key names a parameter") {
    const Scene o = algray::load_scene_text(text, "t.toml", {{"a", "3"}});
    CHECK(o.parameters.at("a") == 3.0);
    CHECK(o.surface().polynomial == equation("x^2+y^2+z^2-3"));
  }
  SECTION("parameters.NAME adds a parameter the file lacks; a bare name may not (issue 46: a typo is refused)") {
    const std::string uses_b = sphere_with({{3, "equation = \"x^2+y^2+z^2-b\""}});
    CHECK(algray::load_scene_text(uses_b, "t.toml", {{"parameters.b", "0.25"}}).surface().polynomial ==
          equation("x^2+y^2+z^2-0.25"));
    CHECK_THROWS_AS(algray::load_scene_text(uses_b, "t.toml", {{"b", "0.25"}}), SceneError);
  }
}

TEST_CASE("dotted overrides reach image, render and camera keys", "[scene]") {
  const Scene base = algray::load_scene_text(sphere_with({}), "t.toml");
  REQUIRE(base.image.width != 64);
  REQUIRE_FALSE(base.render.precision.has_value());
  REQUIRE(base.camera.fov_y_degrees == 45);

  const Scene s = algray::load_scene_text(
      sphere_with({}), "t.toml", {{"image.width", "64"}, {"render.precision", "float"}, {"camera.fov_y", "30"}});
  CHECK(s.image.width == 64);
  REQUIRE(s.render.precision.has_value());
  CHECK(*s.render.precision == algray::Precision::Float);
  CHECK(s.camera.fov_y_degrees == 30);

  // Later overrides win, which is how --width beats an earlier --set image.width.
  const Scene twice =
      algray::load_scene_text(sphere_with({}), "t.toml", {{"image.width", "64"}, {"image.width", "48"}});
  CHECK(twice.image.width == 48);
}

TEST_CASE("camera.shift moves the image's centre across the image plane; none is the camera as before",
          "[scene][camera]") {
  const std::string text = "[surface]\nequation = \"x^2+y^2+z^2-1\"\n[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\n"
                           "fov_y = 40\n";
  const Scene plain = algray::load_scene_text(text, "t.toml");
  const Scene shifted = algray::load_scene_text(text + "shift = [0.25, -0.5]\n", "t.toml");
  CHECK(plain.camera.shift == glm::dvec2(0));
  CHECK(shifted.camera.shift == glm::dvec2(0.25, -0.5));
  // The centre of a 200 x 100 image: on the axis without a shift; a quarter width right and half a height down
  // with it, that is half the view's half-width and its whole half-height.
  const double h = std::tan(20 * 3.14159265358979 / 180), aspect = 2;
  const auto centre_ray = [](const Scene& s) {
    const algray::RayBasis b = algray::make_ray_basis(s.camera, 200, 100);
    return b.d00 + 100.0 * b.du + 50.0 * b.dv;
  };
  const glm::dvec3 c0 = centre_ray(plain), c1 = centre_ray(shifted);
  CHECK(c0.x == Approx(0).margin(1e-12));
  CHECK(c0.y == Approx(0).margin(1e-12));
  CHECK(c1.x / -c1.z == Approx(0.5 * h * aspect));
  CHECK(c1.y / -c1.z == Approx(-h));
  // The rest of the ray basis is unchanged, and the shift reads back from the scene's TOML.
  CHECK(algray::make_ray_basis(shifted.camera, 200, 100).du == algray::make_ray_basis(plain.camera, 200, 100).du);
  CHECK(algray::load_scene_text(algray::scene_to_toml(shifted), "again.toml").camera.shift == shifted.camera.shift);
  CHECK(algray::scene_to_toml(plain).find("shift") == std::string::npos);
  check_error(text + "shift = [0.25]\n", "t.toml:7:9", "camera.shift must be an array of 2 numbers");
  check_error(text + "shift = [0, 1000]\n", "t.toml:7:13", "camera.shift[1] must be between");
}

TEST_CASE("the paper's term list gives the same polynomial as the equation", "[scene]") {
  const Scene s = algray::load_scene_text(
      sphere_with({{3, "terms = [[2,0,0,1.0],[0,2,0,1.0],[0,0,2,1.0],[0,0,0,-1.0]]"}}), "t.toml");
  CHECK(s.surface().polynomial == equation("x^2+y^2+z^2-1"));
  CHECK_FALSE(s.surface().equation.empty());
}

TEST_CASE("unknown keys are reported at the key, with a suggestion when one is close", "[scene][errors]") {
  check_error(sphere_with({{1, "colour = 1"}}), "t.toml:1:1", "unknown key 'colour'");

  const SceneError e = error_of(sphere_with({{10, "fovy = 45"}}));
  CHECK(e.where == "t.toml:10:1");
  CHECK_THAT(e.message, Catch::Contains("unknown key 'camera.fovy'"));
  CHECK_THAT(e.message, Catch::Contains("did you mean 'fov_y'?"));
  CHECK(e.excerpt == "  fovy = 45\n  ^");
}

TEST_CASE("equation errors point at the character inside the string", "[scene][errors]") {
  // `equation = "` is 12 characters, so character n (0-based) of the equation is column 13 + n.
  SECTION("malformed") {
    const SceneError e = error_of(sphere_with({{3, "equation = \"x^2+*y\""}}));
    CHECK(e.where == "t.toml:3:17");
    CHECK_THAT(e.message, Catch::Contains("unexpected"));
    CHECK_THAT(e.message, Catch::Contains("at character 5 of the equation"));
    std::string caret(2 + 16, ' ');  // built apart: GCC 12 misreads the temporaries of a + chain (-Warray-bounds)
    caret += '^';
    CHECK(e.excerpt == "  equation = \"x^2+*y\"\n" + caret);
    // what() carries the location and the excerpt, since that is all the CLI prints.
    CHECK_THAT(std::string(e.what()), Catch::StartsWith("t.toml:3:17: error: "));
    CHECK_THAT(std::string(e.what()), Catch::Contains(e.excerpt));
  }
  SECTION("division by a variable") {
    check_error(sphere_with({{3, "equation = \"x/y\""}}), "t.toml:3:15", "division by a variable");
  }
  SECTION("negative power") {
    check_error(sphere_with({{3, "equation = \"x^-2\""}}), "t.toml:3:15", "negative exponent");
  }
  SECTION("fractional power") {
    check_error(sphere_with({{3, "equation = \"x^2.5\""}}), "t.toml:3:15", "fractional exponent");
  }
  SECTION("unknown identifier") {
    check_error(sphere_with({{3, "equation = \"x^2+w\""}}), "t.toml:3:17", "unknown identifier 'w'");
  }
  SECTION("escapes count as one character") {
    // \u0078 is 'x': six source characters for one equation character, so '*' at offset 2 is column 13+6+1.
    check_error(sphere_with({{3, "equation = \"\\u0078+*y\""}}), "t.toml:3:20", "unexpected");
  }
}

TEST_CASE("the polynomial must have degree 1 to 32", "[scene][errors]") {
  // Too high a power is reported at its exponent, before it is expanded; the rest at the equation value, whose
  // opening quote is column 12.
  check_error(sphere_with({{3, "equation = \"x^33\""}}), "t.toml:3:15", "this power would have degree 33");
  check_error(sphere_with({{3, "terms = [[33, 0, 0, 1.0]]"}}), "t.toml:3:9",
              "degree 33 exceeds the supported maximum 32");
  check_error(sphere_with({{3, "equation = \"x-x\""}}), "t.toml:3:12", "identically zero");
  check_error(sphere_with({{3, "equation = \"2\""}}), "t.toml:3:12", "nonzero constant");
  CHECK_NOTHROW(algray::load_scene_text(sphere_with({{3, "equation = \"x^32+y-1\""}}), "t.toml"));
}

TEST_CASE("nan and inf are rejected where they are written", "[scene][errors]") {
  check_error(sphere_with({{5, "radius = nan"}}), "t.toml:5:10", "must be finite, not nan");
  check_error(sphere_with({{7, "eye = [inf, 0, 0]"}}), "t.toml:7:8", "must be finite, not inf");
  check_error(sphere_with({}, {"[parameters]", "k = nan"}), "t.toml:12:5", "parameter 'k' must be finite");
  check_error(sphere_with({}, {"[parameters]", "k = -inf"}), "t.toml:12:5", "parameter 'k' must be finite");
  // A reserved name is refused at the key, even when the equation does not use it.
  check_error(sphere_with({}, {"[parameters]", "log = 1"}), "t.toml:12:1", "must be an identifier other than");
}

TEST_CASE("empty extents are rejected", "[scene][errors]") {
  check_error(sphere_with({{5, "radius = 0"}}), "t.toml:5:10", "the extent is empty");
  check_error(sphere_with({{5, "radius = -1"}}), "t.toml:5:10", "the extent is empty");
  // The box replaces line 5 with three lines; the error points at max on line 7, `max = [` putting '[' at column 7.
  check_error(sphere_with({{5, "type = \"box\"\nmin = [1, -1, -1]\nmax = [1, 1, 1]"}}), "t.toml:7:7",
              "max.x must exceed min.x");
  check_error(sphere_with({{5, "type = \"box\"\nmin = [-1, -1, -1]\nmax = [1, 1, -2]"}}), "t.toml:7:7",
              "max.z must exceed min.z");
  CHECK_NOTHROW(
      algray::load_scene_text(sphere_with({{5, "type = \"box\"\nmin = [-1, -1, -1]\nmax = [1, 1, 1]"}}), "t.toml"));
}

TEST_CASE("degenerate cameras are rejected", "[scene][errors]") {
  check_error(sphere_with({{8, "look_at = [0, 0, 5]"}}), "t.toml:8:11", "look_at coincides with eye");
  check_error(sphere_with({{9, "up = [0, 0, 2]"}}), "t.toml:9:6", "parallel to the viewing direction");
  check_error(sphere_with({{9, "up = [0, 0, 0]"}}), "t.toml:9:6", "degenerate camera");
  check_error(sphere_with({{10, "fov_y = 0"}}), "t.toml:10:9", "fov_y must be between 0 and 180");
  check_error(sphere_with({{10, "fov_y = 180"}}), "t.toml:10:9", "fov_y must be between 0 and 180");
  check_error(sphere_with({{10, "projection = \"orthographic\"\nheight = 0"}}), "t.toml:11:10",
              "height must be positive");
  CHECK_NOTHROW(algray::load_scene_text(sphere_with({{10, "projection = \"orthographic\"\nheight = 3"}}), "t.toml"));
}

TEST_CASE("equation and terms together are rejected at terms", "[scene][errors]") {
  check_error(sphere_with({{3, "equation = \"x^2+y^2+z^2-1\"\nterms = [[1,0,0,1.0]]"}}), "t.toml:4:9", "not both");
}

TEST_CASE("TOML syntax errors carry toml++'s location", "[scene][errors]") {
  // The second '=' on `radius = = 2` is column 10.
  const SceneError e = error_of(sphere_with({{5, "radius = = 2"}}));
  CHECK(e.where == "t.toml:5:10");
  CHECK_FALSE(e.message.empty());
  CHECK_THAT(e.excerpt, Catch::Contains("radius = = 2") && Catch::Contains("^"));
}

TEST_CASE("errors from overrides name the --set argument", "[scene][errors]") {
  const SceneError e = error_of(sphere_with({}), {{"render.tolerance", "nan"}});
  CHECK_THAT(e.where, Catch::StartsWith("--set"));
  CHECK_THAT(e.where, Catch::Contains("render.tolerance"));
  CHECK_THAT(e.message, Catch::Contains("finite"));
  CHECK(e.excerpt.empty());

  const SceneError width = error_of(sphere_with({}), {{"image.width", "0"}});
  CHECK_THAT(width.where, Catch::StartsWith("--set"));
  CHECK_THAT(width.message, Catch::Contains("image.width must be between 1"));
}

TEST_CASE("several [[surface]] tables: each with its polynomial and materials over the scene's", "[scene]") {
  const std::string camera = "[extent]\nradius = 2\n[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\n";
  const Scene s = algray::load_scene_text(
      "[[surface]]\nname = \"a\"\nequation = \"x^2+y^2+z^2-1\"\n"
      "[[surface]]\nequation = \"x^4+y^4+z^4-1\"\n[surface.material.front]\nreflectivity = 0.5\n"
      "[material.front]\ncolour = [0, 1, 0]\n" +
          camera,
      "t.toml");
  REQUIRE(s.surfaces.size() == 2);
  CHECK(s.name == "a");
  CHECK(s.surfaces[1].polynomial.degree() == 4);
  // The scene's [material] reaches both; the second surface's own table adds to it.
  CHECK(s.surfaces[0].materials.front.colour == glm::dvec3(0, 1, 0));
  CHECK(s.surfaces[1].materials.front.colour == glm::dvec3(0, 1, 0));
  CHECK(s.surfaces[0].materials.front.reflectivity == 0);
  CHECK(s.surfaces[1].materials.front.reflectivity == 0.5);

  std::string nine;
  for (int i = 0; i < 9; ++i) nine += "[[surface]]\nequation = \"x - " + std::to_string(i) + "\"\n";
  const SceneError e = error_of(nine + camera);
  CHECK(e.where == "t.toml:1:1");
  CHECK_THAT(e.message, Catch::Contains("at most 8 surfaces"));
  check_error("[[surface]]\nequation = \"x\"\n[[surface]]\nequation = \"3\"\n" + camera, "t.toml:4:12",
              "nonzero constant");
}

TEST_CASE("lights: kinds, keys that belong to another kind, and area samples spread uniformly", "[scene]") {
  const std::string base = sphere_with({});
  check_error(base + "[[light]]\ntype = \"point\"\nposition = [1, 2, 3]\nradius = 2\n", "t.toml:14:10",
              "does not apply to a point light");
  check_error(base + "[[light]]\ntype = \"rectangle\"\nposition = [1, 2, 3]\nedge_u = [1, 0, 0]\nedge_v = [2, 0, 0]\n",
              "t.toml:15:10", "degenerate");
  check_error(base + "[[light]]\ntype = \"disc\"\nposition = [0, 0, 0]\nradius = 1\nsamples = 9\n", "t.toml:15:11",
              "between 1 and 8");
  // A disc's n x n points lie on the disc, in its plane, and cover it by area: mean r^2 is R^2 / 2.
  const Scene s = algray::load_scene_text(
      base + "[[light]]\ntype = \"disc\"\nposition = [1, 2, 3]\nnormal = [0, 0, 2]\nradius = 2\nsamples = 8\n",
      "t.toml");
  REQUIRE(s.lights.size() == 1);
  const std::vector<glm::dvec3> points = s.lights[0].sample_points();
  REQUIRE(points.size() == 64);
  double mean_r2 = 0;
  for (const glm::dvec3& p : points) {
    const glm::dvec3 d = p - glm::dvec3(1, 2, 3);
    CHECK(std::fabs(d.z) < 1e-12);
    CHECK(glm::length(d) <= 2 + 1e-12);
    mean_r2 += glm::dot(d, d) / 64;
  }
  CHECK(mean_r2 == Approx(2.0).epsilon(0.05));
  // A rectangle's points are the centres of an n x n grid of cells.
  const Scene r = algray::load_scene_text(base +
                                              "[[light]]\ntype = \"rectangle\"\nposition = [0, 0, 0]\nedge_u = [2, 0, "
                                              "0]\nedge_v = [0, 4, 0]\nsamples = 2\n",
                                          "t.toml");
  const std::vector<glm::dvec3> corners = r.lights[0].sample_points();
  REQUIRE(corners.size() == 4);
  CHECK(corners[0] == glm::dvec3(-0.5, -1, 0));
  CHECK(corners[3] == glm::dvec3(0.5, 1, 0));
}

TEST_CASE("--set reaches into [[surface]] and [[light]] lists by index, and says how when not indexed",
          "[scene][errors]") {
  const std::string text = sphere_with({}, {"[[light]]", "position = [1, 2, 3]", "[[light]]", "position = [4, 5, 6]"});
  // Unindexed: refused, naming the list and showing the indexed form.
  for (const char* key : {"light.intensity", "light.position"}) {
    INFO(key);
    const SceneError e = error_of(text, {{key, "2"}});
    CHECK(e.where == std::string("--set ") + key + "=2");
    CHECK_THAT(e.message, Catch::Contains("[[light]]"));
    CHECK_THAT(e.message, Catch::Contains("light.0."));
  }
  // Indexed: only that table changes.
  const Scene lit =
      algray::load_scene_text(text, "t.toml", {{"light.1.intensity", "0.25"}, {"light.0.position", "[7, 8, 9]"}});
  REQUIRE(lit.lights.size() == 2);
  CHECK(lit.lights[0].position == glm::dvec3(7, 8, 9));
  CHECK(lit.lights[0].intensity == 1);
  CHECK(lit.lights[1].position == glm::dvec3(4, 5, 6));
  CHECK(lit.lights[1].intensity == 0.25);
  // Out of range, or the whole table: errors that say what exists.
  CHECK_THAT(error_of(text, {{"light.2.intensity", "1"}}).message, Catch::Contains("2 [[light]] tables"));
  CHECK_THAT(error_of(text, {{"light.0", "1"}}).message, Catch::Contains("whole [[light]] table"));
  // Errors in an indexed value still name the --set argument.
  const SceneError bad = error_of(text, {{"light.1.intensity", "[1, 2]"}});
  CHECK(bad.where == "--set light.1.intensity=[1, 2]");

  const std::string two =
      "[[surface]]\nequation = \"x\"\n[[surface]]\nequation = \"y\"\n" +
      std::string("[extent]\nradius = 2\n[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\n");
  CHECK_THAT(error_of(two, {{"surface.equation", "\"z\""}}).message, Catch::Contains("[[surface]]"));
  const Scene second = algray::load_scene_text(two, "two.toml", {{"surface.1.equation", "\"z\""}});
  CHECK(second.surfaces[0].polynomial == equation("x"));
  CHECK(second.surfaces[1].polynomial == equation("z"));
  CHECK_THAT(error_of(text, {{"surface.0.equation", "\"x\""}}).message, Catch::Contains("single [surface] table"));
  // A single [surface] table is still reachable without an index.
  CHECK(algray::load_scene_text(text, "t.toml", {{"surface.equation", "\"x^2+y^2+z^2-4\""}}).surface().polynomial ==
        equation("x^2+y^2+z^2-4"));
}

TEST_CASE("scene_to_toml reads back to the same scene, for every shipped scene and every kind of key", "[scene]") {
  std::vector<std::pair<std::string, Scene>> scenes;
  const std::filesystem::path dir = std::filesystem::path(ALGRAY_SOURCE_DIR) / "scenes";
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir))
    if (entry.path().extension() == ".toml")
      scenes.emplace_back(entry.path().string(), algray::load_scene_file(entry.path().string()));
  // What the shipped scenes may not use: a box, an orthographic camera, area lights, terms, odd settings.
  scenes.emplace_back("variants",
                      algray::load_scene_text(sphere_with({{3,
                                                            "terms = [[2, 0, 0, 0.1], [0, 2, 0, 1.0], [0, 0, 2, 1e-3], "
                                                            "[0, 0, 0, -1.0]]\nname = \"odd \\\"name\\\"\\t\""},
                                                           {5,
                                                            "type = \"box\"\nmin = [-1.5, -2, -0.30000000000000004]\n"
                                                            "max = [1, 2, 3]"},
                                                           {10, "projection = \"orthographic\"\nheight = 3.25"}},
                                                          {"[[light]]",
                                                           "type = \"disc\"",
                                                           "position = [1, 2, 3]",
                                                           "radius = 0.5",
                                                           "normal = [0, 1, 1]",
                                                           "samples = 3",
                                                           "[[light]]",
                                                           "type = \"rectangle\"",
                                                           "position = [-1, 2, 3]",
                                                           "edge_u = [1, 0, 0]",
                                                           "edge_v = [0, 0.5, 0]",
                                                           "shadows = false",
                                                           "colour = [0.1, 0.2, 0.3]",
                                                           "[render]",
                                                           "precision = \"float\"",
                                                           "tolerance = 1e-7",
                                                           "isolation = \"sturm\"",
                                                           "refinement = \"illinois\"",
                                                           "max_iterations = 77",
                                                           "tile_size = 64",
                                                           "max_depth = 2",
                                                           "[antialias]",
                                                           "samples = 3",
                                                           "adaptive = true",
                                                           "threshold = 0.05",
                                                           "[image]",
                                                           "background = [0, 0, 0, 0.5]"}),
                                              "variants.toml", {{"image.width", "123"}}));
  scenes.emplace_back("cylinder", algray::load_scene_text(sphere_with({{5,
                                                                        "type = \"cylinder\"\ncentre = [0.5, 0, "
                                                                        "-0.25]\nradius = 1.5\naxis = \"y\"\n"
                                                                        "half_height = 0.7"}}),
                                                          "cylinder.toml"));
  REQUIRE(scenes.size() >= 12);
  const auto body = [](const std::string& toml) { return toml.substr(toml.find('\n') + 1); };  // past the comment
  for (const auto& [name, scene] : scenes) {
    INFO(name);
    const std::string toml = algray::scene_to_toml(scene);
    Scene again;
    REQUIRE_NOTHROW(again = algray::load_scene_text(toml, name + " (round trip)"));
    CHECK(body(algray::scene_to_toml(again)) == body(toml));
    REQUIRE(again.surfaces.size() == scene.surfaces.size());
    for (std::size_t i = 0; i < scene.surfaces.size(); ++i)
      CHECK(again.surfaces[i].polynomial == scene.surfaces[i].polynomial);
    CHECK(again.parameters == scene.parameters);
    CHECK(again.camera.eye == scene.camera.eye);
    CHECK(again.image.width == scene.image.width);
    CHECK(again.lights.size() == scene.lights.size());
  }
}

// Issue 46: an equation is a scene, the camera by angles, lights attached to the camera, --set's checks and
// extent.type switching.

TEST_CASE("an equation alone gets algray's defaults: sphere of radius 2, framed from 3R, key and fill, 2x2",
          "[scene][defaults]") {
  const Scene s = algray::load_scene_text("[surface]\nequation = \"x^4+y^4+z^4-1\"\n", "eq.toml");
  CHECK(s.extent.kind == algray::ExtentKind::Sphere);
  CHECK(s.extent.radius == algray::kDefaultExtentRadius);
  CHECK(s.extent.centre == glm::dvec3(0));
  REQUIRE(s.camera.angles);
  CHECK(s.camera.angles->azimuth == 30);
  CHECK(s.camera.angles->elevation == 20);
  CHECK(s.camera.angles->distance == algray::kFramingDistance * 2);
  CHECK(glm::length(s.camera.eye - s.camera.look_at) == Approx(6).epsilon(1e-12));
  CHECK(s.camera.fov_y_degrees == 45);
  CHECK(s.antialias.samples == 2);
  REQUIRE(s.lights.size() == 2);
  for (const algray::Light& l : s.lights) {
    CHECK(l.kind == algray::LightKind::Rectangle);
    CHECK(l.in_camera);
    CHECK(l.shadows);
  }
  // The key light is above and to the left of the eye, in the image's frame.
  const algray::RayBasis b = algray::make_ray_basis(s.camera, 800, 600);
  CHECK(glm::dot(s.lights[0].position - s.camera.eye, b.right) < 0);
  CHECK(glm::dot(s.lights[0].position - s.camera.eye, b.true_up) > 0);
  // The same as load_equation gives.
  const Scene e = algray::load_equation("x^4+y^4+z^4-1");
  CHECK(e.camera.eye == s.camera.eye);
  CHECK(e.lights[1].position == s.lights[1].position);
}

TEST_CASE("a scene that places its eye keeps the headlight and one ray per pixel", "[scene][defaults]") {
  const Scene s = algray::load_scene_text(sphere_with({}), "t.toml");
  CHECK(s.lights.empty());
  CHECK(s.antialias.samples == 1);
  CHECK_FALSE(s.camera.angles);
  // Setting an angle later does not change what the scene as written gets.
  const Scene turned = algray::load_scene_text(sphere_with({}), "t.toml", {{"camera.azimuth", "90"}});
  CHECK(turned.lights.empty());
  CHECK(turned.antialias.samples == 1);
  // Only eye and up: look_at is the extent's centre.
  const Scene no_look = algray::load_scene_text(sphere_with({{8, "# no look_at"}, {9, "# no up"}}), "t.toml");
  CHECK(no_look.camera.look_at == glm::dvec3(0));
  CHECK(no_look.camera.up == glm::dvec3(0, 1, 0));
}

TEST_CASE("camera.azimuth, elevation and distance place the eye about look_at", "[scene][camera]") {
  const auto eye_of = [](const std::string& camera) {
    return algray::load_scene_text("[surface]\nequation = \"x^2+y^2+z^2-1\"\n[camera]\n" + camera, "t.toml").camera;
  };
  const algray::CameraSpec front = eye_of("azimuth = 0\nelevation = 0\ndistance = 5\nlook_at = [1, 0, 0]\n");
  CHECK(glm::length(front.eye - glm::dvec3(1, 0, 5)) < 1e-12);
  const algray::CameraSpec side = eye_of("azimuth = 90\nelevation = 0\ndistance = 5\n");
  CHECK(glm::length(side.eye - glm::dvec3(5, 0, 0)) < 1e-12);
  // Straight down the up axis is a camera too: the image's up is then -z (azimuth 0).
  const algray::CameraSpec top = eye_of("azimuth = 0\nelevation = 90\ndistance = 5\n");
  CHECK(glm::length(top.eye - glm::dvec3(0, 5, 0)) < 1e-12);
  const algray::RayBasis b = algray::make_ray_basis(top, 64, 48);
  CHECK(glm::length(b.true_up - glm::dvec3(0, 0, -1)) < 1e-12);
  CHECK(glm::length(b.right - glm::dvec3(1, 0, 0)) < 1e-12);
  // With up along z, azimuth 0 looks from +x.
  const algray::CameraSpec z_up = eye_of("azimuth = 0\nelevation = 0\ndistance = 2\nup = [0, 0, 1]\n");
  CHECK(glm::length(z_up.eye - glm::dvec3(2, 0, 0)) < 1e-12);
  // camera_angles reads them back from any eye.
  const algray::CameraAngles a = algray::camera_angles(
      algray::load_scene_text(sphere_with({{7, "eye = [3, 4, 0]"}}), "t.toml").camera);
  CHECK(a.azimuth == Approx(90));
  CHECK(a.elevation == Approx(std::asin(0.8) * 180 / 3.14159265358979323846));
  CHECK(a.distance == Approx(5));

  check_error(sphere_with({}, {"azimuth = 10"}), "t.toml:11:11", "not both");
  check_error("[surface]\nequation = \"x-1\"\n[camera]\nelevation = 91\n", "t.toml:4:13", "camera.elevation");
  check_error("[surface]\nequation = \"x-1\"\n[camera]\ndistance = 0\n", "t.toml:4:12", "distance must be positive");
}

TEST_CASE("--set camera.azimuth on a scene with an eye keeps its elevation and distance", "[scene][camera]") {
  const Scene before = algray::load_scene_text(sphere_with({{7, "eye = [0, 3, 4]"}}), "t.toml");
  const Scene after = algray::load_scene_text(sphere_with({{7, "eye = [0, 3, 4]"}}), "t.toml",
                                              {{"camera.azimuth", "90"}});
  CHECK(glm::length(after.camera.eye - glm::dvec3(4, 3, 0)) < 1e-12);
  const Scene back = algray::load_scene_text(sphere_with({{7, "eye = [0, 3, 4]"}}), "t.toml",
                                             {{"camera.azimuth", "90"}, {"camera.eye", "[0, 3, 4]"}});
  CHECK(back.camera.eye == before.camera.eye);
  CHECK_FALSE(back.camera.angles);
}

TEST_CASE("lights attached to the camera follow it, and scene_to_toml keeps them attached", "[scene][camera]") {
  const std::string text = "[surface]\nequation = \"x^2+y^2+z^2-1\"\n[[light]]\nframe = \"camera\"\n"
                           "position = [1, 2, 0]\n";
  for (const double azimuth : {0.0, 75.0, -160.0}) {
    INFO("azimuth " << azimuth);
    const Scene s = algray::load_scene_text(text, "t.toml", {{"camera.azimuth", std::to_string(azimuth)}});
    const algray::RayBasis b = algray::make_ray_basis(s.camera, 8, 8);
    const glm::dvec3 offset = s.lights[0].position - s.camera.eye;
    CHECK(glm::dot(offset, b.right) == Approx(1));
    CHECK(glm::dot(offset, b.true_up) == Approx(2));
    CHECK(glm::dot(offset, b.forward) == Approx(0).margin(1e-12));
    // Written back and read again: the same rays and the same light, bit for bit.
    const Scene again = algray::load_scene_text(algray::scene_to_toml(s), "again.toml");
    CHECK(again.camera.eye == s.camera.eye);
    CHECK(again.camera.up == s.camera.up);
    CHECK(again.lights[0].position == s.lights[0].position);
    CHECK(again.lights[0].in_camera);
    CHECK(again.antialias.samples == s.antialias.samples);
  }
  check_error("[surface]\nequation = \"x-1\"\n[[light]]\nposition = [0, 0, 1]\nframe = \"eye\"\n", "t.toml:5:9",
              "light.frame must be");
}

TEST_CASE("--set of a parameter the scene does not have is refused, naming its parameters", "[scene][errors]") {
  const std::string torus = "[surface]\nequation = \"x^2+y^2+z^2-r^2\"\n[parameters]\nr = 1\n";
  try {
    algray::load_scene_text(torus, "t.toml", {{"a", "2"}});
    FAIL("--set a=2 was accepted");
  } catch (const SceneError& e) {
    CHECK(e.where == "--set a=2");
    CHECK_THAT(e.message, Catch::Contains("no parameter 'a'") && Catch::Contains("its parameters: r"));
  }
  try {
    algray::load_scene_text(sphere_with({}), "t.toml", {{"a", "2"}});
    FAIL("--set a=2 was accepted");
  } catch (const SceneError& e) {
    CHECK_THAT(e.message, Catch::Contains("it has no parameters"));
  }
  // A key the scene does not know gets the nearest spelling.
  try {
    algray::load_scene_text(torus, "t.toml", {{"camera.fovy", "30"}});
    FAIL("camera.fovy was accepted");
  } catch (const SceneError& e) {
    CHECK_THAT(e.message, Catch::Contains("did you mean 'fov_y'"));
  }
  // parameters.NAME adds one; the bare name then sets it.
  const Scene added = algray::load_scene_text(torus, "t.toml", {{"parameters.a", "2"}, {"a", "3"}});
  CHECK(added.parameters.at("a") == 3);
}

TEST_CASE("--set extent.type switches the kind, dropping the other kind's keys with a note", "[scene][extent]") {
  const Scene box = algray::load_scene_text(sphere_with({}), "t.toml", {{"extent.type", "box"}});
  CHECK(box.extent.kind == algray::ExtentKind::Box);
  CHECK(box.extent.min == glm::dvec3(-2));
  CHECK(box.extent.max == glm::dvec3(2));
  REQUIRE(box.warnings.size() == 1);
  CHECK_THAT(box.warnings[0], Catch::Contains("extent.radius") && Catch::Contains("dropped"));
  // And back: the sphere inscribed in the box's largest side.
  const Scene sphere = algray::load_scene_text(
      sphere_with({{5, "type = \"box\"\nmin = [-1, -3, -1]\nmax = [1, 1, 1]"}}), "t.toml", {{"extent.type", "sphere"}});
  CHECK(sphere.extent.kind == algray::ExtentKind::Sphere);
  CHECK(sphere.extent.centre == glm::dvec3(0, -1, 0));
  CHECK(sphere.extent.radius == 2);
  REQUIRE(sphere.warnings.size() == 1);
  CHECK_THAT(sphere.warnings[0], Catch::Contains("extent.min and extent.max"));
  // Keys given after the switch win; a box without a radius to start from needs its own min and max.
  const Scene given = algray::load_scene_text(sphere_with({}), "t.toml",
                                              {{"extent.type", "box"}, {"extent.max", "[3, 3, 3]"}});
  CHECK(given.extent.max == glm::dvec3(3));
  // In a file, keys of another kind are still a located error.
  check_error(sphere_with({{5, "type = \"box\"\nradius = 2"}}), "t.toml:6:10", "belongs to a sphere extent");
  check_error(sphere_with({{5, "type = \"cone\""}}), "t.toml:5:8", "\"sphere\", \"box\" or \"cylinder\"");
}

TEST_CASE("a cylinder extent reads, round-trips, refuses other kinds' keys and is switched to and from",
          "[scene][extent]") {
  const Scene c = algray::load_scene_text(
      sphere_with({{5, "type = \"cylinder\"\ncentre = [1, 0, 0]\nradius = 0.6\naxis = \"x\"\nhalf_height = 0.8"}}),
      "t.toml");
  REQUIRE(c.extent.kind == algray::ExtentKind::Cylinder);
  CHECK(c.extent.axis == 0);
  CHECK(c.extent.half_height == 0.8);
  // It fits in the unit sphere by its cap's rim: radius 0.6 across, 0.8 along x, so a scale of exactly 1.
  CHECK(c.extent.unit_scale() == Approx(1.0).epsilon(1e-15));
  CHECK(c.extent.unit_box_half() == glm::dvec3(c.extent.unit_box_half().x, 0.6, 0.6));
  CHECK(c.extent.unit_box_half().x == Approx(0.8).epsilon(1e-15));
  const Scene again = algray::load_scene_text(algray::scene_to_toml(c), "again.toml");
  CHECK(again.extent.kind == algray::ExtentKind::Cylinder);
  CHECK(again.extent.centre == c.extent.centre);
  CHECK(again.extent.radius == c.extent.radius);
  CHECK(again.extent.axis == c.extent.axis);
  CHECK(again.extent.half_height == c.extent.half_height);
  // The axis is z unless given.
  CHECK(algray::load_scene_text(sphere_with({{5, "type = \"cylinder\"\nradius = 1\nhalf_height = 2"}}), "t.toml")
            .extent.axis == 2);
  check_error(sphere_with({{5, "type = \"cylinder\"\nradius = 1\nhalf_height = 1\nmin = [0, 0, 0]"}}), "t.toml:8:7",
              "extent.min belongs to a box extent");
  check_error(sphere_with({{5, "type = \"cylinder\"\nradius = 1\nhalf_height = 1\naxis = \"w\""}}), "t.toml:8:8",
              "extent.axis must be");
  check_error(sphere_with({{5, "type = \"cylinder\"\nradius = 1"}}), "t.toml:4:1", "needs a half_height");
  check_error(sphere_with({{5, "type = \"sphere\"\nradius = 1\nhalf_height = 1"}}), "t.toml:7:15",
              "extent.half_height belongs to a cylinder extent");
  // --set extent.type=cylinder: from a sphere, the same radius and half_height R about z, with a note.
  const Scene from_sphere = algray::load_scene_text(sphere_with({}), "t.toml", {{"extent.type", "cylinder"}});
  CHECK(from_sphere.extent.kind == algray::ExtentKind::Cylinder);
  CHECK(from_sphere.extent.radius == 2);
  CHECK(from_sphere.extent.half_height == 2);
  CHECK(from_sphere.extent.axis == 2);
  REQUIRE(from_sphere.warnings.size() == 1);
  CHECK_THAT(from_sphere.warnings[0], Catch::Contains("half_height = 2"));
  // From a box: inscribed in its x and y sides, its caps on the box's.
  const Scene from_box =
      algray::load_scene_text(sphere_with({{5, "type = \"box\"\nmin = [-1, -3, -1]\nmax = [1, 1, 3]"}}), "t.toml",
                              {{"extent.type", "cylinder"}});
  CHECK(from_box.extent.centre == glm::dvec3(0, -1, 1));
  CHECK(from_box.extent.radius == 2);
  CHECK(from_box.extent.half_height == 2);
  REQUIRE(from_box.warnings.size() == 1);
  CHECK_THAT(from_box.warnings[0], Catch::Contains("extent.min and extent.max") && Catch::Contains("cylinder is"));
  // And to a box: the box around the cylinder.
  const Scene to_box = algray::load_scene_text(algray::scene_to_toml(c), "t.toml", {{"extent.type", "box"}});
  const glm::dvec3 min{0.2, -0.6, -0.6}, max{1.8, 0.6, 0.6};
  for (int i = 0; i < 3; ++i) {
    CHECK(to_box.extent.min[i] == Approx(min[i]).epsilon(1e-15));
    CHECK(to_box.extent.max[i] == Approx(max[i]).epsilon(1e-15));
  }
}

TEST_CASE("extent.gate makes the shape a ray gate with a far sphere reach times its size; errors are located",
          "[scene][extent]") {
  const Scene g = algray::load_scene_text(sphere_with({{5, "radius = 2\ngate = true\nreach = 3"}}), "t.toml");
  CHECK(g.extent.gate);
  CHECK(g.extent.reach == 3);
  // The kernels' unit sphere is the far sphere; the gate is the sphere of radius 1/reach in it; the camera and
  // the default lights are framed by the gate, not the far sphere.
  CHECK(g.extent.shape_scale() == 2);
  CHECK(g.extent.unit_scale() == 6);
  CHECK(g.extent.unit_box_half().x == Approx(1.0 / 3).epsilon(1e-15));
  const Scene framed = algray::load_scene_text("[surface]\nequation = \"x^2+y^2+z^2-1\"\n", "eq.toml",
                                               {{"extent.gate", "true"}});
  const Scene plain = algray::load_scene_text("[surface]\nequation = \"x^2+y^2+z^2-1\"\n", "eq.toml");
  CHECK(framed.extent.reach == algray::kDefaultGateReach);
  CHECK(framed.camera.eye == plain.camera.eye);
  CHECK(framed.lights.at(0).position == plain.lights.at(0).position);
  // A box or a cylinder gates too; the far sphere holds its half-diagonal (or its cap's rim) reach times.
  const Scene box = algray::load_scene_text(
      sphere_with({{5, "type = \"box\"\nmin = [-1, -2, -2]\nmax = [1, 2, 2]\ngate = true"}}), "t.toml");
  CHECK(box.extent.unit_scale() == Approx(3 * algray::kDefaultGateReach).epsilon(1e-15));
  CHECK(box.extent.unit_box_half().x == Approx(1 / (3 * algray::kDefaultGateReach)).epsilon(1e-15));
  // Written back by scene_to_toml; without a gate, nothing is written and nothing changes.
  const Scene again = algray::load_scene_text(algray::scene_to_toml(g), "again.toml");
  CHECK(again.extent.gate);
  CHECK(again.extent.reach == 3);
  CHECK_FALSE(algray::load_scene_text(algray::scene_to_toml(plain), "again.toml").extent.gate);
  CHECK(plain.extent.unit_box_half() == glm::dvec3(1));
  check_error(sphere_with({{5, "radius = 2\ngate = 1"}}), "t.toml:6:8", "extent.gate must be true or false");
  check_error(sphere_with({{5, "radius = 2\nreach = 3"}}), "t.toml:6:9", "it needs extent.gate = true");
  check_error(sphere_with({{5, "radius = 2\ngate = true\nreach = 0.5"}}), "t.toml:7:9", "extent.reach must be");
  check_error(sphere_with({{5, "radius = 2\ngate = true\nreach = 1e6"}}), "t.toml:7:9", "extent.reach must be");
  CHECK(error_of(sphere_with({}), {{"extent.reach", "2"}}).message.find("needs extent.gate") != std::string::npos);
}

TEST_CASE("an error in -e's equation names its column in the equation", "[scene][errors]") {
  try {
    algray::load_equation("x^2+*y");
    FAIL("x^2+*y was accepted");
  } catch (const SceneError& e) {
    CHECK(e.where == "--equation:1:5");
    CHECK_THAT(e.message, Catch::Contains("at character 5 of the equation"));
    CHECK(e.excerpt == "  x^2+*y\n      ^");
  }
}

TEST_CASE("--set extent.* and --set light.N.* reach the defaults of a scene that leaves them to algray",
          "[scene][defaults]") {
  const std::string eq = "[surface]\nequation = \"x^2+y^2+z^2-1\"\n";
  // No [extent]: the default sphere of radius 2 is what extent.type switches from.
  const Scene box = algray::load_scene_text(eq, "eq.toml", {{"extent.type", "box"}});
  CHECK(box.extent.kind == algray::ExtentKind::Box);
  CHECK(box.extent.min == glm::dvec3(-2));
  CHECK(box.extent.max == glm::dvec3(2));
  const Scene moved = algray::load_scene_text(eq, "eq.toml", {{"extent.centre", "[1, 0, 0]"}});
  CHECK(moved.extent.radius == algray::kDefaultExtentRadius);
  CHECK(moved.extent.centre == glm::dvec3(1, 0, 0));
  // The default key and fill lights are there to change, sized by the extent as overridden after them.
  const Scene plain = algray::load_scene_text(eq, "eq.toml", {{"extent.radius", "3"}});
  const Scene dimmed =
      algray::load_scene_text(eq, "eq.toml", {{"light.1.intensity", "0.5"}, {"extent.radius", "3"}});
  REQUIRE(dimmed.lights.size() == 2);
  CHECK(dimmed.lights[1].intensity == 0.5);
  CHECK(dimmed.lights[0].intensity == plain.lights[0].intensity);
  for (int i = 0; i < 2; ++i) {
    CHECK(dimmed.lights[i].position == plain.lights[i].position);
    CHECK(dimmed.lights[i].edge_u == plain.lights[i].edge_u);
    CHECK(dimmed.lights[i].samples == plain.lights[i].samples);
    CHECK(dimmed.lights[i].in_camera.has_value());
  }
  try {
    algray::load_scene_text(eq, "eq.toml", {{"light.0.intensty", "2"}});
    FAIL("light.0.intensty was accepted");
  } catch (const SceneError& e) {
    CHECK(e.where == "--set light.0.intensty=2");
    CHECK_THAT(e.message, Catch::Contains("unknown key 'light.0.intensty' (did you mean 'intensity'?)"));
  }
  // antialias.adaptive alone keeps the default 2x2.
  CHECK(algray::load_scene_text(eq, "eq.toml", {{"antialias.adaptive", "true"}}).antialias.samples == 2);
  // A sphere and a cylinder share centre and radius: a switch names each dropped key once.
  const Scene cylinder = algray::load_scene_text(
      sphere_with({{5, "type = \"cylinder\"\nradius = 1\nhalf_height = 2"}}), "t.toml", {{"extent.type", "box"}});
  REQUIRE(cylinder.warnings.size() == 1);
  CHECK_THAT(cylinder.warnings[0],
             Catch::StartsWith("--set extent.type=box: extent.radius and extent.half_height do not apply"));
}

TEST_CASE("--section adds a plane section from a linear equation; --set changes or drops sections",
          "[scene][section]") {
  const std::string s = sphere_with({});
  const Override z{algray::kSectionOverrideKey, "z=0.5"};
  const Scene one = algray::load_scene_text(s, "t.toml", {z, {"section.0.colour", "[1, 0, 0]"}});
  REQUIRE(one.sections.size() == 1);
  CHECK(one.sections[0].plane == glm::dvec4(0, 0, 1, -0.5));
  CHECK(one.sections[0].colour == glm::dvec3(1, 0, 0));
  const Scene two =
      algray::load_scene_text("[parameters]\nh = 0.25\n" + s, "t.toml",
                              {z, {algray::kSectionOverrideKey, "x + 2*y = h"}, {algray::kSectionOverrideKey, "-z"}});
  REQUIRE(two.sections.size() == 3);
  CHECK(two.sections[1].plane == glm::dvec4(1, 2, 0, -0.25));
  CHECK(two.sections[2].plane == glm::dvec4(0, 0, -1, 0));
  // The list as a whole: replaced, or emptied.
  CHECK(algray::load_scene_text(s, "t.toml", {z, {"section", "[]"}}).sections.empty());
  const Scene listed = algray::load_scene_text(s, "t.toml", {z, {"section", "[{plane = [1, 0, 0, 0]}]"}});
  REQUIRE(listed.sections.size() == 1);
  CHECK(listed.sections[0].plane == glm::dvec4(1, 0, 0, 0));
  CHECK(algray::load_scene_text(algray::scene_to_toml(two), "again.toml").sections.size() == 3);
  // Errors name the flag and the character of the plane.
  const auto section_error = [&](const std::string& plane) {
    try {
      algray::load_scene_text(s, "t.toml", {{algray::kSectionOverrideKey, plane}});
    } catch (const SceneError& e) {
      CHECK(e.where == "--section " + plane);
      return e;
    }
    FAIL("--section " << plane << " was accepted");
    throw std::logic_error("unreachable");
  };
  CHECK_THAT(section_error("x^2=1").message, Catch::Contains("degree 2"));
  const SceneError star = section_error("x+*y=1");
  CHECK_THAT(star.message, Catch::Contains("at character 3 of the plane"));
  CHECK(star.excerpt == "  x+*y=1\n    ^");
  CHECK_THAT(section_error("2=3").message, Catch::Contains("no x, y or z"));
  CHECK_THAT(section_error("z=1=2").message, Catch::Contains("at character 4"));
  CHECK_THAT(section_error("=1").message, Catch::Contains("left side of the plane is empty"));
  CHECK_THAT(section_error("").message, Catch::Contains("--section takes a plane"));
  // A section that is not there is named, with what adds one.
  try {
    algray::load_scene_text(s, "t.toml", {{"section.0.colour", "[1, 0, 0]"}});
    FAIL("section.0.colour without sections was accepted");
  } catch (const SceneError& e) {
    CHECK_THAT(e.message, Catch::Contains("no [[section]] tables") && Catch::Contains("--section"));
  }
  // A parameter named as a table is still the parameter.
  const Scene param = algray::load_scene_text("[parameters]\nsection = 1\n[surface]\nequation = \"x^2+y^2+z^2-section\"\n",
                                              "t.toml", {{"section", "2"}});
  CHECK(param.parameters.at("section") == 2);
}

TEST_CASE("[[clip]] planes keep a*x + b*y + c*z + d <= 0; --clip adds one from an inequality", "[scene][clip]") {
  // Read, in unit coordinates for the kernels, and written back.
  const Scene read = algray::load_scene_text(
      sphere_with({{5, "centre = [1, 0, 0]\nradius = 2"}}, {"[[clip]]", "plane = [0, 0, 2, -1]", "[[clip]]",
                                                             "plane = [1, 0, 0, 0]"}),
      "t.toml");
  REQUIRE(read.extent.clips.size() == 2);
  CHECK(read.extent.clips[0] == glm::dvec4(0, 0, 2, -1));
  const std::vector<glm::dvec4> unit = read.extent.unit_clips();
  REQUIRE(unit.size() == 2);
  // z <= 0.5 about the centre (1, 0, 0) at scale 2: u_z <= 0.25; x <= 0: u_x <= -0.5.
  CHECK(unit[0] == glm::dvec4(0, 0, 1, -0.25));
  CHECK(unit[1] == glm::dvec4(1, 0, 0, 0.5));
  const Scene again = algray::load_scene_text(algray::scene_to_toml(read), "again.toml");
  CHECK(again.extent.clips == read.extent.clips);
  // No [[clip]]: nothing is cut, and nothing is written.
  const Scene plain = algray::load_scene_text(sphere_with({}), "t.toml");
  CHECK(plain.extent.clips.empty());
  CHECK(algray::scene_to_toml(plain).find("[[clip]]") == std::string::npos);

  // --clip: the side kept, < and <= alike, > and >= the other side, with the scene's parameters.
  const std::string s = "[parameters]\nh = 0.25\n" + sphere_with({});
  const Scene cut = algray::load_scene_text(s, "t.toml",
                                            {{algray::kClipOverrideKey, "z<0.5"},
                                             {algray::kClipOverrideKey, "x + 2*y >= h"},
                                             {algray::kClipOverrideKey, "'y <= -z'"}});
  REQUIRE(cut.extent.clips.size() == 3);
  CHECK(cut.extent.clips[0] == glm::dvec4(0, 0, 1, -0.5));
  CHECK(cut.extent.clips[1] == glm::dvec4(-1, -2, 0, 0.25));
  CHECK(cut.extent.clips[2] == glm::dvec4(0, 1, 1, 0));
  // --set changes one, or drops them all; the count is limited.
  CHECK(algray::load_scene_text(s, "t.toml", {{algray::kClipOverrideKey, "z<0.5"}, {"clip.0.plane", "[1, 0, 0, 0]"}})
            .extent.clips[0] == glm::dvec4(1, 0, 0, 0));
  CHECK(algray::load_scene_text(s, "t.toml", {{algray::kClipOverrideKey, "z<0.5"}, {"clip", "[]"}}).extent.clips.empty());
  std::vector<Override> five;
  for (int i = 0; i < 5; ++i) five.push_back({algray::kClipOverrideKey, "z<" + std::to_string(i)});
  const SceneError fifth = error_of(s, five);
  CHECK(fifth.where == "--clip z<4");
  CHECK_THAT(fifth.message, Catch::Contains("at most 4 clipping planes"));
  CHECK(algray::load_scene_text(s, "t.toml", {five.begin(), five.begin() + 4}).extent.clips.size() == 4);
}

TEST_CASE("clip errors name the file, line and column, or the --clip flag and its character", "[scene][clip][errors]") {
  // Lines 11 on follow the unit sphere's ten.
  check_error(sphere_with({}, {"[[clip]]", "plane = [0, 0, 0, 1]"}), "t.toml:12:9", "a, b and c are all 0");
  check_error(sphere_with({}, {"[[clip]]", "plane = [0, 0, 1]"}), "t.toml:12:9", "array of 4 numbers");
  check_error(sphere_with({}, {"[[clip]]", "plane = [0, 0, \"z\", 1]"}), "t.toml:12:16", "clip.plane[2]");
  check_error(sphere_with({}, {"[[clip]]", "normal = [0, 0, 1, 0]"}), "t.toml:12:1", "normal");
  check_error(sphere_with({}, {"[[clip]]"}), "t.toml:11:1", "a clip needs plane = [a, b, c, d]");
  check_error(sphere_with({{1, "clip = 1"}}), "t.toml:1:8", "[[clip]] tables");
  std::vector<std::string> five;
  for (int i = 0; i < 5; ++i) five.insert(five.end(), {"[[clip]]", "plane = [0, 0, 1, " + std::to_string(i) + "]"});
  check_error(sphere_with({}, five), "t.toml:19:1", "at most 4 clipping planes");

  const std::string s = sphere_with({});
  const auto clip_error = [&](const std::string& plane) {
    try {
      algray::load_scene_text(s, "t.toml", {{algray::kClipOverrideKey, plane}});
    } catch (const SceneError& e) {
      CHECK(e.where == "--clip " + plane);
      return e;
    }
    FAIL("--clip " << plane << " was accepted");
    throw std::logic_error("unreachable");
  };
  CHECK_THAT(clip_error("z=0.5").message, Catch::Contains("not an '='") && Catch::Contains("at character 2"));
  CHECK_THAT(clip_error("z").message, Catch::Contains("--clip takes a half-space"));
  CHECK_THAT(clip_error("x^2<1").message, Catch::Contains("degree 2"));
  CHECK_THAT(clip_error("2<3").message, Catch::Contains("no x, y or z"));
  CHECK_THAT(clip_error("z<1<2").message, Catch::Contains("one inequality") && Catch::Contains("at character 4"));
  CHECK_THAT(clip_error("<1").message, Catch::Contains("left side of the plane is empty"));
  CHECK_THAT(clip_error("z>=").message, Catch::Contains("right side of the plane is empty"));
  const SceneError star = clip_error("x+*y<1");
  CHECK_THAT(star.message, Catch::Contains("at character 3 of the plane"));
  CHECK(star.excerpt == "  x+*y<1\n    ^");
  // A clip that is not there is named, with what adds one.
  CHECK_THAT(error_of(s, {{"clip.0.plane", "[1, 0, 0, 0]"}}).message,
             Catch::Contains("no [[clip]] tables") && Catch::Contains("--clip"));
}
