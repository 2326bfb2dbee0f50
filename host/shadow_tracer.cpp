// Host side of the shadow kernel: uploads surface points and light points, launches, reads the masks back.
#include "shadow_tracer.h"

#include <stdexcept>

namespace algray {

ShadowTracer::ShadowTracer(ClSession& session, ProgramCache& cache, const KernelConfig& config,
                           const DeviceSurface& surface, double offset)
    : session_(session), surface_(surface), offset_(offset) {
  kernel_ = cache.kernel(session, config, &record_);
}

ShadowAnswer ShadowTracer::trace(const std::vector<glm::dvec3>& points, const std::vector<glm::vec3>& normals,
                                 const std::vector<glm::dvec3>& light_points,
                                 const std::vector<std::uint64_t>& already_hidden) {
  if (light_points.empty() || light_points.size() > 64)
    throw std::invalid_argument("a shadow query takes 1 to 64 light points");
  if (normals.size() != points.size()) throw std::invalid_argument("one normal per surface point");
  ShadowAnswer answer;
  const std::size_t count = points.size();
  if (!already_hidden.empty() && already_hidden.size() != count)
    throw std::invalid_argument("one already-hidden mask per surface point");
  answer.masks = already_hidden.empty() ? std::vector<std::uint64_t>(count, 0) : already_hidden;
  if (count == 0) return answer;

  std::vector<float> normal_data;
  normal_data.reserve(4 * count);
  for (const glm::vec3& n : normals) normal_data.insert(normal_data.end(), {n.x, n.y, n.z, 0});
  const cl::Context& ctx = session_.context;
  const Precision precision = surface_.precision();
  const cl::Buffer point_buffer = real4_buffer(ctx, points, precision);
  const cl::Buffer normal_buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, normal_data.size() * sizeof(float),
                                 normal_data.data());
  const cl::Buffer light_buffer = real4_buffer(ctx, light_points, precision);
  cl::Buffer masks(ctx, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, count * sizeof(cl_ulong), answer.masks.data());
  cl_uint traced = 0;
  cl::Buffer traced_buffer(ctx, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, sizeof(cl_uint), &traced);

  KernelArgs args(kernel_, precision);
  args.plain(point_buffer);
  args.plain(normal_buffer);
  args.plain(static_cast<cl_uint>(count));
  args.plain(light_buffer);
  args.plain(static_cast<cl_uint>(light_points.size()));
  args.real(offset_);
  surface_.set_extent_args(args);
  surface_.set_surface_args(args);
  args.plain(masks);
  args.plain(traced_buffer);
  cl::Event done;
  session_.queue.enqueueNDRangeKernel(kernel_, cl::NullRange, cl::NDRange(count), cl::NullRange, nullptr, &done);
  done.wait();
  answer.kernel_ms = ms_between(done);
  session_.queue.enqueueReadBuffer(masks, CL_TRUE, 0, count * sizeof(cl_ulong), answer.masks.data());
  session_.queue.enqueueReadBuffer(traced_buffer, CL_TRUE, 0, sizeof(cl_uint), &traced);
  answer.rays_traced = traced;
  return answer;
}

}  // namespace algray
