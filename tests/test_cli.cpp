// End-to-end tests of the algray binary: exit codes, stderr messages, output files, stats and the program cache.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "algray/device/cl_runtime.h"
#include "algray/io/image_io.h"
#include "algray/scene/scene.h"
#include "algray/scene/solver_options.h"
#include "algray/util/version.h"
#include "cli_sandbox.h"
#include "scene_fixtures.h"

namespace fs = std::filesystem;

using namespace algray::testing;

namespace {

const std::string kTiny = "--width 32 --height 24";

std::string scene_file(const char* name) {
  // Appended, not added: GCC 12 misreads operator+ on this temporary (a false -Warray-bounds).
  std::string path = ALGRAY_SOURCE_DIR "/scenes/";
  path += name;
  return quoted(std::as_const(path));  // the sandbox's quoted, not std::quoted (which a non-const string picks)
}

std::string sphere_with(int line, const std::string& replacement) {
  return algray::testing::sphere_with({{line, replacement}});
}

int finite_depths(const algray::FrameImage& img) {
  int n = 0;
  for (float z : img.depth) n += std::isfinite(z);
  return n;
}

}  // namespace

TEST_CASE("devices lists at least one device with its compute units and fp64 support", "[cli]") {
  Sandbox box;
  const Result r = box.run("devices");
  INFO(r.err);
  if (r.exit_code != 0) FAIL("`algray devices` exited " << r.exit_code << ": no usable OpenCL device\n" << r.err);
  CHECK_THAT(r.out, Catch::Contains("[0] "));
  CHECK_THAT(r.out, Catch::Contains("compute units"));
  CHECK_THAT(r.out, Catch::Contains("fp64"));
}

TEST_CASE("the default render writes EXR, PNG and stats", "[cli]") {
  require_device();
  Sandbox box;
  const Result r = box.run("render -o out.exr -o out.png " + kTiny + " --stats s.json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(fs::exists(box.work / "out.png"));
  REQUIRE(fs::exists(box.work / "out.exr"));
  // Success says on stdout what it wrote and how long it took, and nothing on stderr when it is not a terminal.
  CHECK(r.err.empty());
  CHECK_THAT(r.out, Catch::StartsWith("wrote out.exr, out.png and s.json (32x24) in ") && Catch::EndsWith(" s\n"));

  const algray::FrameImage img = algray::read_exr(box.work / "out.exr");
  CHECK(img.width == 32);
  CHECK(img.height == 24);
  REQUIRE(img.depth.size() == 32u * 24u);
  int misses = 0;
  for (float z : img.depth) misses += std::isinf(z) && z > 0;
  CHECK(finite_depths(img) > 0);
  CHECK(misses > 0);
  CHECK(finite_depths(img) + misses == 32 * 24);
  std::map<std::string, std::string> attrs(img.string_attributes.begin(), img.string_attributes.end());
  REQUIRE(attrs.count("algray/equation"));
  CHECK_FALSE(attrs["algray/equation"].empty());

  const nlohmann::json s = box.stats();
  REQUIRE(s["programs"].is_array());
  REQUIRE_FALSE(s["programs"].empty());
  CHECK(s["programs"][0]["from_cache"].is_boolean());
  REQUIRE_FALSE(s["passes"].empty());
  // The default scene is antialiased: samples x samples primary rays per pixel.
  const int samples = s["plan"]["antialias_samples"].get<int>();
  CHECK(samples >= 1);
  CHECK(s["passes"][0]["rays"] == 768 * samples * samples);
  CHECK(s["primary_rays"]["count"] == 768 * samples * samples);
  CHECK(s["passes"][0]["kernel_ms"].get<double>() > 0);
  CHECK(s["image"]["width"] == 32);
  CHECK(s["image"]["height"] == 24);
  // The stats must agree with the image about how many pixels hit the surface.
  CHECK(s["pixels"]["hits"].get<int>() == finite_depths(img));
}

TEST_CASE("the EXR metadata and the stats name every surface of a scene of several", "[cli]") {
  require_device();
  Sandbox box;
  const std::string scene_path = std::string(ALGRAY_SOURCE_DIR) + "/scenes/examples/ball_and_ring.toml";
  const algray::Scene scene = algray::load_scene_file(scene_path);
  REQUIRE(scene.surfaces.size() >= 2);
  const auto r = box.run("render " + scene_path + " -o out.exr --stats s.json --width 16 --height 12 --preview");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const algray::FrameImage img = algray::read_exr(box.work / "out.exr");
  std::map<std::string, std::string> text(img.string_attributes.begin(), img.string_attributes.end());
  std::map<std::string, double> numbers(img.double_attributes.begin(), img.double_attributes.end());
  CHECK(numbers["algray/surfaces"] == static_cast<double>(scene.surfaces.size()));
  const nlohmann::json stats = box.stats();
  REQUIRE(stats["surfaces"].size() == scene.surfaces.size());
  for (std::size_t k = 0; k < scene.surfaces.size(); ++k) {
    INFO("surface " << k);
    const std::string prefix = "algray/surface" + std::to_string(k) + "/";
    CHECK(text[prefix + "name"] == scene.surfaces[k].name);
    CHECK(text[prefix + "equation"] == scene.surfaces[k].equation);
    CHECK(text[prefix + "polynomial"] == scene.surfaces[k].polynomial.to_string());
    CHECK(numbers[prefix + "degree"] == scene.surfaces[k].polynomial.degree());
    CHECK(stats["surfaces"][k]["equation"] == scene.surfaces[k].equation);
  }
}

TEST_CASE("a second render reuses the compiled program and --no-cache does not", "[cli]") {
  require_device();
  Sandbox box;
  box.cache = box.root / "cache";
  // A fresh cache cannot hold the program: a fresh Sandbox root guarantees the first run compiles. The precision is
  // given: under `auto` each run that does not read the cache times double against float anew, and the --no-cache
  // run once rendered other depths than the first in a loaded suite run (2026-12-07).
  const std::string tiny = kTiny + " --precision double";
  const Result first = box.run("render -o a.exr " + tiny + " --stats s1.json");
  INFO(first.err);
  REQUIRE(first.exit_code == 0);
  const nlohmann::json s1 = box.stats("s1.json");
  CHECK(s1["programs"][0]["origin"] == "built");
  CHECK(s1["programs"][0]["from_cache"] == false);
  CHECK(s1["cache"] == box.cache.string());
  CHECK(fs::exists(box.cache));
  CHECK_FALSE(fs::is_empty(box.cache));

  const Result second = box.run("render -o b.exr " + tiny + " --stats s2.json");
  INFO(second.err);
  REQUIRE(second.exit_code == 0);
  const nlohmann::json s2 = box.stats("s2.json");
  const std::string origin = s2["programs"][0]["origin"];
  CHECK((origin == "disk" || origin == "memory"));
  CHECK(s2["programs"][0]["from_cache"] == true);
  CHECK(s2["programs"][0]["key"] == s1["programs"][0]["key"]);

  const Result uncached = box.run("render -o c.exr " + tiny + " --no-cache --stats s3.json");
  INFO(uncached.err);
  REQUIRE(uncached.exit_code == 0);
  const nlohmann::json s3 = box.stats("s3.json");
  CHECK(s3["programs"][0]["origin"] == "built");
  CHECK(s3["programs"][0]["from_cache"] == false);
  CHECK(s3["cache"] == "off");

  // The cached program must render the same image as the freshly built one.
  const algray::FrameImage a = algray::read_exr(box.work / "a.exr");
  const algray::FrameImage b = algray::read_exr(box.work / "b.exr");
  const algray::FrameImage c = algray::read_exr(box.work / "c.exr");
  CHECK(a.depth == b.depth);
  CHECK(a.depth == c.depth);
}

TEST_CASE("bad input exits 2 with a located message and writes nothing", "[cli][errors]") {
  Sandbox box;
  struct Case {
    const char* what;
    int line;
    const char* replacement;
    const char* location;  // ":line:column" in the scene file
    const char* phrase;
  };
  const std::vector<Case> cases = {
      {"unknown key", 10, "fovy = 45", ":10:1", "unknown key 'camera.fovy' (did you mean 'fov_y'?)"},
      {"malformed equation", 3, "equation = \"x^2+*y\"", ":3:17", "unexpected"},
      {"division by a variable", 3, "equation = \"x/y\"", ":3:15", "division by a variable"},
      {"negative power", 3, "equation = \"x^-2\"", ":3:15", "negative exponent"},
      {"nan", 5, "radius = nan", ":5:10", "must be finite, not nan"},
      {"degree 33", 3, "equation = \"x^33\"", ":3:15", "this power would have degree 33"},
      {"degree 33 by terms", 3, "terms = [[33, 0, 0, 1.0]]", ":3:9", "degree 33 exceeds the supported maximum 32"},
      {"zero polynomial", 3, "equation = \"x-x\"", ":3:12", "identically zero"},
      {"empty extent", 5, "radius = 0", ":5:10", "the extent is empty"},
      {"degenerate camera", 8, "look_at = [0, 0, 5]", ":8:11", "look_at coincides with eye"},
  };
  for (const Case& c : cases) {
    SECTION(c.what) {
      const fs::path scene = box.scene("bad.toml", sphere_with(c.line, c.replacement));
      const Result r = box.run("render " + quoted(scene.string()) + " -o out.exr -o out.png --stats s.json " + kTiny);
      INFO(r.err);
      CHECK(r.exit_code == 2);
      CHECK_THAT(r.err, Catch::StartsWith(scene.string() + c.location + ": error: "));
      CHECK_THAT(r.err, Catch::Contains(c.phrase));
      // The excerpt repeats the offending line under the message.
      CHECK_THAT(r.err, Catch::Contains(c.replacement) && Catch::Contains("^"));
      CHECK(box.work_files().empty());
    }
  }
  SECTION("a good scene renders in this sandbox, so the cases above fail for their own reason") {
    require_device();
    const fs::path scene = box.scene("good.toml", sphere_with(0, ""));  // no line 0: the scene unchanged
    const Result r = box.run("render " + quoted(scene.string()) + " -o out.exr " + kTiny);
    INFO(r.err);
    CHECK(r.exit_code == 0);
    CHECK(fs::exists(box.work / "out.exr"));
  }
  SECTION("unsupported output extension") {
    const Result r = box.run("render -o out.exr -o out.jpg " + kTiny);
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("unsupported output extension '.jpg'"));
    CHECK(box.work_files().empty());
  }
  SECTION("nonexistent scene file") {
    const std::string missing = (box.in / "no-such-scene.toml").string();
    const Result r = box.run("render " + quoted(missing) + " -o out.exr " + kTiny);
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::StartsWith(missing + ": error: cannot read the scene file"));
    CHECK(box.work_files().empty());
  }
  SECTION("bad --set value") {
    const Result r = box.run("render -o out.exr --set render.tolerance=nan " + kTiny);
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::StartsWith("--set render.tolerance=nan: error: "));
    CHECK(box.work_files().empty());
  }
}

TEST_CASE("a bad scene leaves an existing output byte-identical", "[cli][errors]") {
  Sandbox box;
  const std::string previous = "an earlier render that must survive\n";
  write_text(box.work / "out.exr", previous);
  const fs::path scene = box.scene("bad.toml", sphere_with(3, "equation = \"x/y\""));
  const Result r = box.run("render " + quoted(scene.string()) + " -o out.exr " + kTiny);
  CHECK(r.exit_code == 2);
  CHECK(read_text(box.work / "out.exr") == previous);
  CHECK(box.work_files() == std::vector<std::string>{"out.exr"});
}

TEST_CASE("double precision renders on a device with fp64", "[cli]") {
  require_device();
  Sandbox box;
  const Result r = box.run("render -o out.exr --precision double --stats s.json " + kTiny);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const nlohmann::json s = box.stats();
  REQUIRE(s["device"]["fp64"] == true);
  CHECK(s["solver"]["precision"] == "double");
  const algray::FrameImage img = algray::read_exr(box.work / "out.exr");
  CHECK(finite_depths(img) > 0);
}

TEST_CASE("the solver flags reach the kernel and its program key, and a bad choice is refused", "[cli]") {
  require_device();
  Sandbox box;
  const Result r =
      box.run("render -o out.exr --isolation descartes --refine illinois --tolerance 1e-6 --stats s.json " + kTiny);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const nlohmann::json s = box.stats();
  CHECK(s["solver"]["isolation"] == "descartes");
  CHECK(s["solver"]["refinement"] == "illinois");
  CHECK(s["solver"]["tolerance"] == 1e-6);
  CHECK(s["solver"]["max_iterations"] == 100);
  const std::string key = s["programs"][0]["key"];
  CHECK_THAT(key, Catch::Contains("isolation=descartes") && Catch::Contains("refinement=illinois"));
  // Plain regula falsi gets the paper's 1000-iteration cap unless told otherwise.
  REQUIRE(box.run("render -o out.exr --refine regula-falsi --stats s.json " + kTiny).exit_code == 0);
  CHECK(box.stats()["solver"]["max_iterations"] == 1000);
  REQUIRE(box.run("render -o out.exr --refine regula-falsi --max-iterations 50 --stats s.json " + kTiny).exit_code ==
          0);
  CHECK(box.stats()["solver"]["max_iterations"] == 50);

  const Result bad = box.run("render -o other.exr --refine secant " + kTiny);
  CHECK(bad.exit_code == 2);
  CHECK_THAT(bad.err, Catch::Contains("render.refinement must be one of " + algray::refinement_choices()));
  CHECK(!fs::exists(box.work / "other.exr"));
}

TEST_CASE("--device picks by index or name substring and lists the devices when none matches", "[cli]") {
  require_device();
  Sandbox box;
  SECTION("an index out of range") {
    const Result r = box.run("render -o out.exr --device 99 " + kTiny);
    CHECK(r.exit_code != 0);
    CHECK_THAT(r.err, Catch::Contains("--device 99"));
    CHECK_THAT(r.err, Catch::Contains("[0] ") && Catch::Contains("compute units"));
    CHECK(box.work_files().empty());
  }
  SECTION("a substring of the device's name, in another case") {
    const auto devices = algray::enumerate_devices();
    REQUIRE_FALSE(devices.empty());
    // The first word of the first device's name, upper-cased: "PTHREAD" on PoCL, "NVIDIA" on an NVIDIA GPU.
    const std::string word = devices.front().name.substr(0, devices.front().name.find_first_of(" -"));
    std::string upper = word;
    std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return std::toupper(c); });
    const Result r = box.run("render -o out.exr --device " + upper + " --stats s.json " + kTiny);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const std::string name = box.stats()["device"]["name"];
    CHECK_THAT(name, Catch::Contains(word));
  }
}

TEST_CASE("--set on a bare name changes a parameter of the render", "[cli]") {
  require_device();
  Sandbox box;
  const std::string torus = scene_file("torus.toml");
  const Result thin = box.run("render " + torus + " -o thin.exr --set r=0.5 " + kTiny);
  INFO(thin.err);
  REQUIRE(thin.exit_code == 0);
  const Result fat = box.run("render " + torus + " -o fat.exr --set r=0.9 " + kTiny);
  INFO(fat.err);
  REQUIRE(fat.exit_code == 0);
  const int thin_hits = finite_depths(algray::read_exr(box.work / "thin.exr"));
  const int fat_hits = finite_depths(algray::read_exr(box.work / "fat.exr"));
  CHECK(thin_hits > 0);
  CHECK(thin_hits < fat_hits);
  std::map<std::string, std::string> attrs;
  for (const auto& [k, v] : algray::read_exr(box.work / "thin.exr").string_attributes) attrs[k] = v;
  // The exact polynomial must differ too, not only the pixels.
  std::map<std::string, std::string> fat_attrs;
  for (const auto& [k, v] : algray::read_exr(box.work / "fat.exr").string_attributes) fat_attrs[k] = v;
  CHECK(attrs["algray/polynomial"] != fat_attrs["algray/polynomial"]);
}

TEST_CASE("a kernel that fails to build exits 1 with the build log and the options, writing nothing", "[cli][errors]") {
  require_device();
  Sandbox box;
  // A copy of the kernels with a syntax error, read through ALGRAY_KERNEL_DIR instead of the embedded ones.
  const fs::path kernels = box.in / "kernels";
  fs::copy(fs::path(ALGRAY_SOURCE_DIR) / "kernels", kernels, fs::copy_options::recursive);  // methods/ too
  write_text(kernels / "primary.cl", read_text(kernels / "primary.cl") + "\nthis is not OpenCL C;\n");
  const std::string cmd = "ALGRAY_KERNEL_DIR=" + quoted(kernels.string()) + " ";
  const fs::path err = box.in / "build_err.txt";
  const int status = std::system(("cd " + quoted(box.work.string()) + " && " + cmd + quoted(ALGRAY_BINARY) +
                                  " render --no-cache --width 8 --height 6 -o out.png 2>" + quoted(err.string()) +
                                  " >/dev/null </dev/null")
                                     .c_str());
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 1);
  const std::string message = read_text(err);
  INFO(message);
  CHECK(message.find("OpenCL build failed") != std::string::npos);
  CHECK(message.find("options: -cl-std=CL1.2 -D DEGREE=6") != std::string::npos);
  CHECK(message.find("build log:") != std::string::npos);
  // The log names the file and line of the error, on every device (locate_in_kernel_files).
  CHECK(message.find("primary.cl:") != std::string::npos);
  CHECK_FALSE(fs::exists(box.work / "out.png"));
}

TEST_CASE("--version prints the version and git revision; stats, logs and images carry it", "[cli][conventions]") {
  Sandbox box;
  const Result v = box.run("--version");
  INFO(v.err);
  REQUIRE(v.exit_code == 0);
  CHECK_THAT(v.out, Catch::StartsWith(std::string("algray ") + algray::version()));
  const std::string version = v.out.substr(0, v.out.find('\n'));
  CHECK(version == algray::version_string());

  require_device();
  REQUIRE(box.run("render -o out.exr -o out.png --preview " + kTiny + " --stats s.json").exit_code == 0);
  CHECK(box.stats()["version"] == version);
  const algray::FrameImage exr = algray::read_exr(box.work / "out.exr");
  CHECK(exr.software == version);
  CHECK_THAT(exr.comments, Catch::Contains("Barth sextic") && Catch::Contains("= 0"));
  REQUIRE(exr.chromaticities);
  CHECK((*exr.chromaticities)[0] == Approx(0.64));    // Rec.709 red x
  CHECK((*exr.chromaticities)[6] == Approx(0.3127));  // D65 white x
  std::map<std::string, std::string> png;
  for (const auto& [key, text] : algray::read_png_text(box.work / "out.png")) png[key] = text;
  CHECK(png["Software"] == version);
  CHECK_THAT(png[algray::kPngSceneKey], Catch::Contains("[surface]") && Catch::Contains("[camera]"));

  REQUIRE(box.run("probe --pixel 3,3 " + kTiny + " --stats p.json").exit_code == 0);
  CHECK(box.stats("p.json")["version"] == version);
  REQUIRE(box.run("devices --stats d.json").exit_code == 0);
  CHECK(box.stats("d.json")["version"] == version);
}

TEST_CASE("a PNG that algray wrote renders again from the scene it carries", "[cli][conventions]") {
  require_device();
  Sandbox box;
  // An orbit-like change and a --set the scene file does not have: the PNG must carry the scene as rendered.
  const std::string first = "render " + scene_file("torus.toml") + " -o a.png -o a.exr " + kTiny +
                            " --preview --set camera.eye=[1.5,4,3] --set camera.fov_y=35";
  REQUIRE(box.run(first).exit_code == 0);
  const Result again = box.run("render a.png -o b.exr");
  INFO(again.err);
  REQUIRE(again.exit_code == 0);
  const algray::FrameImage a = algray::read_exr(box.work / "a.exr"), b = algray::read_exr(box.work / "b.exr");
  REQUIRE(a.width == b.width);
  CHECK(a.rgba == b.rgba);
  CHECK(a.depth == b.depth);
  // Overrides still apply on top of the embedded scene.
  REQUIRE(box.run("render a.png -o c.exr --width 8 --height 6").exit_code == 0);
  CHECK(algray::read_exr(box.work / "c.exr").width == 8);
  // The image may not overwrite itself, and a PNG from elsewhere is refused with a reason.
  const Result self = box.run("render a.png -o a.png");
  CHECK(self.exit_code == 2);
  CHECK_THAT(self.err, Catch::Contains("is the scene file"));
  algray::FrameImage plain;
  plain.width = plain.height = 2;
  plain.rgba.assign(16, 0.5f);
  algray::write_png(box.work / "plain.png", plain);
  const Result foreign = box.run("render plain.png -o d.exr");
  CHECK(foreign.exit_code == 2);
  CHECK_THAT(foreign.err, Catch::Contains("carries no algray scene"));
  CHECK_FALSE(fs::exists(box.work / "d.exr"));
}

TEST_CASE("the expansion budget is the whole equation's, not each power's", "[cli][errors]") {
  // 40 admissible degree-32 powers in one sum took 18 s; the budget admits about 20 (half a second each in
  // Release). Here, not in test_reliability: reaching the budget takes its time, 30x that under the sanitizers.
  Sandbox box;
  std::string many = "(x+y+z+1)^32";
  for (int i = 0; i < 39; ++i) many += "+(x+y+z+1)^32";
  const fs::path scene = box.scene("many.toml", sphere_with(3, "equation = \"" + many + "\""));
  const auto start = std::chrono::steady_clock::now();
  const Result r = box.run("render " + quoted(scene.string()) + " -o out.png");
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("would take too long") && Catch::Contains("for the equation so far"));
  CHECK(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < 15);
  CHECK(box.work_files().empty());
}

TEST_CASE("algray links neither Open MPI nor the web server, and hands `view` to algray-full", "[cli]") {
  Sandbox box;
  // Their libraries would load at every start (apps/algray/hand_off.cpp); readelf lists what the binary needs.
  const fs::path needed = box.in / "needed.txt";
  REQUIRE(std::system(("readelf -d " + quoted(ALGRAY_BINARY) + " > " + quoted(needed.string())).c_str()) == 0);
  const std::string libraries = read_text(needed);
  INFO(libraries);
  CHECK(libraries.find("libOpenCL") != std::string::npos);  // the listing is the one we think it is
  CHECK(libraries.find("libmpi") == std::string::npos);
  CHECK(libraries.find("httplib") == std::string::npos);
  CHECK(libraries.find("libssl") == std::string::npos);

  SECTION("beside algray-full, `view` reaches it: the error about the address is algray-full's") {
    const Result r = box.run("view --host 256.0.0.1");
    INFO(r.err);
    CHECK(r.exit_code != 0);
    CHECK(r.err.find("cannot listen on 256.0.0.1") != std::string::npos);
  }
  SECTION("alone, `view` says what it needs and where it looked, and exits 1") {
    const fs::path alone = box.in / "alone";
    fs::create_directories(alone);
    fs::copy_file(ALGRAY_BINARY, alone / "algray");
    const fs::path err = box.in / "err.txt";
    const int status = std::system((quoted((alone / "algray").string()) + " view --host 256.0.0.1 2> " +
                                    quoted(err.string()) + " < /dev/null")
                                       .c_str());
    REQUIRE(WIFEXITED(status));
    const std::string text = read_text(err);
    INFO(text);
    CHECK(WEXITSTATUS(status) == 1);
    CHECK(text.find("needs algray-full") != std::string::npos);
    CHECK(text.find((alone / "algray-full").string()) != std::string::npos);
  }
  SECTION("bad arguments are refused before the hand-off, with exit 2") {
    const Result r = box.run("view --port 70000");
    CHECK(r.exit_code == 2);
  }
}

TEST_CASE("an equation alone renders to algray.png with the defaults, which the PNG and --stats record",
          "[cli][equation]") {
  require_device();
  Sandbox box;
  const Result r = box.run("render -e 'x^4+y^4+z^4-1' --preview --radius 1.5 --stats s.json " + kTiny);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());
  CHECK_THAT(r.out, Catch::StartsWith("wrote algray.png and s.json (32x24) in "));
  REQUIRE(fs::exists(box.work / "algray.png"));
  // The stats hold the scene as rendered, defaults included; the PNG carries it and renders the same pixels.
  const std::string stats = read_text(box.work / "s.json");
  CHECK_THAT(stats, Catch::Contains("radius = 1.5") && Catch::Contains("azimuth = 30") &&
                        Catch::Contains("frame = \\\"camera\\\""));
  const Result again = box.run("render algray.png -o again.exr --quiet");
  INFO(again.err);
  REQUIRE(again.exit_code == 0);
  CHECK(again.out.empty());
  const Result first = box.run("render -e 'x^4+y^4+z^4-1' --preview --radius 1.5 -o first.exr -q " + kTiny);
  REQUIRE(first.exit_code == 0);
  const std::vector<float> pixels = algray::read_exr(box.work / "first.exr").rgba;
  CHECK(algray::read_exr(box.work / "again.exr").rgba == pixels);
  // A TOML file holding only the equation is the same scene.
  write_text(box.in / "eq.toml", "[surface]\nequation = \"x^4+y^4+z^4-1\"\n");
  const Result file = box.run("render " + (box.in / "eq.toml").string() +
                              " --preview --radius 1.5 -o file.exr --quiet " + kTiny);
  REQUIRE(file.exit_code == 0);
  CHECK(algray::read_exr(box.work / "file.exr").rgba == pixels);
}

TEST_CASE("-e's errors name the equation's column; --set of a missing parameter exits 2, writing nothing",
          "[cli][equation][errors]") {
  Sandbox box;
  const Result bad = box.run("render -e 'x^2+*y' -o out.png " + kTiny);
  CHECK(bad.exit_code == 2);
  CHECK_THAT(bad.err, Catch::StartsWith("--equation:1:5: error: ") && Catch::Contains("  x^2+*y\n      ^"));
  const Result both = box.run("render " + (box.in / "x.toml").string() + " -e 'x-1' -o out.png");
  CHECK(both.exit_code == 2);
  const std::string torus = (fs::path(ALGRAY_SOURCE_DIR) / "scenes" / "torus.toml").string();
  const Result missing = box.run("render " + torus + " --set b=2 -o out.png " + kTiny);
  CHECK(missing.exit_code == 2);
  CHECK_THAT(missing.err, Catch::StartsWith("--set b=2: error: the scene has no parameter 'b'; its parameters: a, r"));
  const Result typo = box.run("render " + torus + " --set camera.fovy=30 -o out.png " + kTiny);
  CHECK(typo.exit_code == 2);
  CHECK_THAT(typo.err, Catch::Contains("did you mean 'fov_y'"));
  CHECK_FALSE(fs::exists(box.work / "out.png"));
}

TEST_CASE("--section draws a plane's curve, --radius comes before --set, and bad planes exit 2 writing nothing",
          "[cli][section]") {
  require_device();
  Sandbox box;
  const std::string torus = (fs::path(ALGRAY_SOURCE_DIR) / "scenes" / "torus.toml").string();
  REQUIRE(box.run("render " + torus + " --preview -o plain.exr -q " + kTiny).exit_code == 0);
  const Result cut = box.run("render " + torus + " --preview --section z=0.5 --set section.0.colour=[1,0,0] "
                             "--stats s.json -o cut.exr " + kTiny);
  INFO(cut.err);
  REQUIRE(cut.exit_code == 0);
  CHECK_THAT(read_text(box.work / "s.json"), Catch::Contains("plane = [0.0, 0.0, 1.0, -0.5]"));
  CHECK(algray::read_exr(box.work / "cut.exr").rgba != algray::read_exr(box.work / "plain.exr").rgba);
  // --radius makes the sphere that --set extent.type then turns into a cylinder.
  const Result cylinder = box.run("render -e 'x^2+y^2+z^2-1' --radius 1.5 --set extent.type=cylinder --preview "
                                  "--stats c.json -o c.exr " + kTiny);
  INFO(cylinder.err);
  REQUIRE(cylinder.exit_code == 0);
  CHECK_THAT(cylinder.err, Catch::Contains("half_height = 1.5"));
  CHECK_THAT(read_text(box.work / "c.json"), Catch::Contains("type = \\\"cylinder\\\""));
  const Result bad = box.run("render " + torus + " --section 'x+*y=1' -o bad.png " + kTiny);
  CHECK(bad.exit_code == 2);
  CHECK_THAT(bad.err, Catch::StartsWith("--section x+*y=1: error: ") && Catch::Contains("  x+*y=1\n    ^"));
  const Result missing = box.run("render " + torus + " --set section.1.plane=[0,0,1,0] -o bad.png " + kTiny);
  CHECK(missing.exit_code == 2);
  CHECK_THAT(missing.err, Catch::Contains("no [[section]] tables"));
  CHECK_FALSE(fs::exists(box.work / "bad.png"));
}

TEST_CASE("--clip cuts the surface open, --stats lists its planes and a gate, and bad ones exit 2 writing nothing",
          "[cli][clip][gate]") {
  require_device();
  Sandbox box;
  const std::string torus = (fs::path(ALGRAY_SOURCE_DIR) / "scenes" / "torus.toml").string();
  REQUIRE(box.run("render " + torus + " --preview -o plain.exr -q " + kTiny).exit_code == 0);
  const Result cut = box.run("render " + torus + " --preview --clip 'z<0.3' --clip 'x>=-1' --stats s.json -o cut.exr " +
                             kTiny);
  INFO(cut.err);
  REQUIRE(cut.exit_code == 0);
  const nlohmann::json s = box.stats("s.json");
  CHECK(s["plan"]["clip_planes"] == nlohmann::json::parse("[[0, 0, 1, -0.3], [-1, 0, 0, -1]]"));
  CHECK_THAT(read_text(box.work / "s.json"), Catch::Contains("[[clip]]"));
  const algray::FrameImage plain = algray::read_exr(box.work / "plain.exr"), clipped = algray::read_exr(box.work / "cut.exr");
  // The cut takes surface away and adds none: pixels that hit only where the uncut torus does, fewer of them.
  long plain_hits = 0, cut_hits = 0, new_hits = 0;
  for (std::size_t i = 0; i < plain.depth.size(); ++i) {
    plain_hits += std::isfinite(plain.depth[i]);
    cut_hits += std::isfinite(clipped.depth[i]);
    new_hits += std::isfinite(clipped.depth[i]) && !std::isfinite(plain.depth[i]);
  }
  CHECK(cut_hits > 0);
  CHECK(cut_hits < plain_hits);
  CHECK(new_hits == 0);
  // A plane beyond the extent cuts nothing: the same pixels, bit for bit; one before it, everything.
  REQUIRE(box.run("render " + torus + " --preview --clip 'z<100' -o far.exr -q " + kTiny).exit_code == 0);
  CHECK(algray::read_exr(box.work / "far.exr").rgba == plain.rgba);
  REQUIRE(box.run("render " + torus + " --preview --clip 'z>100' -o none.exr -q " + kTiny).exit_code == 0);
  const algray::FrameImage none = algray::read_exr(box.work / "none.exr");
  CHECK(std::none_of(none.depth.begin(), none.depth.end(), [](float d) { return std::isfinite(d); }));
  // Bad planes: located, exit 2, nothing written.
  const Result equal = box.run("render " + torus + " --clip z=0.5 -o bad.png " + kTiny);
  CHECK(equal.exit_code == 2);
  CHECK_THAT(equal.err, Catch::StartsWith("--clip z=0.5: error: ") && Catch::Contains("not an '='") &&
                            Catch::Contains("  z=0.5\n   ^"));
  const Result missing = box.run("render " + torus + " --set clip.0.plane=[0,0,1,0] -o bad.png " + kTiny);
  CHECK(missing.exit_code == 2);
  CHECK_THAT(missing.err, Catch::Contains("no [[clip]] tables"));
  CHECK_FALSE(fs::exists(box.work / "bad.png"));
  // The extent as a gate: --stats shows its far sphere (none above), the header says so, and a reach without a
  // gate is refused.
  CHECK(s["plan"]["extent_gate"].is_null());
  const Result gated = box.run("render " + torus + " --preview --set extent.gate=true --set extent.reach=2 "
                               "--stats g.json -o gate.exr " + kTiny);
  INFO(gated.err);
  REQUIRE(gated.exit_code == 0);
  const nlohmann::json g = box.stats("g.json");
  CHECK(g["plan"]["extent_gate"]["reach"] == 2);
  CHECK(g["plan"]["extent_gate"]["far_sphere"]["radius"] == 7);  // the torus' sphere of radius 3.5, twice
  std::map<std::string, std::string> attrs;
  for (const auto& [k, v] : algray::read_exr(box.work / "gate.exr").string_attributes) attrs[k] = v;
  CHECK_THAT(attrs["algray/extent"], Catch::EndsWith("gate reach 2.000000"));
  const Result reach = box.run("render " + torus + " --set extent.reach=2 -o bad.png " + kTiny);
  CHECK(reach.exit_code == 2);
  CHECK_THAT(reach.err, Catch::Contains("it needs extent.gate = true"));
  CHECK_FALSE(fs::exists(box.work / "bad.png"));
}
