// Surface preparation for the kernels, their argument helpers, and the surface's device buffers.
#include "algray/render/device_surface.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "algray/render/screen_form.h"
#include "kernels/algray_shared.h"

namespace algray {
namespace {

// C(n, k) for 0 <= k <= n <= degree, row-major with rows of degree + 1 entries, as the kernels expect; sixteen
// zeros of padding let a kernel read any row as one 16-wide vector.
std::vector<double> binomial_table(int degree) {
  const int n1 = degree + 1;
  std::vector<double> t(static_cast<std::size_t>(n1 * n1 + 16), 0.0);
  for (int n = 0; n <= degree; ++n) {
    t[static_cast<std::size_t>(n * n1)] = 1;
    for (int k = 1; k <= n; ++k)
      t[static_cast<std::size_t>(n * n1 + k)] = t[static_cast<std::size_t>((n - 1) * n1 + k - 1)] +
                                                (k < n ? t[static_cast<std::size_t>((n - 1) * n1 + k)] : 0);
  }
  return t;
}

}  // namespace

RayLaunch ray_launch(std::size_t count, std::size_t largest_group) {
  // 64 fills a wavefront on AMD and two warps on NVIDIA, and is a multiple of PoCL's vector widths; a kernel
  // too large for it on some device gets the largest power of two that device allows.
  std::size_t group = 64;
  while (group > 1 && group > largest_group) group /= 2;
  // Rows of 16,384 work-items (kernels/ray.h launch_item_index), fewer than 65,536 of them up to 2^30 rays, far
  // past any batch the memory bound lets through: PoCL specialises a kernel for launches whose every dimension is
  // under 65,536 work-items and compiles it again, uninterruptibly, for the first one past that, so a 1024^2 frame
  // after small ones stalled for a second.
  constexpr std::size_t row = 16384;  // a multiple of every group size here
  const std::size_t whole = (count + group - 1) / group * group;
  if (whole <= row) return {cl::NDRange(std::max(whole, group), 1), cl::NDRange(group, 1)};
  return {cl::NDRange(row, (whole + row - 1) / row), cl::NDRange(group, 1)};
}

RayLaunch primary_launch(int lanes, int width, int height, std::size_t largest_group) {
  // One ray per work-item: 8 x 8 pixels, as many as ray_launch's group and each one's neighbours' rays alike.
  // Lanes multiply each work-item's private arrays, and PoCL keeps a work-group's on one thread's stack (its own
  // choice of up to 4096 items overflowed it): rows of 16 work-items, 128 pixels at 8 lanes.
  std::size_t group_x = lanes == 1 ? 8 : 16, group_y = lanes == 1 ? 8 : 1;
  while (group_x * group_y > std::max<std::size_t>(largest_group, 1)) (group_y > 1 ? group_y : group_x) /= 2;
  const auto whole_groups = [](std::size_t n, std::size_t group) { return (n + group - 1) / group * group; };
  const std::size_t items = (static_cast<std::size_t>(width) + static_cast<std::size_t>(lanes) - 1) /
                            static_cast<std::size_t>(lanes);
  return {cl::NDRange(whole_groups(items, group_x), whole_groups(static_cast<std::size_t>(height), group_y)),
          cl::NDRange(group_x, group_y)};
}

std::size_t largest_group(const cl::Kernel& kernel, const cl::Device& device) {
  return kernel.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device);
}

double ms_between(const cl::Event& e) {
  const auto start = e.getProfilingInfo<CL_PROFILING_COMMAND_START>();
  const auto end = e.getProfilingInfo<CL_PROFILING_COMMAND_END>();
  return static_cast<double>(end - start) * 1e-6;
}

// Buffer of REAL values from doubles.
cl::Buffer real_buffer(const cl::Context& ctx, const std::vector<double>& values, Precision precision) {
  if (precision == Precision::Double)
    return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, values.size() * sizeof(double),
                      const_cast<double*>(values.data()));
  std::vector<float> f(values.begin(), values.end());
  return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, f.size() * sizeof(float), f.data());
}

cl::Buffer real4_buffer(const cl::Context& ctx, const std::vector<glm::dvec3>& values, Precision precision) {
  Real4Staging staging;
  staging.pack(values.size(), precision == Precision::Double, [&](std::size_t i) { return values[i]; });
  return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, staging.bytes(), const_cast<void*>(staging.data()));
}

void Real4Staging::write(cl::CommandQueue& queue, const cl::Buffer& buffer) const {
  queue.enqueueWriteBuffer(buffer, CL_TRUE, 0, bytes(), data());
}

SurfaceData prepare_surface(const Scene& scene, std::size_t surface) {
  const glm::dvec3 c = scene.extent.unit_centre();
  const std::array<mpq_class, 3> centre{exact_rational(c.x), exact_rational(c.y), exact_rational(c.z)};
  // Exact translation and scaling: rounding happens once, to the final coefficients.
  Polynomial unit =
      scene.surfaces.at(surface).polynomial.translated_scaled(centre, exact_rational(scene.extent.unit_scale()));
  mpq_class largest = 0;
  for (const auto& [e, a] : unit.terms()) largest = std::max<mpq_class>(largest, abs(a));
  SurfaceData data;
  data.degree = unit.degree();
  Polynomial scaled;
  for (const auto& [e, a] : unit.terms()) scaled.add_term(e[0], e[1], e[2], a / largest);
  data.even_axes = 7;
  for (const Monomial& m : scaled.monomials()) {
    if (m.i % 2) data.even_axes &= ~1u;
    if (m.j % 2) data.even_axes &= ~2u;
    if (m.k % 2) data.even_axes &= ~4u;
    data.exponents.push_back(static_cast<cl_uint>(m.i) | static_cast<cl_uint>(m.j) << 8 |
                             static_cast<cl_uint>(m.k) << 16);
    data.coefficients.push_back(m.coef);
  }
  return data;
}

DeviceSurface::DeviceSurface(const cl::Context& ctx, const Scene& scene, Precision precision, std::size_t surface)
    : precision_(precision), extent_(scene.extent), data_(prepare_surface(scene, surface)) {
  exps_ = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, data_.exponents.size() * sizeof(cl_uint),
                     data_.exponents.data());
  // Mixed precision takes each coefficient as a float pair hi + lo (hi's, then lo's): rounding expanded,
  // cancelling coefficients to float alone would already change the surface.
  std::vector<double> coefficient_data = data_.coefficients;
  auto append_low_parts = [&] {
    for (double c : data_.coefficients) coefficient_data.push_back(c - static_cast<double>(static_cast<float>(c)));
  };
  if (precision == Precision::Mixed) append_low_parts();
  // Adaptive precision's float kernels take, after the coefficients, the sum of |a_m| over the monomials of each
  // degree 0..n: a ray whose coordinates are at most R has terms of size at most sum_d S_d R^d (ray_terms in
  // kernels/restrict.h), the cheap bound it decides by before it sums its own.
  if (precision == Precision::Adaptive) {
    std::vector<double> by_degree(static_cast<std::size_t>(data_.degree) + 1, 0.0);
    for (std::size_t m = 0; m < data_.coefficients.size(); ++m) {
      const cl_uint e = data_.exponents[m];
      by_degree[(e & 0xffu) + ((e >> 8) & 0xffu) + ((e >> 16) & 0xffu)] += std::fabs(data_.coefficients[m]);
    }
    coefficient_data.insert(coefficient_data.end(), by_degree.begin(), by_degree.end());
    // Then each coefficient's low part, as mixed precision's: confirming a flat root in float-float
    // (kernels/surface.h, direct_value_ff) needs the coefficients to float-float's digits.
    append_low_parts();
  }
  coefs_ = real_buffer(ctx, coefficient_data, precision);
  binomials_ = real_buffer(ctx, binomial_table(data_.degree), precision);
  // Each clipping plane (n, e), n.u + e <= 0 kept, as one REAL4.
  std::vector<double> clips;
  for (const glm::dvec4& p : extent_.unit_clips()) clips.insert(clips.end(), {p.x, p.y, p.z, p.w});
  if (!clips.empty()) clips_ = real_buffer(ctx, clips, precision);
}

void DeviceSurface::set_extent_args(KernelBinder& args) const {
  args.real_vec("extent_centre", extent_.unit_centre());
  args.real("extent_inv_scale", 1 / extent_.unit_scale());
  args.real_vec("extent_box_half", extent_.unit_box_half());
  // A cylinder's axis and a gate ride on its kind (kernels/algray_shared.h).
  const cl_int shape = extent_.kind == ExtentKind::Sphere ? ALGRAY_EXTENT_SPHERE
                       : extent_.kind == ExtentKind::Box  ? ALGRAY_EXTENT_BOX
                                                          : ALGRAY_EXTENT_CYLINDER + extent_.axis;
  args.plain("extent_kind", static_cast<cl_int>(shape + (extent_.gate ? ALGRAY_EXTENT_GATE : 0)));
  // Without planes the kernels never read clip_planes (kernels/ray.h).
  if (extent_.clips.empty())
    args.unused_buffer("clip_planes");
  else
    args.plain("clip_planes", clips_);
  args.plain("clip_count", static_cast<cl_uint>(extent_.clips.size()));
}

void DeviceSurface::set_surface_args(KernelBinder& args) const {
  args.plain("mono_exps", exps_);
  args.plain("mono_coefs", coefs_);
  args.plain("mono_count", static_cast<cl_uint>(data_.coefficients.size()));
  args.plain("binomials", binomials_);
  args.plain("even_axes", data_.even_axes);
}

struct DeviceSurface::ScreenCache {
  ScreenGeometry geometry;
  int height;
  ScreenForm form;
  bool same_camera(const ScreenGeometry& g, int h) const {
    return h == height && g.oc == geometry.oc && g.ox == geometry.ox && g.oy == geometry.oy && g.dc == geometry.dc &&
           g.dx == geometry.dx && g.dy == geometry.dy && g.t0 == geometry.t0 && g.xi_scale == geometry.xi_scale;
  }
};

cl::Buffer DeviceSurface::set_screen_args(KernelBinder& args, const cl::Context& ctx, const KernelConfig& config,
                                          const RayBasis& basis, int width, int height, int row0, int rows) const {
  if (config.ray_origin != RayOrigin::Screen) {
    args.unused_buffer("screen_rows");
    args.plain("screen_row0", cl_uint{0});
    for (const char* name : {"screen_t", "xi_scale", "xi_offset"}) args.real(name, 0);
    return {};
  }
  const ScreenGeometry geometry = screen_geometry(basis, width, height, extent_);
  if (!screen_ || !screen_->same_camera(geometry, height)) {
    screen_ = std::make_shared<const ScreenCache>(
        ScreenCache{geometry, height, ScreenForm(data_.exponents, data_.coefficients, data_.degree, geometry)});
  }
  const ScreenForm& form = screen_->form;
  cl::Buffer buffer = real_buffer(ctx, form.rows(row0, rows, height), precision_);
  args.plain("screen_rows", buffer);
  args.plain("screen_row0", static_cast<cl_uint>(row0));
  args.real("screen_t", geometry.t0);
  args.real("xi_scale", geometry.xi_scale);
  args.real("xi_offset", geometry.xi_offset);
  return buffer;
}

}  // namespace algray
