// Fresh directories under the system temp dir for tests, removed with everything in them afterwards.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

namespace algray::testing {

// A new directory, unique across processes and threads.
inline std::filesystem::path unique_temp_dir(const std::string& tag) {
  static std::atomic<int> counter{0};
  const std::string name = "algray-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" +
                           std::to_string(std::random_device{}());
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::create_directories(dir);
  return dir;
}

// unique_temp_dir() for one test, removed with everything in it afterwards.
class TempDir {
 public:
  explicit TempDir(const std::string& tag = "test") : path_(unique_temp_dir(tag)) {}
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
  // File names in the directory, sorted.
  std::vector<std::filesystem::path> entries() const {
    std::vector<std::filesystem::path> out;
    for (const auto& e : std::filesystem::directory_iterator(path_)) out.push_back(e.path().filename());
    std::sort(out.begin(), out.end());
    return out;
  }

 private:
  std::filesystem::path path_;
};

}  // namespace algray::testing
