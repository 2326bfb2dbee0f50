// Program cache: in memory, then on disk (verified before use, rebuilt when stale or corrupt), then compiled.
#include "program_cache.h"

#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "kernel_sources.h"

namespace algray {
namespace {

constexpr char kMagic[] = "algray-program-binary-v1\n";

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

std::string build_log(const cl::Program& program, const cl::Device& device) {
  try {
    return program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device);
  } catch (const cl::Error&) {
    return "(no build log available)";
  }
}

}  // namespace

ProgramCache::ProgramCache(bool enabled, std::filesystem::path dir) : enabled_(enabled), dir_(std::move(dir)) {}

std::filesystem::path ProgramCache::default_directory() {
  if (const char* d = std::getenv("ALGRAY_CACHE_DIR"); d && *d) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::filesystem::path(x) / "algray";
  if (const char* home = std::getenv("HOME"); home && *home) return std::filesystem::path(home) / ".cache" / "algray";
  return std::filesystem::temp_directory_path() / "algray-cache";
}

cl::Kernel ProgramCache::kernel(ClSession& session, const KernelConfig& config, ProgramRecord* record) {
  const auto start = std::chrono::steady_clock::now();
  const std::string source = assemble_kernel_source(config.source_file());
  const std::string options = config.build_options();
  // Everything the binary depends on: a change to any of it must miss.
  const std::string identity = "source-hash=" + hex64(fnv1a(source)) + "\noptions=" + options +
                               "\ndevice=" + session.info.name + "\ndriver=" + session.info.driver_version +
                               "\nplatform=" + session.info.platform_name + " " + session.info.platform_version + "\n";
  ProgramRecord rec{config.key(), options, "built", 0};

  cl::Program program;
  const std::string memory_key = std::to_string(reinterpret_cast<std::uintptr_t>(session.context())) + "\n" + identity;
  if (auto it = memory_.find(memory_key); enabled_ && it != memory_.end()) {
    program = it->second;
    rec.origin = "memory";
  } else {
    const std::filesystem::path file = dir_ / (hex64(fnv1a(identity)) + ".bin");
    if (enabled_ && load_from_disk(session, file, identity, options, program)) {
      rec.origin = "disk";
    } else {
      program = build_from_source(session, source, options, rec.key);
      if (enabled_) store_on_disk(program, file, identity);
    }
    if (enabled_) memory_[memory_key] = program;
  }
  cl::Kernel k(program, config.entry.c_str());
  rec.build_ms = ms_since(start);
  if (record) *record = rec;
  return k;
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
        << build_log(program, session.info.device);
    throw BuildError(msg.str());
  }
  return program;
}

bool ProgramCache::load_from_disk(ClSession& session, const std::filesystem::path& file, const std::string& identity,
                                  const std::string& options, cl::Program& out) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string header = kMagic + identity + "--\n";
  // The stored identity must match exactly: a hash collision or an entry from another driver is never trusted.
  if (content.size() <= header.size() || content.compare(0, header.size(), header) != 0) return false;
  const cl::Program::Binaries binaries{
      std::vector<unsigned char>(content.begin() + static_cast<std::ptrdiff_t>(header.size()), content.end())};
  try {
    std::vector<cl_int> status;
    cl::Program program(session.context, {session.info.device}, binaries, &status);
    if (status.empty() || status[0] != CL_SUCCESS) return false;
    program.build({session.info.device}, options.c_str());
    out = program;
    return true;
  } catch (const cl::Error&) {
    return false;  // corrupt or stale: the caller rebuilds from source and overwrites it
  }
}

void ProgramCache::store_on_disk(const cl::Program& program, const std::filesystem::path& file,
                                 const std::string& identity) {
  // The cache is an optimisation: failing to write it must never fail a render.
  try {
    const auto binaries = program.getInfo<CL_PROGRAM_BINARIES>();
    if (binaries.empty() || binaries[0].empty()) return;
    std::filesystem::create_directories(dir_);
    const std::filesystem::path tmp = file.string() + ".tmp-" + std::to_string(::getpid());
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      out << kMagic << identity << "--\n";
      out.write(reinterpret_cast<const char*>(binaries[0].data()), static_cast<std::streamsize>(binaries[0].size()));
      if (!out) {
        std::filesystem::remove(tmp);
        return;
      }
    }
    std::filesystem::rename(tmp, file);
  } catch (const std::exception&) {
  }
}

}  // namespace algray
