// surf scripts (.pic): surf's framing and position settings, its language, the scene values, located errors and
// warnings; and the one list of readable file types behind the unknown-type error.
#include <catch2/catch.hpp>
#include <cmath>

#include "cli_sandbox.h"
#include "algray/render/render_plan.h"
#include "algray/render/renderer.h"
#include "algray/scene/scene.h"
#include "algray/scene/scene_formats.h"
#include "test_support.h"

using namespace algray;
using algray::testing::device_session;

namespace {

constexpr int kSize = 101;  // 5.05 pixels per unit: surf's shorter side spans -10..10

Scene surf_scene(const std::string& body, int width = kSize, int height = kSize) {
  return load_surf_script_text(body + "\ndraw_surface;\n", "test.pic",
                               {{"image.width", std::to_string(width)},
                                {"image.height", std::to_string(height)},
                                {"antialias.samples", "1"},
                                {"antialias.adaptive", "false"}});
}

HitBuffer render_hits(const Scene& scene) {
  Renderer renderer(device_session(), testing::program_cache());
  return renderer.render_with_records(scene).hits;
}

struct Coverage {
  long count = 0;
  double centre_x = 0, centre_y = 0;  // in surf's units from the image centre, y up
};
Coverage coverage(const Scene& scene) {
  const HitBuffer hits = render_hits(scene);
  const double unit = std::min(hits.width, hits.height) / 20.0;
  Coverage c;
  for (int y = 0; y < hits.height; ++y)
    for (int x = 0; x < hits.width; ++x)
      if (hits.at(x, y).flags & ALGRAY_HIT_FOUND) {
        ++c.count;
        c.centre_x += (x + 0.5 - hits.width / 2.0) / unit;
        c.centre_y += (hits.height / 2.0 - y - 0.5) / unit;
      }
  if (c.count) {
    c.centre_x /= static_cast<double>(c.count);
    c.centre_y /= static_cast<double>(c.count);
  }
  return c;
}

SceneError error_of(const std::string& text) {
  try {
    load_surf_script_text(text, "bad.pic");
  } catch (const SceneError& e) {
    return e;
  }
  FAIL("no error for:\n" << text);
  return SceneError("", "");
}

std::vector<std::string> warnings_of(const std::string& text) { return load_surf_script_text(text, "w.pic").warnings; }

bool any_contains(const std::vector<std::string>& list, const std::string& part) {
  for (const std::string& s : list)
    if (s.find(part) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST_CASE("every readable type is named by the unknown-type error, and the loader dispatches by the list",
          "[surf][errors]") {
  for (const char* path : {"scene.pov2", "clebsch.PICX", "movie.mp4", "x.obj"}) {
    CAPTURE(path);
    try {
      load_scene_file(path);  // none exists: the type is refused before the file is opened
      FAIL("no error");
    } catch (const SceneError& e) {
      CHECK(e.where == path);
      for (const SceneFormatInfo& f : kSceneFormats) CHECK_THAT(e.message, Catch::Contains(f.extension));
    }
  }
  for (const SceneFormatInfo& f : kSceneFormats) {
    std::string upper = std::string("a") + f.extension;
    for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    CHECK(scene_format_of(upper) == f.format);
  }
  CHECK(scene_format_of("no_extension") == SceneFormat::Toml);  // as before: a path without one is TOML
  CHECK_FALSE(scene_format_of("scene.toml.bak"));
}

TEST_CASE("an unknown file type exits 2, lists the readable types and writes nothing", "[surf][errors][cli]") {
  algray::testing::require_device();
  algray::testing::Sandbox box;
  const auto scene = box.scene("scene.obj", "v 0 0 0\n");
  const auto r = box.run("render " + algray::testing::quoted(scene.string()) + " -o out.png --stats s.json");
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("scene.obj"));
  for (const SceneFormatInfo& f : kSceneFormats) CHECK_THAT(r.err, Catch::Contains(f.extension));
  CHECK(box.work_files().empty());
  const auto help = box.run("render --help");
  for (const SceneFormatInfo& f : kSceneFormats) CHECK_THAT(help.out, Catch::Contains(f.extension));
}

TEST_CASE("surf's framing: the shorter side spans -10..10, parallel or central from spec_z", "[surf]") {
  // Measured with surf: a ball of radius 2 at x = 3 is 20 pixels wide at 5 pixels per unit, in a 200 x 100 image
  // as in a 100 x 200 one.
  for (const auto& [w, h] : {std::pair{kSize, kSize}, std::pair{2 * kSize, kSize}, std::pair{kSize, 2 * kSize}}) {
    CAPTURE(w, h);
    const Coverage c = coverage(surf_scene("surface=(x-3)^2+y^2+z^2-4;", w, h));
    const double unit = std::min(w, h) / 20.0;
    CHECK(c.count == Approx(3.14159 * 4 * unit * unit).epsilon(0.08));
    CHECK(c.centre_x == Approx(3).margin(0.1));
    CHECK(c.centre_y == Approx(0).margin(0.1));
  }
  // Central perspective, eye at (0, 0, 25) by default: a ball at (3, 0, 5) is seen at 3 * 25 / 20 (surf: 3.74).
  const Coverage central = coverage(surf_scene("perspective=central;\nsurface=(x-3)^2+y^2+(z-5)^2-1;"));
  CHECK(central.centre_x == Approx(3.75).margin(0.1));
  const Coverage far = coverage(surf_scene("perspective=central; spec_z=50;\nsurface=(x-3)^2+y^2+(z-5)^2-1;"));
  CHECK(far.centre_x == Approx(3 * 50.0 / 45).margin(0.1));
}

TEST_CASE("surf's position settings: rotations' senses and order, scale, origin, first/second/third", "[surf]") {
  // rot_z and rotate(p, a, zAxis) turn (5, 0, 0) counter-clockwise (surf: to (4.36, 2.39)).
  for (const char* body : {"rot_z=0.5;\nsurface=(x-5)^2+y^2+z^2-1;", "surface=rotate((x-5)^2+y^2+z^2-1,0.5,zAxis);"}) {
    CAPTURE(body);
    const Coverage c = coverage(surf_scene(body));
    CHECK(c.centre_x == Approx(5 * std::cos(0.5)).margin(0.1));
    CHECK(c.centre_y == Approx(5 * std::sin(0.5)).margin(0.1));
  }
  // Seen in central perspective, what a rotation brings nearer looks larger. Measured with surf: rot_x = +0.5
  // brings (0, 5, 0) nearer, and so does rot_y = +0.5 for (5, 0, 0): surf turns about y the other way.
  const std::string central = "perspective=central;\n";
  for (const char* axis : {"x", "y"}) {
    CAPTURE(axis);
    const std::string ball = std::string(axis) == "x" ? "surface=x^2+(y-5)^2+z^2-1;" : "surface=(x-5)^2+y^2+z^2-1;";
    const long plus = coverage(surf_scene(central + "rot_" + axis + "=0.5;\n" + ball)).count;
    const long minus = coverage(surf_scene(central + "rot_" + axis + "=-0.5;\n" + ball)).count;
    CHECK(static_cast<double>(plus) > static_cast<double>(minus) * 1.3);
    const std::string name = std::string(axis) == "x" ? "xAxis" : "yAxis";
    const long function = coverage(surf_scene(central + "surface=rotate(" + ball.substr(8, ball.size() - 9) + ",0.5," +
                                              name + ");"))
                              .count;
    CHECK(function == Approx(plus).epsilon(0.02));
  }
  // About y first, then x (surf: (5, 0, 0) with rot_x = rot_y = 0.5 is seen at (4.38, -1.14)).
  const Coverage both = coverage(surf_scene("rot_x=0.5; rot_y=0.5;\nsurface=(x-5)^2+y^2+z^2-1;"));
  CHECK(both.centre_x == Approx(5 * std::cos(0.5)).margin(0.1));
  CHECK(both.centre_y == Approx(-5 * std::sin(0.5) * std::sin(0.5)).margin(0.1));
  // Translate, then scale by default: a ball at x = 2 moved by 1 and shown at P(0.5 x) sits at 6; scaling first
  // puts it at 5.
  const std::string ball = "origin_x=1; scale_x=0.5;\nsurface=(x-2)^2+y^2+z^2-0.25;";
  CHECK(coverage(surf_scene(ball)).centre_x == Approx(6).margin(0.1));
  CHECK(coverage(surf_scene("first=scale; second=translate; third=rotate;\n" + ball)).centre_x ==
        Approx(5).margin(0.1));
}

TEST_CASE("surf's clip region: ball and cube of radius about center, none as the z slab", "[surf]") {
  const Scene ball = surf_scene("radius=5; center_x=3;\nsurface=x^2+y^2+z^2-1;");
  CHECK(ball.extent.kind == ExtentKind::Sphere);
  CHECK(ball.extent.radius == 5);
  CHECK(ball.extent.centre.x == 3);
  const Scene cube = surf_scene("clip=cube; radius=2;\nsurface=x^2+y^2+z^2-1;");
  CHECK(cube.extent.kind == ExtentKind::Box);
  CHECK(cube.extent.max.x == 2);
  // A ball of radius sqrt(150) with clip = none: surf shows it where |z| <= 10 on the surface, a ring.
  const Scene none = surf_scene("clip=none;\nsurface=x^2+y^2+z^2-150;");
  CHECK(none.extent.kind == ExtentKind::Box);
  CHECK(none.extent.max.z == 10);
  CHECK(none.extent.min.z == -10);
  const HitBuffer hits = render_hits(none);
  CHECK_FALSE(hits.at(kSize / 2, kSize / 2).flags & ALGRAY_HIT_FOUND);  // |z| = 12.2 at the centre
  CHECK(hits.at(kSize / 2 + 40, kSize / 2).flags & ALGRAY_HIT_FOUND);   // r = 7.9: z = 8.5
  CHECK(error_of("clip=cylinder_zaxis;\nsurface=x;\ndraw_surface;\n").where == "bad.pic:1:1");
}

TEST_CASE("surf's language: types, precedence, functions, if/goto", "[surf]") {
  auto first_equation_at = [](const std::string& body, double x, double y, double z) {
    return load_surf_script_text(body + "\ndraw_surface;\n", "t.pic").surfaces.front().polynomial.evaluate(x, y, z);
  };
  // -x^2 is (-x)^2 in surf, ^ is left-associative, and ints divide as reals (each measured with surf).
  CHECK(first_equation_at("surface=-x^2+y+z;", 2, 0, 0) == Approx(4));
  CHECK(first_equation_at("surface=x+(2^3^2);", 0, 0, 0) == Approx(64));
  CHECK(first_equation_at("double a=7/2;\nsurface=x+a;", 0, 0, 0) == Approx(3.5));
  CHECK(first_equation_at("double a=-2^2;\nsurface=x+a;", 0, 0, 0) == Approx(4));
  CHECK(first_equation_at("double Pi=2*arccos(0);\nsurface=x+sin(Pi/2)+sqrt(9)+pow(2,3);", 0, 0, 0) ==
        Approx(12));
  CHECK(first_equation_at("poly p=x^2;\npolyxyz q=p*y-1;\nsurface=diff(q,x)+deg(q)+len(q);", 1, 1, 0) ==
        Approx(2 + 3 + 2));
  CHECK(first_equation_at("int i=0;\nloop:\ni=i+1;\nif(i<10) goto loop;\nsurface=x+i;", 0, 0, 0) == Approx(10));
  // Reserved values read back, colours in 0..255, per-surface materials in percent.
  const Scene s = load_surf_script_text(
      "surface_red=255; surface_green=0; surface_blue=inside_blue;\nambient=50; diffuse=40; reflected=30;\n"
      "smoothness=20;\nlight1_vol=0; light2_vol=100; light2_red=0;\nbackground_red=255;\nsurface=x^2+y^2+z^2-1;\n"
      "surface2=x+y;\nsurface2_green=255;\ntransparence2=40;\ndraw_surface;\n",
      "values.pic");
  REQUIRE(s.surfaces.size() == 2);
  const Material& front = s.surfaces[0].materials.front;
  CHECK(front.colour.r == Approx(1));
  CHECK(front.colour.g == 0);
  CHECK(front.colour.b == Approx(srgb_to_linear(30 / 255.0)));  // the default inside blue
  CHECK(front.ambient == Approx(0.5));
  CHECK(front.diffuse == Approx(0.4));
  CHECK(front.specular == Approx(0.3));
  CHECK(front.exponent == 20);
  CHECK(s.surfaces[0].materials.back.colour.r == Approx(srgb_to_linear(230 / 255.0)));
  CHECK(s.surfaces[1].materials.front.colour.g == Approx(1));
  // Measured with surf: without transmitted_light in the illumination (the default), transparence changes nothing.
  CHECK(s.surfaces[1].materials.front.transparency == 0);
  REQUIRE(s.lights.size() == 1);
  CHECK(s.lights[0].position == glm::dvec3(0, 100, 100));
  CHECK(s.lights[0].colour.r == 0);
  CHECK_FALSE(s.lights[0].shadows);
  CHECK(s.image.background.r == Approx(1));
  const Scene lit = load_surf_script_text(
      "illumination=ambient_light+diffuse_light+reflected_light+transmitted_light;\ntransparence=40;\n"
      "surface=x;\ndraw_surface;\n",
      "t.pic");
  CHECK(lit.surfaces[0].materials.front.transparency == Approx(0.4));
}

TEST_CASE("the picture a script saves is the one rendered", "[surf]") {
  std::vector<std::string> warnings;
  const Scene s = load_surf_script_text(
      "int i=1;\nloop:\nsurface=x^2+y^2+z^2-i;\ndraw_surface;\nsave_color_image;\ni=i+1;\nif(i<4) goto loop;\n",
      "anim.pic");
  CHECK(s.surfaces[0].polynomial.evaluate(0, 0, 0) == Approx(-1));  // the first saved
  CHECK(any_contains(s.warnings, "anim.pic:4:1: the script draws 3 pictures"));
  const Scene last = load_surf_script_text("surface=x-1;\ndraw_surface;\nsurface=x-2;\ndraw_surface;\n", "t.pic");
  CHECK(last.surfaces[0].polynomial.evaluate(0, 0, 0) == Approx(-2));  // nothing saved: the last drawn
  // surf's goto jumps back to a label it has passed, never forward.
  CHECK_THAT(error_of("if(1) goto later;\nlater:\n").message, Catch::Contains("no label 'later:' before"));
}

TEST_CASE("bad surf scripts get located errors; statements outside the subset located warnings", "[surf][errors]") {
  CHECK(error_of("surface=x^2+qq;\ndraw_surface;\n").where == "bad.pic:1:13");
  CHECK(error_of("double a=1;\n  double a=2;\n").where == "bad.pic:2:10");
  CHECK(error_of("int k=2.7;\n").where == "bad.pic:1:6");
  CHECK(error_of("surface=x^2 /* never closed\n").where == "bad.pic:1:13");
  CHECK(error_of("surface=x;\nfilename=\"a.ppm;\n").where == "bad.pic:2:10");
  CHECK_THAT(error_of("surface=(x+y)^40;\ndraw_surface;\n").message, Catch::Contains("degree"));
  CHECK_THAT(error_of("surface=x/y;\n").message, Catch::Contains("numbers only"));
  CHECK_THAT(error_of("surface=x+2^1000000;\n").message, Catch::Contains("infinity"));
  CHECK_THAT(error_of("poly p=(x+1)^0+2;\nsurface=x+(p-1)^1000000;\n").message, Catch::Contains("overflows"));
  CHECK_THAT(error_of("loop:\nif(1) goto loop;\n").message, Catch::Contains("goto loop that does not end"));
  CHECK_THAT(error_of("surface=x;\n").message, Catch::Contains("never draws"));
  CHECK_THAT(error_of("curve=x^2-y;\ndraw_curve;\n").message, Catch::Contains("plane curves"));
  CHECK(error_of("surface=x;\nsurface_red=300;\ndraw_surface;\n").where == "bad.pic:2:1");
  CHECK(error_of("surface=x;\nwidth=0;\ndraw_surface;\n").where == "bad.pic:2:1");
  CHECK(error_of("surface=1;\ndraw_surface;\n").where == "bad.pic:1:1");
  CHECK(error_of("surface=sqrt(-1)*x;\n").where == "bad.pic:1:9");
  CHECK(error_of("surface=x;\n draw_surface\n").where == "bad.pic:3:1");  // the missing ';'
  CHECK_THAT(error_of("surface=x;\nstereo_eye=1.2;\ndraw_surface;\n").message, Catch::Contains("stereo"));
  CHECK(load_surf_script_text("clip=sphere;\nsurface=x;\ndraw_surface;\n", "t.pic").extent.kind ==
        ExtentKind::Sphere);

  const auto w = warnings_of(
      "surface=x^2+y^2+z^2-9;\ndraw_surface;\nplane=z;\ncut_with_plane;\ndepth_cueing=yes;\nfoo=3;\n"
      "filename=\"a.ppm\";\nsave_color_image;\n");
  CHECK(any_contains(w, "w.pic:5:1: depth_cueing"));
  CHECK(any_contains(w, "w.pic:6:1: 'foo'"));
  CHECK(w.size() == 2);  // filename and save_color_image change nothing algray draws; the cut is a section
}

TEST_CASE("cut_with_plane is a section of surface surf_nr, its plane moved with the surfaces", "[surf][section]") {
  const std::string ball = "surface=x^2+y^2+z^2-36;\ndraw_surface;\n";
  // The plane, its surface, colour and width as the script left them when cut_with_plane ran.
  // Measured with surf: the curve is curve_width / 400 of the image's shorter side wide (3 by default, 1.5 pixels
  // at the default 200 x 200), and white by default.
  const Scene plain = load_surf_script_text(ball + "plane=z-1;\ncurve_width=8;\ncurve_red=0;\ncut_with_plane;\n"
                                            "curve_width=1;\n", "cut.pic");
  REQUIRE(plain.sections.size() == 1);
  const Section& s = plain.sections[0];
  CHECK(s.plane == glm::dvec4(0, 0, 1, -1));
  CHECK(s.surface == 0);
  CHECK(s.width == 4);
  CHECK(s.colour.r == 0);
  CHECK(s.colour.g == Approx(1));
  CHECK(s.colour.b == Approx(1));
  const Scene wide = load_surf_script_text("width=400; height=300;\n" + ball + "plane=z;\ncut_with_plane;\n", "w.pic");
  CHECK(wide.sections.at(0).width == Approx(2.25));
  // The plane is the surface's own coordinates': rot_x turns it as it turns the ball (y = 0 is seen tilted by
  // 0.8 about x), scale_x = 2 shows x = 1 at x = 0.5, origin_x = 2 moves it by 2.
  const auto plane_of = [&](const std::string& position, const std::string& plane) {
    const Scene sc = load_surf_script_text(position + ball + "plane=" + plane + ";\ncut_with_plane;\n", "p.pic");
    REQUIRE(sc.sections.size() == 1);
    const glm::dvec4 p = sc.sections[0].plane;
    return p / glm::length(glm::dvec3(p));
  };
  // (surf: the section of y = 0 with rot_x = 0.8 crosses the image's middle column 4.3 below the centre; x = 1
  // is seen at 0.5 with scale_x = 2, at 3 with origin_x = 2.)
  const glm::dvec4 turned = plane_of("rot_x=0.8;\n", "y");
  CHECK(turned.x == Approx(0).margin(1e-12));
  CHECK(turned.y == Approx(std::cos(0.8)));
  CHECK(turned.z == Approx(std::sin(0.8)));
  CHECK(turned.w == Approx(0).margin(1e-12));
  const glm::dvec4 scaled = plane_of("scale_x=2;\n", "x-1+0.001*z");
  CHECK(-scaled.w / scaled.x == Approx(0.5));
  const glm::dvec4 moved = plane_of("origin_x=2;\n", "x-1+0.001*z");
  CHECK(-moved.w / moved.x == Approx(3));
  // surf draws no section of a plane seen edge-on (no z once turned: here by rot_y, which surf turns the other
  // way), nor does algray; the plane turned the other way is seen.
  const std::string turn = "rot_y=0.3;\n" + ball;
  const Scene edge = load_surf_script_text(turn + "plane=x*cos(0.3)-z*sin(0.3)+y;\ncut_with_plane;\n", "e.pic");
  CHECK(edge.sections.empty());
  CHECK(any_contains(edge.warnings, "e.pic:5:1: cut_with_plane: the plane is seen edge-on"));
  CHECK(load_surf_script_text(turn + "plane=x*cos(0.3)+z*sin(0.3)+y;\ncut_with_plane;\n", "e.pic").sections.size() ==
        1);
  CHECK(load_surf_script_text(ball + "plane=y;\ncut_with_plane;\n", "e.pic").sections.empty());
  // surf_nr (surface_n too) picks the surface; its index counts the surfaces that are set.
  const std::string two = "surface=(x+4)^2+y^2+z^2-9;\nsurface3=(x-4)^2+y^2+z^2-9;\ndraw_surface;\nplane=z-1;\n";
  CHECK(load_surf_script_text(two + "surf_nr=3;\ncut_with_plane;\n", "t.pic").sections.at(0).surface == 1);
  CHECK(load_surf_script_text(two + "surface_n=3;\ncut_with_plane;\n", "t.pic").sections.at(0).surface == 1);
  CHECK(load_surf_script_text(two + "cut_with_plane;\n", "t.pic").sections.at(0).surface == 0);
  const Scene empty = load_surf_script_text(two + "surf_nr=2;\ncut_with_plane;\n", "t.pic");
  CHECK(empty.sections.empty());
  CHECK(any_contains(empty.warnings, "t.pic:6:1: cut_with_plane cuts surface2"));
  // Each picture keeps its own cuts: the saved one those made before it was saved.
  const Scene saved = load_surf_script_text(ball + "plane=z-1;\ncut_with_plane;\nsave_color_image;\nplane=z+1;\n"
                                            "cut_with_plane;\n", "s.pic");
  CHECK(saved.sections.size() == 1);
  const Scene redrawn = load_surf_script_text("plane=z;\n" + ball + "cut_with_plane;\n" + ball, "r.pic");
  CHECK(redrawn.sections.empty());
  // Before any draw_surface there is nothing to cut: a located warning.
  CHECK(any_contains(warnings_of("plane=x;\ncut_with_plane;\n" + ball), "w.pic:2:1: cut_with_plane before any"));
  // A plane that is no plane, a colour or width out of range, a surface number that is none: located errors.
  CHECK(error_of(ball + "plane=x^2;\ncut_with_plane;\n").where == "bad.pic:3:1");
  CHECK(error_of(ball + "cut_with_plane;\n").where == "bad.pic:3:1");  // plane is 0 until it is set
  CHECK_THAT(error_of(ball + "plane=3;\ncut_with_plane;\n").message, Catch::Contains("linear"));
  CHECK(error_of(ball + "plane=x;\ncurve_green=256;\ncut_with_plane;\n").where == "bad.pic:4:1");
  CHECK(error_of(ball + "plane=x;\ncurve_width=0;\ncut_with_plane;\n").where == "bad.pic:4:1");
  CHECK(error_of(ball + "plane=x;\nsurf_nr=10;\ncut_with_plane;\n").where == "bad.pic:4:1");
  // A plane far beyond anything drawn: a warning, and its numbers stay ones the scene reader takes.
  const Scene far = load_surf_script_text(ball + "plane=z-1e300;\ncut_with_plane;\n", "f.pic");
  CHECK(far.sections.empty());
  CHECK(any_contains(far.warnings, "f.pic:4:1: cut_with_plane: the plane lies too far away"));
  CHECK(load_surf_script_text(ball + "plane=1e30*z-2e30;\ncut_with_plane;\n", "f.pic").sections.at(0).plane ==
        glm::dvec4(0, 0, 1, -2));
}

TEST_CASE("a surf script renders from the command line; a bad one exits 2 and writes nothing", "[surf][cli]") {
  algray::testing::require_device();
  algray::testing::Sandbox box;
  const auto good = box.scene("ball.pic", "width=64; height=48;\nsurface=x^2+y^2+z^2-25;\ncut_with_plane;\n"
                                          "draw_surface;\n");
  const auto r = box.run("render " + algray::testing::quoted(good.string()) + " --preview -o out.png");
  CHECK(r.exit_code == 0);
  CHECK_THAT(r.err, Catch::Contains("ball.pic:3:1: cut_with_plane"));
  CHECK(algray::testing::read_text(box.work / "out.png").size() > 0);
  const auto bad = box.scene("bad.pic", "width=64;\nsurface=x^2+y^2+z^2-25 +;\ndraw_surface;\n");
  const auto b = box.run("render " + algray::testing::quoted(bad.string()) + " -o bad.png");
  CHECK(b.exit_code == 2);
  CHECK_THAT(b.err, Catch::Contains("bad.pic:2:"));
  CHECK_FALSE(std::filesystem::exists(box.work / "bad.png"));
}
