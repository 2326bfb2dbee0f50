// Runs a render plan tile by tile across the devices: the plan, the tile queue the devices take from, a band of
// rows into its film, and the frame shaded from kept records. One device's passes are renderer_device.cpp's,
// bounces renderer_bounces.cpp's, adaptive antialiasing renderer_antialias.cpp's, the tallies renderer_tallies.cpp's.
#include "algray/render/renderer.h"

#include <cstdio>
#include <exception>
#include <future>
#include <limits>
#include <new>
#include <thread>
#include <utility>

#include "algray/device/fp64_speed.h"
#include "algray/render/renderer_parts.h"

namespace algray {
using namespace renderer_parts;

std::size_t tile_memory_bytes(const RenderPlan& plan) { return plan.tile_rays() * sizeof(HitRecord); }

Precision float_precision_for(const Scene& scene) {
  for (const SceneSurface& surface : scene.surfaces)
    if (!adaptive_unsupported(surface.polynomial.degree(), scene.render.isolation).empty()) return Precision::Float;
  return Precision::Adaptive;
}

Precision resolve_precision(const Scene& scene, const DeviceInfo& device, std::optional<double> fp64_slowdown) {
  if (!scene.render.precision)
    return device.fp64 && fp64_slowdown && *fp64_slowdown <= kFastFp64Slowdown ? Precision::Double
                                                                               : float_precision_for(scene);
  if (*scene.render.precision == Precision::Double && !device.fp64)
    throw DeviceError("device '" + device.name + "' has no double precision (" +
                      (device.fp64_hidden ? "cl_khr_fp64 is hidden by --no-fp64 or ALGRAY_NO_FP64" : "cl_khr_fp64") +
                      "); use --precision float");
  return *scene.render.precision;
}

Precision resolve_precision(const Scene& scene, const DeviceInfo& device, ProgramCache& cache) {
  return resolve_precision(scene, device, scene.render.precision ? std::nullopt : fp64_slowdown(device, cache));
}

RenderResult Renderer::render_with_records(const Scene& scene) {
  RenderOptions options;
  options.keep_records = true;
  return render(scene, options);
}

Renderer::Renderer(ClSession& session, ProgramCache& cache) : Renderer(std::vector<ClSession*>{&session}, cache) {}

Renderer::Renderer(std::vector<ClSession*> sessions, ProgramCache& cache)
    : sessions_(std::move(sessions)), cache_(cache) {
  if (sessions_.empty()) throw DeviceError("a render needs at least one device");
  for (std::size_t d = 0; d < sessions_.size(); ++d) kept_work_.push_back(std::make_unique<TileWork>());
}

Renderer::~Renderer() = default;

bool Renderer::holds_tile_memory(std::size_t bytes) const {
  return kept_work_.front()->holds((bytes + sizeof(HitRecord) - 1) / sizeof(HitRecord));
}

Precision Renderer::precision_of(const Scene& scene) const {
  auto on = [&](const ClSession* session) { return resolve_precision(scene, session->info, cache_); };
  Precision precision = on(sessions_.front());
  // Left to the devices, the render is in double only where every device's fp64 is fast: their tiles must match.
  for (const ClSession* session : sessions_)
    if (on(session) != precision) precision = float_precision_for(scene);
  return precision;
}

Precision escalation_precision(const DeviceInfo& device, ProgramCache& cache) {
  const std::optional<double> slowdown = fp64_slowdown(device, cache);
  return slowdown && *slowdown <= kFastFp64Slowdown ? Precision::Double : Precision::Mixed;
}

std::vector<PlanDevice> Renderer::plan_devices(Precision precision) const {
  std::vector<PlanDevice> devices;
  for (const ClSession* session : sessions_)
    devices.push_back({session->info, precision == Precision::Adaptive
                                          ? algray::escalation_precision(session->info, cache_)
                                          : Precision::Mixed});
  return devices;
}

void Renderer::sweep(std::vector<std::unique_ptr<Passes>>& devices, const std::vector<Tile>& tiles,
                     const std::function<void(Passes&, const Tile&)>& work) {
  Shared& shared = devices.front()->shared;
  // Tile d is device d's own, the queue hands out the rest: a device whose thread starts late still renders a
  // tile (under load, one device once took every tile of a small frame before the other's thread began).
  shared.next_tile = devices.size();
  auto take_tiles = [&](Passes& passes, std::size_t first) {
    for (std::size_t t = first; !shared.stop && t < tiles.size(); t = shared.next_tile++) {
      passes.check_cancelled();
      work(passes, tiles[t]);
      passes.progress();
    }
  };
  if (devices.size() == 1) return take_tiles(*devices.front(), 0);
  // One thread per device, each waiting on its own queue and shading its own tiles on the host.
  std::vector<std::exception_ptr> failures(devices.size());
  std::vector<std::thread> threads;
  for (std::size_t d = 0; d < devices.size(); ++d)
    threads.emplace_back([&, d] {
      try {
        take_tiles(*devices[d], d);
      } catch (...) {
        failures[d] = std::current_exception();
        shared.stop = true;
      }
    });
  for (std::thread& t : threads) t.join();
  for (const std::exception_ptr& failure : failures)
    if (failure) std::rethrow_exception(failure);
}

RenderResult Renderer::render(const Scene& scene, const RenderOptions& options) {
  RenderResult result;
  Precision precision = precision_of(scene);
  std::string race_key;
  if (options.race_precision && scene.render.preview && !scene.render.precision && precision == Precision::Double &&
      float_precision_for(scene) == Precision::Adaptive) {
    race_key = PrecisionRace::key_of(scene);
    const std::lock_guard<std::mutex> lock(race_mutex_);
    precision = race_.next(race_key);
    result.precision_reason = race_.reason(race_key);
  }
  result.plan = make_render_plan(scene, precision, plan_devices(precision));
  for (const ClSession* session : sessions_) check_plan_fits(result.plan, session->info);
  result.config = result.plan.passes.front().kernels.front();
  // Plain float runs adaptive's float kernels first (float_measures_noise): the render's precision is still float.
  result.config.precision = precision;
  const RenderPlan& plan = result.plan;
  const int trace_width = plan.trace_width(), trace_height = plan.trace_height();
  result.basis = make_ray_basis(scene.camera, trace_width, trace_height);
  if ((options.rows || options.next_band) && options.keep_records)
    throw std::invalid_argument("a band of rows keeps no records");
  if (options.next_band && !options.on_band) throw std::invalid_argument("bands of rows need on_band");
  Shared shared;
  const Shader shader(scene, plan, result.basis, precision);
  // The devices' kernels are loaded one device after another: the program cache serves one caller at a time.
  std::vector<std::unique_ptr<Passes>> devices;
  for (std::size_t d = 0; d < sessions_.size(); ++d) {
    ClSession* session = sessions_[d];
    devices.push_back(std::make_unique<Passes>(*session, shared, scene, options, precision, result, *kept_work_[d]));
    Passes& passes = *devices.back();
    passes.shader = &shader;
    for (std::size_t i = 0; i < scene.surfaces.size(); ++i)
      passes.kernels.surfaces.push_back(
          std::make_unique<DeviceSurface>(session->context, scene, plan.passes.front().kernels.at(i).precision, i));
    prepare_passes(passes, devices.size() == 1);
  }
  if (options.keep_records) {
    result.hits.width = trace_width;
    result.hits.height = trace_height;
    result.hits.records.resize(static_cast<std::size_t>(trace_width) * trace_height);
    if (scene.surfaces.size() > 1) result.hits.surface.assign(result.hits.records.size(), 0);
    for (int light : plan.shadow_lights) result.shadows.occlusion.push_back({light, {}});
  }
  if (options.next_band) {
    // Band after band with the same kernels and buffers: only the tiles change.
    while (const std::optional<RenderOptions::RowBand> band = options.next_band()) {
      FrameImage film = render_rows(devices, *band, {});
      options.on_band(*band, film);
    }
  } else {
    result.image = render_rows(devices, options.rows.value_or(RenderOptions::RowBand{0, plan.height}), options.film);
  }
  add_device_tallies(devices, result);
  if (!race_key.empty()) {
    // The passes' device time: the shading kernel's is the same in both precisions.
    const std::lock_guard<std::mutex> lock(race_mutex_);
    race_.record(race_key, precision, result.passes_kernel_ms());
  }
  return result;
}

FrameImage Renderer::render_rows(std::vector<std::unique_ptr<Passes>>& devices, const RenderOptions::RowBand& rows,
                                 const std::function<FrameImage()>& film_source) {
  Passes& any = *devices.front();
  const Scene& scene = any.scene;
  RenderResult& result = any.result;
  const RenderPlan& plan = result.plan;
  const bool adaptive = plan.refine_samples > 1;
  const int first_row = rows.first, end_row = rows.end;
  if (first_row < 0 || end_row > plan.height || first_row >= end_row)
    throw std::invalid_argument("rows " + std::to_string(first_row) + " to " + std::to_string(end_row) +
                                " are not a band of the image's " + std::to_string(plan.height));
  // The rows kept, and those traced: adaptive antialiasing's choice at a band's edge needs the row beyond it.
  const int margin = adaptive ? 1 : 0;
  const int traced_first = std::max(0, first_row - margin), traced_end = std::min(plan.height, end_row + margin);
  for (auto& passes : devices) {
    passes->film_y0 = traced_first;
    passes->first_row = first_row;
    passes->end_row = end_row;
    passes->kernels.band_y0 = -1;  // a band's first tile row may start where the last band's did, but be shorter
  }
  const int film_height = traced_end - traced_first;
  FrameImage film;
  if (film_source) film = film_source();
  if (film.width != plan.width || film.height != film_height ||
      film.rgba.size() != 4 * static_cast<std::size_t>(plan.width) * film_height)
    film = make_film(plan.width, film_height, true);
  std::swap(result.image, film);  // the devices' tiles go into result.image
  for (auto& passes : devices) passes->kernels.shading->bind_film(result.image, traced_first, devices.size() == 1);

  // Row by row of tiles, as the film's lines are laid out.
  std::vector<Tile> tiles;
  const int side = plan.tile_pixels(), s = plan.samples;
  for (int y0 = traced_first; y0 < traced_end; y0 += side)
    for (int x0 = 0; x0 < plan.width; x0 += side) {
      const int w = std::min(side, plan.width - x0), h = std::min(side, traced_end - y0);
      tiles.push_back({x0, y0, w, h, x0 * s, y0 * s, w * s, h * s});
    }
  Shared& shared = any.shared;
  shared.tiles_done = 0;
  shared.tiles_total = static_cast<int>(tiles.size()) * (adaptive ? 2 : 1);
  sweep(devices, tiles, [this](Passes& passes, const Tile& tile) {
    if (tile.y0 != passes.kernels.band_y0) {
      set_band_args(passes, tile);
      passes.kernels.band_y0 = tile.y0;
    }
    trace_primary(passes, tile);
    finish_tile(passes, tile);
    ++passes.tally.tiles;
  });
  for (auto& passes : devices) passes->kernels.shading->finish_film();
  if (adaptive) {
    // Every device's first colours are in the film before any pixel is chosen: a tile's choice at its border
    // sees its neighbours', whichever device traced them.
    const auto start = std::chrono::steady_clock::now();
    const RayBasis fine =
        make_ray_basis(scene.camera, plan.width * plan.refine_samples, plan.height * plan.refine_samples);
    for (auto& passes : devices) passes->fine = fine;
    std::vector<std::uint8_t> refine = pixels_to_refine(result.image, plan.refine_threshold);
    // The rows beyond the band were traced for their first colours only.
    const std::size_t width = static_cast<std::size_t>(plan.width);
    std::fill(refine.begin(), refine.begin() + static_cast<std::ptrdiff_t>((first_row - traced_first) * width), 0);
    std::fill(refine.end() - static_cast<std::ptrdiff_t>((traced_end - end_row) * width), refine.end(), 0);
    devices.front()->tally.shade_ms += ms_since(start);
    sweep(devices, tiles, [this, &refine](Passes& passes, const Tile& tile) { refine_tile(passes, tile, refine); });
    if (any.options.keep_records) result.refined = refine;
  }
  std::swap(result.image, film);
  crop_rows(film, first_row - traced_first, end_row - first_row);
  return film;
}

FrameImage shade_frame(const Scene& scene, const RenderResult& result) {
  const HitBuffer& hits = result.hits;
  const Shader shader(scene, result.plan, result.basis, result.config.precision);
  RenderPlan plan = result.plan;
  plan.width = hits.width / std::max(plan.samples, 1);
  plan.height = hits.height / std::max(plan.samples, 1);
  FrameImage img = make_film(plan);

  // What reflection and transmission rays add to each traced camera ray: their weight times what they met.
  // Adaptive antialiasing's camera rays are such contributions too, with weights 1/n^2; they also carry alpha.
  std::vector<glm::dvec3> secondary(result.secondary.empty() ? 0 : hits.records.size(), glm::dvec3(0));
  std::vector<glm::dvec3> refined_colour(result.refined.empty() ? 0 : hits.records.size(), glm::dvec3(0));
  std::vector<double> refined_alpha(refined_colour.size(), 0.0);
  std::vector<double> no_alpha;
  for (const SecondaryBatch& batch : result.secondary) {
    if (batch.refinement)
      shader.add_batch(batch, refined_colour, refined_alpha);
    else
      shader.add_batch(batch, secondary, no_alpha);
  }
  const ShadowLookup shadows(result.shadows, hits.records.size(), scene.lights.size());
  TracedBlock block;
  block.width = hits.width;
  block.height = hits.height;
  block.hits = hits.records.data();
  block.surface = hits.surface.empty() ? nullptr : hits.surface.data();
  block.shadows = &shadows;
  block.secondary = secondary.empty() ? nullptr : secondary.data();
  shader.resolve(block, img);
  for (std::size_t k = 0; k < result.refined.size(); ++k)
    if (result.refined[k]) shader.resolve_refined(k, refined_colour[k], refined_alpha[k], img);
  return img;
}

}  // namespace algray
