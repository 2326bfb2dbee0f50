// Reads /proc/meminfo, the cgroup files of /sys/fs/cgroup and getrlimit for available_host_memory.
#include "algray/util/host_memory.h"

#include <sys/resource.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace algray {
namespace {

// The number after `key` on a line of a /proc file in kB ("MemAvailable:", "VmData:"), in bytes; 0 if absent.
std::uint64_t proc_kb(const char* path, const std::string& key) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) {
      std::istringstream rest(line.substr(key.size()));
      std::uint64_t kb = 0;
      rest >> kb;
      return kb * 1024;
    }
  return 0;
}

// A cgroup file's number; 0 when absent or "max" (no limit).
std::uint64_t cgroup_number(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::uint64_t value = 0;
  return in >> value ? value : 0;
}

void take_least(HostMemory& best, std::uint64_t bytes, const char* why) {
  if (bytes && (!best.bytes || bytes < best.bytes)) best = {bytes, why};
}

std::uint64_t left_under(std::uint64_t limit, std::uint64_t used) { return limit > used ? limit - used : 1; }

// Every limit on the way from this process's cgroup up to the root (cgroup v2), or its memory cgroup (v1).
void cgroup_limits(HostMemory& best) {
  std::ifstream self("/proc/self/cgroup");
  std::string line;
  while (std::getline(self, line)) {
    const auto first = line.find(':'), second = line.find(':', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    const std::string controllers = line.substr(first + 1, second - first - 1);
    const std::filesystem::path path = line.substr(second + 1);
    if (controllers.empty()) {  // v2: "0::/path"
      for (std::filesystem::path p = path;; p = p.parent_path()) {
        const auto dir = std::filesystem::path("/sys/fs/cgroup") / p.relative_path();
        if (const std::uint64_t max = cgroup_number(dir / "memory.max"))
          take_least(best, left_under(max, cgroup_number(dir / "memory.current")), "its cgroup's memory limit");
        if (p == p.parent_path()) break;
      }
    } else if (("," + controllers + ",").find(",memory,") != std::string::npos) {  // v1
      const auto dir = std::filesystem::path("/sys/fs/cgroup/memory") / path.relative_path();
      const std::uint64_t limit = cgroup_number(dir / "memory.limit_in_bytes");
      if (limit && limit < (1ull << 62))  // v1 writes "no limit" as a huge number
        take_least(best, left_under(limit, cgroup_number(dir / "memory.usage_in_bytes")), "its cgroup's memory limit");
    }
  }
}

void rlimit_left(HostMemory& best, int resource, const char* status_key, const char* why) {
  rlimit r{};
  if (getrlimit(resource, &r) == 0 && r.rlim_cur != RLIM_INFINITY)
    take_least(best, left_under(r.rlim_cur, proc_kb("/proc/self/status", status_key)), why);
}

// ALGRAY_MEMORY_LIMIT: bytes, or a number with K, M, G or T (powers of 1024); 0 when unset.
std::uint64_t environment_limit() {
  const char* text = std::getenv("ALGRAY_MEMORY_LIMIT");
  if (!text || !*text) return 0;
  char* end = nullptr;
  const double number = std::strtod(text, &end);
  const std::string unit(end);
  const std::size_t power = unit.empty() ? 0 : unit.size() == 1 ? std::string("KMGT").find(unit[0]) + 1 : 0;
  const bool known_unit = unit.empty() || power != 0;  // find's npos + 1 is 0
  double scale = 1;
  for (std::size_t i = 0; i < power; ++i) scale *= 1024;
  if (end == text || !known_unit || !(number > 0) || number * scale > 1e19)
    throw std::invalid_argument("ALGRAY_MEMORY_LIMIT='" + std::string(text) +
                                "' is not a size: give bytes, or a number with K, M, G or T");
  return static_cast<std::uint64_t>(number * scale);
}

}  // namespace

HostMemory available_host_memory() {
  HostMemory best;
  take_least(best, proc_kb("/proc/meminfo", "MemAvailable:"), "the machine's free memory");
  cgroup_limits(best);
  rlimit_left(best, RLIMIT_DATA, "VmData:", "its data size limit, ulimit -d");
  rlimit_left(best, RLIMIT_AS, "VmSize:", "its address space limit, ulimit -v");
  take_least(best, environment_limit(), "ALGRAY_MEMORY_LIMIT");
  return best;
}

}  // namespace algray
