// How much longer a device takes for double arithmetic than for float, measured once and kept with the programs.
#pragma once

#include <optional>
#include <string>

#include "algray/device/cl_runtime.h"
#include "algray/device/program_cache.h"

namespace algray {

// The time of a chain of double multiply-adds over the same chain in float (kernels/fp_speed.cl), on the
// session's device: about 1-2 on CPUs and datacenter GPUs, 16-64 on most others. Measured the first time and
// then read from the program cache (ProgramCache::remembered), as CLBlast keeps its tuning results; a device
// without fp64 (or with it hidden) has none.
// The device is opened only to measure.
std::optional<double> fp64_slowdown(const DeviceInfo& device, ProgramCache& cache);

// kernels/fp_speed.cl's build options in float or in double (the portability test compiles both).
std::string fp_speed_build_options(bool in_double);

}  // namespace algray
