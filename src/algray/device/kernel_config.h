// KernelConfig: every choice that changes a kernel's code, turned into build options and a cache key.
#pragma once

#include <string>
#include <vector>

#include "algray/scene/solver_options.h"

namespace algray {

struct KernelConfig;

// The lane count a render uses on a device of `device_type` ("CPU", "GPU", ...) unless the scene sets
// render.lanes: 16 on a CPU, whose work-items run one after another, 1 on devices that already run work-items in
// SIMD; and whether a kernel can be built with more than one lane at all.
int default_lanes(const std::string& device_type);
bool lanes_apply(const KernelConfig& config);
// The shadow kernel's point form takes at most 8 light samples of a point side by side in double, whatever the
// camera rays take: at 16 its pass took 1.5 times as long on the Barth sextic and decic (bench/RESULTS.md). In
// float, as many as one vector register holds: with AVX-512 (16 floats) 16 took 0.93x (sextic) and 0.82x (decic)
// the time of 8; with AVX2 (8 floats) 16 took 1.16x to 1.34x the time of 8 on every scene measured
// (bench/history/2026-12.md, "Float shadow lanes").
constexpr int kMaxShadowLanes = 8;
constexpr int kMaxFloatShadowLanes = 16;
// The float shadow kernel's most lanes on a device whose vector registers hold native_float_width floats
// (DeviceInfo::native_float_width): that many, within 8 and kMaxFloatShadowLanes; 0 (not known) gives the most.
int float_shadow_lanes(unsigned native_float_width);
// The point form's lanes: `lanes` (the camera rays'), at most kMaxShadowLanes in double and float_lanes otherwise.
int shadow_lanes(int lanes, Precision precision, int float_lanes = kMaxFloatShadowLanes);
// The trace kernel's lanes for the rays adaptive precision traces again: at most `lanes` (the first pass's),
// and no more than one vector register holds in that precision (native_width: doubles for double, floats for float
// and float-float; 0, not known, leaves `lanes`). The doubted rays are scattered over the image and search for very
// different lengths, and lanes wait on their slowest: with AVX2 at 1024x768 (Barth decic, Endrass octic) 4 lanes of
// double took 0.80x and 0.84x the time of 16, 8 of float 0.97x and 0.91x, 8 of float-float 0.86x and 0.81x, and 2
// or 1 lanes more than 4 (bench/history/2026-12.md, "Camera rays' doubts settled in float first").
int escalation_lanes(int lanes, unsigned native_width);
// The extent form's shadow batch (KernelConfig::shadow_batch) on a device whose vector registers hold native_width
// numbers of the kernel's precision: that many where it is 2, 4, 8 or 16 and the device fuses multiply-adds in that
// precision (the batch's steps are written with fma(), which matches the one-ray vector steps bit for bit where
// the compiler fuses those too); else 0, one accumulator per ray. Degree 16 and 24 shadow passes about 0.65x in
// float, 0.55-0.8x in double with AVX2 (bench/history/2026-12.md, "Shadow rays restricted side by side in lanes").
int shadow_batch_width(unsigned native_width, bool fused_multiply_add);

// The -D switches build_options() writes, in its order; kernels/build_switches.h declares each one.
std::vector<std::string> build_switch_names();

struct KernelConfig {
  std::string entry = "primary";  // kernel file (without .cl) and kernel function
  int degree = 1;
  Precision precision = Precision::Double;
  Isolation isolation = Isolation::Bernstein;
  Refinement refinement = Refinement::Brent;
  RayOrigin ray_origin = RayOrigin::Extent;
  double tolerance = 1e-9;   // the paper's eps: stop when the bracket is <= 4*eps*max(|t|,1)
  int max_iterations = 100;  // see default_max_iterations
  // Rays per work-item, side by side in vector lanes (kernels/lanes.h): more than 1 only for the primary and
  // trace kernels with Bernstein isolation and Brent refinement, and the shadow kernel's point form
  // (lanes_apply), where the plan asks for it.
  int lanes = 1;
  // Adaptive kernels only: the float pass settles more of what it would doubt. In the extent form's shadow kernels a
  // value within the segment's noise is held to the noise of its own interval too (isolation.h, within_noise_at),
  // and before a doubted ray goes to the second pass, two values of P* of opposite signs beyond the noise at 16
  // points settle it as hidden (shadow.h, sampled_sign_change); the point form searches its doubted rays again by
  // the noise of each part (shadow.h, point_part_polys). In camera and secondary ray kernels an interval doubted for
  // an end value within the noise is settled by P's signs there in float-float (discards_settled). These pay where
  // the second pass runs in float-float or float, not where it runs in double (bench/RESULTS.md), so the plan sets
  // it for the former only (escalate_in).
  bool settle_doubts = false;
  // The extent form's shadow kernels: 0, or how many rays they restrict side by side in the lanes of one vector per
  // coefficient (kernels/restrict.h; shadow_batch_width).
  int shadow_batch = 0;

  // "-D DEGREE=6 -D ALGRAY_DOUBLE=1 ..." with the tolerance as an exact hexadecimal literal.
  std::string build_options() const;
  // Everything above, readable; two configs build the same code iff their keys are equal.
  std::string key() const;
  std::string source_file() const { return entry + ".cl"; }
};

}  // namespace algray
