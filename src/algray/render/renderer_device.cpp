// One device's passes over a tile: its kernels and tracers made ready, the camera rays of a tile, a batch of
// secondary rays, and the tile finished with its shadow rays, bounces and shading.
#include <cstdio>
#include <future>
#include <utility>

#include "algray/render/renderer_parts.h"

namespace algray {
using namespace renderer_parts;

// The device's camera-ray kernels, one per surface, and a tile's hit-record buffers.
void Renderer::prepare_primary(Passes& passes, bool first_device) {
  const RenderPlan& plan = passes.result.plan;
  PassStats& primary = *passes.stats_of(PassKind::Primary);
  // The largest tile: a tile's hit records are all the device holds for the camera rays. Their memory (32 MB
  // at 1024^2) is populated on another thread while this one loads the programs, a core's work either way.
  const std::size_t tile_rays = plan.tile_rays(), bytes = tile_memory_bytes(plan);
  // The last render's buffers where they hold this one's tile (a long-lived renderer's frames).
  TileWork& work = passes.work;
  const bool keep_primary = work.holds(tile_rays);
  const bool several = passes.scene.surfaces.size() > 1;
  if (!keep_primary) work.primary_out.reset();  // its memory goes before the new one is made
  if (!several || (work.other_out && work.other_out->capacity() < tile_rays)) work.other_out.reset();
  // The caller's memory, made while the device started, when it fits the tile (the first device only).
  std::future<PopulatedPages> hit_memory;
  if (!keep_primary)
    hit_memory = std::async(std::launch::async, [bytes, made = first_device ? passes.options.tile_memory : nullptr] {
        if (made) {
          try {
            PopulatedPages pages = made();
            if (pages.size() >= bytes && pages.size() <= 2 * bytes) return pages;
          } catch (...) {
            // the caller's could not be made (its memory, or the film before it): make ours below
          }
        }
        return PopulatedPages(bytes);
      });
  DeviceKernels& kernels = passes.kernels;
  for (const KernelConfig& config : plan.find(PassKind::Primary)->kernels) {
    ProgramRecord record;
    kernels.primary.push_back(cache_.kernel(passes.session, config, &record));
    kernels.primary_lanes.push_back(config.lanes);
    kernels.primary_largest_group.push_back(largest_group(kernels.primary.back(), passes.session.info.device));
    kernels.screen_rows.emplace_back();
    passes.tally.programs.push_back(record);
    primary.program_keys.push_back(record.key);
    primary.program_ms.push_back(0);
  }
  if (!keep_primary)
    work.primary_out =
        std::make_unique<TileHits>(passes.session.context, passes.session.queue, tile_rays, hit_memory.get());
  if (several && !work.other_out)
    work.other_out =
        std::make_unique<TileHits>(passes.session.context, passes.session.queue, tile_rays, PopulatedPages(bytes));
}

// The device's shadow tracers, one per surface, and the plan's shadow-casting lights in launch groups.
void Renderer::prepare_shadows(Passes& passes, PassStats& stats) {
  const Scene& scene = passes.scene;
  const RenderPlan& plan = passes.result.plan;
  DeviceKernels& kernels = passes.kernels;
  const double offset = shadow_offset_unit(passes.precision) * scene.extent.unit_scale();
  for (std::size_t i = 0; i < scene.surfaces.size(); ++i) {
    kernels.shadows.push_back(std::make_unique<ShadowTracer>(
        passes.session, cache_, plan.find(PassKind::Shadow)->kernels[i], *kernels.surfaces[i], offset));
    passes.tally.programs.push_back(kernels.shadows.back()->program());
    stats.program_keys.push_back(kernels.shadows.back()->program().key);
    stats.program_ms.push_back(0);
  }
  // In the surfaces' precision: plain float's kernels are adaptive's (float_measures_noise), and so are its points.
  kernels.shadow_points = std::make_unique<ShadowPoints>(passes.session, kernels.surfaces.front()->precision());
  std::vector<std::vector<glm::dvec3>> light_points;  // per shadow-casting light of the plan
  for (int light : plan.shadow_lights)
    light_points.push_back(scene.lights[static_cast<std::size_t>(light)].sample_points());
  kernels.light_groups = group_lights(light_points);
}

// Adaptive precision (and plain float, which runs adaptive's kernels): every ray pass escalates to the same trace
// kernels of the second pass's precision, and shadow rays to its shadow kernels.
void Renderer::prepare_escalation(Passes& passes) {
  const Scene& scene = passes.scene;
  const RenderPlan& plan = passes.result.plan;
  DeviceKernels& kernels = passes.kernels;
  if (const PlannedPass* primary_pass = plan.find(PassKind::Primary); !primary_pass->escalation.empty()) {
    for (std::size_t i = 0; i < scene.surfaces.size(); ++i) {
      kernels.escalate_rays.push_back(
          std::make_unique<RayEscalation>(passes.session, cache_, primary_pass->escalation[i], scene, i));
      passes.tally.programs.push_back(kernels.escalate_rays.back()->program());
    }
    if (const PlannedPass* shadow_pass = plan.find(PassKind::Shadow)) {
      const double offset = shadow_offset_unit(passes.precision) * scene.extent.unit_scale();
      for (std::size_t i = 0; i < scene.surfaces.size(); ++i) {
        kernels.escalate_shadows.push_back(
            std::make_unique<ShadowEscalation>(passes.session, cache_, shadow_pass->escalation[i], scene, i, offset));
        passes.tally.programs.push_back(kernels.escalate_shadows.back()->program());
        const bool in_float = i < shadow_pass->float_escalation.size() && shadow_pass->float_escalation[i];
        kernels.escalate_shadows_in_float.push_back(
            in_float ? std::make_unique<ShadowEscalation>(passes.session, cache_, *shadow_pass->float_escalation[i],
                                                          scene, i, offset)
                     : nullptr);
        if (in_float) passes.tally.programs.push_back(kernels.escalate_shadows_in_float.back()->program());
      }
    }
  }
}

// Every secondary pass (reflection, transmission, adaptive antialiasing) launches the same trace kernels.
void Renderer::prepare_secondary(Passes& passes) {
  const RenderPlan& plan = passes.result.plan;
  DeviceKernels& kernels = passes.kernels;
  for (PassKind kind : {PassKind::Reflection, PassKind::Transmission, PassKind::Antialias})
    if (PassStats* stats = passes.stats_of(kind)) {
      if (kernels.rays.empty())
        for (std::size_t i = 0; i < passes.scene.surfaces.size(); ++i) {
          kernels.rays.push_back(
              std::make_unique<RayTracer>(passes.session, cache_, plan.find(kind)->kernels[i], *kernels.surfaces[i]));
          passes.tally.programs.push_back(kernels.rays.back()->program());
        }
      for (const auto& tracer : kernels.rays) {
        stats->program_keys.push_back(tracer->program().key);
        stats->program_ms.push_back(0);
      }
    }
}

// The device's kernels, tracers and tile buffers for the plan's passes, with their programs in the tallies.
void Renderer::prepare_passes(Passes& passes, bool first_device) {
  prepare_primary(passes, first_device);
  if (PassStats* stats = passes.stats_of(PassKind::Shadow)) prepare_shadows(passes, *stats);
  prepare_escalation(passes);
  prepare_secondary(passes);
  // What the host does with a tile's camera-ray records besides shading them: escalate the doubted, keep the
  // nearest of several surfaces, trace shadow rays and bounces from them, keep them or hand them to the caller.
  const RenderOptions& options = passes.options;
  DeviceKernels& kernels = passes.kernels;
  kernels.host_reads_records = !kernels.escalate_rays.empty() || kernels.surfaces.size() > 1 ||
                               !kernels.shadows.empty() || !kernels.rays.empty() || options.keep_records ||
                               static_cast<bool>(options.on_primary_tile);
  // The last step of every tile, and the last program in the tallies.
  passes.kernels.shading = std::make_unique<DeviceShader>(passes.session, cache_, passes.scene, *passes.shader);
  passes.tally.programs.push_back(passes.kernels.shading->program());
  // The pass's stats list its escalation kernels after its own.
  const RenderPlan& plan = passes.result.plan;
  for (std::size_t i = 0; i < plan.passes.size(); ++i) {
    for (const KernelConfig& config : plan.passes[i].escalation) {
      passes.tally.stats[i].program_keys.push_back(config.key());
      passes.tally.stats[i].program_ms.push_back(0);
    }
    // then the float escalation kernels of the surfaces that have one (trace_shadows finds each one's place)
    for (const std::optional<KernelConfig>& config : plan.passes[i].float_escalation)
      if (config) {
        passes.tally.stats[i].program_keys.push_back(config->key());
        passes.tally.stats[i].program_ms.push_back(0);
      }
  }
}

void Renderer::set_band_args(Passes& passes, const Tile& first) {
  RenderResult& result = passes.result;
  const RenderPlan& plan = result.plan;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t s = 0; s < passes.kernels.surfaces.size(); ++s) {
    const DeviceSurface& surface = *passes.kernels.surfaces[s];
    KernelBinder args(passes.kernels.primary[s], "primary", surface.precision());
    args.ray_basis(result.basis);
    surface.set_extent_args(args);
    surface.set_surface_args(args);
    // The screen form's polynomials of the band's rows; the kernel must answer each camera ray alike whatever
    // tile and band it is in (test_secondary_rays compares renders in small and large tiles bit for bit).
    passes.kernels.screen_rows[s] =
        surface.set_screen_args(args, passes.session.context, plan.find(PassKind::Primary)->kernels[s], result.basis,
                                plan.trace_width(), plan.trace_height(), first.trace_y0, first.trace_h);
    args.plain("out", (s == 0 ? passes.work.primary_out : passes.work.other_out)->buffer());  // the tile: per launch
  }
  passes.stats_of(PassKind::Primary)->wall_ms += ms_since(start);
}

void Renderer::trace_primary(Passes& passes, const Tile& tile) {
  PassStats& pass = *passes.stats_of(PassKind::Primary);
  const std::size_t rays = tile.rays();
  passes.work.primary_out->release();  // the last tile's records: the kernel writes them again
  passes.work.hit_surface.clear();
  for (std::size_t s = 0; s < passes.kernels.surfaces.size(); ++s) {
    const auto start = std::chrono::steady_clock::now();
    cl::Kernel& kernel = passes.kernels.primary[s];
    KernelBinder args(kernel, "primary", passes.kernels.surfaces[s]->precision());
    args.plain("tile_x0", static_cast<cl_uint>(tile.trace_x0));
    args.plain("tile_y0", static_cast<cl_uint>(tile.trace_y0));
    args.plain("tile_w", static_cast<cl_uint>(tile.trace_w));
    args.plain("tile_h", static_cast<cl_uint>(tile.trace_h));
    cl::Event done;
    const RayLaunch launch = primary_launch(passes.kernels.primary_lanes[s], tile.trace_w, tile.trace_h,
                                            passes.kernels.primary_largest_group[s]);
    passes.session.queue.enqueueNDRangeKernel(kernel, cl::NullRange, launch.global, launch.local, nullptr, &done);
    // One tile at a time keeps each launch short (no GPU watchdog) and lets progress be shown.
    done.wait();
    pass.kernel_ms += ms_between(done);
    pass.program_ms[s] += ms_between(done);
    ++pass.launches;
    if (s == 0) pass.rays += rays;  // each camera ray once, however many surfaces it is tested against
    auto camera_ray = [&](std::size_t k) { return passes.camera_ray(tile, k); };
    if (s == 0) {
      // The records stay on the device for the shading kernel unless the host reads them: a GPU copies them
      // back when mapped (32 bytes a ray), a CPU does not.
      passes.work.hits = passes.kernels.host_reads_records ? passes.work.primary_out->map(rays) : nullptr;
      if (passes.work.hits) escalate_doubted(passes, pass, s, passes.work.hits, rays, camera_ray);
    } else {
      HitRecord* other = passes.work.other_out->map(rays);
      escalate_doubted(passes, pass, s, other, rays, camera_ray);
      keep_nearest(passes.work.hits, rays, passes.work.hit_surface, other, static_cast<std::uint8_t>(s));
      passes.work.other_out->release();
    }
    pass.wall_ms += ms_since(start);
  }
}

// Traces one batch of secondary rays, then the shadow rays of its hits.
void Renderer::trace_batch(Passes& passes, SecondaryBatch& batch) {
  const auto start = std::chrono::steady_clock::now();
  PassStats& stats = *passes.stats_of(batch.pass);
  for (std::size_t s = 0; s < passes.kernels.rays.size(); ++s) {
    TracedBatch traced = passes.kernels.rays[s]->trace(batch.rays);
    escalate_doubted(passes, stats, s, traced.hits.data(), traced.hits.size(),
                     [&](std::size_t i) { return batch.rays[i]; });
    if (s == 0)
      batch.hits = std::move(traced.hits);
    else
      keep_nearest(batch.hits.data(), batch.hits.size(), batch.hit_surface, traced.hits.data(),
                   static_cast<std::uint8_t>(s));
    stats.kernel_ms += traced.kernel_ms;
    stats.program_ms[s] += traced.kernel_ms;
    if (s == 0) stats.rays += batch.rays.size();
    ++stats.launches;
  }
  stats.wall_ms += ms_since(start);
  if (!passes.kernels.shadows.empty())
    batch.shadows =
        trace_shadows(passes, batch.hits.data(), batch.hits.size(), [&](std::size_t i) { return batch.rays[i]; });
}

void Renderer::finish_tile(Passes& passes, const Tile& tile) {
  RenderResult& result = passes.result;
  const RenderPlan& plan = result.plan;
  const std::size_t rays = tile.rays();
  const int grid_width = plan.trace_width();
  auto camera_ray = [&](std::size_t k) { return passes.camera_ray(tile, k); };
  if (passes.options.on_primary_tile) {
    const std::lock_guard<std::mutex> hold(passes.shared.lock);
    passes.options.on_primary_tile(
        {tile.trace_x0, tile.trace_y0, tile.trace_w, tile.trace_h, plan.samples, passes.work.hits});
  }
  if (passes.options.keep_records)
    for (std::size_t k = 0; k < rays; ++k) {
      const std::uint32_t at = tile.ray_in_image(k, grid_width);
      result.hits.records[at] = passes.work.hits[k];
      if (!passes.work.hit_surface.empty()) result.hits.surface[at] = passes.work.hit_surface[k];
    }

  ShadowData shadows;
  if (!passes.kernels.shadows.empty()) {
    shadows = trace_shadows(passes, passes.work.hits, rays, camera_ray);
    if (passes.options.keep_records) {
      const std::lock_guard<std::mutex> hold(passes.shared.lock);
      for (std::uint32_t k : shadows.points) result.shadows.points.push_back(tile.ray_in_image(k, grid_width));
      for (std::size_t l = 0; l < shadows.occlusion.size(); ++l) {
        std::vector<std::uint64_t>& all = result.shadows.occlusion[l].masks;
        all.insert(all.end(), shadows.occlusion[l].masks.begin(), shadows.occlusion[l].masks.end());
      }
    }
  }

  // Reflection and transmission from the camera rays' hits, batch_rays camera rays at a time.
  passes.work.any_secondary = false;
  if (passes.stats_of(PassKind::Reflection) || passes.stats_of(PassKind::Transmission)) {
    passes.work.secondary.assign(rays, glm::dvec3(0));
    std::vector<Bounce> first;
    for (std::size_t k = 0; k < rays; ++k) {
      const HitRecord& h = passes.work.hits[k];
      if (!(h.flags & ALGRAY_HIT_FOUND)) continue;
      first.push_back({static_cast<std::uint32_t>(k), 1.0, camera_ray(k), h,
                       passes.work.hit_surface.empty() ? std::uint8_t{0} : passes.work.hit_surface[k]});
      if (first.size() == passes.options.batch_rays) {
        run_bounces(passes, tile, std::move(first), 1, false);
        first.clear();
      }
    }
    if (!first.empty()) run_bounces(passes, tile, std::move(first), 1, false);
  }

  // The tile's pixels, shaded on the device from the records where the primary kernel left them.
  const auto start = std::chrono::steady_clock::now();
  passes.work.primary_out->release();
  ShadeTile shade;
  shade.trace_x0 = tile.trace_x0;
  shade.trace_y0 = tile.trace_y0;
  shade.trace_w = tile.trace_w;
  shade.trace_h = tile.trace_h;
  shade.hits = &passes.work.primary_out->buffer();
  shade.surface = passes.work.hit_surface.empty() ? nullptr : passes.work.hit_surface.data();
  shade.shadows = passes.kernels.shadows.empty() ? nullptr : &shadows;
  shade.secondary = passes.work.any_secondary ? passes.work.secondary.data() : nullptr;
  // Only the rows the film keeps: a band's extra rows are counted by the band they belong to.
  shade.kept_first = passes.first_row;
  shade.kept_end = passes.end_row;
  passes.tally.primary_summary += passes.kernels.shading->shade(shade, passes.tally.shade_kernel_ms);
  passes.tally.shade_ms += ms_since(start);
}

}  // namespace algray
