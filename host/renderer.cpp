// Runs a render plan: the primary pass in tiles, then the shadow pass, with timing per pass.
#include "renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "shadow_tracer.h"

namespace algray {

int default_tile_size(const DeviceInfo& device) { return device.type == "GPU" ? 256 : 1024; }

Precision resolve_precision(const Scene& scene, const DeviceInfo& device) {
  if (!scene.render.precision) return device.fp64 ? Precision::Double : Precision::Float;
  if (*scene.render.precision == Precision::Double && !device.fp64)
    throw DeviceError("device '" + device.name + "' has no double precision (cl_khr_fp64); use --precision float");
  return *scene.render.precision;
}

glm::dvec3 hit_point(const PixelRay& ray, const HitRecord& hit) {
  const double t = static_cast<double>(hit.t_hi) + static_cast<double>(hit.t_lo);
  return ray.origin + t * ray.direction;
}

RenderResult Renderer::render(const Scene& scene, bool show_progress) {
  RenderResult result;
  const Precision precision = resolve_precision(scene, session_.info);
  result.plan = make_render_plan(scene, precision);
  result.config = primary_config(scene, precision);

  const DeviceSurface surface(session_.context, scene, precision);

  run_primary(scene, surface, show_progress, result);
  if (result.plan.find("shadow")) run_shadow(scene, surface, result);
  return result;
}

void Renderer::run_primary(const Scene& scene, const DeviceSurface& surface, bool show_progress,
                           RenderResult& result) {
  const auto wall_start = std::chrono::steady_clock::now();
  const int width = result.plan.trace_width(), height = result.plan.trace_height();
  result.basis = make_ray_basis(scene.camera, width, height);
  ProgramRecord record;
  cl::Kernel kernel = cache_.kernel(session_, result.config, &record);
  result.programs.push_back(record);

  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  cl::Buffer out(session_.context, CL_MEM_WRITE_ONLY, pixels * sizeof(HitRecord));
  const RayBasis& b = result.basis;
  KernelArgs args(kernel, surface.precision());
  args.real_vec(b.o00);
  args.real_vec(b.ou);
  args.real_vec(b.ov);
  args.real_vec(b.d00);
  args.real_vec(b.du);
  args.real_vec(b.dv);
  surface.set_extent_args(args);
  surface.set_surface_args(args);
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
}

void Renderer::run_shadow(const Scene& scene, const DeviceSurface& surface, RenderResult& result) {
  const auto wall_start = std::chrono::steady_clock::now();
  const PlannedPass& planned = *result.plan.find("shadow");
  ShadowTracer tracer(session_, cache_, planned.kernel, surface,
                      shadow_offset_unit(surface.precision()) * scene.extent.unit_scale());
  result.programs.push_back(tracer.program());

  // The surface points: every hit, at the exact point of the ray the kernel traced.
  const bool single = surface.precision() != Precision::Double;
  std::vector<glm::dvec3> points;
  std::vector<glm::vec3> normals;
  const HitBuffer& hits = result.hits;
  for (int y = 0; y < hits.height; ++y) {
    for (int x = 0; x < hits.width; ++x) {
      const HitRecord& h = hits.at(x, y);
      if (!(h.flags & ALGRAY_HIT_FOUND)) continue;
      result.shading_points.push_back(static_cast<std::uint32_t>(y * hits.width + x));
      points.push_back(hit_point(pixel_ray(result.basis, single, x, y), h));
      normals.emplace_back(h.normal_x, h.normal_y, h.normal_z);
    }
  }
  PassStats pass;
  pass.name = "shadow";
  pass.program_key = tracer.program().key;
  for (int light_index : result.plan.shadow_lights) {
    ShadowAnswer answer = tracer.trace(points, normals, scene.lights[static_cast<std::size_t>(light_index)].sample_points());
    pass.kernel_ms += answer.kernel_ms;
    pass.rays += answer.rays_traced;
    ++pass.launches;
    result.occlusion.push_back({light_index, std::move(answer.masks)});
  }
  pass.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall_start).count() -
                 tracer.program().build_ms;
  result.passes.push_back(pass);
}

}  // namespace algray
