// POV-Ray scenes (.pov): handedness, transforms, objects, clips, camera, lights and colours as POV-Ray shows them,
// located errors and warnings, and every scene of tests/data/pov.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <tuple>

#include "cli_sandbox.h"
#include "algray/render/render_plan.h"
#include "algray/render/renderer.h"
#include "algray/scene/scene.h"
#include "test_support.h"

using namespace algray;
using algray::testing::device_session;

namespace {

// POV-Ray's default right (1.33) over up (1): an image of this shape is what POV-Ray stretches the view over.
constexpr int kWidth = 100, kHeight = 75;

Scene pov_scene(const std::string& body) {
  return load_povray_text("camera { location <0, 0, -10> look_at <0, 0, 0> angle 60 }\n"
                          "light_source { <0, 0, -100> color rgb 1 }\n" +
                              body,
                          "test.pov",
                          {{"image.width", std::to_string(kWidth)},
                           {"image.height", std::to_string(kHeight)},
                           {"antialias.samples", "1"}});
}

struct Coverage {
  long count = 0;
  double x = 0, y = 0;  // the centroid in POV-Ray's units on the plane z = 0, x right and y up
};
Coverage coverage(const Scene& scene) {
  Renderer renderer(device_session(), testing::program_cache());
  const HitBuffer hits = renderer.render_with_records(scene).hits;
  const double unit = (hits.width / 2.0) / (10 * std::tan(30 * 3.14159265358979 / 180));  // pixels per unit
  Coverage c;
  for (int y = 0; y < hits.height; ++y)
    for (int x = 0; x < hits.width; ++x)
      if (hits.at(x, y).flags & ALGRAY_HIT_FOUND) {
        ++c.count;
        c.x += (x + 0.5 - hits.width / 2.0) / unit;
        c.y += (hits.height / 2.0 - y - 0.5) / unit;
      }
  if (c.count) {
    c.x /= static_cast<double>(c.count);
    c.y /= static_cast<double>(c.count);
  }
  return c;
}

SceneError error_of_at(const std::string& text, const std::string& source) {
  try {
    load_povray_text(text, source);
  } catch (const SceneError& e) {
    return e;
  }
  FAIL("no error for:\n" << text);
  return SceneError("", "");
}

SceneError error_of(const std::string& text) {
  try {
    load_povray_text(text, "bad.pov");
  } catch (const SceneError& e) {
    return e;
  }
  FAIL("no error for:\n" << text);
  return SceneError("", "");
}

bool any_contains(const std::vector<std::string>& list, const std::string& part) {
  for (const std::string& s : list)
    if (s.find(part) != std::string::npos) return true;
  return false;
}

const std::string kBall = "sphere { <3, 0, 0>, 1 pigment { color rgb 1 } ";

}  // namespace

TEST_CASE("POV-Ray's left-handed world and a right-handed camera show what POV-Ray shows", "[povray]") {
  // Measured with POV-Ray 3.7: the ball at x = 3 is seen on the right, at 3 units.
  const Coverage left = coverage(pov_scene(kBall + "}"));
  CHECK(left.x == Approx(3).margin(0.1));
  CHECK(left.y == Approx(0).margin(0.05));
  CHECK(left.count > 200);
  // A right-handed camera (right = -x) shows the mirror image.
  const Scene mirrored = load_povray_text(
      "camera { location <0, 0, -10> right -1.33*x look_at <0, 0, 0> angle 60 }\n" + kBall + "}", "m.pov",
      {{"image.width", std::to_string(kWidth)}, {"image.height", std::to_string(kHeight)}});
  CHECK(coverage(mirrored).x == Approx(-3).margin(0.1));
  // rotate <0, 30, 0> brings (3, 0, 0) nearer (POV-Ray: 466 pixels against 330, seen at x = 3.06);
  // rotate <0, 0, 30> lifts it to (2.6, 1.5).
  const Coverage turned_y = coverage(pov_scene(kBall + "rotate <0, 30, 0> }"));
  CHECK(static_cast<double>(turned_y.count) / static_cast<double>(left.count) == Approx(466.0 / 330).epsilon(0.08));
  CHECK(turned_y.x == Approx(2.6 * 10 / 8.5).margin(0.12));
  const Coverage turned_z = coverage(pov_scene(kBall + "rotate z*30 }"));
  CHECK(turned_z.x == Approx(2.6).margin(0.1));
  CHECK(turned_z.y == Approx(1.5).margin(0.1));
  // rotate x: (0, 3, 0) goes away from the camera (POV-Ray: 246 pixels against 330).
  const Coverage turned_x = coverage(pov_scene("sphere { <0, 3, 0>, 1 rotate <30, 0, 0> }"));
  CHECK(static_cast<double>(turned_x.count) < static_cast<double>(left.count) * 0.85);
  // matrix rows: x' = x + 0.5 y + 2, then translate y: the ball's centre at (2, 1).
  const Coverage sheared = coverage(
      pov_scene("sphere { <0, 0, 0>, 1 matrix <1, 0, 0, 0.5, 1, 0, 0, 0, 1, 2, 0, 0> translate <0, 1, 0> }"));
  CHECK(sheared.x == Approx(2).margin(0.1));
  CHECK(sheared.y == Approx(1).margin(0.1));
}

TEST_CASE("POV-Ray's objects are the polynomials POV-Ray draws", "[povray]") {
  // poly 2's coefficients, in POV-Ray's order, of (x - 3)^2 + y^2 + z^2 - 1: the same ball as sphere { }.
  const Scene poly = pov_scene("poly { 2, <1, 0, 0, -6, 1, 0, 0, 1, 0, 8> clipped_by { sphere { <3, 0, 0>, 2 } } }");
  const Polynomial& p = poly.surfaces[0].polynomial;
  // Read with z negated: POV-Ray's (3, 0, 0) is algray's (3, 0, 0); (0, 0, 1) is (0, 0, -1).
  CHECK(p.evaluate(3, 0, 0) == Approx(-1));
  CHECK(p.evaluate(4, 0, 0) == Approx(0).margin(1e-12));
  const Scene quartic = pov_scene(
      "quartic { <0,0,0,0,0,0,0,0,0,0, 0,0,0,0,1,0,0,0,0,0, 0,0,0,0,0,0,0,0,0,0, 0,0,0,0,-1> "
      "bounded_by { box { <-2, -2, -2>, <2, 2, 2> } } }");
  CHECK(quartic.surfaces[0].polynomial.evaluate(1, 2, -3) == Approx(1 * 2 * 3 - 1));  // xyz - 1 at z = 3
  const Scene polynomial =
      pov_scene("polynomial { 3, xyz(3,0,0):1, xyz(0,1,1):-2, xyz(0,0,0):0.5 clipped_by { sphere { 0, 3 } } }");
  CHECK(polynomial.surfaces[0].polynomial.evaluate(1, 1, 1) == Approx(1 + 2 + 0.5));
  // torus { R, r } about the y axis.
  const Scene torus = pov_scene("torus { 2, 0.5 }");
  CHECK(torus.surfaces[0].polynomial.evaluate(2, 0, 0) < 0);
  CHECK(torus.surfaces[0].polynomial.evaluate(0, 2, 0) > 0);
  CHECK(torus.surfaces[0].polynomial.evaluate(0, 0, 2) < 0);
  // inverse swaps the sides; a union's transforms move every member.
  CHECK(pov_scene("sphere { 0, 1 inverse }").surfaces[0].polynomial.evaluate(0, 0, 0) > 0);
  const Scene group = pov_scene("union { sphere { <1, 0, 0>, 0.5 } sphere { <-1, 0, 0>, 0.5 } translate y*2 }");
  REQUIRE(group.surfaces.size() == 2);
  CHECK(group.surfaces[1].polynomial.evaluate(-1, 2, 0) == Approx(-0.25));
}

TEST_CASE("clips: a sphere or box, moved by the transforms after them, one region per scene", "[povray]") {
  const Scene boxed = pov_scene("sphere { 0, 2 clipped_by { box { <-1, -3, -3>, <3, 3, 3> } } translate x*2 }");
  REQUIRE(boxed.extent.kind == ExtentKind::Box);
  CHECK(boxed.extent.min.x == Approx(1));  // measured with POV-Ray: the box moves with the later translate
  CHECK(boxed.extent.max.z == Approx(3));
  const Scene after = pov_scene("sphere { 0, 2 translate x*2 clipped_by { box { <-1, -3, -3>, <3, 3, 3> } } }");
  CHECK(after.extent.min.x == Approx(-1));
  const Scene scaled = pov_scene("poly { 2, <1,0,0,0,1,0,0,1,0,-1> bounded_by { sphere { <1, 0, 0>, 2 } } scale 2 }");
  REQUIRE(scaled.extent.kind == ExtentKind::Sphere);
  CHECK(scaled.extent.radius == Approx(4));
  CHECK(scaled.extent.centre.x == Approx(2));
  // Self-bounded objects inside a clipped one's region share it; a second region is an error.
  CHECK(pov_scene("sphere { 0, 0.5 } poly { 2, <1,0,0,0,1,0,0,1,0,-4> clipped_by { sphere { 0, 3 } } }")
            .extent.radius == Approx(3));
  CHECK(error_of("poly { 2, <1,0,0,0,1,0,0,1,0,-4> clipped_by { sphere { 0, 3 } } }\n"
                 "poly { 2, <1,0,0,0,1,0,0,1,0,-1> clipped_by { sphere { 0, 2 } } }\n")
            .where == "bad.pov:2:1");
  // Without any region, and out of the camera's sight: nothing tells algray where to draw it.
  CHECK_THAT(
      error_of("camera { location <0, 0, -10> look_at 0 }\npoly { 2, <1,0,0,0,1,0,0,1,0,-4> translate -z*50 }").message,
      Catch::Contains("clipped_by"));
  // Two boxes turned differently (or one sheared) have no common frame.
  CHECK_THAT(error_of("sphere { 0, 1 clipped_by { box { -1, 1 rotate y*30 } } clipped_by { box { -2, 2 } } }").message,
             Catch::Contains("axis-aligned"));
  CHECK_THAT(error_of("sphere { 0, 1 clipped_by { box { -1, 1 } } rotate y*30 scale <2, 1, 1> }").message,
             Catch::Contains("sheared"));
  CHECK_THAT(error_of("sphere { 0, 1 clipped_by { sphere { 0, 1 } } scale <1, 2, 1> }").message,
             Catch::Contains("ellipsoid"));
}

TEST_CASE("camera, lights, colours and background map to algray's scene", "[povray]") {
  const Scene s = load_povray_text(
      "#declare Gold = rgb <1, 0.8, 0.2>;\n"
      "camera { location <0, 2, -10> look_at <0, 0, 0> right x*image_width/image_height angle 50 sky <0, 1, 0> }\n"
      "light_source { <10, 20, -30> color rgb <2, 1, 0.5> area_light <4, 0, 0>, <0, 0, 4>, 5, 3 adaptive 1 }\n"
      "light_source { <0, 5, 0> color rgb 0.5 shadowless }\n"
      "background { color rgb <0.1, 0.2, 0.3> }\n"
      "sphere { 0, 1 texture { pigment { color Gold } finish { ambient 0.2 diffuse 0.7 phong 0.5 phong_size 60 } }\n"
      "  interior_texture { pigment { color red 0.1 green 0.9 } } }\n",
      "values.pov", {});
  CHECK(s.image.width == 800);
  CHECK(s.image.height == 600);
  CHECK(s.camera.eye == glm::dvec3(0, 2, 10));  // z negated
  // angle is horizontal: 50 degrees across a right of 4/3 make fov_y 2 atan(tan(25 deg) * 3/4).
  CHECK(s.camera.fov_y_degrees == Approx(2 * std::atan(std::tan(25 * 3.14159265358979 / 180) * 0.75) * 180 /
                                         3.14159265358979));
  REQUIRE(s.lights.size() == 2);
  CHECK(s.lights[0].kind == LightKind::Rectangle);
  CHECK(s.lights[0].samples == 5);
  CHECK(s.lights[0].position == glm::dvec3(10, 20, 30));
  CHECK(s.lights[0].edge_v == glm::dvec3(0, 0, -4));
  CHECK(s.lights[0].intensity == 2);
  CHECK(s.lights[0].colour == glm::dvec3(1, 0.5, 0.25));
  CHECK_FALSE(s.lights[1].shadows);
  CHECK(s.image.background.b == Approx(0.3));
  const Material& front = s.surfaces[0].materials.front;
  CHECK(front.colour == glm::dvec3(1, 0.8, 0.2));
  CHECK(front.ambient == 0.2);
  CHECK(front.diffuse == 0.7);
  CHECK(front.specular == 0.5);
  CHECK(front.exponent == 60);
  CHECK(s.surfaces[0].materials.back.colour == glm::dvec3(0.1, 0.9, 0));
  const Scene ortho = load_povray_text(
      "camera { orthographic location <0, 0, -10> look_at 0 right 8*x up 6*y }\nsphere { 0, 1 }\n", "o.pov");
  CHECK(ortho.camera.projection == Projection::Orthographic);
  CHECK(ortho.camera.ortho_height == 6);
}

TEST_CASE("a camera whose direction is not normal to right and up is POV-Ray's off-axis view", "[povray]") {
  // POV-Ray's ray for the image point (u, v), each from -1/2 to 1/2, is direction + u right + v up. Balls where
  // the rays of (0, 0) and (0.35, 0.35) meet z = 2 show at the image's centre and at 85% across, 15% down.
  const std::string camera =
      "camera { location <0, 0, -4> right x*4/3 up y direction <0.3, 0.5, 1.5> }\n"
      "light_source { <0, 0, -100> color rgb 1 }\n";
  const Scene centre = load_povray_text(camera + "sphere { <1.2, 2, 2>, 0.15 }\n", "c.pov",
                                        {{"image.width", "200"}, {"image.height", "150"}, {"antialias.samples", "1"}});
  CHECK(centre.camera.shift.x == Approx(0.3 / (4.0 / 3)));
  CHECK(centre.camera.shift.y == Approx(0.5));
  const Scene corner = load_povray_text(camera + "sphere { <3.0666667, 3.4, 2>, 0.15 }\n", "k.pov",
                                        {{"image.width", "200"}, {"image.height", "150"}, {"antialias.samples", "1"}});
  Renderer renderer(device_session(), testing::program_cache());
  for (const auto& [scene, u, v] : {std::tuple{&centre, 0.5, 0.5}, std::tuple{&corner, 0.85, 0.15}}) {
    const HitBuffer hits = renderer.render_with_records(*scene).hits;
    double sx = 0, sy = 0;
    long n = 0;
    for (int y = 0; y < hits.height; ++y)
      for (int x = 0; x < hits.width; ++x)
        if (hits.at(x, y).flags & ALGRAY_HIT_FOUND) {
          ++n;
          sx += (x + 0.5) / hits.width;
          sy += (y + 0.5) / hits.height;
        }
    REQUIRE(n > 20);
    CAPTURE(u, v);
    // Read on its axis (the view along direction), the corner's ball showed at 80.6%, 22.9%.
    CHECK(sx / static_cast<double>(n) == Approx(u).margin(0.006));
    CHECK(sy / static_cast<double>(n) == Approx(v).margin(0.006));
  }
  // look_at makes direction, right and up normal: no shift. A direction in the plane of right and up is refused.
  CHECK(load_povray_text("camera { location <0, 0, -4> direction <0.3, 0.5, 1.5> look_at 0 }\nsphere { 0, 1 }\n",
                         "l.pov")
            .camera.shift == glm::dvec2(0));
  CHECK(error_of("camera { location <0, 0, -4> direction <1, 0, 0> }\nsphere { 0, 1 }\n").where == "bad.pov:1:8");
  CHECK(error_of("camera { location <0, 0, -4> up 0.001*y direction <0, 1, 1> }\nsphere { 0, 1 }\n").where ==
        "bad.pov:1:8");
}

TEST_CASE("bad POV-Ray scenes get located errors; what is skipped, located warnings", "[povray][errors]") {
  const SceneError open = error_of("sphere { 0, 1\n");
  CHECK(open.where == "bad.pov:1:1");
  CHECK_THAT(open.message, Catch::Contains("never closed"));
  CHECK(error_of("poly { 2, <1, 2, 3> }\n").where == "bad.pov:1:11");
  CHECK(error_of("poly { 40, <1> }\n").where == "bad.pov:1:1");
  CHECK(error_of("camera { fisheye }\nsphere { 0, 1 }\n").where == "bad.pov:1:10");
  CHECK(error_of("#fopen F \"x\" read\n").where == "bad.pov:1:1");
  CHECK(error_of("#macro M() #end\nsphere { 0, M() }\n").where == "bad.pov:2:13");  // skipped, then named
  CHECK(error_of("sphere { 0, Radius }\n").where == "bad.pov:1:13");
  CHECK(error_of("object { Thing }\n").where == "bad.pov:1:10");
  CHECK_THAT(error_of("object { Thing }\n").message, Catch::Contains("'Thing' is not declared"));
  CHECK(error_of("camera { location 0 }\n").message.find("no object") != std::string::npos);
  CHECK(error_of("sphere { 0, 1 } /* open\n").where == "bad.pov:1:17");
  // A dense poly of degree 32 moved by a transform is refused at the budget, where it is, in well under a second.
  std::string dense = "\n poly { 32, <1";
  for (int i = 1; i < 6545; ++i) dense += ",1";
  const SceneError big = error_of(dense + "> clipped_by { sphere { 0, 1 } } rotate <10, 20, 30> translate x }\n");
  CHECK(big.where == "bad.pov:2:2");
  CHECK_THAT(big.message, Catch::Contains("too large to expand"));
  const auto w = load_povray_text(
                     "#include \"nowhere47.inc\"\nplane { y, -1 }\nsphere { 0, 1 finish { reflection 0.3 } }\n"
                     "media { }\n",
                     "w.pov")
                     .warnings;
  CHECK(any_contains(w, "w.pov:1:1: #include \"nowhere47.inc\" is not found"));
  CHECK(any_contains(w, "w.pov:2:1: 'plane' is ignored"));
  CHECK(any_contains(w, "w.pov:3:24: finish 'reflection' is ignored"));
  CHECK(any_contains(w, "w.pov:4:1: 'media' is ignored"));
}

TEST_CASE("every scene of tests/data/pov reads, and one renders from the command line", "[povray][cli]") {
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(ALGRAY_SOURCE_DIR "/tests/data/pov")) {
    CAPTURE(entry.path().string());
    if (entry.path().extension() != ".pov") continue;  // include/ holds the scenes' .inc files
    const Scene s = load_scene_file(entry.path().string());
    CHECK_FALSE(s.surfaces.empty());
    CHECK(s.warnings.empty());
    ++scenes;
  }
  CHECK(scenes >= 12);
  algray::testing::require_device();
  algray::testing::Sandbox box;
  const auto r = box.run("render " + algray::testing::quoted(ALGRAY_SOURCE_DIR "/tests/data/pov/torus.pov") +
                         " --preview --width 64 --height 48 -o out.png");
  CHECK(r.exit_code == 0);
  CHECK(std::filesystem::exists(box.work / "out.png"));
  const auto bad = box.scene("bad.pov", "sphere { 0, 1 }\ntorus { 1 }\n");
  const auto b = box.run("render " + algray::testing::quoted(bad.string()) + " -o bad.png");
  CHECK(b.exit_code == 2);
  CHECK_THAT(b.err, Catch::Contains("bad.pov:2:"));
  CHECK_FALSE(std::filesystem::exists(box.work / "bad.png"));
}

TEST_CASE("#include reads a .inc file in place: its colours, floats and declared objects", "[povray]") {
  // The scene's directory is searched first: the include is tests/data/pov/include/shapes47.inc.
  const std::string scene_path = ALGRAY_SOURCE_DIR "/tests/data/pov/inline.pov";
  auto scene = [&](const std::string& body) {
    return load_povray_text("camera { location <0, 0, -10> look_at <0, 0, 0> angle 60 }\n"
                            "light_source { <0, 0, -100> color rgb 1 }\n#include \"include/shapes47.inc\"\n" + body,
                            scene_path,
                            {{"image.width", std::to_string(kWidth)},
                             {"image.height", std::to_string(kHeight)},
                             {"antialias.samples", "1"}});
  };
  // Ring47 is torus { 1, 0.4 } written as a quartic: declared, then placed twice by object { }.
  const Scene declared = scene("object { Ring47 pigment { Gold47 } rotate -90*x translate 2*x }\n");
  REQUIRE(declared.surfaces.size() == 1);
  CHECK(declared.warnings.empty());
  const Coverage ring = coverage(declared);
  const Coverage torus = coverage(pov_scene("torus { 1, 0.4 rotate -90*x translate 2*x pigment { rgb 1 } }\n"));
  CHECK(ring.count > 300);
  CHECK(ring.count == Approx(torus.count).epsilon(0.01));
  CHECK(ring.x == Approx(2).margin(0.05));
  // A declared object in a union, and a declared object declared again with its own transform.
  // (Turned about y, so that both keep the one bounding sphere algray clips a scene to.)
  const Scene two = scene("#declare Turned = object { Ring47 rotate 90*y }\n"
                          "union { object { Turned } object { Ring47 } pigment { Gold47 } }\n");
  CHECK(two.surfaces.size() == 2);
  // The include's float is a float here; its macro and texture are named for what they are.
  CHECK(scene("sphere { 0, Radius47 pigment { Gold47 } }\n").surfaces.size() == 1);
  const SceneError macro = error_of_at("#include \"include/shapes47.inc\"\nsphere { 0, Twice47(1) }\n", scene_path);
  CHECK(macro.where == scene_path + ":2:13");
  CHECK_THAT(macro.message, Catch::Contains("'Twice47' is a macro (declared at " ALGRAY_SOURCE_DIR
                                            "/tests/data/pov/include/shapes47.inc:14:8)"));
  const SceneError texture = error_of_at("#include \"include/shapes47.inc\"\nobject { Skin47 }\n", scene_path);
  CHECK(texture.where == scene_path + ":2:10");
  CHECK_THAT(texture.message, Catch::Contains("'Skin47' is a texture"));
  // A declared object algray cannot draw (grafbic's axes: infinite quadric cylinders) is skipped with a warning
  // where the scene has something else to draw; alone, it is the error it was.
  const Scene axes = scene("object { Ring47 }\nobject { Axes47 rotate 30*y }\n");
  CHECK(axes.surfaces.size() == 1);
  CHECK(any_contains(axes.warnings, scene_path + ":5:10: 'Axes47' is a union algray cannot draw"));
  const SceneError alone = error_of_at("#include \"include/shapes47.inc\"\nobject { Axes47 }\n", scene_path);
  CHECK(alone.where == scene_path + ":2:10");
  CHECK_THAT(alone.message, Catch::Contains("'Axes47' is a union algray cannot draw"));
}

TEST_CASE("#include's errors are located in the include file, and it reads only .inc files, never forever",
          "[povray]") {
  const std::string scene_path = ALGRAY_SOURCE_DIR "/tests/data/pov/inline.pov";
  const std::string include_dir = ALGRAY_SOURCE_DIR "/tests/data/pov/include/";
  // broken47.inc's fourth line declares a negative colour.
  const SceneError broken = error_of_at("#include \"include/broken47.inc\"\n", scene_path);
  CHECK(broken.where == include_dir + "broken47.inc:4:10");
  CHECK_THAT(broken.message, Catch::Contains("colour components must not be negative"));
  CHECK_THAT(broken.excerpt, Catch::Contains("#declare Bad47"));
  // loop47.inc includes itself: stopped at the depth limit, in the include.
  const SceneError loop = error_of_at("#include \"include/loop47.inc\"\n", scene_path);
  CHECK(loop.where.rfind(include_dir + "loop47.inc:2:1", 0) == 0);
  CHECK_THAT(loop.message, Catch::Contains("nested more than 16 deep"));
  // Other files and other directories are not read.
  const SceneError pov = error_of_at("#include \"torus.pov\"\n", scene_path);
  CHECK(pov.where == scene_path + ":1:10");
  CHECK_THAT(pov.message, Catch::Contains("reads .inc files"));
  const SceneError up = error_of_at("#include \"../pov/include/shapes47.inc\"\n", scene_path);
  CHECK(up.where == scene_path + ":1:10");
  const SceneError absolute = error_of_at("#include \"" + include_dir + "shapes47.inc\"\n", scene_path);
  CHECK(absolute.where == scene_path + ":1:10");
  // A scene given as text alone has no directory: its includes come from POV-Ray's directory only.
  const auto w = load_povray_text("#include \"include/shapes47.inc\"\nsphere { 0, 1 }\n", "w.pov").warnings;
  CHECK(any_contains(w, "w.pov:1:1: #include \"include/shapes47.inc\" is not found"));
  // An unmatched #end and an unknown directive are located too.
  CHECK(error_of("#end\n").where == "bad.pov:1:1");
  CHECK_THAT(error_of("sphere { 0, 1 }\n#fopen F \"x\" read\n").message, Catch::Contains("#fopen is not read"));
}

TEST_CASE("intersection with a sphere or a box reads as the object clipped to it, with a warning", "[povray]") {
  // POV-Ray's samples cut a quartic with a Clear sphere; algray draws the surface within it, not the cut face.
  const Scene cut = pov_scene("intersection { torus { 1, 0.4 } sphere { 0, 1.2 pigment { rgbf 1 } }\n"
                              "  pigment { rgb 1 } rotate -90*x }\n");
  REQUIRE(cut.surfaces.size() == 1);
  CHECK(any_contains(cut.warnings, "test.pov:3:1: intersection is read as its algebraic objects clipped"));
  const Scene clipped = pov_scene("torus { 1, 0.4 clipped_by { sphere { 0, 1.2 } } pigment { rgb 1 } rotate -90*x }\n");
  CHECK(coverage(cut).count == coverage(clipped).count);
  CHECK(error_of("intersection { torus { 1, 0.4 } }\n").message.find("no sphere or box") != std::string::npos);
  // A declared box turned off the axes: located at the object it would clip.
  const SceneError turned = error_of(
      "#declare B = box { -1, 1 }\nintersection { torus { 1, 0.4 } object { B rotate 30*y scale <2, 1, 1> } }\n");
  CHECK(turned.where == "bad.pov:2:16");
  CHECK_THAT(turned.message, Catch::Contains("sheared"));
}

TEST_CASE("a turned clipping box: the scene is written in the box's own frame, which shows the same picture",
          "[povray]") {
  // A ball cut to a slab that is turned 30 degrees about y and moved, as POV-Ray's monkey, trough and quarpara
  // samples turn theirs.
  const Scene turned = pov_scene(
      "poly { 2, <1,0,0,0,1,0,0,1,0,-1> clipped_by { box { <-1, -1, -0.6>, <1, 1, 0.6> } } rotate y*30 "
      "translate x*0.5 pigment { rgb 1 } }\n");
  REQUIRE(turned.extent.kind == ExtentKind::Box);
  CHECK(turned.extent.min.x == Approx(-1));
  CHECK(turned.extent.max.y == Approx(1));
  CHECK(turned.extent.max.z == Approx(0.6));
  CHECK(turned.extent.min.z == Approx(-0.6));
  // The ball's polynomial as written, in the box's frame; the camera at the same distance from the ball.
  const Polynomial& p = turned.surfaces[0].polynomial;
  CHECK(p.evaluate(0, 0, 0) == Approx(-1));
  CHECK(p.evaluate(0, 0.6, 0.8) == Approx(0).margin(1e-12));
  CHECK(glm::length(turned.camera.eye) == Approx(std::sqrt(0.25 + 100)));
  // The same picture as the scene whose camera is turned the other way about the unturned object: POV-Ray's
  // rotate y*-30 takes the eye <-0.5, 0, -10> (seen from the moved object) to <4.5669873, 0, -8.9102540>, and
  // look_at <-0.5, 0, 0> to <-0.4330127, 0, -0.25>.
  const Scene still = load_povray_text(
      "camera { location <4.566987298, 0, -8.910254038> look_at <-0.433012702, 0, -0.25> angle 60 }\n"
      "light_source { <0, 0, -100> color rgb 1 }\n"
      "poly { 2, <1,0,0,0,1,0,0,1,0,-1> clipped_by { box { <-1, -1, -0.6>, <1, 1, 0.6> } } pigment { rgb 1 } }\n",
      "still.pov",
      {{"image.width", std::to_string(kWidth)}, {"image.height", std::to_string(kHeight)}, {"antialias.samples", "1"}});
  const long a = coverage(turned).count, b = coverage(still).count;
  CHECK(a > 100);
  CHECK(a == Approx(b).epsilon(0.02));
}

TEST_CASE("bounded_by alone is a gate: the rays that pass the bound see the whole surface, as POV-Ray draws it",
          "[povray][gate]") {
  // A cylinder about POV-Ray's y axis, bounded by a sphere of radius 2: POV-Ray shows the band where rays pass the
  // sphere, including the parts of the cylinder outside it. The reference here is that rule, traced exactly.
  const Scene bounded =
      pov_scene("poly { 2, <1,0,0,0,0,0,0,1,0,-1> bounded_by { sphere { 0, 2 } } pigment { rgb 1 } }\n");
  REQUIRE(bounded.extent.kind == ExtentKind::Sphere);
  CHECK(bounded.extent.gate);
  CHECK(bounded.extent.radius == Approx(2));
  CHECK(bounded.extent.reach >= kDefaultGateReach);
  CHECK(bounded.warnings.empty());  // the gate is POV-Ray's rule: nothing to say
  CHECK_THAT(scene_to_toml(bounded), Catch::Contains("gate = true"));
  Renderer renderer(device_session(), testing::program_cache());
  const HitBuffer hits = renderer.render_with_records(bounded).hits;
  const RayBasis basis = make_ray_basis(bounded.camera, hits.width, hits.height);
  long both = 0, either = 0, clipped = 0;
  for (int y = 0; y < hits.height; ++y)
    for (int x = 0; x < hits.width; ++x) {
      const PixelRay ray = pixel_ray(basis, false, x, y);
      const glm::dvec3 o = ray.origin, d = glm::normalize(ray.direction);
      const double half_b = glm::dot(o, d), disc = half_b * half_b - (glm::dot(o, o) - 4);
      // x^2 + z^2 = 1 along the ray
      const double qa = d.x * d.x + d.z * d.z, qb = o.x * d.x + o.z * d.z, qc = o.x * o.x + o.z * o.z - 1;
      const bool meets = qb * qb - qa * qc >= 0, passes = disc >= 0;
      const double first = (-qb - std::sqrt(std::max(0.0, qb * qb - qa * qc))) / qa;
      clipped += passes && meets && glm::length(o + first * d) <= 2;  // what clipping to the sphere would show
      const bool shown = passes && meets, drawn = hits.at(x, y).flags & ALGRAY_HIT_FOUND;
      both += shown && drawn;
      either += shown || drawn;
    }
  REQUIRE(either > 300);
  // All but the pixels whose ray grazes the sphere or the cylinder, where rounding decides.
  CHECK(static_cast<double>(both) / static_cast<double>(either) >= 0.995);
  CHECK(static_cast<double>(clipped) / static_cast<double>(either) < 0.97);  // the clip alone would fall short
  // A bound that holds all of a closed surface is a gate all the same, with nothing to say.
  const Scene ball = pov_scene("poly { 2, <1,0,0,0,1,0,0,1,0,-1> bounded_by { sphere { 0, 1.5 } } }\n");
  CHECK(ball.extent.radius == Approx(1.5));
  CHECK(ball.extent.gate);
  CHECK(ball.warnings.empty());
  // clipped_by stays a cut.
  CHECK_FALSE(pov_scene("poly { 2, <1,0,0,0,0,0,0,1,0,-1> clipped_by { sphere { 0, 2 } } }\n").extent.gate);
}

TEST_CASE("no clipped_by or bounded_by: a closed surface the camera sees whole is drawn whole, with a note",
          "[povray]") {
  // POV-Ray's bicube and teardrop samples: a poly with no region at all, which POV-Ray draws without end.
  const Scene free = pov_scene("poly { 2, <1,0,0,0,1,0,0,1,0,-4> translate x }\n");
  REQUIRE(free.extent.kind == ExtentKind::Sphere);
  CHECK(any_contains(free.warnings, "test.pov:3:1: no clipped_by or bounded_by"));
  // The extent holds the half of the ball of radius 2 about (1, 0, 0) that the camera sees, and not much more.
  CHECK(glm::length(free.extent.centre - glm::dvec3(1, 0, 0)) < 2);
  CHECK(free.extent.radius < 4);
  const Coverage seen = coverage(free);
  const Coverage clipped =
      coverage(pov_scene("poly { 2, <1,0,0,0,1,0,0,1,0,-4> translate x "
                         "clipped_by { sphere { x, 2.5 } } }\n"));
  CHECK(seen.count > 300);
  CHECK(seen.count == clipped.count);
}

TEST_CASE("clipped_by { plane { n, d } } keeps n.x <= d: algray's clipping planes, moved by the transforms after it",
          "[povray][clip]") {
  // The default camera is left-handed: algray reads z negated, so POV-Ray's z <= 1 is algray's -z - 1 <= 0.
  const Scene cut = pov_scene("poly { 2, <1,0,0,0,1,0,0,1,0,-4>\n"
                              "  clipped_by { plane { x, 0.5 } plane { z, 1 } } translate x*1 }\n");
  REQUIRE(cut.extent.clips.size() == 2);
  CHECK(cut.extent.clips[0] == glm::dvec4(1, 0, 0, -1.5));
  CHECK(cut.extent.clips[1] == glm::dvec4(0, 0, -1, -1));
  // inverse keeps the other side; a normal of any length is the same plane, n.x <= d.
  const Scene other = pov_scene("sphere { 0, 2 clipped_by { plane { <0, 2, 0>, 1 inverse } } }\n");
  REQUIRE(other.extent.clips.size() == 1);
  CHECK(other.extent.clips[0] == glm::dvec4(0, -1, 0, 0.5));
  // A bound is POV-Ray's hint: a plane there is ignored, with a located warning.
  const Scene bound = pov_scene("sphere { 0, 2 bounded_by { plane { x, 0 } } }\n");
  CHECK(bound.extent.clips.empty());
  CHECK(any_contains(bound.warnings, "test.pov:3:28: bounded_by { plane } is ignored"));
  // Too many different planes for algray's kMaxClipPlanes, located at the first object.
  const SceneError many = error_of("sphere { 0, 2 clipped_by { plane { x, 1 } plane { -x, 1 } plane { y, 1 } "
                                   "plane { -y, 1 } plane { z, 1 } } }");
  CHECK(many.where == "bad.pov:1:1");
  CHECK_THAT(many.message, Catch::Contains("at most 4"));
}

TEST_CASE("grafbic's union of two objects, each clipped by its own planes, then turned: every surface cut by all",
          "[povray][clip]") {
  // As POV-Ray's grafbic sample: two nested spheres (its bicorns) in a union, each between its own pair of planes,
  // the union turned afterwards. algray cuts both by all four planes, and says so at each object.
  const Scene s = pov_scene("union {\n"
                            "  sphere { 0, 2 clipped_by { plane { x, 0.5 } plane { -x, 0.5 } } }\n"
                            "  sphere { 0, 1.9 clipped_by { plane { x, 0.49 } plane { -x, 0.49 } } }\n"
                            "  rotate <0, 90, 0>\n"
                            "}\n");
  REQUIRE(s.surfaces.size() == 2);
  REQUIRE(s.extent.clips.size() == 4);
  // rotate y*90 turns POV-Ray's x plane into a z plane, 0.5 from the origin.
  CHECK(std::fabs(s.extent.clips[0].z) == Approx(1));
  CHECK(s.extent.clips[0].w == Approx(-0.5));
  CHECK(std::fabs(s.extent.clips[0].x) < 1e-12);
  CHECK(s.extent.clips[0].z == Approx(-s.extent.clips[1].z));
  CHECK(any_contains(s.warnings, "test.pov:4:3: algray cuts every surface of a scene by the same planes"));
  CHECK(any_contains(s.warnings, "test.pov:5:3: algray cuts every surface of a scene by the same planes"));
  // grafbic's objects are quartics bounded (not clipped) by spheres of radius 3 and 2.99: two bounds alone are
  // hints, so the scene's region holds both, fitted to what the rays see, where two clips would be an error.
  const Scene bounds = pov_scene(
      "poly { 2, <1,0,0,0,1,0,0,1,0,-4> bounded_by { sphere { 0, 3 } } clipped_by { plane { x, 0.5 } } }\n"
      "poly { 2, <1,0,0,0,1,0,0,1,0,-3.9> bounded_by { sphere { 0, 2.99 } } clipped_by { plane { x, 0.49 } } }\n");
  CHECK(bounds.surfaces.size() == 2);
  CHECK(bounds.extent.clips.size() == 2);
  CHECK_THAT(error_of("poly { 2, <1,0,0,0,1,0,0,1,0,-4> clipped_by { sphere { 0, 3 } } }\n"
                      "poly { 2, <1,0,0,0,1,0,0,1,0,-4> clipped_by { sphere { 0, 2.99 } } }\n")
                 .message,
             Catch::Contains("clipped differently"));
  // Rendered: the camera on -z sees the ball of radius 2 as a disc, and the slab |y| <= 0.5 of it as a band
  // across the disc's middle.
  const Coverage whole = coverage(pov_scene("sphere { 0, 2 }\n"));
  const Coverage slab = coverage(pov_scene("sphere { 0, 2 clipped_by { plane { y, 0.5 } plane { -y, 0.5 } } }\n"));
  CHECK(whole.count > 300);
  CHECK(slab.count > 0);
  CHECK(slab.count < whole.count / 2);  // the band |y| <= 0.5 across a disc of radius 2 seen face on
  CHECK(std::fabs(slab.y) < 0.1);
}
