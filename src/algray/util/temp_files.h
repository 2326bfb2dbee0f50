// Temporary files named "<prefix><pid>-<counter>" beside their destination, and the removal of those a dead process
// left.
#pragma once

#include <filesystem>
#include <string>

namespace algray {

// How long a dead pid's temporary must have been left alone before it is removed: a writer on another machine
// sharing the directory (NFS, Slurm shards) has a pid that means nothing here.
inline constexpr int kStaleTempSeconds = 60;

// "<prefix><pid>-<counter>" for this process, unique within it.
std::string temp_file_name(const std::string& prefix);

// Removes the files in `dir` named "<prefix><pid>-<counter>" whose pid is no live process and which have not been
// modified for kStaleTempSeconds: what a process killed by SIGKILL left. Never touches this process's files or a
// live process's. Best effort: a file that cannot be listed or removed stays.
void remove_stale_temps(const std::filesystem::path& dir, const std::string& prefix);

}  // namespace algray
