// Double precision as a device offers it: hidden by ALGRAY_NO_FP64 or --no-fp64, and its speed against float,
// measured once and kept in the program cache.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "algray/device/cl_runtime.h"
#include "algray/device/fp64_speed.h"
#include "algray/device/program_cache.h"
#include "algray/render/renderer.h"
#include "cli_sandbox.h"
#include "scene_fixtures.h"
#include "temp_dir.h"
#include "test_support.h"

using namespace algray;

using testing::HiddenFp64;

TEST_CASE("ALGRAY_NO_FP64 hides double precision: auto picks float and double is refused", "[fp64]") {
  testing::device_session();  // fails loudly without a device
  ::unsetenv("ALGRAY_NO_FP64");
  const std::vector<DeviceInfo> shown = enumerate_devices();
  REQUIRE(!shown.empty());
  const bool any_fp64 = std::any_of(shown.begin(), shown.end(), [](const DeviceInfo& d) { return d.fp64; });
  INFO("PoCL's CPU devices have cl_khr_fp64, so this test hides something");
  REQUIRE(any_fp64);
  for (const DeviceInfo& d : shown) CHECK_FALSE(d.fp64_hidden);
  CHECK_FALSE(fp64_hidden_by_environment());
  for (const char* off : {"", "0"}) {
    ::setenv("ALGRAY_NO_FP64", off, 1);
    CHECK_FALSE(fp64_hidden_by_environment());
  }
  ::unsetenv("ALGRAY_NO_FP64");

  const HiddenFp64 hidden;
  CHECK(fp64_hidden_by_environment());
  const std::vector<DeviceInfo> devices = enumerate_devices();
  REQUIRE(devices.size() == shown.size());
  for (std::size_t i = 0; i < devices.size(); ++i) {
    CHECK_FALSE(devices[i].fp64);
    CHECK(devices[i].fp64_hidden == shown[i].fp64);
  }
  CHECK_THAT(describe_devices(devices), Catch::Contains("fp64 hidden (ALGRAY_NO_FP64)"));
  Scene scene = load_scene_text(testing::sphere_with({}), "sphere.toml");
  const DeviceInfo& device = devices.front();
  ProgramCache cache(false);
  CHECK(resolve_precision(scene, device, cache) == Precision::Adaptive);
  scene.render.precision = Precision::Double;
  CHECK_THROWS_WITH(resolve_precision(scene, device, cache), Catch::Contains("hidden by --no-fp64 or ALGRAY_NO_FP64"));
  scene.render.precision = Precision::Mixed;  // compensated float: no fp64 needed
  CHECK(resolve_precision(scene, device, cache) == Precision::Mixed);
}

TEST_CASE("double's speed against float is measured once a device and then read from the cache", "[fp64]") {
  ::unsetenv("ALGRAY_NO_FP64");
  ClSession& session = testing::device_session();
  REQUIRE(session.info.fp64);
  const testing::TempDir dir("fp64-cache");
  ProgramCache cache(true, dir.path());
  int measured = 0;
  const double first = cache.remembered(session.info, "test-measurement", [&] { return ++measured, 2.5; });
  const double again = cache.remembered(session.info, "test-measurement", [&] { return ++measured, 7.0; });
  CHECK(first == 2.5);
  CHECK(again == 2.5);  // from the file, not measured again
  CHECK(measured == 1);
  // A damaged entry is measured again, never read.
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    if (e.path().extension() == ".measured") testing::write_text(e.path(), "algray-program-binary-v2\ngarbage");
  CHECK(cache.remembered(session.info, "test-measurement", [&] { return ++measured, 3.0; }) == 3.0);
  CHECK(measured == 2);
  ProgramCache off(false, dir.path());
  CHECK(off.remembered(session.info, "test-measurement", [&] { return ++measured, 4.0; }) == 4.0);

  const std::optional<double> slowdown = fp64_slowdown(session.info, cache);
  REQUIRE(slowdown.has_value());
  INFO("double takes " << *slowdown << "x float's time");
  CHECK(std::isfinite(*slowdown));
  CHECK(*slowdown > 0.2);  // a CPU does double at about float's speed per element; anything is within 0.2-100
  CHECK(*slowdown < 100);
  CHECK(fp64_slowdown(session.info, cache) == slowdown);  // the second time from the cache, so the same number

  const HiddenFp64 hidden;
  CHECK_FALSE(fp64_slowdown(enumerate_devices().at(static_cast<std::size_t>(session.info.index)), cache).has_value());
}

TEST_CASE("--no-fp64 on the command line: devices say so, auto renders adaptive float, double is bad input",
          "[fp64][cli]") {
  ::unsetenv("ALGRAY_NO_FP64");
  const testing::Sandbox box;
  const testing::Result listed = box.run("devices --stats d.json");
  REQUIRE(listed.exit_code == 0);
  CHECK_THAT(listed.out, Catch::Contains("double takes"));
  const nlohmann::json devices = box.stats("d.json")["devices"];
  REQUIRE(!devices.empty());
  CHECK(devices[0]["fp64_slowdown"].is_number());
  const testing::Result hidden = box.run("devices --no-fp64");
  REQUIRE(hidden.exit_code == 0);
  CHECK_THAT(hidden.out, Catch::Contains("fp64 hidden"));
  CHECK_THAT(hidden.out, !Catch::Contains("double takes"));

  const std::string scene = box.scene("s.toml", testing::sphere_with({})).string();
  const testing::Result as_float =
      box.run("render " + scene + " --no-fp64 --width 32 --height 24 -o a.png --stats s.json");
  REQUIRE(as_float.exit_code == 0);
  const nlohmann::json stats = box.stats("s.json");
  CHECK(stats["solver"]["precision"] == "adaptive");
  // Without fp64 the doubted rays go to mixed precision; with this CPU's fast fp64, to double.
  const nlohmann::json& primary = stats["plan"]["passes"][0];
  REQUIRE(primary["escalation"].size() == 1);
  CHECK_THAT(primary["escalation"][0].get<std::string>(),
             Catch::Contains("trace") && Catch::Contains("precision=mixed"));
  const testing::Result with_fp64 =
      box.run("render " + scene + " --precision adaptive --width 32 --height 24 -o c.png --stats c.json");
  REQUIRE(with_fp64.exit_code == 0);
  CHECK_THAT(box.stats("c.json")["plan"]["passes"][0]["escalation"][0].get<std::string>(),
             Catch::Contains("precision=double"));
  const testing::Result refused =
      box.run("render " + scene + " --no-fp64 --precision double --width 32 --height 24 -o b.png");
  CHECK(refused.exit_code == 2);
  CHECK_THAT(refused.err, Catch::Contains("--no-fp64"));
  CHECK(!std::filesystem::exists(box.work / "b.png"));
}
