// Host side of the primary pass: surface preparation, kernel arguments, tiled dispatch and timing.
#include "renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

namespace algray {
namespace {

double ms_between(const cl::Event& e) {
  const auto start = e.getProfilingInfo<CL_PROFILING_COMMAND_START>();
  const auto end = e.getProfilingInfo<CL_PROFILING_COMMAND_END>();
  return static_cast<double>(end - start) * 1e-6;
}

// Sets kernel arguments in declaration order; REAL-typed ones follow the build's precision.
class KernelArgs {
 public:
  KernelArgs(cl::Kernel& k, Precision p) : kernel_(k), double_(p == Precision::Double) {}
  void real_vec(const glm::dvec3& v) {
    if (double_)
      kernel_.setArg(index_++, cl_double4{{v.x, v.y, v.z, 0}});
    else
      kernel_.setArg(index_++,
                     cl_float4{{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), 0}});
  }
  void real(double v) {
    if (double_)
      kernel_.setArg(index_++, v);
    else
      kernel_.setArg(index_++, static_cast<float>(v));
  }
  template <typename T>
  void plain(const T& v) {
    kernel_.setArg(index_++, v);
  }
  cl_uint next() const { return index_; }
  void skip(cl_uint n) { index_ += n; }

 private:
  cl::Kernel& kernel_;
  bool double_;
  cl_uint index_ = 0;
};

// Buffer of REAL values from doubles.
cl::Buffer real_buffer(const cl::Context& ctx, const std::vector<double>& values, Precision precision) {
  if (precision == Precision::Double)
    return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, values.size() * sizeof(double),
                      const_cast<double*>(values.data()));
  std::vector<float> f(values.begin(), values.end());
  return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, f.size() * sizeof(float), f.data());
}

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

SurfaceData prepare_surface(const Scene& scene) {
  const glm::dvec3 c = scene.extent.unit_centre();
  const std::array<mpq_class, 3> centre{exact_rational(c.x), exact_rational(c.y), exact_rational(c.z)};
  // Exact translation and scaling: rounding happens once, to the final coefficients.
  Polynomial unit = scene.polynomial.translated_scaled(centre, exact_rational(scene.extent.unit_scale()));
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

int default_tile_size(const DeviceInfo& device) { return device.type == "GPU" ? 256 : 1024; }

Precision resolve_precision(const Scene& scene, const DeviceInfo& device) {
  if (!scene.render.precision) return device.fp64 ? Precision::Double : Precision::Float;
  if (*scene.render.precision == Precision::Double && !device.fp64)
    throw DeviceError("device '" + device.name + "' has no double precision (cl_khr_fp64); use --precision float");
  return *scene.render.precision;
}

KernelConfig primary_config(const Scene& scene, Precision precision) {
  KernelConfig config;
  config.entry = "primary";
  config.degree = scene.polynomial.degree();
  config.precision = precision;
  config.isolation = scene.render.isolation;
  config.refinement = scene.render.refinement;
  config.ray_origin = scene.render.ray_origin;
  // Below a few units of roundoff the stopping rule can never trigger.
  const double eps =
      precision == Precision::Double ? std::numeric_limits<double>::epsilon() : std::numeric_limits<float>::epsilon();
  config.tolerance = std::max(scene.render.tolerance, 2 * eps);
  config.max_iterations =
      scene.render.max_iterations > 0 ? scene.render.max_iterations : default_max_iterations(scene.render.refinement);
  return config;
}

RenderResult Renderer::render(const Scene& scene, bool show_progress) {
  const auto wall_start = std::chrono::steady_clock::now();
  RenderResult result;
  const int width = scene.image.width, height = scene.image.height;
  const Precision precision = resolve_precision(scene, session_.info);
  result.config = primary_config(scene, precision);
  result.basis = make_ray_basis(scene.camera, width, height);

  ProgramRecord record;
  cl::Kernel kernel = cache_.kernel(session_, result.config, &record);
  result.programs.push_back(record);

  const SurfaceData surface = prepare_surface(scene);
  const cl::Context& ctx = session_.context;
  cl::Buffer exps(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, surface.exponents.size() * sizeof(cl_uint),
                  const_cast<cl_uint*>(surface.exponents.data()));
  // Mixed precision takes each coefficient as a float pair hi + lo (hi's, then lo's): rounding expanded,
  // cancelling coefficients to float alone would already change the surface.
  std::vector<double> coefficient_data = surface.coefficients;
  if (precision == Precision::Mixed)
    for (double c : surface.coefficients) coefficient_data.push_back(c - static_cast<double>(static_cast<float>(c)));
  const cl::Buffer coefs = real_buffer(ctx, coefficient_data, precision);
  const cl::Buffer binomials = real_buffer(ctx, binomial_table(surface.degree), precision);
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  cl::Buffer out(ctx, CL_MEM_WRITE_ONLY, pixels * sizeof(HitRecord));

  const RayBasis& b = result.basis;
  KernelArgs args(kernel, precision);
  args.real_vec(b.o00);
  args.real_vec(b.ou);
  args.real_vec(b.ov);
  args.real_vec(b.d00);
  args.real_vec(b.du);
  args.real_vec(b.dv);
  args.real_vec(scene.extent.unit_centre());
  args.real(1 / scene.extent.unit_scale());
  args.real_vec(scene.extent.unit_box_half());
  args.plain(static_cast<cl_int>(scene.extent.kind == ExtentKind::Sphere ? ALGRAY_EXTENT_SPHERE : ALGRAY_EXTENT_BOX));
  args.plain(exps);
  args.plain(coefs);
  args.plain(static_cast<cl_uint>(surface.coefficients.size()));
  args.plain(binomials);
  args.plain(surface.even_axes);
  args.plain(static_cast<cl_uint>(width));
  const cl_uint tile_arg = args.next();  // tile_x0, tile_y0, tile_w, tile_h: set per launch
  args.skip(4);
  args.plain(out);
  PassStats pass;
  pass.name = "primary";
  pass.program_key = record.key;
  const int tile = scene.render.tile_size > 0 ? scene.render.tile_size : default_tile_size(session_.info);
  const int tiles_x = (width + tile - 1) / tile, tiles_y = (height + tile - 1) / tile;
  const int tiles = tiles_x * tiles_y;
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      const int x0 = tx * tile, y0 = ty * tile;
      const int w = std::min(tile, width - x0), h = std::min(tile, height - y0);
      kernel.setArg(tile_arg, static_cast<cl_uint>(x0));
      kernel.setArg(tile_arg + 1, static_cast<cl_uint>(y0));
      kernel.setArg(tile_arg + 2, static_cast<cl_uint>(w));
      kernel.setArg(tile_arg + 3, static_cast<cl_uint>(h));
      cl::Event done;
      session_.queue.enqueueNDRangeKernel(kernel, cl::NullRange,
                                          cl::NDRange(static_cast<std::size_t>(w), static_cast<std::size_t>(h)),
                                          cl::NullRange, nullptr, &done);
      // One tile at a time keeps each launch short (no GPU watchdog) and lets progress be shown.
      done.wait();
      pass.kernel_ms += ms_between(done);
      ++pass.launches;
      if (show_progress) {
        std::fprintf(stderr, "\rrendering %s: %3d%% (%d/%d tiles)", scene.name.c_str(), 100 * pass.launches / tiles,
                     pass.launches, tiles);
        std::fflush(stderr);
      }
    }
  }
  if (show_progress) std::fprintf(stderr, "\n");
  pass.rays = pixels;

  result.hits.width = width;
  result.hits.height = height;
  result.hits.records.resize(pixels);
  session_.queue.enqueueReadBuffer(out, CL_TRUE, 0, pixels * sizeof(HitRecord), result.hits.records.data());
  pass.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall_start).count() -
                 record.build_ms;
  result.passes.push_back(pass);
  return result;
}

}  // namespace algray
