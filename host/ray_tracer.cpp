// Host side of the secondary-ray kernel: uploads rays, launches, reads the hit records back.
#include "ray_tracer.h"

namespace algray {

RayTracer::RayTracer(ClSession& session, ProgramCache& cache, const KernelConfig& config,
                     const DeviceSurface& surface)
    : session_(session), surface_(surface) {
  kernel_ = cache.kernel(session, config, &record_);
}

TracedBatch RayTracer::trace(const std::vector<PixelRay>& rays) {
  TracedBatch batch;
  const std::size_t count = rays.size();
  batch.hits.resize(count);
  if (count == 0) return batch;
  std::vector<glm::dvec3> origins, directions;
  origins.reserve(count);
  directions.reserve(count);
  for (const PixelRay& r : rays) {
    origins.push_back(r.origin);
    directions.push_back(r.direction);
  }
  const cl::Context& ctx = session_.context;
  const cl::Buffer origin_buffer = real4_buffer(ctx, origins, surface_.precision());
  const cl::Buffer direction_buffer = real4_buffer(ctx, directions, surface_.precision());
  cl::Buffer out(ctx, CL_MEM_WRITE_ONLY, count * sizeof(HitRecord));
  KernelArgs args(kernel_, surface_.precision());
  args.plain(origin_buffer);
  args.plain(direction_buffer);
  args.plain(static_cast<cl_uint>(count));
  surface_.set_extent_args(args);
  surface_.set_surface_args(args);
  args.plain(out);
  cl::Event done;
  session_.queue.enqueueNDRangeKernel(kernel_, cl::NullRange, cl::NDRange(count), cl::NullRange, nullptr, &done);
  done.wait();
  batch.kernel_ms = ms_between(done);
  session_.queue.enqueueReadBuffer(out, CL_TRUE, 0, count * sizeof(HitRecord), batch.hits.data());
  return batch;
}

}  // namespace algray
