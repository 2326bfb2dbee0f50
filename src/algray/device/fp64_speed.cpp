// The float-against-double timing of kernels/fp_speed.cl, best of a few launches each.
#include "algray/device/fp64_speed.h"

#include <algorithm>
#include <limits>

#include "algray/device/kernel_sources.h"

namespace algray {
namespace {

// The fp_speed kernel built in float or double, with its output buffer.
struct SpeedKernel {
  cl::Program program;
  cl::Kernel kernel;
  cl::Buffer out;
  std::size_t items = 0;
};

SpeedKernel speed_kernel(ClSession& session, bool in_double) {
  SpeedKernel k;
  const std::string source = assemble_kernel_source("fp_speed.cl");
  k.program = cl::Program(session.context, source);
  const std::string options = fp_speed_build_options(in_double);
  try {
    k.program.build({session.info.device}, options.c_str());
  } catch (const cl::Error&) {
    throw BuildError("fp_speed.cl did not build on '" + session.info.name + "' with options '" + options + "':\n" +
                     locate_in_kernel_files(k.program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(session.info.device), source));
  }
  k.kernel = cl::Kernel(k.program, "fp_speed");
  // Enough work-items for every compute unit's lanes, and enough rounds that a launch's overhead is noise.
  k.items = std::max<std::size_t>(16384, 1024u * session.info.compute_units);
  constexpr cl_uint kRounds = 2048;
  k.out = cl::Buffer(session.context, CL_MEM_WRITE_ONLY, k.items * (in_double ? sizeof(double) : sizeof(float)));
  k.kernel.setArg(0, k.out);
  k.kernel.setArg(1, kRounds);
  return k;
}

// Device time of one launch, in ms.
double launch_ms(ClSession& session, SpeedKernel& k) {
  cl::Event done;
  session.queue.enqueueNDRangeKernel(k.kernel, cl::NullRange, cl::NDRange(k.items), cl::NullRange, nullptr, &done);
  done.wait();
  return static_cast<double>(done.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                             done.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
         1e-6;
}

}  // namespace

std::string fp_speed_build_options(bool in_double) { return in_double ? "-D ALGRAY_FP_DOUBLE=1" : ""; }

std::optional<double> fp64_slowdown(const DeviceInfo& device, ProgramCache& cache) {
  if (!device.fp64) return std::nullopt;
  // v1: the kernel and its sizes; a change to either must measure again.
  return cache.remembered(device, "fp64-slowdown-v1", [&] {
    ClSession session(device);
    SpeedKernel in_float = speed_kernel(session, false), in_double = speed_kernel(session, true);
    // Best of each, launched in turn: on a shared machine a burst of other work then slows both alike (measured
    // one after the other, a test under ctest -j2 once read double as twice float's time on a CPU where it is
    // 0.9x, and rendered in adaptive precision instead of double).
    double best_float = std::numeric_limits<double>::infinity(), best_double = best_float;
    for (int run = 0; run < 4; ++run) {
      best_float = std::min(best_float, launch_ms(session, in_float));
      best_double = std::min(best_double, launch_ms(session, in_double));
    }
    return best_double / std::max(best_float, 1e-6);
  });
}

}  // namespace algray
