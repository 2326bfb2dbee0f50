// Runs a render plan: camera rays in tiles, shadow rays for every hit, then bounce by bounce the secondary rays.
#include "renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "ray_tracer.h"
#include "shade.h"
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

namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// Shadow rays from every hit of one batch; ray(i) is the ray of hit i (camera rays rebuilt exactly as the
// kernel traced them; secondary rays in double, which a float kernel traced rounded).
template <typename RayOf>
ShadowData trace_shadows(const Scene& scene, const RenderPlan& plan,
                         const std::vector<std::unique_ptr<ShadowTracer>>& tracers, const std::vector<HitRecord>& hits,
                         RayOf ray, PassStats& stats) {
  const auto start = std::chrono::steady_clock::now();
  ShadowData data;
  std::vector<glm::dvec3> points;
  std::vector<glm::vec3> normals;
  for (std::size_t i = 0; i < hits.size(); ++i) {
    const HitRecord& h = hits[i];
    if (!(h.flags & ALGRAY_HIT_FOUND)) continue;
    data.points.push_back(static_cast<std::uint32_t>(i));
    points.push_back(hit_point(ray(i), h));
    normals.emplace_back(h.normal_x, h.normal_y, h.normal_z);
  }
  for (int light : plan.shadow_lights) {
    // Each surface's kernel in turn; a light point one surface hides is not traced against the next. A ray
    // counts once, from the first surface's kernel, which traces every light point in front of the surface.
    std::vector<std::uint64_t> hidden;
    for (std::size_t s = 0; s < tracers.size(); ++s) {
      ShadowAnswer answer =
          tracers[s]->trace(points, normals, scene.lights[static_cast<std::size_t>(light)].sample_points(), hidden);
      if (!points.empty()) {
        stats.kernel_ms += answer.kernel_ms;
        stats.program_ms[s] += answer.kernel_ms;
        ++stats.launches;
      }
      if (s == 0) stats.rays += answer.rays_traced;
      hidden = std::move(answer.masks);
    }
    data.occlusion.push_back({light, std::move(hidden)});
  }
  stats.wall_ms += ms_since(start);
  return data;
}

// Keeps, per ray, the nearer of the hits found so far (surface `best`) and `other`'s hits (surface `index`).
// The solver work of both is added up, and a depth-limited isolation on either is kept, so the statistics
// and the solver channels count every surface's kernel.
void keep_nearest(std::vector<HitRecord>& best, std::vector<std::uint8_t>& best_surface,
                  const std::vector<HitRecord>& other, std::uint8_t index) {
  if (best_surface.empty()) best_surface.assign(best.size(), 0);
  for (std::size_t i = 0; i < best.size(); ++i) {
    const HitRecord& o = other[i];
    HitRecord& b = best[i];
    const std::uint32_t steps = std::min(0xffffu, (b.work & 0xffffu) + (o.work & 0xffffu));
    const std::uint32_t iterations = std::min(0xffffu, (b.work >> 16) + (o.work >> 16));
    const std::uint32_t shared_flags = (b.flags | o.flags) & (ALGRAY_HIT_BUDGET | ALGRAY_HIT_IN_EXTENT);
    const double tb = static_cast<double>(b.t_hi) + static_cast<double>(b.t_lo);
    const double to = static_cast<double>(o.t_hi) + static_cast<double>(o.t_lo);
    if ((o.flags & ALGRAY_HIT_FOUND) && (!(b.flags & ALGRAY_HIT_FOUND) || to < tb)) {
      b = o;
      best_surface[i] = index;
    }
    b.work = steps | iterations << 16;
    b.flags |= shared_flags;
  }
}

}  // namespace

// A ray waiting to be continued: the traced camera ray it adds to, its weight, the ray and its hit.
struct Renderer::Bounce {
  std::uint32_t sample;
  double weight;
  PixelRay ray;
  HitRecord hit;
  std::uint8_t surface;  // which of the scene's surfaces it hit
};

// What the passes after the primary one share while a render runs: the kernels built so far and the stats.
struct Renderer::Passes {
  const Scene& scene;
  Precision precision;
  std::vector<std::unique_ptr<DeviceSurface>> surfaces;  // one per scene surface
  RenderResult& result;
  std::vector<PassStats> stats;                        // one per planned pass, in plan order
  std::vector<std::unique_ptr<ShadowTracer>> shadows;  // one per surface, when the plan has a shadow pass
  std::vector<std::unique_ptr<RayTracer>> rays;        // one per surface, when it has a secondary pass

  PassStats* stats_of(const std::string& name) {
    for (std::size_t i = 0; i < stats.size(); ++i)
      if (result.plan.passes[i].name == name) return &stats[i];
    return nullptr;
  }
};

RenderResult Renderer::render(const Scene& scene, bool show_progress) {
  RenderResult result;
  const Precision precision = resolve_precision(scene, session_.info);
  result.plan = make_render_plan(scene, precision);
  check_plan_fits(result.plan, session_.info);
  result.config = primary_config(scene, precision);
  Passes passes{scene, precision, {}, result, std::vector<PassStats>(result.plan.passes.size()), {}, {}};
  for (std::size_t i = 0; i < scene.surfaces.size(); ++i)
    passes.surfaces.push_back(std::make_unique<DeviceSurface>(session_.context, scene, precision, i));
  run_primary(passes, show_progress);

  if (PassStats* stats = passes.stats_of("shadow")) {
    const double offset = shadow_offset_unit(precision) * scene.extent.unit_scale();
    for (std::size_t i = 0; i < scene.surfaces.size(); ++i) {
      passes.shadows.push_back(std::make_unique<ShadowTracer>(session_, cache_, result.plan.find("shadow")->kernels[i],
                                                              *passes.surfaces[i], offset));
      result.programs.push_back(passes.shadows.back()->program());
      stats->program_keys.push_back(passes.shadows.back()->program().key);
      stats->program_ms.push_back(0);
    }
  }
  // Every secondary pass launches the same trace kernels.
  for (const char* name : {"reflection", "transmission", "antialias"})
    if (PassStats* stats = passes.stats_of(name)) {
      if (passes.rays.empty())
        for (std::size_t i = 0; i < scene.surfaces.size(); ++i) {
          passes.rays.push_back(
              std::make_unique<RayTracer>(session_, cache_, result.plan.find(name)->kernels[i], *passes.surfaces[i]));
          result.programs.push_back(passes.rays.back()->program());
        }
      for (const auto& tracer : passes.rays) {
        stats->program_keys.push_back(tracer->program().key);
        stats->program_ms.push_back(0);
      }
    }

  const bool single = precision != Precision::Double;
  const int width = result.hits.width;
  auto camera_ray = [&](std::size_t i) {
    return pixel_ray(result.basis, single, static_cast<int>(i % width), static_cast<int>(i / width));
  };
  if (!passes.shadows.empty())
    result.shadows =
        trace_shadows(scene, result.plan, passes.shadows, result.hits.records, camera_ray, *passes.stats_of("shadow"));
  std::vector<Bounce> first;
  for (std::size_t i = 0; i < result.hits.records.size(); ++i)
    if (result.hits.records[i].flags & ALGRAY_HIT_FOUND)
      first.push_back({static_cast<std::uint32_t>(i), 1.0, camera_ray(i), result.hits.records[i],
                       static_cast<std::uint8_t>(result.hits.surface_of(i))});
  run_bounces(passes, std::move(first), false);
  if (result.plan.refine_samples > 1) run_antialias(passes);

  for (std::size_t i = 0; i < passes.stats.size(); ++i) {
    passes.stats[i].name = result.plan.passes[i].name;
    result.passes.push_back(passes.stats[i]);
  }
  return result;
}

void Renderer::run_primary(Passes& passes, bool show_progress) {
  const Scene& scene = passes.scene;
  RenderResult& result = passes.result;
  PassStats& pass = *passes.stats_of("primary");
  const int width = result.plan.trace_width(), height = result.plan.trace_height();
  result.basis = make_ray_basis(scene.camera, width, height);
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  result.hits.width = width;
  result.hits.height = height;
  const int tile = scene.render.tile_size > 0 ? scene.render.tile_size : default_tile_size(session_.info);
  const int tiles_x = (width + tile - 1) / tile, tiles_y = (height + tile - 1) / tile;
  const int tiles = tiles_x * tiles_y * static_cast<int>(scene.surfaces.size());
  for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
    const auto wall_start = std::chrono::steady_clock::now();
    const DeviceSurface& surface = *passes.surfaces[s];
    ProgramRecord record;
    cl::Kernel kernel = cache_.kernel(session_, result.plan.find("primary")->kernels[s], &record);
    result.programs.push_back(record);
    pass.program_keys.push_back(record.key);
    pass.program_ms.push_back(0);
    cl::Buffer out(session_.context, CL_MEM_WRITE_ONLY, pixels * sizeof(HitRecord));
    KernelArgs args(kernel, surface.precision());
    args.ray_basis(result.basis);
    surface.set_extent_args(args);
    surface.set_surface_args(args);
    const cl::Buffer screen_rows = surface.set_screen_args(args, session_.context, result.plan.find("primary")->kernels[s],
                                                           result.basis, width, height, 0, height);
    args.plain(static_cast<cl_uint>(width));
    const cl_uint tile_arg = args.next();  // tile_x0, tile_y0, tile_w, tile_h: set per launch
    args.skip(4);
    args.plain(out);
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
        pass.program_ms[s] += ms_between(done);
        ++pass.launches;
        if (show_progress) {
          std::fprintf(stderr, "\rrendering %s: %3d%% (%d/%d tiles)", scene.name.c_str(), 100 * pass.launches / tiles,
                       pass.launches, tiles);
          std::fflush(stderr);
        }
      }
    }
    if (s == 0) pass.rays += pixels;  // each camera ray once, however many surfaces it is tested against
    std::vector<HitRecord> hits(pixels);
    session_.queue.enqueueReadBuffer(out, CL_TRUE, 0, pixels * sizeof(HitRecord), hits.data());
    if (s == 0)
      result.hits.records = std::move(hits);
    else
      keep_nearest(result.hits.records, result.hits.surface, hits, static_cast<std::uint8_t>(s));
    pass.wall_ms += ms_since(wall_start) - record.build_ms;
  }
  if (show_progress) std::fprintf(stderr, "\n");
}

// Traces one batch of secondary rays, then the shadow rays of its hits.
void Renderer::trace_batch(Passes& passes, SecondaryBatch& batch) {
  const auto start = std::chrono::steady_clock::now();
  PassStats& stats = *passes.stats_of(batch.pass);
  for (std::size_t s = 0; s < passes.rays.size(); ++s) {
    TracedBatch traced = passes.rays[s]->trace(batch.rays);
    if (s == 0)
      batch.hits = std::move(traced.hits);
    else
      keep_nearest(batch.hits, batch.hit_surface, traced.hits, static_cast<std::uint8_t>(s));
    stats.kernel_ms += traced.kernel_ms;
    stats.program_ms[s] += traced.kernel_ms;
    if (s == 0) stats.rays += batch.rays.size();
    ++stats.launches;
  }
  stats.wall_ms += ms_since(start);
  if (!passes.shadows.empty())
    batch.shadows = trace_shadows(
        passes.scene, passes.result.plan, passes.shadows, batch.hits, [&](std::size_t i) { return batch.rays[i]; },
        *passes.stats_of("shadow"));
}

void Renderer::run_bounces(Passes& passes, std::vector<Bounce> current, bool refinement) {
  const Scene& scene = passes.scene;
  const double offset = shadow_offset_unit(passes.precision) * scene.extent.unit_scale();
  // Below this a bounce cannot change a pixel's 8-bit colour.
  constexpr double kNegligibleWeight = 1.0 / 512;
  const double pixel_share =
      refinement ? static_cast<double>(passes.result.plan.refine_samples) * passes.result.plan.refine_samples : 1.0;
  const char* const names[2] = {"reflection", "transmission"};
  const bool wanted[2] = {passes.stats_of(names[0]) != nullptr, passes.stats_of(names[1]) != nullptr};
  for (int depth = 1; depth <= scene.render.max_depth && !current.empty(); ++depth) {
    std::vector<Bounce> next;
    for (int k = 0; k < 2; ++k) {
      if (!wanted[k]) continue;
      SecondaryBatch batch;
      batch.pass = names[k];
      batch.depth = depth;
      batch.refinement = refinement;
      for (const Bounce& b : current) {
        const Materials& sides = scene.surfaces[b.surface].materials;
        const Material& m = (b.hit.flags & ALGRAY_HIT_BACK) ? sides.back : sides.front;
        const double share = k == 0 ? m.reflectivity : m.transparency;
        // A refined pixel's rays carry 1/n^2 each: the cut-off is on the share of the pixel they stand for.
        if (b.weight * share * pixel_share < kNegligibleWeight) continue;
        const glm::dvec3 p = hit_point(b.ray, b.hit);
        const glm::dvec3 n(b.hit.normal_x, b.hit.normal_y, b.hit.normal_z);  // faces the incoming ray
        const glm::dvec3 d = b.ray.direction;
        // Off the surface on the side the new ray leaves into, as shadow rays are, so it cannot find its own hit.
        const PixelRay ray =
            k == 0 ? PixelRay{p + offset * n, d - 2 * glm::dot(d, n) * n} : PixelRay{p - offset * n, d};
        batch.sample.push_back(b.sample);
        batch.weight.push_back(b.weight * share);
        batch.rays.push_back(ray);
      }
      if (batch.rays.empty()) continue;
      trace_batch(passes, batch);
      for (std::size_t i = 0; i < batch.rays.size(); ++i)
        if (batch.hits[i].flags & ALGRAY_HIT_FOUND)
          next.push_back({batch.sample[i], batch.weight[i], batch.rays[i], batch.hits[i],
                          batch.hit_surface.empty() ? std::uint8_t{0} : batch.hit_surface[i]});
      passes.result.secondary.push_back(std::move(batch));
    }
    current = std::move(next);
  }
}

void Renderer::run_antialias(Passes& passes) {
  RenderResult& result = passes.result;
  const RenderPlan& plan = result.plan;
  // The image as it stands, one ray per pixel: where a pixel differs from a neighbour, it gets n x n rays.
  const FrameImage coarse = shade_frame(passes.scene, result);
  const int w = coarse.width, h = coarse.height, n = plan.refine_samples;
  auto differs = [&](int x0, int y0, int x1, int y1) {
    if (x1 < 0 || y1 < 0 || x1 >= w || y1 >= h) return false;
    const std::size_t a = 4 * (static_cast<std::size_t>(y0) * w + x0), b = 4 * (static_cast<std::size_t>(y1) * w + x1);
    for (int c = 0; c < 4; ++c)
      if (std::fabs(coarse.rgba[a + c] - coarse.rgba[b + c]) > plan.refine_threshold) return true;
    return false;
  };
  result.refined.assign(static_cast<std::size_t>(w) * h, 0);
  const bool single = passes.precision != Precision::Double;
  // The rays of the n-times finer grid, so that a refined pixel gets exactly the rays uniform n x n would trace.
  const RayBasis fine = make_ray_basis(passes.scene.camera, w * n, h * n);
  SecondaryBatch batch;
  batch.pass = "antialias";
  batch.depth = 0;
  batch.refinement = true;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!(differs(x, y, x - 1, y) || differs(x, y, x + 1, y) || differs(x, y, x, y - 1) || differs(x, y, x, y + 1)))
        continue;
      const std::uint32_t pixel = static_cast<std::uint32_t>(y * w + x);
      result.refined[pixel] = 1;
      for (int sy = 0; sy < n; ++sy)
        for (int sx = 0; sx < n; ++sx) {
          batch.sample.push_back(pixel);
          batch.weight.push_back(1.0 / (n * n));
          batch.rays.push_back(pixel_ray(fine, single, x * n + sx, y * n + sy));
        }
    }
  if (batch.rays.empty()) return;
  trace_batch(passes, batch);
  std::vector<Bounce> first;
  for (std::size_t i = 0; i < batch.rays.size(); ++i)
    if (batch.hits[i].flags & ALGRAY_HIT_FOUND)
      first.push_back({batch.sample[i], batch.weight[i], batch.rays[i], batch.hits[i],
                       batch.hit_surface.empty() ? std::uint8_t{0} : batch.hit_surface[i]});
  result.secondary.push_back(std::move(batch));
  run_bounces(passes, std::move(first), true);
}

}  // namespace algray
