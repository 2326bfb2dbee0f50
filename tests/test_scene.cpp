// Tests of the TOML scene reader: the shipped scenes, parameters, overrides and every error's file:line:column.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

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
  SECTION("a bare override may add a parameter the file lacks") {
    const std::string uses_b = sphere_with({{3, "equation = \"x^2+y^2+z^2-b\""}});
    CHECK(algray::load_scene_text(uses_b, "t.toml", {{"b", "0.25"}}).surface().polynomial ==
          equation("x^2+y^2+z^2-0.25"));
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
