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

// Kernel arguments whose type follows REAL.
class RealArgs {
 public:
  RealArgs(cl::Kernel& k, Precision p) : kernel_(k), double_(p == Precision::Double) {}
  void vec(cl_uint index, const glm::dvec3& v, double w = 0) {
    if (double_) kernel_.setArg(index, cl_double4{{v.x, v.y, v.z, w}});
    else kernel_.setArg(index, cl_float4{{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z),
                                          static_cast<float>(w)}});
  }
  void scalar(cl_uint index, double v) {
    if (double_) kernel_.setArg(index, v);
    else kernel_.setArg(index, static_cast<float>(v));
  }

 private:
  cl::Kernel& kernel_;
  bool double_;
};

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
  for (const Monomial& m : scaled.monomials()) {
    data.exponents.push_back(static_cast<cl_uint>(m.i) | static_cast<cl_uint>(m.j) << 8 |
                             static_cast<cl_uint>(m.k) << 16);
    data.coefficients.push_back(m.coef);
    data.abs_sum += std::fabs(m.coef);
  }
  return data;
}

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
  const double eps = precision == Precision::Double ? std::numeric_limits<double>::epsilon()
                                                    : std::numeric_limits<float>::epsilon();
  config.tolerance = std::max(scene.render.tolerance, 2 * eps);
  config.max_iterations = scene.render.max_iterations;
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
  cl::Buffer coefs;
  if (precision == Precision::Double) {
    coefs = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, surface.coefficients.size() * sizeof(double),
                       const_cast<double*>(surface.coefficients.data()));
  } else {
    std::vector<float> f(surface.coefficients.begin(), surface.coefficients.end());
    coefs = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, f.size() * sizeof(float), f.data());
  }
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  cl::Buffer out(ctx, CL_MEM_WRITE_ONLY, pixels * sizeof(HitRecord));

  const double eps = precision == Precision::Double ? std::numeric_limits<double>::epsilon()
                                                    : std::numeric_limits<float>::epsilon();
  const RayBasis& b = result.basis;
  RealArgs real(kernel, precision);
  real.vec(0, b.o00);
  real.vec(1, b.ou);
  real.vec(2, b.ov);
  real.vec(3, b.d00);
  real.vec(4, b.du);
  real.vec(5, b.dv);
  real.vec(6, scene.extent.unit_centre());
  real.scalar(7, 1 / scene.extent.unit_scale());
  real.vec(8, scene.extent.unit_box_half());
  kernel.setArg(9, static_cast<cl_int>(scene.extent.kind == ExtentKind::Sphere ? ALGRAY_EXTENT_SPHERE
                                                                                  : ALGRAY_EXTENT_BOX));
  kernel.setArg(10, exps);
  kernel.setArg(11, coefs);
  kernel.setArg(12, static_cast<cl_uint>(surface.coefficients.size()));
  real.scalar(13, kTangentNoiseFactor * surface.degree * eps * surface.abs_sum);
  kernel.setArg(14, static_cast<cl_uint>(width));
  kernel.setArg(19, out);

  PassStats pass;
  pass.name = "primary";
  const int tile = scene.render.tile_size;
  const int tiles_x = (width + tile - 1) / tile, tiles_y = (height + tile - 1) / tile;
  const int tiles = tiles_x * tiles_y;
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      const int x0 = tx * tile, y0 = ty * tile;
      const int w = std::min(tile, width - x0), h = std::min(tile, height - y0);
      kernel.setArg(15, static_cast<cl_uint>(x0));
      kernel.setArg(16, static_cast<cl_uint>(y0));
      kernel.setArg(17, static_cast<cl_uint>(w));
      kernel.setArg(18, static_cast<cl_uint>(h));
      cl::Event done;
      session_.queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(static_cast<std::size_t>(w),
                                                                             static_cast<std::size_t>(h)),
                                          cl::NullRange, nullptr, &done);
      // One tile at a time keeps each launch short (no GPU watchdog) and lets progress be shown.
      done.wait();
      pass.kernel_ms += ms_between(done);
      ++pass.launches;
      if (show_progress) {
        std::fprintf(stderr, "\rrendering %s: %3d%% (%d/%d tiles)", scene.name.c_str(),
                     100 * pass.launches / tiles, pass.launches, tiles);
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
