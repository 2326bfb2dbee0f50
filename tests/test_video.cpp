// Videos from batches: --video .mp4/.webm/.gif decoded back (frame count, size, first and last frame against the
// PNG render), jobs given as seconds x fps, jobs without outputs, folders made from output patterns, and the
// writer's refusals.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cli_sandbox.h"
#include "algray/io/video_writer.h"

using namespace algray;
using algray::testing::quoted;
namespace fs = std::filesystem;

namespace {

// Every test here needs the ffmpeg program, to write and to decode: missing, the test fails and says so.
void require_ffmpeg() {
  if (std::system("ffmpeg -version >/dev/null 2>&1") != 0)
    FAIL("the ffmpeg program is missing: videos need it (scripts/install-deps.sh test installs it)");
}

std::string run_output(const std::string& command) {
  std::FILE* p = ::popen(command.c_str(), "r");
  REQUIRE(p != nullptr);
  std::string out;
  char buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  ::pclose(p);
  return out;
}

// Every frame of a video or image as 8-bit RGB, decoded by ffmpeg.
std::string decoded(const fs::path& file) {
  return run_output("ffmpeg -v error -i " + quoted(file.string()) + " -f rawvideo -pix_fmt rgb24 -");
}

// Mean and largest absolute difference of two RGB frames.
std::pair<double, int> difference(const std::string& a, const std::string& b) {
  REQUIRE(a.size() == b.size());
  double sum = 0;
  int worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const int d = std::abs(static_cast<unsigned char>(a[i]) - static_cast<unsigned char>(b[i]));
    sum += d;
    worst = std::max(worst, d);
  }
  return {sum / static_cast<double>(a.size()), worst};
}

constexpr int kWidth = 64, kHeight = 48, kFrames = 5;

std::string jobs(const std::string& output_line) {
  return "[[job]]\nscene = \"" ALGRAY_SOURCE_DIR "/scenes/torus.toml\"\n" + output_line +
         "seconds = 0.5\nfps = 10\nsweep = { r = { from = 0.4, to = 0.9 } }\n" +
         "set = { \"image.width\" = " + std::to_string(kWidth) + ", \"image.height\" = " + std::to_string(kHeight) +
         " }\n";
}

}  // namespace

TEST_CASE("batch --video encodes every frame in order: decoded back, it is the PNG render", "[video][cli]") {
  algray::testing::require_device();
  require_ffmpeg();
  // The tolerances are the codecs': H.264 at crf 18 and VP9 at crf 30 are lossy in 4:2:0, GIF has 256 colours.
  struct Case {
    const char* name;
    double mean;
    int worst;
  };
  for (const Case c : {Case{"out.mp4", 3.0, 80}, Case{"out.webm", 4.0, 90}, Case{"out.gif", 4.0, 90}}) {
    CAPTURE(c.name);
    algray::testing::Sandbox box;
    const fs::path file = box.scene("jobs.toml", jobs("output = \"frames/{name}/f_{frame:02}.png\"\n"));
    const auto r = box.run("batch " + quoted(file.string()) + " --preview --video " + c.name);
    REQUIRE(r.exit_code == 0);
    CHECK_THAT(r.err, Catch::Contains("wrote " + std::string(c.name) + " (5 frames, 64x48)"));
    // The output folder the pattern names was made; no temporary is left beside the video.
    const fs::path frames = box.in / "frames" / "torus_0";
    REQUIRE(fs::is_directory(frames));
    for (const auto& e : fs::directory_iterator(box.work))
      CHECK(e.path().filename().string().find(".tmp-") == std::string::npos);
    const std::string probe = run_output("ffprobe -v error -count_frames -select_streams v:0 -show_entries "
                                         "stream=nb_read_frames,width,height -of csv=p=0 " +
                                         quoted((box.work / c.name).string()));
    CHECK(probe.rfind("64,48,5", 0) == 0);
    const std::string video = decoded(box.work / c.name);
    const std::size_t frame_bytes = 3 * kWidth * kHeight;
    REQUIRE(video.size() == kFrames * frame_bytes);
    for (const int frame : {0, kFrames - 1}) {
      CAPTURE(frame);
      char name[32];
      std::snprintf(name, sizeof name, "f_%02d.png", frame);
      const auto [mean, worst] =
          difference(video.substr(static_cast<std::size_t>(frame) * frame_bytes, frame_bytes), decoded(frames / name));
      CHECK(mean < c.mean);
      CHECK(worst <= c.worst);
    }
    // The sweep moved: the first and last frames differ (the test would pass on a still otherwise).
    CHECK(difference(video.substr(0, frame_bytes), video.substr((kFrames - 1) * frame_bytes)).first > 1.0);
  }
}

TEST_CASE("jobs without outputs render into the video alone; without --video they are bad input", "[video][cli]") {
  algray::testing::require_device();
  require_ffmpeg();
  algray::testing::Sandbox box;
  const fs::path file = box.scene("jobs.toml", jobs(""));
  const auto ok = box.run("batch " + quoted(file.string()) + " --preview --log " +
                          quoted((box.in / "log.jsonl").string()) + " --video v.mp4");
  CHECK(ok.exit_code == 0);
  CHECK(box.work_files() == std::vector<std::string>{"v.mp4"});
  algray::testing::Sandbox bad;
  const fs::path file2 = bad.scene("jobs.toml", jobs(""));
  const auto refused = bad.run("batch " + quoted(file2.string()) + " --preview");
  CHECK(refused.exit_code == 2);
  CHECK_THAT(refused.err, Catch::Contains("jobs.toml:1:1"));
  CHECK_THAT(refused.err, Catch::Contains("--video"));
  for (const char* args : {"--video v.avi", "--video v.mp4 --shard 0/2", "--video v.mp4 --resume"}) {
    CAPTURE(args);
    const auto r = bad.run("batch " + quoted(file2.string()) + " --preview " + args);
    CHECK(r.exit_code == 2);
    CHECK(bad.work_files().empty());
  }
}

TEST_CASE("Slurm-style shards render apart; --merge-logs --video encodes their images in order", "[video][cli]") {
  algray::testing::require_device();
  require_ffmpeg();
  algray::testing::Sandbox box;
  const fs::path file = box.scene("jobs.toml", jobs("output = \"f_{frame:02}.png\"\n"));
  for (const char* shard : {"0/2", "1/2"})
    REQUIRE(box.run("batch " + quoted(file.string()) + " --preview --shard " + shard).exit_code == 0);
  const auto merged = box.run("batch " + quoted(file.string()) + " --merge-logs --video merged.mp4");
  REQUIRE(merged.exit_code == 0);
  CHECK_THAT(merged.err, Catch::Contains("wrote merged.mp4 (5 frames, 64x48) from the shards' images"));
  const std::string video = decoded(box.work / "merged.mp4");
  const std::size_t frame_bytes = 3 * kWidth * kHeight;
  REQUIRE(video.size() == kFrames * frame_bytes);
  // Each frame is its own image, not another's: nearest to the PNG of its own number.
  for (int frame = 0; frame < kFrames; ++frame) {
    CAPTURE(frame);
    int nearest = -1;
    double best = 1e9;
    for (int k = 0; k < kFrames; ++k) {
      char name[32];
      std::snprintf(name, sizeof name, "f_%02d.png", k);
      const double d =
          difference(video.substr(static_cast<std::size_t>(frame) * frame_bytes, frame_bytes), decoded(box.in / name))
              .first;
      if (d < best) best = d, nearest = k;
    }
    CHECK(nearest == frame);
    CHECK(best < 3.0);
  }
}

TEST_CASE("the video writer refuses what it cannot encode and leaves nothing behind", "[video]") {
  require_ffmpeg();
  const fs::path dir = algray::testing::unique_temp_dir("video");
  FrameImage frame;
  frame.width = 8;
  frame.height = 6;
  frame.rgba.assign(4 * 8 * 6, 0.5f);
  CHECK_THROWS_AS(VideoWriter(dir / "v.mov", 8, 6, 30), OutputError);
  CHECK_THROWS_AS(VideoWriter(dir / "v.mp4", 8, 6, 0), OutputError);
  CHECK_THROWS_AS(VideoWriter(dir / "missing" / "v.mp4", 8, 6, 30), OutputError);
  {
    VideoWriter writer(dir / "v.mp4", 8, 6, 30);
    writer.add(frame);
    FrameImage other = frame;
    other.width = 6;
    other.height = 8;
    CHECK_THROWS_AS(writer.add(other), OutputError);
  }  // abandoned: no video, no temporary
  CHECK(fs::is_empty(dir));
  VideoWriter writer(dir / "v.gif", 8, 6, 12.5);
  writer.add(frame);
  writer.add(frame);
  writer.finish();
  CHECK(fs::exists(dir / "v.gif"));
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);
  fs::remove_all(dir);
}
