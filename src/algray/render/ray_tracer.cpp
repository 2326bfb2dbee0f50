// Host side of the secondary-ray kernel: uploads rays, launches, reads the hit records back.
#include "algray/render/ray_tracer.h"

namespace algray {

RayTracer::RayTracer(ClSession& session, ProgramCache& cache, const KernelConfig& config, const DeviceSurface& surface)
    : session_(session), surface_(surface), lanes_(static_cast<std::size_t>(config.lanes)) {
  kernel_ = cache.kernel(session, config, &record_);
  largest_group_ = largest_group(kernel_, session.info.device);
}

TracedBatch RayTracer::trace(const std::vector<PixelRay>& rays) {
  TracedBatch batch;
  const std::size_t count = rays.size();
  batch.hits.resize(count);
  if (count == 0) return batch;
  const bool is_double = surface_.precision() == Precision::Double;
  const std::size_t real4_size = 4 * (is_double ? sizeof(double) : sizeof(float));
  const cl::Context& ctx = session_.context;
  if (count > capacity_) {
    capacity_ = count;
    origins_ = cl::Buffer(ctx, CL_MEM_READ_ONLY, capacity_ * real4_size);
    directions_ = cl::Buffer(ctx, CL_MEM_READ_ONLY, capacity_ * real4_size);
    out_ = cl::Buffer(ctx, CL_MEM_WRITE_ONLY, capacity_ * sizeof(HitRecord));
  }
  cl::CommandQueue& queue = session_.queue;
  staging_.pack(count, is_double, [&](std::size_t i) { return rays[i].origin; });
  staging_.write(queue, origins_);
  staging_.pack(count, is_double, [&](std::size_t i) { return rays[i].direction; });
  staging_.write(queue, directions_);
  KernelBinder args(kernel_, "trace", surface_.precision());
  args.plain("origins", origins_);
  args.plain("directions", directions_);
  args.plain("count", static_cast<cl_uint>(count));
  surface_.set_extent_args(args);
  surface_.set_surface_args(args);
  args.plain("out", out_);
  cl::Event done;
  const RayLaunch launch = ray_launch((count + lanes_ - 1) / lanes_, largest_group_);
  queue.enqueueNDRangeKernel(kernel_, cl::NullRange, launch.global, launch.local, nullptr, &done);
  done.wait();
  batch.kernel_ms = ms_between(done);
  queue.enqueueReadBuffer(out_, CL_TRUE, 0, count * sizeof(HitRecord), batch.hits.data());
  return batch;
}

}  // namespace algray
