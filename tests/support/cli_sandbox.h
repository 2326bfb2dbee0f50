// The algray binary run in a throwaway directory with a test-only program cache, and its stats read back.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "temp_dir.h"

namespace algray::testing {

namespace fs = std::filesystem;

inline std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

inline std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
  REQUIRE(out.good());
}

// Compiled kernels are shared by all tests of this run but never by the user's own cache: under CTest the run's
// kernel cache (ALGRAY_TEST_KERNEL_CACHE, tests/CMakeLists.txt), otherwise one for this test program.
inline const fs::path& shared_cache_dir() {
  struct Owned {
    fs::path dir;
    bool temporary = false;
    Owned() {
      if (const char* run = std::getenv("ALGRAY_TEST_KERNEL_CACHE"); run && *run) {
        dir = fs::path(run) / "algray";
      } else {
        dir = unique_temp_dir("cache");
        temporary = true;
      }
    }
    ~Owned() {
      std::error_code ec;
      if (temporary) fs::remove_all(dir, ec);
    }
  };
  static const Owned owned;
  return owned.dir;
}

struct Result {
  int exit_code;
  std::string out, err;
};

// One test's sandbox: the binary runs in work/ (so anything it leaves behind shows up there), while scenes and
// captured output live in in/.
struct Sandbox {
  fs::path root = unique_temp_dir("cli");
  fs::path work = root / "work";
  fs::path in = root / "in";
  fs::path cache = shared_cache_dir();
  std::string limits;  // shell commands run before the binary, such as "export ALGRAY_MEMORY_LIMIT=4G"

  Sandbox() {
    fs::create_directories(work);
    fs::create_directories(in);
  }
  ~Sandbox() {
    std::error_code ec;
    fs::remove_all(root, ec);
  }

  // Standard input is `stdin_path`, /dev/null unless a test pipes a scene in.
  Result run(const std::string& args, const fs::path& stdin_path = "/dev/null") const {
    const fs::path out = in / "stdout.txt", err = in / "stderr.txt";
    const std::string cmd = "cd " + quoted(work.string()) + " && " + (limits.empty() ? "" : limits + " && ") +
                            "ALGRAY_CACHE_DIR=" + quoted(cache.string()) + " " + quoted(ALGRAY_BINARY) + " " + args +
                            " >" + quoted(out.string()) + " 2>" + quoted(err.string()) + " <" +
                            quoted(stdin_path.string());
    const int status = std::system(cmd.c_str());
    REQUIRE(status != -1);
    REQUIRE(WIFEXITED(status));
    return {WEXITSTATUS(status), read_text(out), read_text(err)};
  }

  fs::path scene(const std::string& name, const std::string& text) const {
    write_text(in / name, text);
    return in / name;
  }

  std::vector<std::string> work_files() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(work)) names.push_back(e.path().filename().string());
    return names;
  }

  nlohmann::json stats(const std::string& name = "s.json") const {
    const std::string text = read_text(work / name);
    REQUIRE_FALSE(text.empty());
    return nlohmann::json::parse(text);
  }
};

// Every device-dependent test goes through this, so a missing OpenCL driver fails loudly instead of skipping.
inline void require_device() {
  static const bool ok = [] {
    Sandbox box;
    return box.run("devices").exit_code == 0;
  }();
  if (!ok) FAIL("`algray devices` failed: no usable OpenCL device; install pocl-opencl-icd to run these tests");
}

}  // namespace algray::testing
