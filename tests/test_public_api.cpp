// The public C++ API (include/algray/algray.h): scenes, typed errors, renders into memory, callbacks, probe, batch.
#include <algray/algray.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "algray/api/render_job.h"
#include "algray/io/image_io.h"
#include "algray/render/precision_race.h"
#include "algray/render/renderer.h"
#include "temp_dir.h"
#include "test_support.h"

namespace api = algray::api;
namespace fs = std::filesystem;

namespace {

const std::string kTorus = std::string(ALGRAY_SOURCE_DIR) + "/scenes/torus.toml";

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

}  // namespace

TEST_CASE("a scene loads from a file, TOML text or .jsurf text, and set() takes the keys --set takes", "[api]") {
  const api::Scene file = api::Scene::load(kTorus);
  CHECK(file.source() == kTorus);
  REQUIRE(file.equations().size() == 1);
  const api::Scene text = api::Scene::from_toml(read_text(kTorus), "torus text");
  CHECK(text.equations() == file.equations());
  CHECK(text.source() == "torus text");
  // What to_toml writes reads back to the same scene: the same TOML but for its first line, which names the source.
  const auto body = [](const std::string& toml) { return toml.substr(toml.find('\n')); };
  CHECK(body(api::Scene::from_toml(file.to_toml()).to_toml()) == body(file.to_toml()));

  api::Scene copy = file;
  copy.set("image.width", "77").set("camera.fov_y", "30");
  CHECK(copy.width() == 77);
  CHECK(file.width() != 77);  // copies are independent
  CHECK(api::Scene::from_toml(copy.to_toml()).width() == 77);

  const api::Scene jsurf = api::Scene::from_jsurf("surface_equation=x^2+y^2+z^2-1\nscale_factor=0.0\n", "ball.jsurf");
  REQUIRE(jsurf.equations().size() == 1);
  CHECK(jsurf.equations()[0].find("x^2") != std::string::npos);
  CHECK_FALSE(jsurf.warnings().empty());  // no light is on: algray says how it lights the surface instead
  CHECK(api::Scene::default_scene().equations().size() == 1);
}

TEST_CASE("bad scene input raises SceneError with its file, line and column, and changes nothing", "[api]") {
  try {
    api::Scene::from_toml("[surface]\nequation = \"x^2+*y\"\n", "bad.toml");
    FAIL("a malformed equation was accepted");
  } catch (const api::SceneError& e) {
    CHECK(e.file == "bad.toml");
    CHECK(e.line == 2);
    CHECK(e.column > 12);
    CHECK_FALSE(e.message.empty());
    CHECK(e.excerpt.find('^') != std::string::npos);
    CHECK(std::string(e.what()).find("bad.toml:2:") != std::string::npos);
  }
  api::Scene scene = api::Scene::load(kTorus);
  const int width = scene.width();
  CHECK_THROWS_AS(scene.set("image.width", "-3"), api::SceneError);
  CHECK(scene.width() == width);
  CHECK_THROWS_AS(api::Scene::load("/nonexistent/scene.toml"), api::SceneError);
}

TEST_CASE("a render through the API is the renderer's own film, bit for bit, with progress and stats", "[api]") {
  algray::testing::device_session();  // fails loudly without a device
  api::Renderer renderer;
  const api::Scene scene = api::Scene::load(kTorus);
  std::vector<api::Progress> progress;
  api::RenderSettings settings;
  settings.width = 64;
  settings.height = 48;
  settings.preview = true;
  settings.aovs = {"iterations", "classification"};
  settings.on_progress = [&](const api::Progress& p) { progress.push_back(p); };
  const api::Image image = renderer.render(scene, settings);

  algray::RenderContext context("", true);
  algray::Renderer internal(context.session(), context.cache());
  const algray::RenderResult direct = internal.render(
      algray::load_scene_file(kTorus, {{"image.width", "64"}, {"image.height", "48"}, {"render.preview", "true"}}),
      algray::RenderOptions{});
  REQUIRE(image.width() == 64);
  REQUIRE(image.height() == 48);
  CHECK(image.rgba() == direct.image.rgba);
  CHECK(image.depth() == direct.image.depth);
  CHECK(image.normal() == direct.image.normal);
  REQUIRE(image.uint_channel("solver.refineIterations"));
  CHECK(image.uint_channel("solver.refineIterations")->size() == 64u * 48u);
  CHECK_FALSE(image.uint_channel("no such channel"));

  REQUIRE_FALSE(progress.empty());
  for (std::size_t i = 0; i < progress.size(); ++i) CHECK(progress[i].tiles_done == static_cast<int>(i) + 1);
  CHECK(progress.back().tiles_done == progress.back().tiles_total);
  const nlohmann::json stats = nlohmann::json::parse(image.stats_json());
  CHECK(stats["image"]["width"] == 64);
  CHECK(stats["primary_rays"]["count"] == 64 * 48);

  algray::testing::TempDir dir("api");
  image.save((dir / "t.exr").string());
  image.save((dir / "t.png").string());
  CHECK(algray::read_exr(dir / "t.exr").width == 64);
  CHECK(fs::file_size(dir / "t.png") > 0);
  // In memory, the same bytes as the file: the scene included, so `algray render` can redo it from either.
  std::ifstream saved(dir / "t.png", std::ios::binary);
  const std::string file_bytes((std::istreambuf_iterator<char>(saved)), std::istreambuf_iterator<char>());
  CHECK(image.png() == file_bytes);
  CHECK_THROWS_AS(image.save((dir / "t.bmp").string()), api::OutputError);
  CHECK_FALSE(fs::exists(dir / "t.bmp"));
}

// A renderer keeps each device's tile buffers from one render to the next (Renderer::kept_work_): frames of other
// sizes, a larger tile (the buffers are made again), two surfaces (a second buffer) and a full-mode frame with
// shadows between them must each come out as a fresh renderer's, bit for bit.
TEST_CASE("one renderer's frames of other sizes and scenes are fresh renderers' bit for bit", "[api]") {
  algray::testing::device_session();
  const std::string ball_and_ring = std::string(ALGRAY_SOURCE_DIR) + "/scenes/examples/ball_and_ring.toml";
  struct Frame {
    std::string scene;
    int width, height;
    bool preview;
  };
  const std::vector<Frame> frames = {{kTorus, 48, 40, true},       {kTorus, 300, 280, true},
                                     {ball_and_ring, 64, 48, true}, {kTorus, 48, 40, true},
                                     {kTorus, 40, 30, false},      {ball_and_ring, 320, 260, false}};
  api::Renderer kept;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const Frame& f = frames[i];
    api::RenderSettings settings;
    settings.precision = "double";  // the kept renderer's previews would race precisions (the next test case)
    settings.width = f.width;
    settings.height = f.height;
    settings.preview = f.preview;
    const api::Image again = kept.render(api::Scene::load(f.scene), settings);
    const api::Image fresh = api::Renderer().render(api::Scene::load(f.scene), settings);
    INFO("frame " << i << ": " << f.scene << " at " << f.width << "x" << f.height << (f.preview ? " preview" : ""));
    REQUIRE(again.width() == f.width);
    CHECK(again.rgba() == fresh.rgba());
    CHECK(again.depth() == fresh.depth());
    CHECK(again.normal() == fresh.normal());
  }
}

// Issue 44, goal 3: an API renderer draws frame after frame, so its previews with the precision left open race
// double against adaptive (render/precision_race.h) and keep the faster; each frame is a fresh render's in its
// precision, bit for bit. Final renders and a precision the scene sets do not race.
TEST_CASE("an API renderer's previews race double against adaptive and keep the faster, and nothing else races",
          "[api]") {
  algray::testing::device_session();
  api::Renderer renderer;
  const api::Scene scene = api::Scene::load(kTorus);
  api::RenderSettings preview;
  preview.width = 64;
  preview.height = 48;
  preview.preview = true;
  const auto solver = [](const api::Image& image) { return nlohmann::json::parse(image.stats_json())["solver"]; };
  std::vector<std::string> precisions;
  const int frames = 2 * algray::PrecisionRace::kRounds + 2;
  for (int i = 0; i < frames; ++i) {
    const api::Image image = renderer.render(scene, preview);
    const nlohmann::json s = solver(image);
    precisions.push_back(s["precision"]);
    INFO("frame " << i << ": " << s.dump());
    if (i == 0) REQUIRE(precisions[0] == "double");  // this device's auto: fast fp64 (test_config's CPUs)
    REQUIRE(s.contains("precision_reason"));
    const std::string reason = s["precision_reason"];
    CHECK_THAT(reason, i < 2 * algray::PrecisionRace::kRounds ? Catch::StartsWith("racing double against adaptive")
                                                              : Catch::StartsWith(precisions.back() + ": "));
    api::RenderSettings same = preview;
    same.precision = precisions.back();
    const api::Image fresh = api::Renderer().render(scene, same);
    CHECK(image.rgba() == fresh.rgba());
    CHECK(image.depth() == fresh.depth());
    CHECK_FALSE(solver(fresh).contains("precision_reason"));  // asked for: no race
  }
  for (int i = 0; i < 2 * algray::PrecisionRace::kRounds; ++i)
    CHECK(precisions[static_cast<std::size_t>(i)] == (i % 2 == 0 ? "double" : "adaptive"));
  for (std::size_t i = 2 * algray::PrecisionRace::kRounds; i < precisions.size(); ++i)
    CHECK(precisions[i] == precisions.back());
  // Another size is another race; a final render keeps auto's double.
  api::RenderSettings bigger = preview;
  bigger.width = 80;
  CHECK(solver(renderer.render(scene, bigger))["precision"] == "double");
  api::RenderSettings final_render = preview;
  final_render.preview = false;
  const nlohmann::json final_solver = solver(renderer.render(scene, final_render));
  CHECK(final_solver["precision"] == "double");
  CHECK_FALSE(final_solver.contains("precision_reason"));
}

TEST_CASE("a cancelled render raises Cancelled and the renderer goes on", "[api]") {
  algray::testing::device_session();
  api::Renderer renderer;
  api::RenderSettings settings;
  settings.width = 32;
  settings.height = 24;
  settings.preview = true;
  settings.cancelled = [] { return true; };
  CHECK_THROWS_AS(renderer.render(api::Scene::load(kTorus), settings), api::Cancelled);
  settings.cancelled = [] { return false; };
  CHECK(renderer.render(api::Scene::load(kTorus), settings).width() == 32);
}

TEST_CASE("devices, probes and their errors through the API", "[api]") {
  algray::testing::device_session();
  REQUIRE_FALSE(api::devices().empty());
  api::Renderer renderer;
  CHECK_FALSE(renderer.device().name.empty());
  const api::Scene scene = api::Scene::load(kTorus);
  const nlohmann::json pixel =
      nlohmann::json::parse(renderer.probe_pixel(scene, scene.width() / 2, scene.height() / 2));
  REQUIRE(pixel["surfaces"].size() == 1);
  CHECK_FALSE(pixel["surfaces"][0]["solvers"].empty());
  const nlohmann::json ray = nlohmann::json::parse(renderer.probe_ray(scene, {-5, 0, 0.85}, {1, 0, 0}, true));
  CHECK(ray["surfaces"][0]["solvers"].size() > 1);
  try {
    renderer.probe_pixel(scene, -1, 0);
    FAIL("a pixel outside the image was probed");
  } catch (const api::SceneError& e) {
    CHECK(e.file == "--pixel");
  }
  CHECK_THROWS_AS(api::Renderer("no such device 12345").device(), api::DeviceError);
}

TEST_CASE("a batch through the API renders every frame once and reports each", "[api]") {
  algray::testing::device_session();
  algray::testing::TempDir dir("api-batch");
  write_text(dir / "ball.toml",
             "[surface]\nequation = \"x^2+y^2+z^2-r^2\"\n[parameters]\nr = 1\n[extent]\nradius = 2\n"
             "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nfov_y = 45\n");
  write_text(dir / "jobs.toml",
             "[defaults]\nset = { image = { width = 16, height = 12 } }\n[[job]]\nname = \"grow\"\n"
             "scene = \"ball.toml\"\noutput = \"grow_{frame}.png\"\nsweep.r = { from = 0.5, to = 1.0, steps = 3 }\n");
  api::Renderer renderer;
  api::BatchSettings settings;
  settings.jobs_path = (dir / "jobs.toml").string();
  std::vector<api::BatchFrame> frames;
  std::string messages;
  settings.on_frame = [&](const api::BatchFrame& f) { frames.push_back(f); };
  settings.on_message = [&](const std::string& m) { messages += m; };
  CHECK(renderer.batch(settings) == api::BatchResult::Done);
  INFO(messages);
  REQUIRE(frames.size() == 3);
  for (int i = 0; i < 3; ++i) {
    CHECK(frames[static_cast<std::size_t>(i)].frame == i);
    CHECK(frames[static_cast<std::size_t>(i)].status == "ok");
    CHECK(fs::exists(dir / ("grow_" + std::to_string(i) + ".png")));
  }
  settings.jobs_path = (dir / "missing.toml").string();
  CHECK(renderer.batch(settings) == api::BatchResult::BadInput);
  CHECK(messages.find("missing.toml") != std::string::npos);
}
