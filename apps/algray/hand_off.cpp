// `algray` hands `algray view` and runs under an MPI launcher to algray-full, which links cpp-httplib and Open MPI.
// Linked into every run, their 14 libraries load and relocate at each start, and every symbol PoCL's LLVM and
// clang look up when the device opens passes them first: 1-3 ms of a 1024^2 preview's 100-150, 3.6 ms of its CPU
// time (bench/history/2026-12.md, "Two binaries").
#include "hand_off.h"

#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <vector>

#include "exit_codes.h"

namespace algray::cli {

bool started_by_mpi_launcher() {
  // Open MPI's mpirun; PMIx launchers (Open MPI 5, srun --mpi=pmix); PMI-1/2 launchers (MPICH's hydra, srun
  // --mpi=pmi2).
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (const char* value = std::getenv(name); value && *value) return true;
  return false;
}

int hand_off_to_full(char** argv, std::ostream& err) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) {
    err << "algray: cannot find this executable (/proc/self/exe: " << ec.message() << "), so not algray-full either\n";
    return kExitFailure;
  }
  // ALGRAY_FULL_FROM_BINDIR: the install's libexec/algray relative to its bin (apps/algray/CMakeLists.txt).
  const std::vector<fs::path> candidates{self.parent_path() / "algray-full",
                                         self.parent_path() / ALGRAY_FULL_FROM_BINDIR / "algray-full"};
  for (const fs::path& full : candidates) {
    if (::access(full.c_str(), X_OK) != 0) continue;
    ::execv(full.c_str(), argv);
    err << "algray: cannot start " << full.string() << ": " << std::strerror(errno) << "\n";
    return kExitFailure;
  }
  err << "algray: this command needs algray-full (the command line with the web server and MPI), which is neither "
      << candidates[0].string() << " nor " << candidates[1].lexically_normal().string()
      << "; build or install it with algray\n";
  return kExitFailure;
}

}  // namespace algray::cli
