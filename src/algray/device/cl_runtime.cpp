// Device enumeration and selection over the OpenCL ICD loader.
#include "algray/device/cl_runtime.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace algray {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\0' || std::isspace(static_cast<unsigned char>(s.back())))) s.pop_back();
  return s;
}

std::string type_name(cl_device_type t) {
  if (t & CL_DEVICE_TYPE_GPU) return "GPU";
  if (t & CL_DEVICE_TYPE_CPU) return "CPU";
  if (t & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

}  // namespace

bool fp64_hidden_by_environment() {
  const char* value = std::getenv("ALGRAY_NO_FP64");
  return value && *value && std::string(value) != "0";
}

std::vector<DeviceInfo> enumerate_devices() {
  std::vector<DeviceInfo> out;
  std::vector<cl::Platform> platforms;
  // With no ICD registered the loader reports CL_PLATFORM_NOT_FOUND_KHR; that simply means "no devices".
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error&) {
    return out;
  }
  for (const cl::Platform& p : platforms) {
    std::vector<cl::Device> devices;
    try {
      p.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;
    }
    for (const cl::Device& d : devices) {
      DeviceInfo info;
      info.index = static_cast<int>(out.size());
      info.platform_name = trimmed(p.getInfo<CL_PLATFORM_NAME>());
      info.platform_version = trimmed(p.getInfo<CL_PLATFORM_VERSION>());
      info.name = trimmed(d.getInfo<CL_DEVICE_NAME>());
      info.vendor = trimmed(d.getInfo<CL_DEVICE_VENDOR>());
      info.version = trimmed(d.getInfo<CL_DEVICE_VERSION>());
      info.driver_version = trimmed(d.getInfo<CL_DRIVER_VERSION>());
      info.type = type_name(d.getInfo<CL_DEVICE_TYPE>());
      info.compute_units = d.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
      info.native_float_width = d.getInfo<CL_DEVICE_NATIVE_VECTOR_WIDTH_FLOAT>();
      info.native_double_width = d.getInfo<CL_DEVICE_NATIVE_VECTOR_WIDTH_DOUBLE>();
      const cl_device_fp_config double_config = d.getInfo<CL_DEVICE_DOUBLE_FP_CONFIG>();
      const bool fp64 = double_config != 0;
      info.float_fma = (d.getInfo<CL_DEVICE_SINGLE_FP_CONFIG>() & CL_FP_FMA) != 0;
      info.double_fma = (double_config & CL_FP_FMA) != 0;
      info.fp64_hidden = fp64 && fp64_hidden_by_environment();
      info.fp64 = fp64 && !info.fp64_hidden;
      info.global_mem_bytes = d.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
      info.max_alloc_bytes = d.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
      info.device = d;
      out.push_back(std::move(info));
    }
  }
  return out;
}

std::string describe_devices(const std::vector<DeviceInfo>& devices,
                             const std::vector<std::optional<double>>& fp64_slowdown) {
  std::ostringstream s;
  std::string platform;
  for (const DeviceInfo& d : devices) {
    if (d.platform_name != platform) {
      platform = d.platform_name;
      s << "platform: " << d.platform_name << " (" << d.platform_version << ")\n";
    }
    s << "  [" << d.index << "] " << d.name << "\n"
      << "      type " << d.type << ", " << d.compute_units << " compute units, fp64 "
      << (d.fp64          ? "yes"
          : d.fp64_hidden ? "hidden (ALGRAY_NO_FP64)"
                          : "no");
    const std::size_t k = static_cast<std::size_t>(&d - devices.data());
    if (k < fp64_slowdown.size() && fp64_slowdown[k]) {
      char ratio[64];
      std::snprintf(ratio, sizeof ratio, " (double takes %.2fx float's time)", *fp64_slowdown[k]);
      s << ratio;
    }
    s << ", " << d.version << ", driver " << d.driver_version << "\n";
  }
  return s.str();
}

namespace {

// One item of a device spec among `devices`: digits are an index, anything else the first device or platform
// name containing it that `taken` does not already hold (so "pthread,pthread" names two PoCL devices).
const DeviceInfo& find_device(const std::vector<DeviceInfo>& devices, const std::string& item,
                              const std::vector<DeviceInfo>& taken) {
  auto is_taken = [&](const DeviceInfo& d) {
    return std::any_of(taken.begin(), taken.end(), [&](const DeviceInfo& t) { return t.index == d.index; });
  };
  if (!item.empty() && std::all_of(item.begin(), item.end(), [](unsigned char c) { return std::isdigit(c); })) {
    const unsigned long index = item.size() > 9 ? devices.size() : std::stoul(item);
    if (index >= devices.size())
      throw DeviceError("--device " + item + ": there are only " + std::to_string(devices.size()) + " devices:\n" +
                        describe_devices(devices));
    if (is_taken(devices[index])) throw DeviceError("--device: device " + item + " is named twice");
    return devices[index];
  }
  const std::string needle = lower(item);
  bool matched = false;
  for (const DeviceInfo& d : devices)
    if (lower(d.name).find(needle) != std::string::npos || lower(d.platform_name).find(needle) != std::string::npos) {
      matched = true;
      if (!is_taken(d)) return d;
    }
  throw DeviceError("--device " + item +
                    (matched ? ": every device whose name contains it is already named; the devices are:\n"
                             : ": no device or platform name contains it; the devices are:\n") +
                    describe_devices(devices));
}

std::vector<DeviceInfo> devices_or_error() {
  std::vector<DeviceInfo> devices = enumerate_devices();
  if (devices.empty())
    throw DeviceError(
        "no OpenCL device found: install an OpenCL driver (for the CPU on Debian: apt-get install "
        "pocl-opencl-icd) and check with `algray devices`");
  return devices;
}

}  // namespace

DeviceInfo select_device(const std::string& spec) {
  const std::vector<DeviceInfo> devices = devices_or_error();
  if (spec.empty()) {
    for (const DeviceInfo& d : devices)
      if (d.type == "GPU") return d;
    return devices.front();
  }
  return find_device(devices, spec, {});
}

std::vector<DeviceInfo> select_devices(const std::string& spec) {
  if (lower(spec) == "all") return devices_or_error();
  if (spec.find(',') == std::string::npos) return {select_device(spec)};
  const std::vector<DeviceInfo> devices = devices_or_error();
  std::vector<DeviceInfo> chosen;
  std::size_t begin = 0;
  while (begin <= spec.size()) {
    const std::size_t comma = std::min(spec.find(',', begin), spec.size());
    std::string item = trimmed(spec.substr(begin, comma - begin));
    item.erase(0, std::min(item.size(), item.find_first_not_of(' ')));
    if (item.empty()) throw DeviceError("--device " + spec + ": an empty item in the list");
    chosen.push_back(find_device(devices, item, chosen));
    begin = comma + 1;
  }
  return chosen;
}

ClSession::ClSession(DeviceInfo chosen, int copy_number)
    : info(std::move(chosen)),
      copy(copy_number),
      context(info.device),
      queue(context, info.device, CL_QUEUE_PROFILING_ENABLE) {}

std::vector<std::unique_ptr<ClSession>> open_sessions(const std::vector<DeviceInfo>& devices) {
  std::vector<std::unique_ptr<ClSession>> sessions;
  for (const DeviceInfo& d : devices) {
    int copy = 0;
    for (const auto& s : sessions)
      if (s->info.name == d.name && s->info.driver_version == d.driver_version) ++copy;
    sessions.push_back(std::make_unique<ClSession>(d, copy));
  }
  return sessions;
}

}  // namespace algray
