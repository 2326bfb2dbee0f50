// Runs a render plan tile by tile: a tile's camera rays, their shadow rays and bounces, then its pixels in the
// film, before the next tile; adaptive antialiasing then refines tile by tile from the film's first colours.
#include "algray/render/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <future>
#include <limits>
#include <memory>
#include <mutex>
#include <new>
#include <thread>
#include <utility>

#include "algray/device/fp64_speed.h"
#include "algray/render/escalation.h"
#include "algray/render/populated_pages.h"
#include "algray/render/ray_tracer.h"
#include "algray/render/shade.h"
#include "algray/render/shadow_tracer.h"

namespace algray {

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

namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// A primary launch covers the tile with one work-item per `lanes` pixels of a row (kernels/primary.cl).
constexpr std::size_t kLaneGroupWidth = 16;
cl::NDRange primary_global_size(int lanes, int width, int height) {
  const std::size_t w = static_cast<std::size_t>(width), h = static_cast<std::size_t>(height);
  if (lanes == 1) return cl::NDRange(w, h);
  const std::size_t items = (w + static_cast<std::size_t>(lanes) - 1) / static_cast<std::size_t>(lanes);
  return cl::NDRange((items + kLaneGroupWidth - 1) / kLaneGroupWidth * kLaneGroupWidth, h);
}
// Lanes multiply each work-item's private arrays; PoCL keeps a work-group's on one thread's stack and picks
// work-groups of up to 4096 items on its own, which overflows it (bench/lockstep_lanes crashed so). Rows of 16
// work-items, 128 pixels at 8 lanes, keep it small; one-lane kernels keep the device's choice.
cl::NDRange primary_local_size(int lanes) { return lanes == 1 ? cl::NullRange : cl::NDRange(kLaneGroupWidth, 1); }

// Keeps, per ray, the nearer of the hits found so far (surface `best`) and `other`'s hits (surface `index`).
// The solver work of both is added up, and a depth-limited isolation on either is kept, so the statistics
// and the solver channels count every surface's kernel.
void keep_nearest(HitRecord* best, std::size_t count, std::vector<std::uint8_t>& best_surface, const HitRecord* other,
                  std::uint8_t index) {
  if (best_surface.size() != count) best_surface.assign(count, 0);
  for (std::size_t i = 0; i < count; ++i) {
    const HitRecord& o = other[i];
    HitRecord& b = best[i];
    const std::uint32_t steps =
        std::min(ALGRAY_WORK_MAX, ALGRAY_WORK_ISOLATION_STEPS(b.work) + ALGRAY_WORK_ISOLATION_STEPS(o.work));
    const std::uint32_t iterations =
        std::min(ALGRAY_WORK_MAX, ALGRAY_WORK_REFINE_ITERATIONS(b.work) + ALGRAY_WORK_REFINE_ITERATIONS(o.work));
    const std::uint32_t shared_flags = (b.flags | o.flags) & (ALGRAY_HIT_BUDGET | ALGRAY_HIT_IN_EXTENT);
    const double tb = static_cast<double>(b.t_hi) + static_cast<double>(b.t_lo);
    const double to = static_cast<double>(o.t_hi) + static_cast<double>(o.t_lo);
    if ((o.flags & ALGRAY_HIT_FOUND) && (!(b.flags & ALGRAY_HIT_FOUND) || to < tb)) {
      b = o;
      best_surface[i] = index;
    }
    b.work = ALGRAY_WORK_PACK(steps, iterations);
    b.flags |= shared_flags;
  }
}

// Adaptive antialiasing's choice, from the film's first colours (one ray per pixel): the pixels whose colour
// differs from a neighbour's by more than the threshold in some channel. Made for the whole image before any
// pixel is refined, so a tile's choice at its border sees its neighbours' first colours, as one image would.
std::vector<std::uint8_t> pixels_to_refine(const FrameImage& coarse, double threshold) {
  const int w = coarse.width, h = coarse.height;
  auto differs = [&](int x0, int y0, int x1, int y1) {
    if (x1 < 0 || y1 < 0 || x1 >= w || y1 >= h) return false;
    const std::size_t a = 4 * (static_cast<std::size_t>(y0) * w + x0), b = 4 * (static_cast<std::size_t>(y1) * w + x1);
    for (int c = 0; c < 4; ++c)
      if (std::fabs(coarse.rgba[a + c] - coarse.rgba[b + c]) > threshold) return true;
    return false;
  };
  std::vector<std::uint8_t> refine(static_cast<std::size_t>(w) * h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      refine[static_cast<std::size_t>(y) * w + x] =
          differs(x, y, x - 1, y) || differs(x, y, x + 1, y) || differs(x, y, x, y - 1) || differs(x, y, x, y + 1);
  return refine;
}

// Keeps `rows` rows of the film from row `first` on.
void crop_rows(FrameImage& film, int first, int rows) {
  if (first == 0 && rows == film.height) return;
  const std::size_t width = static_cast<std::size_t>(film.width);
  auto crop = [&](auto& channel, std::size_t per_pixel) {
    if (channel.empty()) return;
    channel.erase(channel.begin(), channel.begin() + static_cast<std::ptrdiff_t>(first * width * per_pixel));
    channel.resize(static_cast<std::size_t>(rows) * width * per_pixel);
  };
  crop(film.rgba, 4);
  crop(film.depth, 1);
  crop(film.normal, 3);
  film.height = rows;
}

}  // namespace

// Host memory for one tile's hit records, which the primary kernel writes through a CL_MEM_USE_HOST_PTR buffer.
// On a CPU device the kernel writes this memory itself and mapping it copies nothing; on a GPU the map copies
// once. Either way the host neither zero-fills a vector of 32 bytes a ray nor copies into it: at 1024^2 that
// was 32 MB of page faults and a 32 MB copy, about a fifth of a preview's host time.
class Renderer::TileHits {
 public:
  // `memory` holds at least `capacity` records.
  TileHits(const cl::Context& context, cl::CommandQueue& queue, std::size_t capacity, PopulatedPages memory)
      : memory_(std::move(memory)),
        buffer_(context, CL_MEM_WRITE_ONLY | CL_MEM_USE_HOST_PTR, capacity * sizeof(HitRecord), memory_.data()),
        queue_(queue) {}
  TileHits(const TileHits&) = delete;
  TileHits& operator=(const TileHits&) = delete;
  ~TileHits() {
    // No throwing from here: the C call, whose failure leaves nothing to undo.
    if (mapped_) clEnqueueUnmapMemObject(queue_(), buffer_(), mapped_, 0, nullptr, nullptr);
    clFinish(queue_());
  }
  const cl::Buffer& buffer() const { return buffer_; }
  // The first `count` records as the queue's finished work left them, readable and writable on the host until
  // release(), which must come before the buffer is written again.
  HitRecord* map(std::size_t count) {
    release();
    mapped_ = static_cast<HitRecord*>(
        queue_.enqueueMapBuffer(buffer_, CL_TRUE, CL_MAP_READ | CL_MAP_WRITE, 0, count * sizeof(HitRecord)));
    return mapped_;
  }
  void release() {
    if (!mapped_) return;
    queue_.enqueueUnmapMemObject(buffer_, mapped_);
    mapped_ = nullptr;
  }

 private:
  PopulatedPages memory_;  // page-aligned, as zero-copy host pointers want
  cl::Buffer buffer_;
  cl::CommandQueue& queue_;
  HitRecord* mapped_ = nullptr;
};

// A block of whole output pixels and the camera rays that trace it.
struct Renderer::Tile {
  int x0, y0, width, height;                 // output pixels
  int trace_x0, trace_y0, trace_w, trace_h;  // traced rays: samples per pixel side
  std::size_t rays() const { return static_cast<std::size_t>(trace_w) * trace_h; }
  std::size_t pixels() const { return static_cast<std::size_t>(width) * height; }
  // A camera ray of the tile (index k of its traced block) in the whole traced grid of `grid_width`.
  std::uint32_t ray_in_image(std::size_t k, int grid_width) const {
    return static_cast<std::uint32_t>((trace_y0 + k / trace_w) * static_cast<std::size_t>(grid_width) + trace_x0 +
                                      k % trace_w);
  }
  // A pixel of the tile (index k, row-major) in the whole image of `image_width`.
  std::size_t pixel_in_image(std::size_t k, int image_width) const {
    return (y0 + k / width) * static_cast<std::size_t>(image_width) + x0 + k % width;
  }
};

// A ray waiting to be continued: the sample it adds to (the tile's camera ray, or pixel when refining), its
// weight, the ray and its hit.
struct Renderer::Bounce {
  std::uint32_t sample;
  double weight;
  PixelRay ray;
  HitRecord hit;
  std::uint8_t surface;  // which of the scene's surfaces it hit
};

// What the devices of one render share: the tile queue, and a lock around the caller's callbacks and the kept
// records. Each device's thread writes its own tiles' pixels into the film, so the film itself needs no lock.
struct Renderer::Shared {
  std::mutex lock;
  std::atomic<std::size_t> next_tile{0};
  std::atomic<bool> stop{false};  // a device failed, or the render was cancelled: the others take no more tiles
  int tiles_done = 0, tiles_total = 0;
};

// What every tile's passes on one device share while a render runs: kernels, tracers, the device's stats, and
// one tile's buffers, which the device's next tile reuses.
struct Renderer::Passes {
  Passes(ClSession& se, Shared& sh, const Scene& s, const RenderOptions& o, Precision p, RenderResult& r)
      : session(se), shared(sh), scene(s), options(o), precision(p), result(r), stats(r.plan.passes.size()) {}
  ClSession& session;
  Shared& shared;
  const Scene& scene;
  const RenderOptions& options;
  Precision precision;
  RenderResult& result;  // its plan, basis and film are the render's; the tallies below are this device's
  std::vector<std::unique_ptr<DeviceSurface>> surfaces;  // one per scene surface
  std::vector<PassStats> stats;                          // one per planned pass, in plan order
  std::vector<cl::Kernel> primary;                       // one per surface
  std::vector<int> primary_lanes;                        // per surface: its kernel's camera rays per work-item
  std::vector<cl::Buffer> screen_rows;                   // per surface: a band's rows for screen-form builds
  std::unique_ptr<TileHits> primary_out;                 // a tile's hit records, of the first surface
  std::unique_ptr<TileHits> other_out;                   // several surfaces: those of the next ones
  std::vector<std::unique_ptr<ShadowTracer>> shadows;    // one per surface, when the plan has a shadow pass
  std::unique_ptr<ShadowPoints> shadow_points;           // a batch's surface points on the device
  std::vector<LightGroup> light_groups;                  // the plan's shadow-casting lights, a launch per group
  std::vector<std::unique_ptr<RayTracer>> rays;          // one per surface, when it has a secondary pass
  // Adaptive precision: per surface, mixed precision's trace kernel for doubted camera and secondary rays, and
  // its shadow kernel for doubted shadow rays (when the plan has a shadow pass).
  std::vector<std::unique_ptr<RayEscalation>> escalate_rays;
  std::vector<std::unique_ptr<ShadowEscalation>> escalate_shadows;
  const Shader* shader = nullptr;  // the render's: shading is const, so the devices share one
  RayBasis fine;                   // adaptive antialiasing: the rays of the n-times finer grid

  // This device's share, added into the result when every device is done.
  PrimarySummary primary_summary;
  double shade_ms = 0;
  std::vector<ProgramRecord> programs;
  int tiles = 0;
  int band_y0 = -1;  // the band (row of tiles) whose arguments the primary kernels hold
  int film_y0 = 0;   // the image row of the film's row 0, and the output rows [first_row, end_row) kept
  int first_row = 0, end_row = 0;
  // A pixel of the image (its index in the whole image) in the film.
  std::size_t film_pixel(std::size_t image_pixel) const {
    return image_pixel - static_cast<std::size_t>(film_y0) * static_cast<std::size_t>(result.plan.width);
  }

  // One tile's work.
  HitRecord* hits = nullptr;              // camera rays, row-major in the tile: primary_out mapped
  std::vector<std::uint8_t> hit_surface;  // several surfaces: which one each hit
  std::vector<glm::dvec3> secondary;      // per camera ray: what its bounces bring back
  bool any_secondary = false;
  std::vector<glm::dvec3> refined_colour;  // adaptive antialiasing: per pixel of the tile
  std::vector<double> refined_alpha;

  PassStats* stats_of(PassKind kind) {
    for (std::size_t i = 0; i < stats.size(); ++i)
      if (result.plan.passes[i].kind == kind) return &stats[i];
    return nullptr;
  }
  bool single() const { return precision != Precision::Double; }
  // Camera ray k of the tile's traced block, rebuilt exactly as the primary kernel traced it.
  PixelRay camera_ray(const Tile& tile, std::size_t k) const {
    return pixel_ray(result.basis, single(), tile.trace_x0 + static_cast<int>(k % tile.trace_w),
                     tile.trace_y0 + static_cast<int>(k / tile.trace_w));
  }
  // One more tile done; then, before the next, whether to go on. The caller's callbacks are called by one
  // device at a time.
  void progress() {
    const std::lock_guard<std::mutex> hold(shared.lock);
    ++shared.tiles_done;
    if (options.on_progress) options.on_progress({shared.tiles_done, shared.tiles_total});
  }
  void check_cancelled() const {
    const std::lock_guard<std::mutex> hold(shared.lock);
    if (options.cancelled && options.cancelled()) throw RenderCancelled("the render was cancelled");
  }
};

namespace {

// Adds an escalation's rays and time to its pass's stats; `program` indexes its kernel in the pass's programs,
// after those of the pass's own kernels.
void count_escalation(PassStats& stats, std::size_t program, const EscalationCount& done) {
  stats.escalated += done.rays;
  stats.escalation_ms += done.kernel_ms;
  stats.kernel_ms += done.kernel_ms;
  stats.program_ms[program] += done.kernel_ms;
}

// Adaptive precision: traces again, in mixed precision, the records among `records` (of `surface`) that the
// float kernel doubted, ray_of(i) being record i's ray, and counts them in the pass's stats.
template <typename Passes, typename RayOf>
void escalate_doubted(Passes& p, PassStats& stats, std::size_t surface, HitRecord* records, std::size_t count,
                      RayOf ray_of) {
  if (p.escalate_rays.empty()) return;
  const EscalationCount done = p.escalate_rays[surface]->redo(records, count, ray_of, p.options.batch_rays);
  count_escalation(stats, p.surfaces.size() + surface, done);
}

// Shadow rays from every hit of one batch, in groups of at most batch_rays surface points; ray(i) is the ray of hit i
// (camera rays rebuilt exactly as the kernel traced them; secondary rays in double, which a float kernel traced
// rounded).
template <typename Passes, typename RayOf>
ShadowData trace_shadows(Passes& p, const HitRecord* hits, std::size_t count, RayOf ray) {
  const auto start = std::chrono::steady_clock::now();
  PassStats& stats = *p.stats_of(PassKind::Shadow);
  ShadowData data;
  for (std::size_t i = 0; i < count; ++i)
    if (hits[i].flags & ALGRAY_HIT_FOUND) data.points.push_back(static_cast<std::uint32_t>(i));
  const std::vector<int>& lights = p.result.plan.shadow_lights;
  for (int light : lights) data.occlusion.push_back({light, std::vector<std::uint64_t>(data.points.size())});
  std::vector<glm::dvec3> points;
  std::vector<glm::vec3> normals;
  const std::size_t batch_rays = p.options.batch_rays;
  for (std::size_t begin = 0; begin < data.points.size(); begin += batch_rays) {
    const std::size_t end = std::min(data.points.size(), begin + batch_rays);
    points.clear();
    normals.clear();
    for (std::size_t k = begin; k < end; ++k) {
      const HitRecord& h = hits[data.points[k]];
      points.push_back(hit_point(ray(data.points[k]), h));
      normals.emplace_back(h.normal_x, h.normal_y, h.normal_z);
    }
    p.shadow_points->upload(points, normals);
    for (const LightGroup& group : p.light_groups) {
      // Each surface's kernel in turn; a light point one surface hides is not traced against the next. A ray
      // counts once, from the first surface's kernel, which traces every light point in front of the surface.
      std::vector<std::uint64_t> hidden;
      for (std::size_t s = 0; s < p.shadows.size(); ++s) {
        ShadowAnswer answer = p.shadows[s]->trace(*p.shadow_points, group.points, hidden);
        stats.kernel_ms += answer.kernel_ms;
        stats.program_ms[s] += answer.kernel_ms;
        ++stats.launches;
        if (s == 0) stats.rays += answer.rays_traced;
        if (!p.escalate_shadows.empty()) {
          count_escalation(stats, p.shadows.size() + s,
                           p.escalate_shadows[s]->redo(points, normals, group.points, answer.undecided, answer.masks));
        }
        hidden = std::move(answer.masks);
      }
      for (const LightGroup::Member& m : group.members) {
        std::vector<std::uint64_t>& masks = data.occlusion[m.light].masks;
        for (std::size_t k = 0; k < hidden.size(); ++k) masks[begin + k] = group.mask_of(m, hidden[k]);
      }
    }
  }
  stats.wall_ms += ms_since(start);
  return data;
}

// Splits rays waiting for a bounce into groups of whole samples, each of about batch_rays rays, keeping their
// order. A sample's colour adds up its rays in the order they are traced, and that order is the same whether
// its group is traced alone or with others, so the split changes no pixel.
template <typename Bounce>
std::vector<std::vector<Bounce>> split_by_sample(std::vector<Bounce>& all, std::size_t sample_count,
                                                 std::size_t batch_rays) {
  std::vector<std::uint32_t> group(sample_count, 0);  // first the rays per sample, then each sample's group
  for (const Bounce& b : all) ++group[b.sample];
  std::uint32_t g = 0;
  std::size_t filled = 0;
  for (std::uint32_t& count : group) {
    if (filled > 0 && filled + count > batch_rays) {
      ++g;
      filled = 0;
    }
    filled += count;
    count = g;
  }
  std::vector<std::vector<Bounce>> groups(g + 1);
  for (Bounce& b : all) groups[group[b.sample]].push_back(b);
  all.clear();
  all.shrink_to_fit();
  return groups;
}

}  // namespace

RenderResult Renderer::render_with_records(const Scene& scene) {
  RenderOptions options;
  options.keep_records = true;
  return render(scene, options);
}

Renderer::Renderer(std::vector<ClSession*> sessions, ProgramCache& cache)
    : sessions_(std::move(sessions)), cache_(cache) {
  if (sessions_.empty()) throw DeviceError("a render needs at least one device");
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
  const Precision precision = precision_of(scene);
  result.plan = make_render_plan(scene, precision, plan_devices(precision));
  for (const ClSession* session : sessions_) check_plan_fits(result.plan, session->info);
  result.config = result.plan.passes.front().kernels.front();
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
  for (ClSession* session : sessions_) {
    devices.push_back(std::make_unique<Passes>(*session, shared, scene, options, precision, result));
    Passes& passes = *devices.back();
    for (std::size_t i = 0; i < scene.surfaces.size(); ++i)
      passes.surfaces.push_back(std::make_unique<DeviceSurface>(session->context, scene, precision, i));
    prepare_passes(passes, devices.size() == 1);
    passes.shader = &shader;
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
    passes->band_y0 = -1;  // a band's first tile row may start where the last band's did, but be shorter
  }
  const int film_height = traced_end - traced_first;
  FrameImage film;
  if (film_source) film = film_source();
  if (film.width != plan.width || film.height != film_height ||
      film.rgba.size() != 4 * static_cast<std::size_t>(plan.width) * film_height)
    film = make_film(plan.width, film_height, true);
  std::swap(result.image, film);  // the devices' tiles go into result.image

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
    if (tile.y0 != passes.band_y0) {
      set_band_args(passes, tile);
      passes.band_y0 = tile.y0;
    }
    trace_primary(passes, tile);
    finish_tile(passes, tile);
    ++passes.tiles;
  });
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
    devices.front()->shade_ms += ms_since(start);
    sweep(devices, tiles, [this, &refine](Passes& passes, const Tile& tile) { refine_tile(passes, tile, refine); });
    if (any.options.keep_records) result.refined = refine;
  }
  std::swap(result.image, film);
  crop_rows(film, first_row - traced_first, end_row - first_row);
  return film;
}

void add_counts(PassStats& into, const PassStats& more) {
  into.rays += more.rays;
  into.launches += more.launches;
  into.kernel_ms += more.kernel_ms;
  into.wall_ms += more.wall_ms;
  into.escalated += more.escalated;
  into.escalation_ms += more.escalation_ms;
  into.program_ms.resize(std::max(into.program_ms.size(), more.program_ms.size()));
  for (std::size_t k = 0; k < more.program_ms.size(); ++k) into.program_ms[k] += more.program_ms[k];
}

void add_counts(DeviceShare& into, const DeviceShare& more) {
  into.tiles += more.tiles;
  into.rays += more.rays;
  into.kernel_ms += more.kernel_ms;
  into.programs_ms += more.programs_ms;
}

void Renderer::add_device_tallies(const std::vector<std::unique_ptr<Passes>>& devices, RenderResult& result) {
  const RenderPlan& plan = result.plan;
  for (std::size_t i = 0; i < plan.passes.size(); ++i) {
    PassStats total = devices.front()->stats[i];
    for (std::size_t d = 1; d < devices.size(); ++d) add_counts(total, devices[d]->stats[i]);
    total.name = to_string(plan.passes[i].kind);
    result.passes.push_back(total);
  }
  // Every device loads the same programs; the first device's records stand for them, each device's load time
  // is in its share.
  result.programs = devices.front()->programs;
  for (const auto& passes : devices) {
    result.primary += passes->primary_summary;
    result.shade_ms += passes->shade_ms;
    DeviceShare share;
    share.index = passes->session.info.index;
    share.name = passes->session.info.name;
    share.tiles = passes->tiles;
    for (const PassStats& pass : passes->stats) {
      share.rays += pass.rays;
      share.kernel_ms += pass.kernel_ms;
    }
    for (const ProgramRecord& program : passes->programs) share.programs_ms += program.build_ms;
    result.devices.push_back(share);
  }
}

void Renderer::prepare_passes(Passes& passes, bool first_device) {
  const Scene& scene = passes.scene;
  RenderResult& result = passes.result;
  const RenderPlan& plan = result.plan;
  PassStats& primary = *passes.stats_of(PassKind::Primary);
  // The largest tile: a tile's hit records are all the device holds for the camera rays. Their memory (32 MB
  // at 1024^2) is populated on another thread while this one loads the programs, a core's work either way.
  const std::size_t tile_rays = plan.tile_rays(), bytes = tile_memory_bytes(plan);
  // The caller's memory, made while the device started, when it fits the tile (the first device only).
  std::future<PopulatedPages> hit_memory =
      std::async(std::launch::async, [bytes, made = first_device ? passes.options.tile_memory : nullptr] {
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
  for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
    ProgramRecord record;
    passes.primary.push_back(cache_.kernel(passes.session, plan.find(PassKind::Primary)->kernels[s], &record));
    passes.primary_lanes.push_back(plan.find(PassKind::Primary)->kernels[s].lanes);
    passes.screen_rows.emplace_back();
    passes.programs.push_back(record);
    primary.program_keys.push_back(record.key);
    primary.program_ms.push_back(0);
  }
  passes.primary_out =
      std::make_unique<TileHits>(passes.session.context, passes.session.queue, tile_rays, hit_memory.get());
  if (scene.surfaces.size() > 1)
    passes.other_out =
        std::make_unique<TileHits>(passes.session.context, passes.session.queue, tile_rays, PopulatedPages(bytes));

  if (PassStats* stats = passes.stats_of(PassKind::Shadow)) {
    const double offset = shadow_offset_unit(passes.precision) * scene.extent.unit_scale();
    for (std::size_t i = 0; i < scene.surfaces.size(); ++i) {
      passes.shadows.push_back(std::make_unique<ShadowTracer>(
          passes.session, cache_, plan.find(PassKind::Shadow)->kernels[i], *passes.surfaces[i], offset));
      passes.programs.push_back(passes.shadows.back()->program());
      stats->program_keys.push_back(passes.shadows.back()->program().key);
      stats->program_ms.push_back(0);
    }
    passes.shadow_points = std::make_unique<ShadowPoints>(passes.session, passes.precision);
    std::vector<std::vector<glm::dvec3>> light_points;  // per shadow-casting light of the plan
    for (int light : plan.shadow_lights)
      light_points.push_back(scene.lights[static_cast<std::size_t>(light)].sample_points());
    passes.light_groups = group_lights(light_points);
  }
  // Adaptive precision: every ray pass escalates to the same mixed trace kernels.
  if (const PlannedPass* primary_pass = plan.find(PassKind::Primary); !primary_pass->escalation.empty()) {
    for (std::size_t i = 0; i < scene.surfaces.size(); ++i) {
      passes.escalate_rays.push_back(
          std::make_unique<RayEscalation>(passes.session, cache_, primary_pass->escalation[i], scene, i));
      passes.programs.push_back(passes.escalate_rays.back()->program());
    }
    if (const PlannedPass* shadow_pass = plan.find(PassKind::Shadow)) {
      const double offset = shadow_offset_unit(passes.precision) * scene.extent.unit_scale();
      for (std::size_t i = 0; i < scene.surfaces.size(); ++i) {
        passes.escalate_shadows.push_back(
            std::make_unique<ShadowEscalation>(passes.session, cache_, shadow_pass->escalation[i], scene, i, offset));
        passes.programs.push_back(passes.escalate_shadows.back()->program());
      }
    }
  }
  // Every secondary pass launches the same trace kernels.
  for (PassKind kind : {PassKind::Reflection, PassKind::Transmission, PassKind::Antialias})
    if (PassStats* stats = passes.stats_of(kind)) {
      if (passes.rays.empty())
        for (std::size_t i = 0; i < scene.surfaces.size(); ++i) {
          passes.rays.push_back(
              std::make_unique<RayTracer>(passes.session, cache_, plan.find(kind)->kernels[i], *passes.surfaces[i]));
          passes.programs.push_back(passes.rays.back()->program());
        }
      for (const auto& tracer : passes.rays) {
        stats->program_keys.push_back(tracer->program().key);
        stats->program_ms.push_back(0);
      }
    }
  // The pass's stats list its escalation kernels after its own.
  for (std::size_t i = 0; i < plan.passes.size(); ++i)
    for (const KernelConfig& config : plan.passes[i].escalation) {
      passes.stats[i].program_keys.push_back(config.key());
      passes.stats[i].program_ms.push_back(0);
    }
}

void Renderer::set_band_args(Passes& passes, const Tile& first) {
  RenderResult& result = passes.result;
  const RenderPlan& plan = result.plan;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t s = 0; s < passes.surfaces.size(); ++s) {
    const DeviceSurface& surface = *passes.surfaces[s];
    KernelBinder args(passes.primary[s], "primary", surface.precision());
    args.ray_basis(result.basis);
    surface.set_extent_args(args);
    surface.set_surface_args(args);
    // The screen form's polynomials of the band's rows; the kernel must answer each camera ray alike whatever
    // tile and band it is in (test_secondary_rays compares renders in small and large tiles bit for bit).
    passes.screen_rows[s] =
        surface.set_screen_args(args, passes.session.context, plan.find(PassKind::Primary)->kernels[s], result.basis,
                                plan.trace_width(), plan.trace_height(), first.trace_y0, first.trace_h);
    args.plain("out", (s == 0 ? passes.primary_out : passes.other_out)->buffer());  // the tile: per launch
  }
  passes.stats_of(PassKind::Primary)->wall_ms += ms_since(start);
}

void Renderer::trace_primary(Passes& passes, const Tile& tile) {
  PassStats& pass = *passes.stats_of(PassKind::Primary);
  const std::size_t rays = tile.rays();
  passes.primary_out->release();  // the last tile's records: the kernel writes them again
  passes.hit_surface.clear();
  for (std::size_t s = 0; s < passes.surfaces.size(); ++s) {
    const auto start = std::chrono::steady_clock::now();
    cl::Kernel& kernel = passes.primary[s];
    KernelBinder args(kernel, "primary", passes.surfaces[s]->precision());
    args.plain("tile_x0", static_cast<cl_uint>(tile.trace_x0));
    args.plain("tile_y0", static_cast<cl_uint>(tile.trace_y0));
    args.plain("tile_w", static_cast<cl_uint>(tile.trace_w));
    args.plain("tile_h", static_cast<cl_uint>(tile.trace_h));
    cl::Event done;
    passes.session.queue.enqueueNDRangeKernel(kernel, cl::NullRange,
                                              primary_global_size(passes.primary_lanes[s], tile.trace_w, tile.trace_h),
                                              primary_local_size(passes.primary_lanes[s]), nullptr, &done);
    // One tile at a time keeps each launch short (no GPU watchdog) and lets progress be shown.
    done.wait();
    pass.kernel_ms += ms_between(done);
    pass.program_ms[s] += ms_between(done);
    ++pass.launches;
    if (s == 0) pass.rays += rays;  // each camera ray once, however many surfaces it is tested against
    auto camera_ray = [&](std::size_t k) { return passes.camera_ray(tile, k); };
    if (s == 0) {
      passes.hits = passes.primary_out->map(rays);
      escalate_doubted(passes, pass, s, passes.hits, rays, camera_ray);
    } else {
      HitRecord* other = passes.other_out->map(rays);
      escalate_doubted(passes, pass, s, other, rays, camera_ray);
      keep_nearest(passes.hits, rays, passes.hit_surface, other, static_cast<std::uint8_t>(s));
      passes.other_out->release();
    }
    pass.wall_ms += ms_since(start);
  }
}

// Traces one batch of secondary rays, then the shadow rays of its hits.
void Renderer::trace_batch(Passes& passes, SecondaryBatch& batch) {
  const auto start = std::chrono::steady_clock::now();
  PassStats& stats = *passes.stats_of(batch.pass);
  for (std::size_t s = 0; s < passes.rays.size(); ++s) {
    TracedBatch traced = passes.rays[s]->trace(batch.rays);
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
  if (!passes.shadows.empty())
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
        {tile.trace_x0, tile.trace_y0, tile.trace_w, tile.trace_h, plan.samples, passes.hits});
  }
  if (passes.options.keep_records)
    for (std::size_t k = 0; k < rays; ++k) {
      const std::uint32_t at = tile.ray_in_image(k, grid_width);
      result.hits.records[at] = passes.hits[k];
      if (!passes.hit_surface.empty()) result.hits.surface[at] = passes.hit_surface[k];
    }

  ShadowData shadows;
  if (!passes.shadows.empty()) {
    shadows = trace_shadows(passes, passes.hits, rays, camera_ray);
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
  passes.any_secondary = false;
  if (passes.stats_of(PassKind::Reflection) || passes.stats_of(PassKind::Transmission)) {
    passes.secondary.assign(rays, glm::dvec3(0));
    std::vector<Bounce> first;
    for (std::size_t k = 0; k < rays; ++k) {
      const HitRecord& h = passes.hits[k];
      if (!(h.flags & ALGRAY_HIT_FOUND)) continue;
      first.push_back({static_cast<std::uint32_t>(k), 1.0, camera_ray(k), h,
                       passes.hit_surface.empty() ? std::uint8_t{0} : passes.hit_surface[k]});
      if (first.size() == passes.options.batch_rays) {
        run_bounces(passes, tile, std::move(first), 1, false);
        first.clear();
      }
    }
    if (!first.empty()) run_bounces(passes, tile, std::move(first), 1, false);
  }

  const auto start = std::chrono::steady_clock::now();
  const ShadowLookup lookup(shadows, rays, passes.scene.lights.size());
  TracedBlock block;
  block.x0 = tile.trace_x0;
  block.y0 = tile.trace_y0;
  block.width = tile.trace_w;
  block.height = tile.trace_h;
  block.hits = passes.hits;
  block.surface = passes.hit_surface.empty() ? nullptr : passes.hit_surface.data();
  block.shadows = &lookup;
  block.secondary = passes.any_secondary ? passes.secondary.data() : nullptr;
  block.film_y0 = passes.film_y0;
  // The camera rays' totals, counted as the shading threads finish their rows, while the records are in cache
  // (a pass of its own over a 1024^2 preview's 32 MB of records took 4 ms). Only the rows the film keeps: a
  // band's extra rows are counted by the band they belong to.
  PrimarySummary tile_summary;
  std::mutex summary_lock;
  block.after_rows = [&](int row_begin, int row_end) {
    const int first = std::max(tile.y0 + row_begin, passes.first_row);
    const int end = std::min(tile.y0 + row_end, passes.end_row);
    if (end <= first) return;
    PrimarySummary rows;
    rows.add(passes.hits + static_cast<std::size_t>(first - tile.y0) * plan.samples * tile.trace_w, tile.trace_w,
             (end - first) * plan.samples, plan.samples);
    const std::lock_guard<std::mutex> hold(summary_lock);
    tile_summary += rows;
  };
  passes.shader->resolve(block, result.image);
  passes.primary_summary += tile_summary;
  passes.shade_ms += ms_since(start);
}

void Renderer::run_bounces(Passes& passes, const Tile& tile, std::vector<Bounce> current, int depth, bool refinement) {
  const Scene& scene = passes.scene;
  RenderResult& result = passes.result;
  if (current.empty() || depth > scene.render.max_depth) return;
  const std::size_t samples_in_tile = refinement ? tile.pixels() : tile.rays();
  if (current.size() > passes.options.batch_rays) {
    // A group at a time, to the last bounce, so that memory holds one group's rays however many a bounce makes.
    std::vector<std::vector<Bounce>> groups = split_by_sample(current, samples_in_tile, passes.options.batch_rays);
    for (std::vector<Bounce>& group : groups) run_bounces(passes, tile, std::move(group), depth, refinement);
    return;
  }
  const double offset = shadow_offset_unit(passes.precision) * scene.extent.unit_scale();
  // Below this a bounce cannot change a pixel's 8-bit colour.
  constexpr double kNegligibleWeight = 1.0 / 512;
  const double pixel_share =
      refinement ? static_cast<double>(result.plan.refine_samples) * result.plan.refine_samples : 1.0;
  const PassKind kinds[2] = {PassKind::Reflection, PassKind::Transmission};
  const bool wanted[2] = {passes.stats_of(kinds[0]) != nullptr, passes.stats_of(kinds[1]) != nullptr};
  std::vector<Bounce> next;
  for (int k = 0; k < 2; ++k) {
    if (!wanted[k]) continue;
    SecondaryBatch batch;
    batch.pass = kinds[k];
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
      const PixelRay ray = k == 0 ? PixelRay{p + offset * n, d - 2 * glm::dot(d, n) * n} : PixelRay{p - offset * n, d};
      batch.sample.push_back(b.sample);
      batch.weight.push_back(b.weight * share);
      batch.rays.push_back(ray);
    }
    if (batch.rays.empty()) continue;
    trace_batch(passes, batch);
    const auto start = std::chrono::steady_clock::now();
    passes.shader->add_batch(batch, refinement ? passes.refined_colour : passes.secondary, passes.refined_alpha);
    passes.any_secondary = true;
    passes.shade_ms += ms_since(start);
    for (std::size_t i = 0; i < batch.rays.size(); ++i)
      if (batch.hits[i].flags & ALGRAY_HIT_FOUND)
        next.push_back({batch.sample[i], batch.weight[i], batch.rays[i], batch.hits[i],
                        batch.hit_surface.empty() ? std::uint8_t{0} : batch.hit_surface[i]});
    if (passes.options.keep_records) {
      const std::lock_guard<std::mutex> hold(passes.shared.lock);
      for (std::uint32_t& sample : batch.sample)
        sample = refinement ? static_cast<std::uint32_t>(tile.pixel_in_image(sample, result.plan.width))
                            : tile.ray_in_image(sample, result.plan.trace_width());
      result.secondary.push_back(std::move(batch));
    }
  }
  // This bounce's rays are done with before the next bounce's are traced.
  current.clear();
  current.shrink_to_fit();
  run_bounces(passes, tile, std::move(next), depth + 1, refinement);
}

void Renderer::refine_tile(Passes& passes, const Tile& tile, const std::vector<std::uint8_t>& refine) {
  RenderResult& result = passes.result;
  const RenderPlan& plan = result.plan;
  const int n = plan.refine_samples;
  std::vector<std::uint32_t> pixels;  // the tile's pixels to refine, row-major
  for (std::size_t k = 0; k < tile.pixels(); ++k)
    if (refine[passes.film_pixel(tile.pixel_in_image(k, plan.width))]) pixels.push_back(static_cast<std::uint32_t>(k));
  if (pixels.empty()) return;
  passes.refined_colour.assign(tile.pixels(), glm::dvec3(0));
  passes.refined_alpha.assign(tile.pixels(), 0.0);
  const bool single = passes.single();
  // Whole pixels per batch, each with the n x n rays of the n-times finer grid, so that a refined pixel gets
  // exactly the rays uniform n x n antialiasing would trace.
  const std::size_t per_batch = std::max<std::size_t>(1, passes.options.batch_rays / (static_cast<std::size_t>(n) * n));
  for (std::size_t begin = 0; begin < pixels.size(); begin += per_batch) {
    SecondaryBatch batch;
    batch.pass = PassKind::Antialias;
    batch.depth = 0;
    batch.refinement = true;
    for (std::size_t j = begin; j < std::min(pixels.size(), begin + per_batch); ++j) {
      const int x = tile.x0 + static_cast<int>(pixels[j] % tile.width),
                y = tile.y0 + static_cast<int>(pixels[j] / tile.width);
      for (int sy = 0; sy < n; ++sy)
        for (int sx = 0; sx < n; ++sx) {
          batch.sample.push_back(pixels[j]);
          batch.weight.push_back(1.0 / (n * n));
          batch.rays.push_back(pixel_ray(passes.fine, single, x * n + sx, y * n + sy));
        }
    }
    trace_batch(passes, batch);
    const auto start = std::chrono::steady_clock::now();
    passes.shader->add_batch(batch, passes.refined_colour, passes.refined_alpha);
    passes.shade_ms += ms_since(start);
    std::vector<Bounce> first;
    for (std::size_t i = 0; i < batch.rays.size(); ++i)
      if (batch.hits[i].flags & ALGRAY_HIT_FOUND)
        first.push_back({batch.sample[i], batch.weight[i], batch.rays[i], batch.hits[i],
                         batch.hit_surface.empty() ? std::uint8_t{0} : batch.hit_surface[i]});
    if (passes.options.keep_records) {
      const std::lock_guard<std::mutex> hold(passes.shared.lock);
      for (std::uint32_t& sample : batch.sample)
        sample = static_cast<std::uint32_t>(tile.pixel_in_image(sample, plan.width));
      result.secondary.push_back(std::move(batch));
    }
    run_bounces(passes, tile, std::move(first), 1, true);
  }
  const auto start = std::chrono::steady_clock::now();
  for (std::uint32_t k : pixels)
    passes.shader->resolve_refined(passes.film_pixel(tile.pixel_in_image(k, plan.width)), passes.refined_colour[k],
                                   passes.refined_alpha[k], result.image);
  passes.shade_ms += ms_since(start);
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
