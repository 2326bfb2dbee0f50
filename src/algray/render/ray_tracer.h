// The secondary-ray kernel on a batch of given rays: reflection and transmission rays against the surface.
#pragma once

#include <vector>

#include "algray/device/program_cache.h"
#include "algray/render/device_surface.h"
#include "algray/scene/camera.h"
#include "kernels/algray_shared.h"

namespace algray {

struct TracedBatch {
  std::vector<HitRecord> hits;  // one per ray, as the primary kernel writes them
  double kernel_ms = 0;
};

// Built once per render, then asked once per batch of rays. Its device buffers grow to the largest batch and
// are then reused.
class RayTracer {
 public:
  RayTracer(ClSession& session, ProgramCache& cache, const KernelConfig& config, const DeviceSurface& surface);
  const ProgramRecord& program() const { return record_; }
  TracedBatch trace(const std::vector<PixelRay>& rays);

 private:
  ClSession& session_;
  const DeviceSurface& surface_;
  ProgramRecord record_;
  cl::Kernel kernel_;
  std::size_t largest_group_ = 1;  // the kernel's work-group limit on the device
  std::size_t lanes_ = 1;          // rays per work-item (KernelConfig::lanes)
  std::size_t capacity_ = 0;
  cl::Buffer origins_, directions_, out_;
  Real4Staging staging_;  // REAL4 values before the upload
};

}  // namespace algray
