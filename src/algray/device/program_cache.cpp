// Program cache: in memory, then on disk (verified before use, rebuilt when stale or corrupt), then compiled.
#include "algray/device/program_cache.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>

#include "algray/device/kernel_sources.h"
#include "algray/util/temp_files.h"

namespace algray {
namespace {

// v2 added the payload's length and checksum to the header: v1 entries cut short by a full disk or a crash reached
// cl::Program unchecked and crashed PoCL.
constexpr char kMagic[] = "algray-program-binary-v2\n";
// No device binary comes near this; a larger file is not ours, and reading it would only waste memory.
constexpr std::uintmax_t kMaxEntryBytes = 512ull << 20;

std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

std::string hex64(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The device and driver a cache entry was made on, and the driver's own build flags from the environment (PoCL
// appends POCL_EXTRA_BUILD_FLAGS to every build: the tests' unoptimised programs, docs/testing.md): any change to
// them must miss. Unset, the flags add nothing, so entries made without them keep their names.
std::string device_identity(const DeviceInfo& d) {
  std::string identity = "device=" + d.name + "\ndriver=" + d.driver_version + "\nplatform=" + d.platform_name + " " +
                         d.platform_version + "\n";
  if (const char* flags = std::getenv("POCL_EXTRA_BUILD_FLAGS"); flags && *flags)
    identity += "driver-build-flags=" + std::string(flags) + "\n";
  return identity;
}

std::string build_log(const cl::Program& program, const cl::Device& device) {
  try {
    return program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device);
  } catch (const cl::Error&) {
    return "(no build log available)";
  }
}

struct CacheWarnings {
  std::mutex lock;
  std::function<void(const std::string&)> handler;
  std::set<std::filesystem::path> warned;  // directories already reported
};

CacheWarnings& cache_warnings() {
  static CacheWarnings w;
  return w;
}

}  // namespace

void set_cache_warning_handler(std::function<void(const std::string&)> handler) {
  CacheWarnings& w = cache_warnings();
  const std::lock_guard<std::mutex> hold(w.lock);
  w.handler = std::move(handler);
}

void ProgramCache::warn_unusable(const std::error_code& why) const {
  CacheWarnings& w = cache_warnings();
  const std::lock_guard<std::mutex> hold(w.lock);
  if (!w.handler || !w.warned.insert(dir_).second) return;
  w.handler("algray: warning: the kernel cache " + dir_.string() + " cannot be used (" + why.message() +
            "): kernels are compiled on every run; set ALGRAY_CACHE_DIR to a writable directory, or pass "
            "--no-cache to silence this\n");
}

ProgramCache::ProgramCache(bool enabled, std::filesystem::path dir) : enabled_(enabled), dir_(std::move(dir)) {}

std::filesystem::path ProgramCache::default_directory() {
  if (const char* d = std::getenv("ALGRAY_CACHE_DIR"); d && *d) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::filesystem::path(x) / "algray";
  if (const char* home = std::getenv("HOME"); home && *home) return std::filesystem::path(home) / ".cache" / "algray";
  return std::filesystem::temp_directory_path() / "algray-cache";
}

const ProgramCache::AssembledSource& ProgramCache::assembled_source(const std::string& entry_file) {
  const auto assemble = [&entry_file] {
    AssembledSource a;
    a.text = assemble_kernel_source(entry_file);
    a.hash = fnv1a(a.text);
    return a;
  };
  if (const char* dir = std::getenv("ALGRAY_KERNEL_DIR"); dir && *dir) return from_kernel_dir_ = assemble();
  auto it = sources_.find(entry_file);
  if (it == sources_.end()) it = sources_.emplace(entry_file, assemble()).first;
  return it->second;
}

cl::Kernel ProgramCache::kernel(ClSession& session, const KernelConfig& config, ProgramRecord* record) {
  const auto start = std::chrono::steady_clock::now();
  const AssembledSource& source = assembled_source(config.source_file());
  const std::string options =
      config.build_options() + (session.copy ? " -DALGRAY_DEVICE_COPY=" + std::to_string(session.copy) : "");
  // Everything the binary depends on: a change to any of it must miss.
  const std::string identity =
      "source-hash=" + hex64(source.hash) + "\noptions=" + options + "\n" + device_identity(session.info);
  ProgramRecord rec{config.key(), options, "built", 0};

  cl::Program program;
  const std::string memory_key = std::to_string(reinterpret_cast<std::uintptr_t>(session.context())) + "\n" + identity;
  if (auto it = memory_.find(memory_key); enabled_ && it != memory_.end()) {
    program = it->second;
    rec.origin = "memory";
  } else {
    const std::filesystem::path file = dir_ / (hex64(fnv1a(identity)) + ".bin");
    if (on_disk() && load_from_disk(session, file, identity, options, program)) {
      rec.origin = "disk";
    } else {
      program = build_from_source(session, source.text, options, rec.key);
      if (on_disk()) store_on_disk(program, file, identity);
    }
    if (enabled_) memory_[memory_key] = program;
  }
  cl::Kernel k(program, config.entry.c_str());
  rec.build_ms = ms_since(start);
  if (record) *record = rec;
  return k;
}

double ProgramCache::remembered(const DeviceInfo& device, const std::string& name,
                                const std::function<double()>& measure) {
  const std::string identity = "measurement=" + name + "\n" + device_identity(device);
  if (!on_disk()) {
    const auto [kept, fresh] = measured_.try_emplace(identity, 0.0);
    if (fresh) kept->second = measure();
    return kept->second;
  }
  const std::filesystem::path file = dir_ / (hex64(fnv1a(identity)) + ".measured");
  if (std::string payload; read_entry(file, identity, payload)) {
    char* end = nullptr;
    const double value = std::strtod(payload.c_str(), &end);
    if (end != payload.c_str() && std::isfinite(value) && value > 0) return value;
  }
  const double value = measure();
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", value);
  // A cache that cannot be written just measures again, with a word why.
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (!ec) ec = write_entry(file, entry_header(identity, text) + text);
  if (ec) warn_unusable(ec);
  return value;
}

cl::Program ProgramCache::build_from_source(ClSession& session, const std::string& source, const std::string& options,
                                            const std::string& key) {
  cl::Program program(session.context, source);
  try {
    program.build({session.info.device}, options.c_str());
  } catch (const cl::Error& e) {
    std::ostringstream msg;
    msg << "OpenCL build failed (" << e.what() << ", code " << e.err() << ") for " << key << "\n"
        << "  device: " << session.info.name << " (" << session.info.platform_name << ")\n"
        << "  options: " << options << "\n"
        << "build log:\n"
        << locate_in_kernel_files(build_log(program, session.info.device), source);
    throw BuildError(msg.str());
  }
  return program;
}

bool ProgramCache::load_from_disk(ClSession& session, const std::filesystem::path& file, const std::string& identity,
                                  const std::string& options, cl::Program& out) {
  std::string payload;
  if (!read_entry(file, identity, payload)) return false;
  const cl::Program::Binaries binaries{std::vector<unsigned char>(payload.begin(), payload.end())};
  try {
    std::vector<cl_int> status;
    cl::Program program(session.context, {session.info.device}, binaries, &status);
    if (status.empty() || status[0] != CL_SUCCESS) return false;
    program.build({session.info.device}, options.c_str());
    out = program;
    return true;
  } catch (const cl::Error&) {
    return false;  // stale for this driver after all: the caller rebuilds from source and overwrites it
  }
}

std::string ProgramCache::entry_header(const std::string& identity, const std::string& payload) {
  return kMagic + identity + "payload-bytes=" + std::to_string(payload.size()) +
         "\npayload-fnv1a64=" + hex64(fnv1a(payload)) + "\n--\n";
}

bool ProgramCache::read_entry(const std::filesystem::path& file, const std::string& identity, std::string& payload) {
  // Anything but a regular file of sane size under the entry's name (a directory, a FIFO, a huge file) is not an
  // entry: reading a directory throws from inside the stream, and a FIFO would block.
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::symlink_status(file, ec);
  if (ec || !std::filesystem::exists(status)) return false;
  if (!std::filesystem::is_regular_file(status)) {
    std::filesystem::remove(file, ec);  // an empty directory or a stray link goes; anything else stays, unused
    return false;
  }
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec || size > kMaxEntryBytes) return false;
  std::string content;
  try {
    std::ifstream in(file, std::ios::binary);
    if (!in) return false;
    content.resize(static_cast<std::size_t>(size));
    in.read(content.data(), static_cast<std::streamsize>(size));
    if (static_cast<std::uintmax_t>(in.gcount()) != size) return false;
  } catch (const std::exception&) {
    return false;
  }
  // The header names the identity exactly (a hash collision or another driver's entry is never trusted) and the
  // payload's length and checksum, so a truncated or damaged entry is caught before OpenCL sees a byte of it.
  const std::string prefix = kMagic + identity + "payload-bytes=";
  if (content.compare(0, prefix.size(), prefix) != 0) return false;
  const std::size_t end = content.find("\n--\n", prefix.size());
  if (end == std::string::npos || end > prefix.size() + 64) return false;
  const std::size_t body = end + 4;
  payload.assign(content, body, std::string::npos);
  if (payload.empty()) return false;
  return content.compare(0, body, entry_header(identity, payload)) == 0;
}

void ProgramCache::store_on_disk(const cl::Program& program, const std::filesystem::path& file,
                                 const std::string& identity) {
  // The cache is an optimisation: failing to write it must never fail a render, only be said once.
  std::error_code ec;
  try {
    const auto binaries = program.getInfo<CL_PROGRAM_BINARIES>();
    if (binaries.empty() || binaries[0].empty()) return;
    std::filesystem::create_directories(dir_, ec);
    const std::string payload(binaries[0].begin(), binaries[0].end());
    if (!ec) ec = write_entry(file, entry_header(identity, payload) + payload);
  } catch (const std::filesystem::filesystem_error& e) {
    ec = e.code();
  } catch (const std::exception&) {
    return;  // no binary from the driver: nothing the directory could help
  }
  if (ec) warn_unusable(ec);
}

std::error_code ProgramCache::write_entry(const std::filesystem::path& file, const std::string& content) {
  // Written in full and fsync'd before the rename, so that no crash or power cut can leave a short entry under the
  // final name; pid and counter keep concurrent writers (threads or processes) apart.
  const std::string prefix = file.filename().string() + ".tmp-";
  remove_stale_temps(file.parent_path(), prefix);  // left by writers killed mid-write
  const std::string tmp = (file.parent_path() / temp_file_name(prefix)).string();
  const auto failed = [] { return std::error_code(errno ? errno : EIO, std::generic_category()); };
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return failed();
  std::error_code ec;
  for (std::size_t done = 0; !ec && done < content.size();) {
    errno = 0;
    const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n > 0)
      done += static_cast<std::size_t>(n);
    else
      ec = n == 0 ? std::make_error_code(std::errc::no_space_on_device) : failed();
  }
  if (!ec && ::fsync(fd) != 0) ec = failed();
  if (::close(fd) != 0 && !ec) ec = failed();
  if (!ec && ::rename(tmp.c_str(), file.c_str()) != 0) ec = failed();
  if (ec) ::unlink(tmp.c_str());
  return ec;
}

}  // namespace algray
