// Renderer's private parts, shared by the files that carry out a render (renderer*.cpp): the tile, a device's
// passes and what the devices share, and the helpers more than one of those files uses. Nothing else includes it.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <vector>

#include "algray/render/device_shader.h"
#include "algray/render/escalation.h"
#include "algray/render/populated_pages.h"
#include "algray/render/ray_tracer.h"
#include "algray/render/renderer.h"
#include "algray/render/shade.h"
#include "algray/render/shadow_tracer.h"

namespace algray {
namespace renderer_parts {

inline double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// Keeps, per ray, the nearer of the hits found so far (surface `best`) and `other`'s hits (surface `index`).
// The solver work of both is added up, and a depth-limited isolation on either is kept, so the statistics
// and the solver channels count every surface's kernel.
inline void keep_nearest(HitRecord* best, std::size_t count, std::vector<std::uint8_t>& best_surface,
                         const HitRecord* other, std::uint8_t index) {
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
inline std::vector<std::uint8_t> pixels_to_refine(const FrameImage& coarse, double threshold) {
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
inline void crop_rows(FrameImage& film, int first, int rows) {
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

}  // namespace renderer_parts

// Host memory for one tile's hit records, which the primary kernel writes through a CL_MEM_USE_HOST_PTR buffer.
// On a CPU device the kernel writes this memory itself and mapping it copies nothing; on a GPU the map copies
// once. Either way the host neither zero-fills a vector of 32 bytes a ray nor copies into it: at 1024^2 that
// was 32 MB of page faults and a 32 MB copy, about a fifth of a preview's host time.
class Renderer::TileHits {
 public:
  // `memory` holds at least `capacity` records.
  TileHits(const cl::Context& context, cl::CommandQueue& queue, std::size_t capacity, PopulatedPages memory)
      : capacity_(capacity),
        memory_(std::move(memory)),
        buffer_(context, CL_MEM_READ_WRITE | CL_MEM_USE_HOST_PTR, capacity * sizeof(HitRecord), memory_.data()),
        queue_(queue) {}
  TileHits(const TileHits&) = delete;
  TileHits& operator=(const TileHits&) = delete;
  ~TileHits() {
    // No throwing from here: the C call, whose failure leaves nothing to undo.
    if (mapped_) clEnqueueUnmapMemObject(queue_(), buffer_(), mapped_, 0, nullptr, nullptr);
    clFinish(queue_());
  }
  const cl::Buffer& buffer() const { return buffer_; }
  std::size_t capacity() const { return capacity_; }  // in records
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
  std::size_t capacity_;
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
// One device's kernels and tracers for the render, built once (prepare_passes) and used by every tile.
struct Renderer::DeviceKernels {
  std::vector<std::unique_ptr<DeviceSurface>> surfaces;  // one per scene surface
  std::vector<cl::Kernel> primary;                       // one per surface
  std::vector<int> primary_lanes;                        // per surface: its kernel's camera rays per work-item
  std::vector<std::size_t> primary_largest_group;        // per surface: its kernel's work-group limit
  std::vector<cl::Buffer> screen_rows;                   // per surface: a band's rows for screen-form builds
  int band_y0 = -1;                                      // the band (row of tiles) whose arguments they hold
  std::vector<std::unique_ptr<ShadowTracer>> shadows;    // one per surface, when the plan has a shadow pass
  std::unique_ptr<ShadowPoints> shadow_points;   // a batch's surface points on the device
  std::vector<LightGroup> light_groups;          // the plan's shadow-casting lights, a launch per group
  std::vector<std::unique_ptr<RayTracer>> rays;  // one per surface, when it has a secondary pass
  // Adaptive precision: per surface, mixed precision's trace kernel for doubted camera and secondary rays, and
  // its shadow kernel for doubted shadow rays (when the plan has a shadow pass); plain float: float's own.
  std::vector<std::unique_ptr<RayEscalation>> escalate_rays;
  std::vector<std::unique_ptr<ShadowEscalation>> escalate_shadows;
  // per surface, null where the plan has none: PlannedPass::float_escalation, before escalate_shadows
  std::vector<std::unique_ptr<ShadowEscalation>> escalate_shadows_in_float;
  std::unique_ptr<DeviceShader> shading;  // the camera rays' pixels into the film
  bool host_reads_records = true;         // the host reads a tile's camera-ray records (prepare_passes)
};

// One tile's buffers and intermediate results, which the device's next tile reuses, and the renderer's next
// render too (Renderer::kept_work_).
struct Renderer::TileWork {
  std::unique_ptr<TileHits> primary_out;  // a tile's hit records, of the first surface
  std::unique_ptr<TileHits> other_out;    // several surfaces: those of the next ones
  HitRecord* hits = nullptr;  // camera rays, row-major in the tile: primary_out mapped, where the host reads them
  std::vector<std::uint8_t> hit_surface;  // several surfaces: which one each hit
  std::vector<glm::dvec3> secondary;      // per camera ray: what its bounces bring back
  bool any_secondary = false;
  std::vector<glm::dvec3> refined_colour;  // adaptive antialiasing: per pixel of the tile
  std::vector<double> refined_alpha;
  // Whether the last render's buffers hold a tile of `rays` camera rays (a long-lived renderer's next frame).
  bool holds(std::size_t rays) const { return primary_out && primary_out->capacity() >= rays; }
};

// One device's share of the render's tallies, added into the result when every device is done.
struct Renderer::DeviceTally {
  std::vector<PassStats> stats;  // one per planned pass, in plan order
  PrimarySummary primary_summary;
  double shade_ms = 0;
  double shade_kernel_ms = 0;
  std::vector<ProgramRecord> programs;
  int tiles = 0;
};

// What every tile's passes on one device share while a render runs: the render's context, the device's kernels,
// one tile's work, and the device's tallies.
struct Renderer::Passes {
  Passes(ClSession& se, Shared& sh, const Scene& s, const RenderOptions& o, Precision p, RenderResult& r,
         TileWork& w)
      : session(se), shared(sh), scene(s), options(o), precision(p), result(r), work(w) {
    tally.stats.resize(r.plan.passes.size());
  }
  ClSession& session;
  Shared& shared;
  const Scene& scene;
  const RenderOptions& options;
  Precision precision;
  RenderResult& result;            // its plan, basis and film are the render's; the tallies below are this device's
  const Shader* shader = nullptr;  // the render's: shading is const, so the devices share one
  RayBasis fine;                   // adaptive antialiasing: the rays of the n-times finer grid
  DeviceKernels kernels;
  TileWork& work;  // the renderer's, kept for its next render
  DeviceTally tally;
  int film_y0 = 0;  // the image row of the film's row 0, and the output rows [first_row, end_row) kept
  int first_row = 0, end_row = 0;
  // A pixel of the image (its index in the whole image) in the film.
  std::size_t film_pixel(std::size_t image_pixel) const {
    return image_pixel - static_cast<std::size_t>(film_y0) * static_cast<std::size_t>(result.plan.width);
  }

  PassStats* stats_of(PassKind kind) {
    for (std::size_t i = 0; i < tally.stats.size(); ++i)
      if (result.plan.passes[i].kind == kind) return &tally.stats[i];
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

namespace renderer_parts {

// Adds an escalation's rays and time to its pass's stats; `program` indexes its kernel in the pass's programs,
// after those of the pass's own kernels.
inline void count_escalation(PassStats& stats, std::size_t program, const EscalationCount& done) {
  stats.escalated += done.rays;
  stats.escalation_ms += done.kernel_ms;
  stats.kernel_ms += done.kernel_ms;
  stats.program_ms[program] += done.kernel_ms;
}

// Adaptive precision: traces again, in mixed precision, the records among `records` (of `surface`) that the
// float kernel doubted, ray_of(i) being record i's ray, and counts them in the pass's stats.
template <typename Passes, typename RayOf>
inline void escalate_doubted(Passes& p, PassStats& stats, std::size_t surface, HitRecord* records, std::size_t count,
                             RayOf ray_of) {
  if (p.kernels.escalate_rays.empty()) return;
  const EscalationCount done = p.kernels.escalate_rays[surface]->redo(records, count, ray_of, p.options.batch_rays);
  count_escalation(stats, p.kernels.surfaces.size() + surface, done);
}

// Shadow rays from every hit of one batch, in groups of at most batch_rays surface points; ray(i) is the ray of hit i
// (camera rays rebuilt exactly as the kernel traced them; secondary rays in double, which a float kernel traced
// rounded).
template <typename Passes, typename RayOf>
inline ShadowData trace_shadows(Passes& p, const HitRecord* hits, std::size_t count, RayOf ray) {
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
    p.kernels.shadow_points->upload(points, normals);
    for (const LightGroup& group : p.kernels.light_groups) {
      // Each surface's kernel in turn; a light point one surface hides is not traced against the next. A ray
      // counts once, from the first surface's kernel, which traces every light point in front of the surface.
      std::vector<std::uint64_t> hidden;
      for (std::size_t s = 0; s < p.kernels.shadows.size(); ++s) {
        ShadowAnswer answer = p.kernels.shadows[s]->trace(*p.kernels.shadow_points, group.points, hidden);
        stats.kernel_ms += answer.kernel_ms;
        stats.program_ms[s] += answer.kernel_ms;
        ++stats.launches;
        if (s == 0) stats.rays += answer.rays_traced;
        if (!p.kernels.escalate_shadows.empty()) {
          const std::size_t n = p.kernels.shadows.size();
          if (const auto& in_float = p.kernels.escalate_shadows_in_float.at(s)) {
            // The first pass's doubts in float's extent construction, then what that doubts in float-float: the
            // escalated rays are the first pass's, the time both passes'.
            // Its program follows the pass's own and the last tier's, among the surfaces that have one.
            const auto& tiers = p.kernels.escalate_shadows_in_float;
            const auto earlier = std::count_if(tiers.begin(), tiers.begin() + static_cast<std::ptrdiff_t>(s),
                                               [](const auto& tier) { return tier != nullptr; });
            std::vector<std::uint64_t> still;
            count_escalation(stats, 2 * n + static_cast<std::size_t>(earlier),
                             in_float->redo(points, normals, group.points, answer.undecided, answer.masks, &still));
            EscalationCount last =
                p.kernels.escalate_shadows[s]->redo(points, normals, group.points, still, answer.masks);
            last.rays = 0;
            count_escalation(stats, n + s, last);
          } else {
            count_escalation(
                stats, n + s,
                p.kernels.escalate_shadows[s]->redo(points, normals, group.points, answer.undecided, answer.masks));
          }
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

}  // namespace renderer_parts
}  // namespace algray
