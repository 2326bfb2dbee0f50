// OpenCL platforms and devices: listing, choosing one by index or name, and the context and queue on it.
#pragma once

#include <CL/opencl.hpp>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace algray {

struct DeviceError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct DeviceInfo {
  int index = 0;  // position in enumerate_devices(), the number `--device` accepts
  std::string platform_name, platform_version;
  std::string name, vendor, version, driver_version;
  std::string type;  // "GPU", "CPU", "accelerator", ...
  unsigned compute_units = 0;
  unsigned native_float_width = 0;     // CL_DEVICE_NATIVE_VECTOR_WIDTH_FLOAT: floats a vector register holds
  unsigned native_double_width = 0;    // CL_DEVICE_NATIVE_VECTOR_WIDTH_DOUBLE: doubles it holds (0 without fp64)
  bool float_fma = false;              // CL_FP_FMA in CL_DEVICE_SINGLE_FP_CONFIG: fused multiply-add in hardware
  bool double_fma = false;             // the same for double
  bool fp64 = false;                   // double precision usable: the device has cl_khr_fp64 and fp64_hidden is false
  bool fp64_hidden = false;            // the device has it, but ALGRAY_NO_FP64 (--no-fp64) makes algray act as if not
  std::uint64_t global_mem_bytes = 0;  // CL_DEVICE_GLOBAL_MEM_SIZE
  std::uint64_t max_alloc_bytes = 0;   // CL_DEVICE_MAX_MEM_ALLOC_SIZE: the largest single buffer
  cl::Device device;
};

// Whether ALGRAY_NO_FP64 is set (to anything but "" or "0"): every device then counts as having no double
// precision, so that the float-only path can be tried on any machine. `--no-fp64` sets it.
bool fp64_hidden_by_environment();

// Every device of every platform, in platform order. Empty when no ICD is installed.
std::vector<DeviceInfo> enumerate_devices();

// spec "": the first GPU, else the first device. Digits: that index. Otherwise a case-insensitive substring of
// the device or platform name. Throws DeviceError naming the devices that exist.
DeviceInfo select_device(const std::string& spec);
// Several devices for one render: "all", or a comma-separated list of indices and name substrings ("0,2",
// "pthread,pthread": a repeated substring takes the next device it matches). One item is select_device's.
// Throws DeviceError naming the devices that exist, or a device named twice.
std::vector<DeviceInfo> select_devices(const std::string& spec);

// The list as `algray devices` prints it; `fp64_slowdown` (one per device, where measured) adds how much longer
// each takes for double arithmetic than for float.
std::string describe_devices(const std::vector<DeviceInfo>& devices,
                             const std::vector<std::optional<double>>& fp64_slowdown = {});

struct ClSession {
  explicit ClSession(DeviceInfo chosen, int copy = 0);
  DeviceInfo info;
  // 0, or n for the n-th other device of one process with this device's name and driver. Its programs are built
  // with -DALGRAY_DEVICE_COPY=n, so that they differ from the first device's: PoCL 3.1 keeps one table of loaded
  // kernels for all its devices, matched by the program's hash and work-group size only, and two such devices
  // running the same kernel at once broke its reference counts (an assertion in pocl_release_dlhandle_cache).
  int copy = 0;
  cl::Context context;
  cl::CommandQueue queue;
};

// A session on each device, with `copy` numbered among devices of one name and driver.
std::vector<std::unique_ptr<ClSession>> open_sessions(const std::vector<DeviceInfo>& devices);

}  // namespace algray
