// Adaptive precision's second pass: the rays a float kernel doubted, traced again in mixed precision or double.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "algray/device/program_cache.h"
#include "algray/render/device_surface.h"
#include "algray/render/ray_tracer.h"
#include "algray/render/shadow_tracer.h"
#include "kernels/algray_shared.h"

namespace algray {

// Why a float kernel doubted a ray (ALGRAY_DOUBT_* in kernels/algray_shared.h), for the probe and messages.
struct DoubtReason {
  unsigned id;
  const char* name;
  const char* meaning;
};
inline constexpr std::array<DoubtReason, 4> kDoubtReasons{{
    {ALGRAY_DOUBT_DISCARD, "discard", "an interval looked root-free, but a coefficient was within rounding noise of 0"},
    {ALGRAY_DOUBT_ACCEPT, "accept",
     "a root looked isolated, but P at an end of its interval was within rounding noise"},
    {ALGRAY_DOUBT_CLUSTER, "cluster", "the search reached the stopping width with several roots left"},
    {ALGRAY_DOUBT_FLAT, "flat",
     "P is so flat at the refined root that the noise could move it by " ALGRAY_DOUBT_POSITION_TEXT " of its t"},
}};
// The reason's entry, or nullptr for an id that is none of them.
const DoubtReason* doubt_reason(unsigned id);

// What one escalation did: the rays it traced again and their device time.
struct EscalationCount {
  std::uint64_t rays = 0;
  double kernel_ms = 0;
};

// One surface's trace kernel in mixed precision or double, for the camera and secondary rays a float kernel doubted.
class RayEscalation {
 public:
  // config: the pass's escalation kernel (PlannedPass::escalation), whose precision the surface is uploaded in.
  RayEscalation(ClSession& session, ProgramCache& cache, const KernelConfig& config, const Scene& scene,
                std::size_t surface);
  const ProgramRecord& program() const { return tracer_.program(); }
  // Every record of `records` flagged ALGRAY_HIT_DOUBT is traced again along ray_of(i) (the float ray as the float
  // kernel traced it, which double holds exactly), in batches of at most
  // batch_rays, and replaced by the answer, flagged ALGRAY_HIT_ESCALATED. Its work adds both searches'.
  EscalationCount redo(HitRecord* records, std::size_t count, const std::function<PixelRay(std::size_t)>& ray_of,
                       std::size_t batch_rays);

 private:
  DeviceSurface surface_;
  RayTracer tracer_;
};

// One surface's shadow kernel in mixed precision or double, for the shadow rays a float kernel doubted; or in float
// (the extent construction's, for the point form's doubted rays before float-float: PlannedPass::float_escalation).
class ShadowEscalation {
 public:
  ShadowEscalation(ClSession& session, ProgramCache& cache, const KernelConfig& config, const Scene& scene,
                   std::size_t surface, double offset);
  const ProgramRecord& program() const { return tracer_.program(); }
  // For each surface point i (points[i], normals[i]) whose undecided[i] has bits set, the shadow rays to those
  // light points are traced again and masks[i]'s bits there replaced by the answers. Where the kernel doubts
  // some of them in turn (a float kernel: PlannedPass::float_escalation), still_undecided, if given, gets them
  // (one mask per point, as undecided).
  EscalationCount redo(const std::vector<glm::dvec3>& points, const std::vector<glm::vec3>& normals,
                       const std::vector<glm::dvec3>& light_points, const std::vector<std::uint64_t>& undecided,
                       std::vector<std::uint64_t>& masks, std::vector<std::uint64_t>* still_undecided = nullptr);

 private:
  DeviceSurface surface_;
  ShadowTracer tracer_;
};

}  // namespace algray
