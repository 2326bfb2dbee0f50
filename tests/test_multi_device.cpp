// One image split: several devices from one tile queue (the devices chosen, the image bit for bit against one
// device, each device's share, the callbacks, cancellation), and bands of rows put together. CTest runs it with
// two PoCL "basic" devices.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "algray/api/render_job.h"
#include "algray/device/program_cache.h"
#include "algray/render/renderer.h"
#include "algray/render/shade.h"
#include "algray/render/solver_aov.h"
#include "cli_sandbox.h"
#include "film_compare.h"
#include "scene_fixtures.h"
#include "temp_dir.h"
#include "test_support.h"

using namespace algray;
using testing::same_bits;
using testing::same_film;

namespace {

// Two devices of one kind, as the test's environment makes them (POCL_DEVICES="basic basic"); without them the
// test fails, since it could check nothing.
std::vector<ClSession*> two_devices() {
  static std::vector<std::unique_ptr<ClSession>> owned;
  if (owned.empty()) {
    testing::device_session();  // fails loudly without any device
    const std::vector<DeviceInfo> devices = enumerate_devices();
    if (devices.size() < 2)
      FAIL("test_multi_device needs two OpenCL devices; CTest runs it with POCL_DEVICES=\"basic basic\", found "
           << devices.size() << ":\n"
           << describe_devices(devices));
    owned = open_sessions(select_devices("0,1"));
    REQUIRE(owned[1]->copy == 1);  // the same device kind: its programs are built apart (ClSession::copy)
  }
  return {owned[0].get(), owned[1].get()};
}

// The test's own program cache, removed at exit: every renderer and render context of the test uses it.
const std::filesystem::path& cache_dir() {
  static const testing::TempDir dir("multi-device-cache");
  return dir.path();
}

// A scene the renders are compared on, and what it is for the failure message.
struct Case {
  std::string what;
  Scene scene;
};

std::size_t tile_count(const RenderPlan& plan) {
  const std::size_t side = static_cast<std::size_t>(plan.tile_pixels());
  return ((plan.width + side - 1) / side) * ((plan.height + side - 1) / side);
}

}  // namespace

TEST_CASE("device lists: all, indices, repeated name substrings, and the errors", "[devices]") {
  two_devices();
  const std::vector<DeviceInfo> all = select_devices("all");
  CHECK(all.size() == enumerate_devices().size());
  const std::vector<DeviceInfo> listed = select_devices("1, 0");
  REQUIRE(listed.size() == 2);
  CHECK(listed[0].index == 1);
  CHECK(listed[1].index == 0);
  // The two PoCL devices share a name: the substring, given twice, names both.
  const std::vector<DeviceInfo> by_name = select_devices("basic,basic");
  REQUIRE(by_name.size() == 2);
  CHECK(by_name[0].index == 0);
  CHECK(by_name[1].index == 1);
  CHECK(select_devices("1").front().index == 1);
  CHECK_THROWS_WITH(select_devices("0,0"), Catch::Contains("named twice"));
  CHECK_THROWS_WITH(select_devices("0,,1"), Catch::Contains("empty item"));
  CHECK_THROWS_WITH(select_devices("0,99"), Catch::Contains("there are only"));
  CHECK_THROWS_WITH(select_devices("0,no-such-device"), Catch::Contains("no device or platform name contains it"));
  const std::string three = "basic,basic,basic";
  if (all.size() == 2) CHECK_THROWS_WITH(select_devices(three), Catch::Contains("already named"));
}

TEST_CASE("two devices render the one-device image bit for bit, sharing the tiles", "[devices][tiles]") {
  const std::vector<ClSession*> both = two_devices();
  Renderer one(*both[0], testing::program_cache());
  Renderer two(both, testing::program_cache());
  std::vector<Case> cases;
  // Everything that crosses a tile's border: two surfaces, bounces, an area light's shadows, and adaptive
  // antialiasing, whose choice at a tile's edge needs the neighbouring tiles' first colours from either device.
  cases.push_back({"ball and ring, adaptive 3x3",
                   testing::ball_and_ring({{"antialias.adaptive", "true"}, {"antialias.samples", "3"}})});
  cases.push_back({"ball and ring, 2x2", testing::ball_and_ring({{"antialias.samples", "2"}})});
  for (const char* precision : {"double", "float"})
    cases.push_back(
        {std::string("Barth sextic, full mode, ") + precision,
         load_scene_file(std::string(ALGRAY_SOURCE_DIR) + "/scenes/barth_sextic.toml",
                         {{"image.width", "80"}, {"image.height", "60"}, {"render.precision", precision}})});
  cases.push_back({"Barth decic, preview",
                   load_scene_file(std::string(ALGRAY_SOURCE_DIR) + "/scenes/barth_decic.toml",
                                   {{"image.width", "96"}, {"image.height", "72"}, {"render.preview", "true"}})});
  for (const Case& c : cases) {
    INFO(c.what);
    RenderOptions records;
    records.keep_records = true;
    const RenderResult alone = one.render(c.scene, records);
    const RenderResult shared = two.render(c.scene, records);
    INFO("first difference: " << testing::first_difference(alone.image, shared.image));
    CHECK(same_film(alone.image, shared.image));
    CHECK(same_bits(alone.hits.records, shared.hits.records));
    CHECK(same_bits(alone.hits.surface, shared.hits.surface));
    CHECK(same_bits(alone.refined, shared.refined));
    // The records kept from both devices shade to the film, as one device's do.
    CHECK(same_film(shade_frame(c.scene, shared), shared.image));
    CHECK(alone.config.key() == shared.config.key());

    // Each device took tiles from the queue, together every tile once, and the totals are one device's.
    REQUIRE(shared.devices.size() == 2);
    CHECK(shared.devices[0].index == both[0]->info.index);
    CHECK(shared.devices[1].index == both[1]->info.index);
    CHECK(shared.devices[0].tiles + shared.devices[1].tiles == static_cast<int>(tile_count(shared.plan)));
    CHECK(tile_count(shared.plan) >= 16);  // about 8 a device, so that neither idles at the end
    CHECK(shared.devices[0].tiles > 0);
    CHECK(shared.devices[1].tiles > 0);
    REQUIRE(alone.devices.size() == 1);
    CHECK(alone.devices[0].tiles == static_cast<int>(tile_count(alone.plan)));
    REQUIRE(shared.passes.size() == alone.passes.size());
    std::uint64_t rays = 0;
    for (std::size_t p = 0; p < alone.passes.size(); ++p) {
      INFO("pass " << alone.passes[p].name);
      CHECK(shared.passes[p].name == alone.passes[p].name);
      CHECK(shared.passes[p].rays == alone.passes[p].rays);
      rays += shared.passes[p].rays;
    }
    CHECK(shared.devices[0].rays + shared.devices[1].rays == rays);
    CHECK(shared.devices[0].kernel_ms > 0);
    CHECK(shared.devices[1].kernel_ms > 0);
    CHECK(shared.primary.rays == alone.primary.rays);
    CHECK(shared.primary.hits == alone.primary.hits);
    CHECK(shared.primary.isolation_steps == alone.primary.isolation_steps);
    CHECK(shared.primary.refine_iterations == alone.primary.refine_iterations);
    CHECK(shared.primary.pixels_hit == alone.primary.pixels_hit);
  }
}

TEST_CASE("with two devices the callbacks come one at a time, and cancelling stops both", "[devices][callbacks]") {
  const std::vector<ClSession*> both = two_devices();
  Renderer two(both, testing::program_cache());
  Scene scene = testing::ball_and_ring({{"antialias.samples", "2"}});

  // The solver channels gathered from both devices' tiles are one device's, and every callback was alone.
  RenderOptions options;
  std::vector<int> done;
  int total = 0, inside = 0, overlapped = 0;
  std::set<std::thread::id> threads;
  SolverWork work;
  options.on_progress = [&](const RenderProgress& p) {
    if (++inside > 1) ++overlapped;
    done.push_back(p.tiles_done);
    total = p.tiles_total;
    threads.insert(std::this_thread::get_id());
    --inside;
  };
  options.on_primary_tile = [&](const PrimaryTile& tile) {
    if (++inside > 1) ++overlapped;
    if (work.isolation_steps.empty()) work = empty_solver_work(scene.image.width, scene.image.height, tile.samples);
    add_tile_work(work, tile);
    --inside;
  };
  const RenderResult shared = two.render(scene, options);
  CHECK(overlapped == 0);
  REQUIRE(!done.empty());
  // Adaptive antialiasing (the scene's) sweeps the tiles twice.
  CHECK(total == static_cast<int>(tile_count(shared.plan)) * (shared.plan.refine_samples > 1 ? 2 : 1));
  CHECK(static_cast<int>(done.size()) == total);
  for (std::size_t i = 0; i < done.size(); ++i) CHECK(done[i] == static_cast<int>(i + 1));
  CHECK(threads.size() >= 2);  // each device's own thread reported its tiles (one pair of threads per sweep)
  Renderer one(*both[0], testing::program_cache());
  const SolverWork whole = solver_work(one.render_with_records(scene));
  CHECK(work.isolation_steps == whole.isolation_steps);
  CHECK(work.refine_iterations == whole.refine_iterations);
  CHECK(work.classification == whole.classification);

  // Cancelled after a few tiles: the render throws, and neither device takes many more.
  RenderOptions cancel;
  int tiles_seen = 0;
  cancel.on_progress = [&](const RenderProgress&) { ++tiles_seen; };
  cancel.cancelled = [&] { return tiles_seen >= 3; };
  CHECK_THROWS_AS(two.render(scene, cancel), RenderCancelled);
  CHECK(tiles_seen >= 3);
  CHECK(tiles_seen <= 3 + 2);  // at most the tile each device had in hand
}

TEST_CASE("a render context of several devices renders with all of them and reports each", "[devices][api]") {
  two_devices();
  ::setenv("ALGRAY_CACHE_DIR", cache_dir().c_str(), 1);
  const Scene scene = testing::ball_and_ring({});
  RenderContext all("all", true), first("0", true);
  REQUIRE(all.sessions().size() == enumerate_devices().size());
  CHECK(&all.session() == all.sessions().front());
  FrameRequest request;
  const RenderedFrame together = render_frame(scene, request, all);
  const RenderedFrame alone = render_frame(scene, request, first);
  CHECK(same_bits(together.image.rgba, alone.image.rgba));
  const nlohmann::json stats = frame_stats(scene, together, {}, true);
  REQUIRE(stats["devices"].size() == all.sessions().size());
  int tiles = 0;
  for (const nlohmann::json& d : stats["devices"]) {
    CHECK(d["tiles"].get<int>() > 0);
    CHECK(d["rays"].get<std::uint64_t>() > 0);
    tiles += d["tiles"].get<int>();
  }
  CHECK(tiles == static_cast<int>(tile_count(together.result.plan)));
  CHECK(frame_stats(scene, alone, {}, true)["devices"].size() == 1);
  std::string device_attribute;
  for (const auto& [key, value] : together.image.string_attributes)
    if (key == "algray/device") device_attribute = value;
  CHECK_THAT(device_attribute, Catch::Contains(" + [1] "));
}

TEST_CASE("bands of rows, on one device or two, put together are the whole image bit for bit", "[devices][bands]") {
  const std::vector<ClSession*> both = two_devices();
  Renderer one(*both[0], testing::program_cache());
  Renderer two(both, testing::program_cache());
  // Adaptive antialiasing chooses at a band's edge from the rows beyond it; bounces, shadows and two surfaces
  // cross every edge too.
  const std::vector<Case> cases = {
      {"ball and ring, adaptive 3x3",
       testing::ball_and_ring({{"antialias.adaptive", "true"}, {"antialias.samples", "3"}})},
      {"ball and ring, 2x2", testing::ball_and_ring({{"antialias.samples", "2"}})},
      {"Barth sextic, full mode", load_scene_file(std::string(ALGRAY_SOURCE_DIR) + "/scenes/barth_sextic.toml",
                                                  {{"image.width", "80"}, {"image.height", "60"}})}};
  for (const Case& c : cases) {
    const RenderResult whole = one.render(c.scene, {});
    const int height = c.scene.image.height, width = c.scene.image.width;
    // Bands of 1 row, at both ends, and of sizes that split tiles.
    const std::vector<int> edges = {0, 1, 8, 21, 22, height - 1, height};
    for (Renderer* renderer : {&one, &two}) {
      INFO(c.what << (renderer == &two ? ", two devices" : ", one device"));
      FrameImage stitched = make_film(width, height, true);
      PrimarySummary summed;
      for (std::size_t b = 0; b + 1 < edges.size(); ++b) {
        RenderOptions options;
        options.rows = RenderOptions::RowBand{edges[b], edges[b + 1]};
        const RenderResult band = renderer->render(c.scene, options);
        REQUIRE(band.image.height == edges[b + 1] - edges[b]);
        REQUIRE(band.image.width == width);
        const std::size_t at = static_cast<std::size_t>(edges[b]) * width;
        std::copy(band.image.rgba.begin(), band.image.rgba.end(), stitched.rgba.begin() + 4 * at);
        std::copy(band.image.depth.begin(), band.image.depth.end(), stitched.depth.begin() + at);
        std::copy(band.image.normal.begin(), band.image.normal.end(), stitched.normal.begin() + 3 * at);
        summed += band.primary;
      }
      INFO("first difference: " << testing::first_difference(whole.image, stitched));
      CHECK(same_film(whole.image, stitched));
      // The same bands in another order from one render (next_band), its kernels and buffers set up once.
      FrameImage handed = make_film(width, height, true);
      std::vector<std::size_t> order(edges.size() - 1);
      for (std::size_t b = 0; b < order.size(); ++b) order[b] = order.size() - 1 - b;
      std::size_t next = 0;
      RenderOptions in_turn;
      in_turn.next_band = [&]() -> std::optional<RenderOptions::RowBand> {
        if (next == order.size()) return std::nullopt;
        const std::size_t b = order[next++];
        return RenderOptions::RowBand{edges[b], edges[b + 1]};
      };
      in_turn.on_band = [&](const RenderOptions::RowBand& band, FrameImage& film) {
        REQUIRE(film.height == band.end - band.first);
        const std::size_t at = static_cast<std::size_t>(band.first) * width;
        std::copy(film.rgba.begin(), film.rgba.end(), handed.rgba.begin() + 4 * at);
        std::copy(film.depth.begin(), film.depth.end(), handed.depth.begin() + at);
        std::copy(film.normal.begin(), film.normal.end(), handed.normal.begin() + 3 * at);
      };
      const RenderResult bands = renderer->render(c.scene, in_turn);
      CHECK(next == order.size());
      CHECK(same_film(whole.image, handed));
      CHECK(bands.primary.pixels == whole.primary.pixels);
      CHECK(bands.primary.hits == whole.primary.hits);
      CHECK(bands.image.rgba.empty());
      CHECK(summed.pixels == whole.primary.pixels);
      CHECK(summed.pixels_hit == whole.primary.pixels_hit);
      CHECK(summed.rays == whole.primary.rays);
      CHECK(summed.hits == whole.primary.hits);
      CHECK(summed.isolation_steps == whole.primary.isolation_steps);
    }
  }
  const Scene scene = testing::ball_and_ring({});
  RenderOptions bad;
  for (const RenderOptions::RowBand& rows : {RenderOptions::RowBand{5, 5}, RenderOptions::RowBand{-1, 3},
                                             RenderOptions::RowBand{0, scene.image.height + 1}}) {
    bad.rows = rows;
    CHECK_THROWS_AS(one.render(scene, bad), std::invalid_argument);
  }
  bad.rows = RenderOptions::RowBand{0, 4};
  bad.keep_records = true;
  CHECK_THROWS_AS(one.render(scene, bad), std::invalid_argument);
  RenderOptions no_hand_over;
  no_hand_over.next_band = [] { return std::optional<RenderOptions::RowBand>(); };
  CHECK_THROWS_AS(one.render(scene, no_hand_over), std::invalid_argument);
}

TEST_CASE("algray batch --device all renders every frame on both devices, as one device does", "[devices][batch]") {
  two_devices();
  const testing::Sandbox box;
  const std::string jobs =
      "[defaults]\nset = { image = { width = 64, height = 48 } }\n[[job]]\nname = \"turn\"\nscene = \"" +
      std::string(ALGRAY_SOURCE_DIR) +
      "/scenes/examples/ball_and_ring.toml\"\noutput = \"{dir}/turn_{frame}.png\"\nframes = 3\norbit = { degrees = 90 "
      "}\n";
  for (const char* dir : {"one", "all"}) {
    std::filesystem::create_directories(box.work / dir);
    std::string text = jobs;
    text.replace(text.find("{dir}"), 5, dir);
    testing::write_text(box.work / (std::string(dir) + ".toml"), text);
  }
  const testing::Result one = box.run("batch one.toml --device 0 --log one.jsonl");
  INFO(one.err);
  REQUIRE(one.exit_code == 0);
  const testing::Result all = box.run("batch all.toml --device all --log all.jsonl");
  INFO(all.err);
  REQUIRE(all.exit_code == 0);
  std::istringstream log(testing::read_text(box.work / "all.jsonl"));
  int frames = 0;
  for (std::string line; std::getline(log, line); ++frames) {
    const nlohmann::json entry = nlohmann::json::parse(line);
    INFO("frame " << entry["frame"]);
    REQUIRE(entry["status"] == "ok");
    const nlohmann::json& devices = entry["stats"]["devices"];
    REQUIRE(devices.size() == 2);
    CHECK(devices[0]["tiles"].get<int>() > 0);
    CHECK(devices[1]["tiles"].get<int>() > 0);
  }
  CHECK(frames == 3);
  for (int f = 0; f < 3; ++f) {
    const std::string name = "turn_" + std::to_string(f) + ".png";
    INFO(name);
    CHECK(testing::read_text(box.work / "one" / name) == testing::read_text(box.work / "all" / name));
  }
}
