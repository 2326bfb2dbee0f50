// The float-against-double timing of kernels/fp_speed.cl, best of a few launches each.
#include "algray/device/fp64_speed.h"

#include <algorithm>
#include <limits>

#include "algray/device/kernel_sources.h"

namespace algray {
namespace {

// Device time of the kernel's best launch, in ms.
double best_launch_ms(ClSession& session, bool in_double) {
  cl::Program program(session.context, assemble_kernel_source("fp_speed.cl"));
  const std::string options = in_double ? "-D ALGRAY_FP_DOUBLE=1" : "";
  try {
    program.build({session.info.device}, options.c_str());
  } catch (const cl::Error&) {
    throw BuildError("fp_speed.cl did not build on '" + session.info.name + "' with options '" + options + "':\n" +
                     program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(session.info.device));
  }
  cl::Kernel kernel(program, "fp_speed");
  // Enough work-items for every compute unit's lanes, and enough rounds that a launch's overhead is noise.
  const std::size_t items = std::max<std::size_t>(16384, 1024u * session.info.compute_units);
  constexpr cl_uint kRounds = 2048;
  cl::Buffer out(session.context, CL_MEM_WRITE_ONLY, items * (in_double ? sizeof(double) : sizeof(float)));
  kernel.setArg(0, out);
  kernel.setArg(1, kRounds);
  double best = std::numeric_limits<double>::infinity();
  for (int run = 0; run < 3; ++run) {
    cl::Event done;
    session.queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(items), cl::NullRange, nullptr, &done);
    done.wait();
    const double ms = static_cast<double>(done.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                                          done.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
                      1e-6;
    best = std::min(best, ms);
  }
  return best;
}

}  // namespace

std::optional<double> fp64_slowdown(const DeviceInfo& device, ProgramCache& cache) {
  if (!device.fp64) return std::nullopt;
  // v1: the kernel and its sizes; a change to either must measure again.
  return cache.remembered(device, "fp64-slowdown-v1", [&] {
    ClSession session(device);
    const double in_float = best_launch_ms(session, false);
    return best_launch_ms(session, true) / std::max(in_float, 1e-6);
  });
}

}  // namespace algray
