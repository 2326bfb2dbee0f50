// Host side of the shadow kernel: uploads surface points and light points, launches, reads the masks back.
#include "algray/render/shadow_tracer.h"

#include <stdexcept>

namespace algray {

std::uint64_t LightGroup::mask_of(const Member& m, std::uint64_t group_mask) const {
  const std::uint64_t low = m.count == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << m.count) - 1;
  return (group_mask >> m.first_bit) & low;
}

std::vector<LightGroup> group_lights(const std::vector<std::vector<glm::dvec3>>& light_points) {
  std::vector<LightGroup> groups;
  for (std::size_t l = 0; l < light_points.size(); ++l) {
    const std::vector<glm::dvec3>& points = light_points[l];
    if (points.empty() || points.size() > 64) throw std::invalid_argument("a light has 1 to 64 sample points");
    if (groups.empty() || groups.back().points.size() + points.size() > 64) groups.emplace_back();
    LightGroup& g = groups.back();
    g.members.push_back({l, static_cast<int>(g.points.size()), static_cast<int>(points.size())});
    g.points.insert(g.points.end(), points.begin(), points.end());
  }
  return groups;
}

void ShadowPoints::upload(const std::vector<glm::dvec3>& points, const std::vector<glm::vec3>& normals) {
  if (normals.size() != points.size()) throw std::invalid_argument("one normal per surface point");
  count_ = points.size();
  if (count_ == 0) return;
  const bool is_double = precision_ == Precision::Double;
  const std::size_t real_size = is_double ? sizeof(double) : sizeof(float);
  const cl::Context& ctx = session_.context;
  if (count_ > capacity_) {
    capacity_ = count_;
    points_ = cl::Buffer(ctx, CL_MEM_READ_ONLY, capacity_ * 4 * real_size);
    normals_ = cl::Buffer(ctx, CL_MEM_READ_ONLY, capacity_ * 4 * sizeof(float));
    masks_ = cl::Buffer(ctx, CL_MEM_READ_WRITE, capacity_ * sizeof(cl_ulong));
    if (precision_ == Precision::Adaptive)
      undecided_ = cl::Buffer(ctx, CL_MEM_WRITE_ONLY, capacity_ * sizeof(cl_ulong));
  }
  staging_.pack(count_, is_double, [&](std::size_t i) { return points[i]; });
  staging_.write(session_.queue, points_);
  // Normals are float4 in every precision; a float survives the round trip through double exactly.
  staging_.pack(count_, false, [&](std::size_t i) { return glm::dvec3(normals[i]); });
  staging_.write(session_.queue, normals_);
}

ShadowTracer::ShadowTracer(ClSession& session, ProgramCache& cache, const KernelConfig& config,
                           const DeviceSurface& surface, double offset)
    : session_(session), surface_(surface), offset_(offset), entry_(config.entry) {
  kernel_ = cache.kernel(session, config, &record_);
  largest_group_ = largest_group(kernel_, session.info.device);
  traced_ = cl::Buffer(session.context, CL_MEM_READ_WRITE, sizeof(cl_uint));
}

ShadowAnswer ShadowTracer::trace(const std::vector<glm::dvec3>& points, const std::vector<glm::vec3>& normals,
                                 const std::vector<glm::dvec3>& light_points,
                                 const std::vector<std::uint64_t>& already_hidden) {
  ShadowPoints uploaded(session_, surface_.precision());
  uploaded.upload(points, normals);
  return trace(uploaded, light_points, already_hidden);
}

ShadowAnswer ShadowTracer::trace(ShadowPoints& points, const std::vector<glm::dvec3>& light_points,
                                 const std::vector<std::uint64_t>& already_hidden) {
  if (light_points.empty() || light_points.size() > 64)
    throw std::invalid_argument("a shadow query takes 1 to 64 light points");
  if (points.precision_ != surface_.precision())
    throw std::invalid_argument("shadow points uploaded in another precision than the surface's");
  ShadowAnswer answer;
  const std::size_t count = points.size();
  if (!already_hidden.empty() && already_hidden.size() != count)
    throw std::invalid_argument("one already-hidden mask per surface point");
  answer.masks = already_hidden.empty() ? std::vector<std::uint64_t>(count, 0) : already_hidden;
  if (count == 0) return answer;

  const Precision precision = surface_.precision();
  cl::CommandQueue& queue = session_.queue;
  queue.enqueueWriteBuffer(points.masks_, CL_TRUE, 0, count * sizeof(cl_ulong), answer.masks.data());
  // Padded to a multiple of 16 with the last point: the point form reads the light points a block of lanes at a
  // time (kernels/shadow.h), past light_count in the last block.
  std::vector<glm::dvec3> padded = light_points;
  padded.resize((light_points.size() + 15) / 16 * 16, light_points.back());
  const cl::Buffer light_buffer = real4_buffer(session_.context, padded, precision);
  cl_uint traced = 0;
  queue.enqueueWriteBuffer(traced_, CL_TRUE, 0, sizeof(cl_uint), &traced);

  KernelBinder args(kernel_, entry_, precision);
  args.plain("points", points.points_);
  args.plain("normals", points.normals_);
  args.plain("point_count", static_cast<cl_uint>(count));
  args.plain("light_points", light_buffer);
  args.plain("light_count", static_cast<cl_uint>(light_points.size()));
  args.real("offset", offset_);
  surface_.set_extent_args(args);
  surface_.set_surface_args(args);
  args.plain("occluded", points.masks_);
  args.plain("rays_traced", traced_);
  if (precision == Precision::Adaptive)
    args.plain("undecided", points.undecided_);
  else
    args.unused_buffer("undecided");
  cl::Event done;
  const RayLaunch launch = ray_launch(count, largest_group_);
  queue.enqueueNDRangeKernel(kernel_, cl::NullRange, launch.global, launch.local, nullptr, &done);
  done.wait();
  answer.kernel_ms = ms_between(done);
  queue.enqueueReadBuffer(points.masks_, CL_TRUE, 0, count * sizeof(cl_ulong), answer.masks.data());
  queue.enqueueReadBuffer(traced_, CL_TRUE, 0, sizeof(cl_uint), &traced);
  if (precision == Precision::Adaptive) {
    answer.undecided.resize(count);
    queue.enqueueReadBuffer(points.undecided_, CL_TRUE, 0, count * sizeof(cl_ulong), answer.undecided.data());
  }
  answer.rays_traced = traced;
  return answer;
}

}  // namespace algray
