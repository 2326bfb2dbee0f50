// Helpers shared by the tests that need an OpenCL device: the device is required, never optional.
#pragma once

#include <catch2/catch.hpp>
#include <memory>
#include <string>

#include "cl_runtime.h"

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

}  // namespace algray::testing
