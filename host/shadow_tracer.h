// The shadow kernel on a set of surface points: which sample points of a light the surface hides from each.
#pragma once

#include <cstdint>
#include <vector>

#include "device_surface.h"
#include "program_cache.h"

namespace algray {

struct ShadowAnswer {
  std::vector<std::uint64_t> masks;  // per surface point: bit s set when light point s is hidden
  std::uint64_t rays_traced = 0;     // shadow rays that reached root isolation
  double kernel_ms = 0;
};

// Built once per render (one program, one upload of the surface), then asked once per light.
class ShadowTracer {
 public:
  // config: the shadow pass's kernel (RenderPlan); offset: how far each shadow ray's origin moves along the
  // normal, in world units.
  ShadowTracer(ClSession& session, ProgramCache& cache, const KernelConfig& config, const DeviceSurface& surface,
               double offset);
  const ProgramRecord& program() const { return record_; }
  // points and normals: world-space surface points and unit normals on the side the light is looked for from.
  // At most 64 light points. already_hidden (empty, or one mask per point): light points another surface
  // hides, which are not traced again and stay set in the answer.
  ShadowAnswer trace(const std::vector<glm::dvec3>& points, const std::vector<glm::vec3>& normals,
                     const std::vector<glm::dvec3>& light_points, const std::vector<std::uint64_t>& already_hidden = {});

 private:
  ClSession& session_;
  const DeviceSurface& surface_;
  double offset_;
  ProgramRecord record_;
  cl::Kernel kernel_;
};

}  // namespace algray
