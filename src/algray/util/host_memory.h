// How much more memory this process may take: the machine's, its cgroup's and its resource limits' least.
#pragma once

#include <cstdint>
#include <string>

namespace algray {

struct HostMemory {
  std::uint64_t bytes = 0;  // 0: unknown
  std::string
      limited_by;  // "the machine's free memory", "its cgroup's memory limit", "its data size limit, ulimit -d", ...
};

// The least of: MemAvailable; each enclosing cgroup's limit less its use (a Slurm job's --mem, a container's
// limit, where a node's free memory would promise far more than the job may take); RLIMIT_DATA and RLIMIT_AS
// less this process's data and address space; and ALGRAY_MEMORY_LIMIT (bytes, or with K, M, G or T), a cap a
// user sets by hand. Throws std::invalid_argument when ALGRAY_MEMORY_LIMIT is not a size.
HostMemory available_host_memory();

}  // namespace algray
