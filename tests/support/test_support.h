// Helpers shared by the tests that need an OpenCL device: the device is required, never optional.
#pragma once

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "algray/device/cl_runtime.h"
#include "algray/device/kernel_config.h"
#include "algray/device/program_cache.h"
#include "algray/render/render_plan.h"

namespace algray::testing {

// One session for the whole test executable. Without a device the calling test fails loudly: a suite that
// passes because nothing could run would hide exactly the failure it exists to catch.
inline ClSession& device_session() {
  static std::unique_ptr<ClSession> session;
  if (!session) {
    const auto devices = enumerate_devices();
    if (devices.empty())
      FAIL(
          "No OpenCL device found. These tests need one: on Debian install pocl-opencl-icd "
          "(scripts/install-deps.sh does) and check with `algray devices`.");
    session = std::make_unique<ClSession>(select_device(""));
  }
  return *session;
}

// The lanes a render's plan gives the point form's shadow kernel on the test device (render_plan.cpp), so that the
// shadow tests run the programs renders run, and share them with the other tests' renders in a cold suite.
inline int plan_shadow_lanes(Precision precision) {
  const DeviceInfo& device = device_session().info;
  return shadow_lanes(default_lanes(device.type), precision, float_shadow_lanes(device.native_float_width));
}
// The extent form's shadow batch the plan gives a kernel of this precision on the test device (shadow_batch_width).
inline int plan_shadow_batch(Precision precision) { return shadow_batch_on(device_session().info, precision); }

// One program cache for the whole test executable, in memory only. Every test that builds kernels through it
// compiles each configuration once per process: a cache per test case, or `--no-cache`'s ProgramCache(false),
// built every program again on every render through PoCL's own cache (60-130 ms each, some 1,300 times in a
// cold suite). Memory only, because a disk entry costs PoCL a compile (program_cache.h). The tests of the
// cache itself make their own.
inline ProgramCache& program_cache() {
  static ProgramCache cache(true, {});
  return cache;
}

// Sets ALGRAY_NO_FP64 for one scope, and puts back what was there: devices enumerated (and sessions opened) in it
// count as having no double precision, so adaptive precision's second pass runs in float-float.
class HiddenFp64 {
 public:
  HiddenFp64() {
    if (const char* v = std::getenv("ALGRAY_NO_FP64")) before_ = v;
    ::setenv("ALGRAY_NO_FP64", "1", 1);
  }
  ~HiddenFp64() {
    if (before_.empty())
      ::unsetenv("ALGRAY_NO_FP64");
    else
      ::setenv("ALGRAY_NO_FP64", before_.c_str(), 1);
  }
  HiddenFp64(const HiddenFp64&) = delete;
  HiddenFp64& operator=(const HiddenFp64&) = delete;

 private:
  std::string before_;
};

// Every scene file in scenes/, sorted by name.
inline std::vector<std::filesystem::path> scene_files() {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(ALGRAY_SOURCE_DIR "/scenes"))
    if (entry.path().extension() == ".toml") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace algray::testing
