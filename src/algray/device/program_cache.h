// Built OpenCL programs, kept in memory per session and on disk as device binaries keyed by everything they depend on.
#pragma once

#include <filesystem>
#include <functional>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <system_error>

#include "algray/device/cl_runtime.h"
#include "algray/device/kernel_config.h"

namespace algray {

// A program that failed to build; the message carries the options, the device and the full build log.
struct BuildError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct ProgramRecord {
  std::string key;      // KernelConfig::key()
  std::string options;  // the build options used
  std::string origin;   // "built", "memory" or "disk"
  double build_ms = 0;  // wall time to obtain the program (compile, or load and link a binary)
};

// Where a warning that the disk cache cannot be used goes: the command line prints it, the Python module writes
// it to sys.stderr. This layer writes nothing to the terminal itself; with no handler set the warning is lost.
// Called at most once per process and cache directory, from whichever thread first failed to use it.
void set_cache_warning_handler(std::function<void(const std::string&)> handler);

class ProgramCache {
 public:
  // enabled = false is `--no-cache`: every program is compiled from source and nothing is kept or stored.
  // An empty `dir` keeps programs in this object's memory only. On PoCL that saves a compile per program:
  // asking a built program for its binary, as the disk store must, makes PoCL compile every kernel in it once
  // more for a work-group size fixed only at launch (about 1 s at degree 10), a cost worth paying only where a
  // later process reads the entry.
  explicit ProgramCache(bool enabled, std::filesystem::path dir = default_directory());

  // The kernel named config.entry, from the cheapest place that has a valid program.
  cl::Kernel kernel(ClSession& session, const KernelConfig& config, ProgramRecord* record = nullptr);

  // A number measured on a device, such as its double arithmetic's speed: read from the cache directory when it
  // was measured before on this device and driver, otherwise measured now (`measure` opens the device only
  // then) and kept there. Without a directory, or with the cache off, it is measured once for this object's life
  // (a render asks on every frame), and never stored.
  double remembered(const DeviceInfo& device, const std::string& name, const std::function<double()>& measure);

  // $ALGRAY_CACHE_DIR, else $XDG_CACHE_HOME/algray, else ~/.cache/algray.
  static std::filesystem::path default_directory();

 private:
  cl::Program build_from_source(ClSession& session, const std::string& source, const std::string& options,
                                const std::string& key);
  bool load_from_disk(ClSession& session, const std::filesystem::path& file, const std::string& identity,
                      const std::string& options, cl::Program& out);
  void store_on_disk(const cl::Program& program, const std::filesystem::path& file, const std::string& identity);

  // An entry on disk: a text header (magic, identity, payload length and checksum), then the device binary.
  static std::string entry_header(const std::string& identity, const std::string& payload);
  // The payload of a well-formed entry for `identity`; false for anything missing, foreign, short or damaged.
  static bool read_entry(const std::filesystem::path& file, const std::string& identity, std::string& payload);
  // Empty on success, else why the entry could not be written.
  static std::error_code write_entry(const std::filesystem::path& file, const std::string& content);
  // A disk cache that cannot be used falls back to compiling every time: say so, once per process and directory,
  // so that a user who wonders why every run compiles finds out.
  void warn_unusable(const std::error_code& why) const;

  // An entry file's program text with its includes, and the text's hash (the identity's source-hash).
  struct AssembledSource {
    std::string text;
    std::uint64_t hash = 0;
  };
  // Assembled once per entry file and kept: the embedded files do not change while the process runs, and
  // assembling and hashing some 200 KB on every render was most of a render's host time under the sanitizers
  // (and 1-3 ms of every frame of `algray view`). Files read from ALGRAY_KERNEL_DIR are read every time.
  const AssembledSource& assembled_source(const std::string& entry_file);

  bool on_disk() const { return enabled_ && !dir_.empty(); }

  bool enabled_;
  std::filesystem::path dir_;  // empty: memory only
  std::map<std::string, AssembledSource> sources_;  // by entry file, embedded sources only
  AssembledSource from_kernel_dir_;                 // the last one read from ALGRAY_KERNEL_DIR
  std::map<std::string, cl::Program> memory_;  // keyed by device identity + options + source hash
  std::map<std::string, double> measured_;     // no disk: remembered()'s numbers, by identity
};

}  // namespace algray
