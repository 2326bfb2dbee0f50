// Temporary file names with pid and counter, and the cleanup of those whose writer died.
#include "algray/util/temp_files.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <system_error>

namespace algray {
namespace {

// The pid in "<prefix><pid>-<counter>", or 0 for any other name.
pid_t temp_file_pid(const std::string& name, const std::string& prefix) {
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return 0;
  const std::string rest = name.substr(prefix.size());
  const std::size_t dash = rest.find('-');
  if (dash == 0 || dash == std::string::npos || dash + 1 == rest.size()) return 0;
  auto digits = [](const std::string& t) {
    return std::all_of(t.begin(), t.end(), [](unsigned char c) { return c >= '0' && c <= '9'; });
  };
  const std::string pid_text = rest.substr(0, dash);
  if (!digits(pid_text) || !digits(rest.substr(dash + 1)) || pid_text.size() > 9) return 0;
  return static_cast<pid_t>(std::stol(pid_text));
}

}  // namespace

std::string temp_file_name(const std::string& prefix) {
  static std::atomic<unsigned long> counter{0};
  return prefix + std::to_string(::getpid()) + "-" + std::to_string(++counter);
}

void remove_stale_temps(const std::filesystem::path& dir, const std::string& prefix) {
  namespace fs = std::filesystem;
  const pid_t self = ::getpid();
  std::error_code ec;
  fs::directory_iterator it(dir, ec);
  for (const fs::directory_iterator end; !ec && it != end; it.increment(ec)) {
    const pid_t pid = temp_file_pid(it->path().filename().string(), prefix);
    // Our own pid: another thread of this process is writing it.
    if (pid <= 0 || pid == self) continue;
    if (::kill(pid, 0) == 0 || errno != ESRCH) continue;
    std::error_code file_ec;
    if (!it->is_regular_file(file_ec)) continue;
    const auto modified = it->last_write_time(file_ec);
    if (file_ec || fs::file_time_type::clock::now() - modified < std::chrono::seconds(kStaleTempSeconds)) continue;
    fs::remove(it->path(), file_ec);
  }
}

}  // namespace algray
