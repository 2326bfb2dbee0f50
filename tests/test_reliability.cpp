// Hostile input, full disks, damaged caches: each a failure once found in algray, now an error or a render.
#include <algray/algray.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "algray/api/batch.h"
#include "algray/io/image_io.h"
#include "algray/scene/expression.h"
#include "algray/util/host_memory.h"
#include "algray/util/json_text.h"
#include "cli_sandbox.h"
#include "scene_fixtures.h"
#include "test_seed.h"

namespace fs = std::filesystem;
using namespace algray::testing;

namespace {

const std::string kTiny = "--width 16 --height 12";

// A dotted key of `parts` parts: a.a.a...
std::string dotted_key(int parts) {
  std::string key = "a";
  for (int i = 1; i < parts; ++i) key += ".a";
  return key;
}

// The cache entries (program binaries) a render left in `dir`.
std::vector<fs::path> cache_entries(const fs::path& dir) {
  std::vector<fs::path> out;
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".bin") out.push_back(e.path());
  return out;
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

const std::string kBall =
    "[surface]\nequation = \"x^2+y^2+z^2-r^2\"\n[parameters]\nr = 1\n[extent]\nradius = 2\n"
    "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nfov_y = 45\n";

// ball.toml and jobs.toml in the sandbox: a 3-frame sweep of the ball's radius over `range` ("from = a, to = b").
void write_ball_sweep(const Sandbox& box, const std::string& range) {
  write_text(box.work / "ball.toml", kBall);
  write_text(box.work / "jobs.toml",
             "[[job]]\nscene = \"ball.toml\"\noutput = \"b{frame}.png\"\n"
             "set = { image = { width = 8, height = 8 } }\nsweep.r = { " +
                 range + ", steps = 3 }\n");
}

// The bytes that hex_bytes wrote: two hex digits each.
std::string from_hex(const std::string& hex) {
  std::string out;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2)
    out += static_cast<char>(std::stoi(hex.substr(i, 2), nullptr, 16));
  return out;
}

bool ends_with(const std::string& text, const std::string& tail) {
  return text.size() >= tail.size() && text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
}

std::size_t occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Bytes Linux allows in a file name and UTF-8 does not: a Latin-1 "café", a lone continuation byte, 0xff.
const std::string kNotUtf8 = "caf\xe9_\x80\xff";

}  // namespace

TEST_CASE("a damaged program-cache entry is rebuilt, never handed to OpenCL", "[reliability][cache]") {
  require_device();
  Sandbox box;
  box.cache = box.root / "cache";  // this test's own cache, so its entry is the only one
  // In double, so that the render builds one camera-ray kernel (a preview left open is adaptive, which builds its
  // second pass's kernel too), and the shading kernel.
  const std::string render = "render --preview --precision double -o out.png " + kTiny + " --stats s.json";
  REQUIRE(box.run(render).exit_code == 0);
  const std::vector<fs::path> entries = cache_entries(box.cache);
  // Two entries, the camera rays' kernel and the shading kernel: each is damaged alike.
  REQUIRE(entries.size() == 2);
  std::vector<std::string> good;
  for (const fs::path& entry : entries) {
    good.push_back(read_text(entry));
    REQUIRE(good.back().size() > 100);
  }
  const std::string reference = read_text(box.work / "out.png");

  struct Damage {
    const char* what;
    std::function<void(const fs::path& entry, const std::string& good)> apply;
  };
  const std::vector<Damage> damages = {
      {"cut to half its size", [](const fs::path& entry, const std::string& g) { fs::resize_file(entry, g.size() / 2); }},
      {"cut to its header",
       [](const fs::path& entry, const std::string& g) { fs::resize_file(entry, g.find("\n--\n") + 4); }},
      {"one payload byte flipped",
       [](const fs::path& entry, const std::string& g) {
         std::string bad = g;
         bad[bad.size() - bad.size() / 3] ^= 0x5a;
         write_text(entry, bad);
       }},
      {"empty", [](const fs::path& entry, const std::string&) { write_text(entry, ""); }},
      {"a directory", [](const fs::path& entry, const std::string&) {
         fs::remove(entry);
         fs::create_directory(entry);
       }}};
  // A temporary entry that a writer killed by SIGKILL left (a reaped child's pid is dead), old enough to be stale.
  const pid_t dead = fork();
  if (dead == 0) _exit(0);
  REQUIRE(dead > 0);
  REQUIRE(waitpid(dead, nullptr, 0) == dead);
  const fs::path leftover = entries[0].string() + ".tmp-" + std::to_string(dead) + "-1";
  for (const Damage& d : damages) {
    SECTION(d.what) {
      write_text(leftover, "half an entry");
      fs::last_write_time(leftover, fs::file_time_type::clock::now() - std::chrono::minutes(5));
      for (std::size_t e = 0; e < entries.size(); ++e) d.apply(entries[e], good[e]);
      const Result r = box.run(render);
      INFO(r.err);
      REQUIRE(r.exit_code == 0);
      CHECK(box.stats()["programs"][0]["origin"] == "built");
      CHECK(read_text(box.work / "out.png") == reference);
      // Rebuilt and stored again: the next run loads it from disk.
      const Result again = box.run(render);
      REQUIRE(again.exit_code == 0);
      CHECK(box.stats()["programs"][0]["origin"] == "disk");
      CHECK(read_text(box.work / "out.png") == reference);
      // Loaded from disk, the entry passed the cache's own check of its length and checksum. It names the same
      // program as before; its payload need not be the same bytes, since PoCL's binary of a fresh compile differs
      // from one its own kernel cache serves (with an empty POCL_CACHE_DIR the first build here is the former).
      const auto identity = [](const std::string& e) { return e.substr(0, e.find("payload-bytes=")); };
      for (std::size_t e = 0; e < entries.size(); ++e) CHECK(identity(read_text(entries[e])) == identity(good[e]));
      CHECK_FALSE(fs::exists(leftover));  // the rebuild's write removed it
    }
  }
}

TEST_CASE("keys nested 50,000 deep get a located error, not a stack overflow", "[reliability][errors]") {
  Sandbox box;
  const std::string deep = dotted_key(50000);
  SECTION("in a scene file") {
    const fs::path scene = box.scene("deep.toml", sphere_with({{1, deep + " = 1"}}));
    const Result r = box.run("render " + quoted(scene.string()) + " -o out.png");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::StartsWith(scene.string() + ":1:1: error: ") && Catch::Contains("more than 32 parts"));
  }
  SECTION("in --set") {
    const Result r = box.run("render -o out.png --set " + deep + "=1");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::StartsWith("--set a.a.a") && Catch::Contains("at most 32"));
    CHECK(r.err.size() < 1000);  // the key is shown shortened, not 100,000 characters of it
  }
  SECTION("in an --set value") {
    const Result r = box.run("render -o out.png --set 'camera.x={" + deep + "=1}'");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("more than 32 parts"));
  }
  SECTION("in arrays nested 50,000 deep") {
    const fs::path scene =
        box.scene("deep.toml", sphere_with({{1, "a = " + std::string(50000, '[') + std::string(50000, ']')}}));
    const Result r = box.run("render " + quoted(scene.string()) + " -o out.png");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::StartsWith(scene.string() + ":1:") && Catch::Contains("nested more than"));
  }
  SECTION("in a jobs file") {
    write_text(box.work / "jobs.toml", "[[job]]\nscene = \"s.toml\"\noutput = \"o.png\"\n" + deep + " = 2\n");
    const Result r = box.run("batch jobs.toml");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::StartsWith("jobs.toml:4:1: error: "));
    CHECK(box.work_files() == std::vector<std::string>{"jobs.toml"});
  }
  CHECK_FALSE(fs::exists(box.work / "out.png"));
}

TEST_CASE("an equation of too high a degree is refused at its exponent before it is expanded",
          "[reliability][errors][expression]") {
  struct Case {
    const char* equation;
    std::size_t position;  // 0-based, where the error points
    const char* phrase;
  };
  const std::vector<Case> cases = {
      {"(x+y+z+1)^1000", 10, "degree 1000"},
      {"(x+y+z+1)^65", 10, "degree 65"},
      {"(x^2+y^2+z^2-1)^10*(x+y)^13", 18, "product would have degree 33"},
      {"((x+y+z+1)^8)^8", 14, "degree 64"},
      {"x*(10^300)^1000", 11, "digits"},
      {"((9^1000)^1000)^1000*x", 10, "digits"},
      // Within the degree, but with coefficients so long that the expansion would take minutes.
      {"(x+y+z+0.123456789012345678901234567890123456789012345678901234567890)^32", 71, "too long"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    INFO("case " << i << ": " << cases[i].equation);
    const auto start = std::chrono::steady_clock::now();
    try {
      algray::parse_equation(cases[i].equation, {}, 32);
      FAIL("accepted");
    } catch (const algray::EquationError& e) {
      CHECK(e.position == cases[i].position);
      CHECK_THAT(e.what(), Catch::Contains(cases[i].phrase));
    }
    CHECK(seconds_since(start) < 2);  // refused before expanding: milliseconds, with room for a loaded sanitizer build
  }
  // The bound is the degree of the result, not of the text: these stay within it and expand.
  CHECK(algray::parse_equation("(x+y+z+1)^32", {}, 32).degree() == 32);
  CHECK(algray::parse_equation("(x^2+y^2+z^2-1)^16*1", {}, 32).degree() == 32);
}

TEST_CASE("an endless scene file or standard input is refused after a few MB", "[reliability][errors]") {
  Sandbox box;
  const auto start = std::chrono::steady_clock::now();
  const Result file = box.run("render /dev/zero -o out.png");
  CHECK(file.exit_code == 2);
  CHECK_THAT(file.err, Catch::StartsWith("/dev/zero: error: the scene file is larger than 4 MiB"));
  const Result piped = box.run("render - -o out.png", "/dev/zero");
  CHECK(piped.exit_code == 2);
  CHECK_THAT(piped.err, Catch::StartsWith("<stdin>: error: the scene file is larger than 4 MiB"));
  const Result jobs = box.run("batch /dev/zero");
  CHECK(jobs.exit_code == 2);
  CHECK_THAT(jobs.err, Catch::Contains("the jobs file is larger than 4 MiB"));
  CHECK(seconds_since(start) < 20);
  CHECK(box.work_files().empty());
}

TEST_CASE("a directory as the scene says so", "[reliability][errors]") {
  Sandbox box;
  const Result r = box.run("render " + quoted(box.in.string()) + " -o out.png");
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::StartsWith(box.in.string() + ": error: is a directory, not a scene file"));
  const Result jobs = box.run("batch " + quoted(box.in.string()));
  CHECK(jobs.exit_code == 2);
  CHECK_THAT(jobs.err, Catch::Contains("is a directory, not a jobs file"));
}

TEST_CASE("no output may be an input or another output of the same run", "[reliability][errors]") {
  Sandbox box;
  const std::string scene_text = sphere_with({});
  const fs::path scene = box.scene("s.toml", scene_text);
  const std::string s = quoted(scene.string());
  struct Case {
    const char* what;
    std::string args;
    const char* phrase;
  };
  const std::vector<Case> cases = {
      {"--stats on the scene", "render " + s + " -o out.png --stats " + s, "is the scene file"},
      {"--stats on the scene, other spelling",
       "render " + s + " -o out.png --stats " + quoted((box.in / "." / "s.toml").string()), "is the scene file"},
      {"--stats on an output", "render " + s + " -o out.png --stats ./out.png", "are the same file"},
      {"one output twice", "render " + s + " -o out.exr -o ../work/out.exr", "are the same file"},
      {"--heatmap on an output", "render " + s + " -o out.png --heatmap out.png", "are the same file"},
      {"probe --stats on the scene", "probe " + s + " --pixel 1,1 --stats " + s, "is the scene file"},
      {"probe --plot on --stats", "probe " + s + " --pixel 1,1 --stats p.png --plot p.png", "are the same file"},
  };
  for (const Case& c : cases) {
    SECTION(c.what) {
      const Result r = box.run(c.args);
      INFO(r.err);
      CHECK(r.exit_code == 2);
      CHECK_THAT(r.err, Catch::Contains(c.phrase));
      CHECK(read_text(scene) == scene_text);
      CHECK(box.work_files().empty());
    }
  }
  SECTION("a hard link to the scene") {
    fs::create_hard_link(scene, box.work / "linked.png");
    const Result r = box.run("render " + s + " -o linked.png");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("is the scene file"));
    CHECK(read_text(scene) == scene_text);
  }
  SECTION("batch: a job's stats on its scene, the log on the jobs file") {
    write_text(box.work / "ball.toml", kBall);
    const std::string jobs = "[[job]]\nscene = \"ball.toml\"\noutput = \"b.png\"\nstats = \"ball.toml\"\n";
    write_text(box.work / "jobs.toml", jobs);
    Result r = box.run("batch jobs.toml");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("is the scene of job"));
    CHECK(read_text(box.work / "ball.toml") == kBall);
    write_text(box.work / "jobs.toml", "[[job]]\nscene = \"ball.toml\"\noutput = \"b.png\"\n");
    r = box.run("batch jobs.toml --log jobs.toml");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--log jobs.toml is the jobs file"));
    CHECK(read_text(box.work / "jobs.toml") == "[[job]]\nscene = \"ball.toml\"\noutput = \"b.png\"\n");
    r = box.run("batch jobs.toml --stats ball.toml");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--stats ball.toml is the scene of job"));
    CHECK_FALSE(fs::exists(box.work / "b.png"));
  }
}

TEST_CASE("a write that fails after rendering exits 1 and names what was and was not written",
          "[reliability][output]") {
  require_device();
  Sandbox box;
  // The EXR with its channels is far larger than the PNG: a file size limit between the two lets the first
  // through and stops the second. With SIGXFSZ ignored the write fails with EFBIG, as on a full disk.
  const std::string args = "render -o small.png -o big.exr --stats s.json --width 64 --height 64";
  REQUIRE(box.run(args).exit_code == 0);  // also puts the kernel into the cache
  const std::uintmax_t limit_kib = fs::file_size(box.work / "small.png") / 1024 + 2;
  REQUIRE(fs::file_size(box.work / "big.exr") > limit_kib * 1024);
  for (const char* f : {"small.png", "big.exr", "s.json"}) fs::remove(box.work / f);
  const std::string limited =
      "bash -c " + quoted("trap '' XFSZ; ulimit -f " + std::to_string(limit_kib) + "; exec \"$0\" \"$@\"") + " ";
  const std::string cmd = "cd " + quoted(box.work.string()) + " && ALGRAY_CACHE_DIR=" + quoted(box.cache.string()) +
                          " " + limited + quoted(ALGRAY_BINARY) + " " + args + " 2>" +
                          quoted((box.in / "err.txt").string());
  const int status = std::system(cmd.c_str());
  REQUIRE(WIFEXITED(status));
  const std::string err = read_text(box.in / "err.txt");
  INFO(err);
  CHECK(WEXITSTATUS(status) == 1);
  CHECK_THAT(err, Catch::Contains("big.exr"));
  CHECK_THAT(err, Catch::Contains("written: small.png"));
  CHECK_THAT(err, Catch::Contains("not written: big.exr, s.json"));
  CHECK(fs::exists(box.work / "small.png"));
  // Nothing half-written is left: no partial EXR, no temporary file.
  CHECK(box.work_files() == std::vector<std::string>{"small.png"});
}

TEST_CASE("batch --log on a full disk stops with exit 1 and a message, not an abort", "[reliability][output]") {
  require_device();
  Sandbox box;
  write_ball_sweep(box, "from = 0.5, to = 1");
  const Result r = box.run("batch jobs.toml --log /dev/full");
  INFO(r.err);
  CHECK(r.exit_code == 1);
  CHECK_THAT(r.err, Catch::Contains("cannot write the batch log /dev/full: No space left on device"));
  CHECK_THAT(r.err, Catch::Contains("stopped after"));
}

TEST_CASE("huge numbers get located errors with exit 2, or render", "[reliability][errors]") {
  Sandbox box;
  SECTION("a box extent of +-1e200") {
    const fs::path scene =
        box.scene("box.toml", sphere_with({{5, "type = \"box\"\nmin = [-1e200, -1, -1]\nmax = [1e200, 1, 1]"}}));
    const Result r = box.run("render " + quoted(scene.string()) + " -o out.png");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::StartsWith(scene.string() + ":6:8: error: extent.min[0] is too large"));
  }
  SECTION("an eye at 1e300") {
    const fs::path scene = box.scene("eye.toml", sphere_with({{7, "eye = [0, 0, 1e300]"}}));
    const Result r = box.run("render " + quoted(scene.string()) + " -o out.png");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::StartsWith(scene.string() + ":7:") && Catch::Contains("camera.eye[2] is too large"));
  }
  SECTION("a sweep from -1.7e308 to 1.7e308 sweeps finite values") {
    require_device();
    write_ball_sweep(box, "from = -1.7e308, to = 1.7e308");
    const Result r = box.run("batch jobs.toml");
    INFO(r.err);
    CHECK((r.exit_code == 0 || r.exit_code == 1));  // frames may fail on such a surface, but the batch runs
    std::istringstream log(read_text(box.work / "jobs.log.jsonl"));
    int lines = 0;
    for (std::string line; std::getline(log, line); ++lines) {
      const nlohmann::json j = nlohmann::json::parse(line);
      const double r_value = std::stod(j["set"]["r"].get<std::string>());
      INFO(line);
      CHECK(std::isfinite(r_value));
    }
    CHECK(lines == 3);
  }
  SECTION("--plot-range -1e308,1e308") {
    const Result r = box.run("probe --pixel 1,1 --plot p.svg --plot-range -1e308,1e308");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("--plot-range -1e308,1e308: expected"));
  }
  SECTION("a 300-character file name") {
    const Result r = box.run("render -o " + std::string(300, 'a') + ".png");
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains("the file name is 304 bytes long"));
    write_ball_sweep(box, "from = 0.5, to = 1");
    write_text(box.work / "jobs.toml",
               read_text(box.work / "jobs.toml") + "stats = \"" + std::string(300, 's') + "{frame}.json\"\n");
    const Result batch = box.run("batch jobs.toml");
    CHECK(batch.exit_code == 2);
    CHECK_THAT(batch.err, Catch::Contains("the file name is 306 bytes long"));
    CHECK_FALSE(fs::exists(box.work / "b0.png"));
  }
}

TEST_CASE("an error in what a .jsurf file translates to points into the .jsurf", "[reliability][errors][jsurf]") {
  Sandbox box;
  const fs::path file = box.scene("big.jsurf",
                                  "surface_equation=x^2+y^2+z^2-1\n"
                                  "scale_factor=308\n"
                                  "light_status_0=ON\n");
  const Result r = box.run("render " + quoted(file.string()) + " -o out.png");
  INFO(r.err);
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::StartsWith(file.string() + ":2:14: error: scale_factor: "));
  CHECK_THAT(r.err, Catch::Contains("scale_factor=308"));  // the excerpt is the .jsurf line
  CHECK_THAT(r.err, !Catch::Contains("translated"));
}

TEST_CASE("a render too large for the memory is refused up front, naming the estimate", "[reliability][errors]") {
  require_device();
  Sandbox box;
  // The film alone takes tens of GB, more than a cap of 4 GB allows on any machine (a machine of 128 GB would
  // otherwise start the render: seen on a lent GPU machine). The cap is ALGRAY_MEMORY_LIMIT rather than ulimit -d,
  // under which AddressSanitizer cannot reserve its shadow memory.
  box.limits = "export ALGRAY_MEMORY_LIMIT=4G";
  const auto start = std::chrono::steady_clock::now();
  const Result r = box.run("render -o out.exr --width 32768 --height 32768 --set antialias.samples=2");
  INFO(r.err);
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("needs about") && Catch::Contains(" GB of memory") &&
                        Catch::Contains("32768x32768 render with 2x2 samples") &&
                        Catch::Contains("available to this process (ALGRAY_MEMORY_LIMIT)"));
  CHECK(seconds_since(start) < 30);
  CHECK(box.work_files().empty());
}

TEST_CASE("an ALGRAY_MEMORY_LIMIT that is not a size exits 2 naming it, writing nothing", "[reliability][errors]") {
  require_device();
  Sandbox box;
  for (const char* bad : {"lots", "4X", "-1G", "0"}) {
    box.limits = std::string("export ALGRAY_MEMORY_LIMIT='") + bad + "'";
    const Result r = box.run("render -o out.exr " + kTiny);
    INFO(bad << ": " << r.err);
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains(std::string("ALGRAY_MEMORY_LIMIT='") + bad + "' is not a size"));
    CHECK(box.work_files().empty());
  }
}

TEST_CASE("the memory a process may take is the least of the machine's, its cgroup's and its limits'",
          "[reliability][memory]") {
  const algray::HostMemory unlimited = algray::available_host_memory();
  REQUIRE(unlimited.bytes > 0);  // every Linux has MemAvailable
  // In a child, so that the limit stays there: a data size limit below what the machine offers becomes the answer.
  int pipe_fds[2];
  REQUIRE(pipe(pipe_fds) == 0);
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    // 256 MB beyond the data it has now (which, under AddressSanitizer, holds terabytes of reserved shadow).
    std::ifstream status("/proc/self/status");
    std::uint64_t data_kb = 0;
    for (std::string line; std::getline(status, line);)
      if (line.rfind("VmData:", 0) == 0) data_kb = std::stoull(line.substr(7));
    const rlim_t cap = static_cast<rlim_t>((data_kb << 10) + (256ull << 20));
    const rlimit data{cap, cap};
    const algray::HostMemory limited =
        setrlimit(RLIMIT_DATA, &data) == 0 ? algray::available_host_memory() : algray::HostMemory{};
    const std::string answer = std::to_string(limited.bytes) + " " + limited.limited_by;
    const ssize_t written = write(pipe_fds[1], answer.data(), answer.size());
    _exit(written == static_cast<ssize_t>(answer.size()) ? 0 : 1);
  }
  close(pipe_fds[1]);
  std::string answer;
  char buf[256];
  for (ssize_t n; (n = read(pipe_fds[0], buf, sizeof buf)) > 0;) answer.append(buf, static_cast<std::size_t>(n));
  close(pipe_fds[0]);
  int status = 0;
  REQUIRE(waitpid(child, &status, 0) == child);
  INFO(answer);
  REQUIRE(answer.find(' ') != std::string::npos);
  const std::uint64_t bytes = std::stoull(answer.substr(0, answer.find(' ')));
  CHECK(bytes > 0);
  CHECK(bytes <= (256ull << 20));
  CHECK_THAT(answer, Catch::Contains("ulimit -d"));
}

TEST_CASE("what the one-hour fuzz runs found is refused with a located error", "[reliability][errors][fuzz]") {
  // fuzz_scene: an --set value that is neither TOML nor valid as a literal string (bytes that are not UTF-8)
  // escaped as toml::parse_error from the second parse and terminated the process.
  // (A bare name must now be one of the scene's parameters, so the new parameter is named in full.)
  const std::string text = sphere_with({});
  try {
    algray::load_scene_text(text, "t.toml", {{"parameters.r", std::string("0],\xff\xff]]")}});
    FAIL("accepted");
  } catch (const algray::SceneError& e) {
    CHECK(e.where == "--set parameters.r=0],\xff\xff]]");
    CHECK_THAT(e.message, Catch::Contains("neither valid TOML nor a plain string"));
  }
  // fuzz_jobs: a stats pattern's unknown placeholder was reported under the job's name, not where it is written.
  try {
    algray::load_jobs("[[job]]\nname = \"one\"\nscene = \"s.toml\"\noutput = \"o.png\"\nstats = \"{$name}.json\"\n",
                      "jobs.toml", "/tmp");
    FAIL("accepted");
  } catch (const algray::SceneError& e) {
    CHECK(e.where == "jobs.toml:5:9");
    CHECK_THAT(e.message, Catch::Contains("unknown placeholder {$name}"));
  }
}

TEST_CASE("file names that are not UTF-8 go into every JSON exactly, and no JSON write fails on them",
          "[reliability][output]") {
  require_device();
  Sandbox box;
  box.cache = box.root / ("cache_" + kNotUtf8);
  SECTION("batch: the log and the stats of every frame") {
    write_ball_sweep(box, "from = 0.5, to = 1");
    const Result r = box.run("batch jobs.toml --stats b.json");
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    std::istringstream log(read_text(box.work / "jobs.log.jsonl"));
    int lines = 0;
    for (std::string line; std::getline(log, line); ++lines) {
      INFO(line);
      const nlohmann::json entry = nlohmann::json::parse(line);
      CHECK(entry["status"] == "ok");
      CHECK(from_hex(entry["stats"]["cache_bytes"].get<std::string>()) == box.cache.string());
      CHECK_THAT(entry["stats"]["cache"].get<std::string>(), Catch::Contains("cache_caf\xEF\xBF\xBD_"));
    }
    CHECK(lines == 3);
    CHECK(box.stats("b.json")["frames"]["ok"] == 3);
  }
  SECTION("render --stats: the scene, the outputs and the cache") {
    const std::string scene = "ball_" + kNotUtf8 + ".toml", image = "out_" + kNotUtf8 + ".png";
    write_text(box.work / scene, kBall);
    const Result r = box.run("render " + quoted(scene) + " " + kTiny + " -o " + quoted(image) + " --stats s.json");
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(fs::exists(box.work / image));
    const nlohmann::json stats = box.stats();
    CHECK(ends_with(from_hex(stats["scene_bytes"].get<std::string>()), scene));
    REQUIRE(stats["outputs_bytes"].size() == 1);
    CHECK(ends_with(from_hex(stats["outputs_bytes"][0].get<std::string>()), image));
    CHECK(from_hex(stats["cache_bytes"].get<std::string>()) == box.cache.string());
  }
  SECTION("the API's stats_json, which `algray view` answers each frame with") {
    const fs::path scene = box.in / ("ball_" + kNotUtf8 + ".toml");
    write_text(scene, kBall);
    // The library reads its cache directory from the environment, as the view server's does.
    const char* given = std::getenv("ALGRAY_CACHE_DIR");
    const std::optional<std::string> before = given ? std::optional<std::string>(given) : std::nullopt;
    ::setenv("ALGRAY_CACHE_DIR", box.cache.c_str(), 1);
    struct Restore {
      const std::optional<std::string>& value;
      ~Restore() { value ? ::setenv("ALGRAY_CACHE_DIR", value->c_str(), 1) : ::unsetenv("ALGRAY_CACHE_DIR"); }
    } restore{before};
    algray::api::RenderSettings settings;
    settings.width = 16;
    settings.height = 12;
    settings.preview = true;
    const algray::api::Image image = algray::api::Renderer().render(algray::api::Scene::load(scene.string()), settings);
    const nlohmann::json stats = nlohmann::json::parse(image.stats_json());
    CHECK(from_hex(stats["scene_bytes"].get<std::string>()) == scene.string());
    CHECK(from_hex(stats["cache_bytes"].get<std::string>()) == box.cache.string());
  }
}

TEST_CASE("a cache directory that cannot be used is named once per process, with the reason", "[reliability][cache]") {
  require_device();
  Sandbox box;
  write_ball_sweep(box, "from = 0.5, to = 1");
  const fs::path file = box.root / "a_file";
  write_text(file, "where the cache directory should be");
  for (const fs::path& cache : {file, file / "below"}) {
    DYNAMIC_SECTION(cache.filename().string()) {
      box.cache = cache;
      const Result r = box.run("batch jobs.toml");  // three frames, each storing its programs
      INFO(r.err);
      REQUIRE(r.exit_code == 0);
      CHECK(occurrences(r.err, "the kernel cache " + cache.string() + " cannot be used (") == 1);
      CHECK(occurrences(r.err, "cannot be used") == 1);
      CHECK(read_text(file) == "where the cache directory should be");  // and it was left alone
    }
  }
}

TEST_CASE("text from outside is UTF-8 exactly when nlohmann would write it, and JSON of any bytes is written",
          "[reliability][output]") {
  const unsigned seed = fresh_test_seed();
  std::mt19937 rng(seed);
  // Bytes weighted towards the ones UTF-8's rules are about: lead bytes, continuations, E0/ED/F0/F4's edges.
  const std::vector<unsigned char> interesting = {0x00, 0x41, 0x7f, 0x80, 0x8f, 0x90, 0x9f, 0xa0, 0xbf, 0xc0,
                                                  0xc1, 0xc2, 0xdf, 0xe0, 0xed, 0xef, 0xf0, 0xf4, 0xf5, 0xff};
  std::uniform_int_distribution<int> length(0, 8), pick(0, 2 * static_cast<int>(interesting.size()) - 1);
  for (int c = 0; c < 20000; ++c) {
    std::string text;
    for (int n = length(rng); n > 0; --n) {
      const int k = pick(rng);
      text += static_cast<char>(k < static_cast<int>(interesting.size()) ? interesting[static_cast<std::size_t>(k)]
                                                                         : rng() & 0xff);
    }
    bool strict_ok = true;
    try {
      (void)nlohmann::json(text).dump();
    } catch (const nlohmann::json::type_error&) {
      strict_ok = false;
    }
    const nlohmann::json object = [&] {
      nlohmann::json o;
      algray::put_path(o, "path", text);
      return o;
    }();
    INFO("seed " << seed << " (ALGRAY_TEST_SEED), case " << c << ": bytes " << algray::hex_bytes(text));
    REQUIRE(algray::is_utf8(text) == strict_ok);
    REQUIRE(algray::is_utf8(algray::utf8_for_json(text)));
    const nlohmann::json back = nlohmann::json::parse(object.dump());  // dump() itself must not throw now
    REQUIRE(back.contains("path_bytes") == !strict_ok);
    if (strict_ok) REQUIRE(back["path"] == text);
    if (!strict_ok) REQUIRE(from_hex(back["path_bytes"].get<std::string>()) == text);
    REQUIRE_NOTHROW(algray::dump_json(nlohmann::json{{"raw", text}}));
  }
}
