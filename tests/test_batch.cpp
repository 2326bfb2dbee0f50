// algray batch: sweeps, orbits, the log, failures that do not stop the rest, resume, and jobs-file errors.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <sstream>

#include "cli_sandbox.h"
#include "algray/io/image_io.h"
#include "scene_fixtures.h"

using namespace algray::testing;

namespace {

// A sphere of radius r (a parameter), so a sweep visibly changes the picture.
const std::string kBall =
    "[surface]\nequation = \"x^2+y^2+z^2-r^2\"\n[parameters]\nr = 1\n[extent]\nradius = 2\n"
    "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nfov_y = 45\n"
    "[[light]]\nposition = [3, 4, 5]\n";

std::vector<nlohmann::json> read_log(const fs::path& p) {
  std::vector<nlohmann::json> lines;
  std::istringstream in(read_text(p));
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

const std::string kSmall = "[defaults]\nset = { image = { width = 24, height = 24 } }\n";

}  // namespace

TEST_CASE("a 10-frame sweep writes 10 images and a log line per frame, in one program cache", "[batch][cli]") {
  Sandbox box;
  write_text(box.work / "ball.toml", kBall);
  write_text(box.work / "jobs.toml", kSmall +
                                         "[[job]]\nname = \"grow\"\nscene = \"ball.toml\"\n"
                                         "output = \"grow_{frame:02}.png\"\n"
                                         "sweep.r = { from = 0.5, to = 1.4, steps = 10 }\n");
  const Result r = box.run("batch jobs.toml --stats summary.json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  std::string first, last;
  for (int i = 0; i < 10; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "grow_%02d.png", i);
    INFO(name);
    REQUIRE(fs::exists(box.work / name));
    if (i == 0) first = read_text(box.work / name);
    if (i == 9) last = read_text(box.work / name);
  }
  CHECK(first != last);
  const std::vector<nlohmann::json> log = read_log(box.work / "jobs.log.jsonl");
  REQUIRE(log.size() == 10);
  for (int i = 0; i < 10; ++i) {
    INFO("frame " << i);
    CHECK(log[i]["job"] == "grow");
    CHECK(log[i]["frame"] == i);
    CHECK(log[i]["status"] == "ok");
    CHECK(std::stod(log[i]["set"]["r"].get<std::string>()) == Approx(0.5 + 0.1 * i));
    CHECK(log[i]["stats"]["pixels"]["count"] == 24 * 24);
    // One process, one cache: after the first frame every program comes from memory.
    if (i > 0)
      for (const auto& p : log[i]["stats"]["programs"]) CHECK(p["origin"] == "memory");
  }
  // The ball grows with r.
  CHECK(log[9]["stats"]["pixels"]["hits"].get<int>() > log[0]["stats"]["pixels"]["hits"].get<int>());
  const nlohmann::json summary = nlohmann::json::parse(read_text(box.work / "summary.json"));
  CHECK(summary["frames"]["ok"] == 10);
  CHECK(summary["frames"]["failed"] == 0);
}

TEST_CASE("a job that fails in the middle of a batch does not stop the others", "[batch][cli]") {
  Sandbox box;
  write_text(box.work / "ball.toml", kBall);
  write_text(box.work / "jobs.toml", kSmall +
                                         "[[job]]\nscene = \"ball.toml\"\noutput = \"a.png\"\n"
                                         "[[job]]\nname = \"bad\"\nscene = \"ball.toml\"\nset = { r = \"huge\" }\n"
                                         "output = \"b.png\"\n"
                                         "[[job]]\nname = \"missing\"\nscene = \"nowhere.toml\"\noutput = \"c.png\"\n"
                                         "[[job]]\nname = \"typo\"\nscene = \"ball.toml\"\noutput = \"t_{frame}.png\"\n"
                                         "sweep.\"camera.fov_yy\" = { from = 30, to = 40, steps = 2 }\n"
                                         "[[job]]\nscene = \"ball.toml\"\noutput = \"d_{frame}.png\"\n"
                                         "sweep.r = { from = 0.5, to = 1, steps = 2 }\n");
  const Result r = box.run("batch jobs.toml");
  CHECK(r.exit_code == 1);
  CHECK(fs::exists(box.work / "a.png"));
  CHECK(!fs::exists(box.work / "b.png"));
  CHECK(!fs::exists(box.work / "c.png"));
  CHECK(fs::exists(box.work / "d_0.png"));
  CHECK(fs::exists(box.work / "d_1.png"));
  CHECK_THAT(r.err, Catch::Contains("job bad frame 0 failed"));
  CHECK_THAT(r.err, Catch::Contains("'r' must be a number"));
  CHECK_THAT(r.err, Catch::Contains("nowhere.toml"));
  // A value the jobs file sets is named by its place there, not as a --set argument.
  CHECK_THAT(r.err, Catch::Contains("jobs.toml:9:13: set r=\"huge\""));
  CHECK_THAT(r.err, Catch::Contains("jobs.toml:19:25: set camera.fov_yy=30"));
  CHECK_THAT(r.err, Catch::Contains("4 of 7 frames failed"));
  const std::vector<nlohmann::json> log = read_log(box.work / "jobs.log.jsonl");
  REQUIRE(log.size() == 7);
  CHECK(log[0]["status"] == "ok");
  CHECK(log[1]["status"] == "failed");
  CHECK_THAT(log[1]["error"].get<std::string>(), Catch::Contains("must be a number"));
  CHECK(log[2]["status"] == "failed");
  CHECK(log[3]["status"] == "failed");
  CHECK(log[4]["status"] == "failed");
  CHECK(log[5]["status"] == "ok");
  CHECK(log[6]["status"] == "ok");
}

TEST_CASE("--resume skips frames whose outputs exist and renders the rest", "[batch][cli]") {
  Sandbox box;
  write_text(box.work / "ball.toml", kBall);
  write_text(box.work / "jobs.toml",
             kSmall +
                 "[[job]]\nscene = \"ball.toml\"\noutput = [\"f_{frame}.png\", \"f_{frame}.exr\"]\n"
                 "sweep.r = { from = 0.5, to = 1, steps = 4 }\n");
  REQUIRE(box.run("batch jobs.toml").exit_code == 0);
  // A frame with one of its two outputs missing counts as not done.
  fs::remove(box.work / "f_2.exr");
  const auto before = fs::last_write_time(box.work / "f_0.png");
  const Result again = box.run("batch jobs.toml --resume");
  INFO(again.err);
  REQUIRE(again.exit_code == 0);
  CHECK(fs::exists(box.work / "f_2.exr"));
  CHECK(fs::last_write_time(box.work / "f_0.png") == before);
  const std::vector<nlohmann::json> log = read_log(box.work / "jobs.log.jsonl");
  REQUIRE(log.size() == 8);  // --resume appends to the log
  CHECK(log[4]["status"] == "skipped");
  CHECK(log[5]["status"] == "skipped");
  CHECK(log[6]["status"] == "ok");
  CHECK(log[6]["frame"] == 2);
  CHECK(log[7]["status"] == "skipped");
}

TEST_CASE("an orbit turns the camera, and the lights with it, about the look-at point", "[batch][cli]") {
  Sandbox box;
  write_text(box.work / "ball.toml", kBall);
  write_text(box.work / "jobs.toml",
             kSmall +
                 "[[job]]\nname = \"studio\"\nscene = \"ball.toml\"\noutput = \"o_{angle}.exr\"\n"
                 "orbit = { frames = 4 }\n"
                 "[[job]]\nname = \"fixed\"\nscene = \"ball.toml\"\noutput = \"w_{angle}.exr\"\n"
                 "orbit = { frames = 4, lights = \"world\" }\n");
  const Result r = box.run("batch jobs.toml");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const std::vector<nlohmann::json> log = read_log(box.work / "jobs.log.jsonl");
  REQUIRE(log.size() == 8);
  // About the up axis (y) through the origin: the eye (0, 0, 5) goes to (5, 0, 0), (0, 0, -5), (-5, 0, 0).
  const double expected[4][3] = {{0, 0, 5}, {5, 0, 0}, {0, 0, -5}, {-5, 0, 0}};
  for (int i = 0; i < 4; ++i) {
    INFO("frame " << i);
    for (int k = 0; k < 3; ++k) CHECK(log[i]["camera"]["eye"][k].get<double>() == Approx(expected[i][k]).margin(1e-9));
  }
  const auto mean_red = [&](const char* name) {
    const algray::FrameImage img = algray::read_exr(box.work / name);
    double sum = 0;  // over the sphere's pixels, not the white background
    int count = 0;
    for (std::size_t p = 0; p < img.depth.size(); ++p)
      if (std::isfinite(img.depth[p])) {
        sum += img.rgba[4 * p];
        ++count;
      }
    REQUIRE(count > 50);
    return sum / count;
  };
  // Lights turning with the camera light the sphere the same way from every side; lights fixed in the world
  // leave the far side, seen at 180 degrees, in the dark (the light is at +z, in front of the first view).
  CHECK(mean_red("o_180.exr") == Approx(mean_red("o_0.exr")).epsilon(0.01));
  CHECK(mean_red("w_0.exr") == Approx(mean_red("o_0.exr")).epsilon(0.001));
  CHECK(mean_red("w_180.exr") < 0.8 * mean_red("w_0.exr"));
}

TEST_CASE("jobs files with errors are refused before anything renders, with file, line and column",
          "[batch][cli][errors]") {
  Sandbox box;
  write_text(box.work / "ball.toml", kBall);
  struct Case {
    std::string jobs, message;
  };
  const Case cases[] = {
      {"[[job]]\nscene = \"ball.toml\"\nouput = \"x.png\"\n", "did you mean 'output'"},
      {"[[job]]\nscene = \"ball.toml\"\noutput = \"same.png\"\nsweep.r = { from = 1, to = 2, steps = 3 }\n",
       "no {frame}"},
      {"[[job]]\nscene = \"ball.toml\"\noutput = \"x_{frames}.png\"\n", "unknown placeholder {frames}"},
      {"[[job]]\nscene = \"ball.toml\"\noutput = \"x_{frame}.png\"\nsweep.r = { from = 1, steps = 3 }\n", "needs 'to'"},
      {"[[job]]\nscene = \"ball.toml\"\noutput = \"x_{frame}.png\"\nframes = 2\n"
       "sweep.r = { from = 1, to = 2, steps = 3 }\n",
       "gives 3 frames but the job has 2"},
      {"[[job]]\noutput = \"x.png\"\n", "needs a scene"},
      {"[defaults]\nframes = 3\n[[job]]\nscene = \"ball.toml\"\noutput = \"x.png\"\n", "unknown key 'defaults.frames'"},
      // Three frames of one value, and two jobs with one name: each file written twice.
      {"[[job]]\nscene = \"ball.toml\"\noutput = \"v_{value}.png\"\nsweep.r = { from = 1, to = 1, steps = 3 }\n",
       "writes too"},
      {"[[job]]\nscene = \"ball.toml\"\noutput = \"same.png\"\n[[job]]\nscene = \"ball.toml\"\noutput = \"same.png\"\n",
       "writes too"},
      {"[[job]]\nscene = \"ball.toml\"\noutput = \"g.gif\"\n", "unsupported output extension"},
      {"[[job]]\nscene = \"ball.toml\"\noutput = \"f_{frame:0999}.png\"\nframes = 2\norbit = {}\n",
       "unknown placeholder {frame:0999}"},
  };
  for (const Case& c : cases) {
    INFO(c.jobs);
    write_text(box.work / "jobs.toml", c.jobs);
    const Result r = box.run("batch jobs.toml");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("jobs.toml:"));
    CHECK_THAT(r.err, Catch::Contains(c.message));
    CHECK(!fs::exists(box.work / "jobs.log.jsonl"));
  }
}

TEST_CASE("every command takes its input on standard input, --set for list keys, and --stats", "[batch][cli]") {
  Sandbox box;
  write_text(box.work / "ball.toml", kBall);
  write_text(box.in / "jobs.toml",
             kSmall + "[[job]]\nscene = \"" + (box.work / "ball.toml").string() + "\"\noutput = \"piped.png\"\n");
  const Result batch = box.run("batch - --set light.0.intensity=0.5 --log piped.jsonl", box.in / "jobs.toml");
  INFO(batch.err);
  CHECK(batch.exit_code == 0);
  CHECK(fs::exists(box.work / "piped.png"));
  const std::vector<nlohmann::json> log = read_log(box.work / "piped.jsonl");
  REQUIRE(log.size() == 1);
  CHECK(log[0]["set"]["light.0.intensity"] == "0.5");

  const Result render =
      box.run("render - --width 16 --height 16 -o stdin.png --stats stdin.json", box.work / "ball.toml");
  CHECK(render.exit_code == 0);
  CHECK(nlohmann::json::parse(read_text(box.work / "stdin.json"))["scene"] == "<stdin>");
  const Result probe = box.run("probe - --pixel 8,8 --width 16 --height 16 --stats probe.json", box.work / "ball.toml");
  INFO(probe.err);
  CHECK(probe.exit_code == 0);
  CHECK(nlohmann::json::parse(read_text(box.work / "probe.json"))["surfaces"][0]["solvers"][0]["found"] == true);
  REQUIRE(box.run("devices --stats devices.json").exit_code == 0);
  const nlohmann::json stats = nlohmann::json::parse(read_text(box.work / "devices.json"));
  CHECK_THAT(stats["version"].get<std::string>(), Catch::StartsWith("algray "));
  const nlohmann::json& devices = stats["devices"];
  REQUIRE(!devices.empty());
  CHECK(devices[0]["compute_units"].get<int>() > 0);
}

namespace {

// Seven frames over two jobs, so that shards number frames across jobs: grow 0-4 are 0-4, spin 0-1 are 5-6.
const std::string kTwoJobs = kSmall +
                             "[[job]]\nname = \"grow\"\nscene = \"ball.toml\"\noutput = \"grow_{frame}.png\"\n"
                             "sweep.r = { from = 0.5, to = 1.3, steps = 5 }\n"
                             "[[job]]\nname = \"spin\"\nscene = \"ball.toml\"\noutput = \"spin_{frame}.png\"\n"
                             "frames = 2\norbit = { degrees = 90 }\n";
const std::vector<std::string> kTwoJobsImages = {"grow_0.png", "grow_1.png", "grow_2.png", "grow_3.png",
                                                 "grow_4.png", "spin_0.png", "spin_1.png"};

// Sets environment variables for one scope (the commands a Sandbox runs inherit them).
class ScopedEnvironment {
 public:
  explicit ScopedEnvironment(std::vector<std::pair<std::string, std::string>> vars) : vars_(std::move(vars)) {
    for (const auto& [name, value] : vars_) ::setenv(name.c_str(), value.c_str(), 1);
  }
  ~ScopedEnvironment() {
    for (const auto& [name, value] : vars_) ::unsetenv(name.c_str());
  }

 private:
  std::vector<std::pair<std::string, std::string>> vars_;
};

}  // namespace

TEST_CASE("shards render every frame exactly once, as one process would, and --merge-logs joins their logs",
          "[batch][cli][shard]") {
  Sandbox whole, shards;
  for (const Sandbox* box : {&whole, &shards}) {
    write_text(box->work / "ball.toml", kBall);
    write_text(box->work / "jobs.toml", kTwoJobs);
  }
  REQUIRE(whole.run("batch jobs.toml").exit_code == 0);
  // Two shards by --shard, the third as a Slurm array task would find it.
  for (int k = 0; k < 2; ++k) {
    const Result r = shards.run("batch jobs.toml --shard " + std::to_string(k) + "/3");
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
  }
  {
    ScopedEnvironment slurm({{"SLURM_ARRAY_TASK_ID", "2"}, {"SLURM_ARRAY_TASK_COUNT", "3"}});
    const Result r = shards.run("batch jobs.toml");
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
  }
  std::map<std::string, int> rendered;  // "job/frame" -> times
  for (int k = 0; k < 3; ++k) {
    const fs::path log = shards.work / ("jobs.log.shard-" + std::to_string(k) + "-of-3.jsonl");
    REQUIRE(fs::exists(log));
    for (const nlohmann::json& entry : read_log(log)) {
      const int frame = entry["frame"].get<int>();
      const int number = entry["job"] == "grow" ? frame : 5 + frame;
      INFO("shard " << k << ": " << entry.dump());
      CHECK(number % 3 == k);
      CHECK(entry["shard"] == std::to_string(k) + "/3");
      CHECK(entry["status"] == "ok");
      ++rendered[entry["job"].get<std::string>() + "/" + std::to_string(frame)];
    }
  }
  CHECK(rendered.size() == 7);
  for (const auto& [frame, times] : rendered) {
    INFO(frame);
    CHECK(times == 1);
  }
  for (const std::string& image : kTwoJobsImages) {
    INFO(image);
    REQUIRE(fs::exists(shards.work / image));
    CHECK(read_text(shards.work / image) == read_text(whole.work / image));
  }
  CHECK_FALSE(fs::exists(shards.work / "jobs.log.jsonl"));  // each shard wrote only its own log

  const Result merged = shards.run("batch jobs.toml --merge-logs");
  INFO(merged.err);
  REQUIRE(merged.exit_code == 0);
  const std::vector<nlohmann::json> log = read_log(shards.work / "jobs.log.jsonl");
  REQUIRE(log.size() == 7);
  for (std::size_t i = 0; i < log.size(); ++i) {
    INFO("line " << i);
    CHECK(log[i]["job"] == (i < 5 ? "grow" : "spin"));
    CHECK(log[i]["frame"] == static_cast<int>(i < 5 ? i : i - 5));
  }
  // A shard that never ran leaves its frames in no log: the merge says which, and fails.
  fs::remove(shards.work / "jobs.log.shard-1-of-3.jsonl");
  const Result incomplete = shards.run("batch jobs.toml --merge-logs");
  CHECK(incomplete.exit_code == 1);
  CHECK_THAT(incomplete.err, Catch::Contains("2 in no log (grow/1, grow/4)"));
}

TEST_CASE("a shard comes from --shard or the Slurm array's variables, and a bad one is bad input",
          "[batch][cli][shard]") {
  Sandbox box;
  write_text(box.work / "ball.toml", kBall);
  write_text(box.work / "jobs.toml", kTwoJobs);
  for (const char* bad : {"3/3", "-1/2", "1/0", "a/b", "1", "1/2/3"}) {
    INFO(bad);
    const Result r = box.run(std::string("batch jobs.toml --shard ") + bad);
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("expected K/N"));
  }
  {
    ScopedEnvironment slurm({{"SLURM_ARRAY_TASK_ID", "5"}, {"SLURM_ARRAY_TASK_COUNT", "3"}});
    const Result r = box.run("batch jobs.toml");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("outside its array of 3 tasks"));
  }
  std::vector<std::string> files = box.work_files();
  std::sort(files.begin(), files.end());
  CHECK(files == std::vector<std::string>{"ball.toml", "jobs.toml"});  // nothing written
  // --array=1-3: task ids 1 to 3 are shards 0 to 2; --shard wins over the environment.
  ScopedEnvironment slurm({{"SLURM_ARRAY_TASK_ID", "2"}, {"SLURM_ARRAY_TASK_MIN", "1"}, {"SLURM_ARRAY_TASK_MAX", "3"}});
  REQUIRE(box.run("batch jobs.toml").exit_code == 0);
  std::vector<int> frames;
  for (const nlohmann::json& e : read_log(box.work / "jobs.log.shard-1-of-3.jsonl")) frames.push_back(e["frame"]);
  CHECK(frames == std::vector<int>{1, 4});  // grow 1 and 4: numbers 1 and 4
  REQUIRE(box.run("batch jobs.toml --shard 0/2").exit_code == 0);
  CHECK(fs::exists(box.work / "jobs.log.shard-0-of-2.jsonl"));
}

TEST_CASE("--resume after a torn last log line starts its entries on a line of their own, and says so",
          "[batch][cli]") {
  Sandbox box;
  write_text(box.work / "ball.toml", kBall);
  write_text(box.work / "jobs.toml",
             "[[job]]\nscene = \"ball.toml\"\noutput = \"t_{frame}.png\"\n"
             "set = { image = { width = 8, height = 8 } }\n"
             "sweep.r = { from = 0.5, to = 1, steps = 3 }\n");
  REQUIRE(box.run("batch jobs.toml").exit_code == 0);
  // A kill (or a full disk) in the middle of the last append: half its line, no newline.
  const fs::path log_path = box.work / "jobs.log.jsonl";
  const std::string whole = read_text(log_path);
  const std::size_t last_start = whole.rfind('\n', whole.size() - 2) + 1;
  const std::string torn = whole.substr(0, last_start + (whole.size() - last_start) / 2);
  write_text(log_path, torn);
  fs::remove(box.work / "t_2.png");
  const Result r = box.run("batch jobs.toml --resume");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(r.err, Catch::Contains("jobs.log.jsonl:3: the last entry is torn"));
  const std::string after = read_text(log_path);
  REQUIRE(after.compare(0, torn.size(), torn) == 0);  // the torn line is left as it was
  std::vector<std::string> lines;
  std::istringstream in(after.substr(torn.size()));
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  // A newline that ends the torn line, then one whole entry per frame of this run.
  REQUIRE(lines.size() == 4);
  CHECK(lines[0].empty());
  for (std::size_t i = 1; i < lines.size(); ++i) {
    INFO("new line " << i << ": " << lines[i]);
    const nlohmann::json entry = nlohmann::json::parse(lines[i], nullptr, false);
    REQUIRE(entry.is_object());
    CHECK(entry["frame"] == static_cast<int>(i - 1));
    CHECK(entry["status"] == (i == 3 ? "ok" : "skipped"));
  }
}

TEST_CASE("--merge-logs refuses mixed shard counts, reports conflicts and keeps a log it did not write",
          "[batch][cli][shard]") {
  Sandbox box;
  write_text(box.work / "ball.toml", kBall);
  write_text(box.work / "jobs.toml",
             "[[job]]\nname = \"m\"\nscene = \"ball.toml\"\noutput = \"m_{frame}.png\"\n"
             "set = { image = { width = 8, height = 8 } }\n"
             "sweep.r = { from = 0.5, to = 1, steps = 5 }\n");
  REQUIRE(box.run("batch jobs.toml").exit_code == 0);
  // The shard logs of a 3-way run made from the whole run's entries, and a stale 0-of-2 beside them whose entry
  // for frame 2 says it failed.
  const fs::path whole_log = box.work / "jobs.log.jsonl";
  const std::string history = read_text(whole_log) + read_text(whole_log);  // as after a --resume
  const std::vector<nlohmann::json> entries = read_log(whole_log);
  REQUIRE(entries.size() == 5);
  std::string shard_text[3], stale_text;
  for (int frame = 0; frame < 5; ++frame) {
    shard_text[frame % 3] += entries[static_cast<std::size_t>(frame)].dump() + "\n";
    if (frame % 2 == 0) {
      nlohmann::json e = entries[static_cast<std::size_t>(frame)];
      if (frame == 2) e["status"] = "failed";
      stale_text += e.dump() + "\n";
    }
  }
  for (int k = 0; k < 3; ++k)
    write_text(box.work / ("jobs.log.shard-" + std::to_string(k) + "-of-3.jsonl"), shard_text[k]);
  write_text(box.work / "jobs.log.shard-0-of-2.jsonl", stale_text);
  write_text(whole_log, history);

  const Result refused = box.run("batch jobs.toml --merge-logs");
  INFO(refused.err);
  CHECK(refused.exit_code == 2);
  for (const char* name : {"jobs.log.shard-0-of-2.jsonl", "jobs.log.shard-0-of-3.jsonl", "jobs.log.shard-1-of-3.jsonl",
                           "jobs.log.shard-2-of-3.jsonl"})
    CHECK_THAT(refused.err, Catch::Contains(name));
  CHECK_THAT(refused.err, Catch::Contains("different shard counts"));
  CHECK(read_text(whole_log) == history);  // nothing written

  const Result mixed = box.run("batch jobs.toml --merge-logs --mixed-shard-counts");
  INFO(mixed.err);
  CHECK(mixed.exit_code == 0);
  CHECK_THAT(mixed.err, Catch::Contains("conflicting shard logs: job m frame 2: "));
  CHECK_THAT(mixed.err, Catch::Contains("failed in jobs.log.shard-0-of-2.jsonl:2"));
  CHECK_THAT(mixed.err, Catch::Contains("1 in conflict"));
  const std::vector<nlohmann::json> merged = read_log(whole_log);
  REQUIRE(merged.size() == 5);
  for (int frame = 0; frame < 5; ++frame) {
    INFO("frame " << frame);
    CHECK(merged[static_cast<std::size_t>(frame)]["frame"] == frame);
    CHECK(merged[static_cast<std::size_t>(frame)]["status"] == "ok");
    CHECK(merged[static_cast<std::size_t>(frame)].contains("merged_from"));
  }
  // The run's own log, --resume history and all, is kept beside the merge rather than replaced.
  const fs::path kept = box.work / "jobs.log.before-merge.jsonl";
  REQUIRE(fs::exists(kept));
  CHECK(read_text(kept) == history);
  CHECK_THAT(mixed.err, Catch::Contains("kept as jobs.log.before-merge.jsonl"));
  // A log the merge wrote is its own: merging again replaces it and keeps nothing more.
  REQUIRE(box.run("batch jobs.toml --merge-logs --mixed-shard-counts").exit_code == 0);
  CHECK_FALSE(fs::exists(box.work / "jobs.log.before-merge-1.jsonl"));
  CHECK(read_log(whole_log).size() == 5);
}
