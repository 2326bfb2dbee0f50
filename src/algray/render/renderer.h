// The render of a plan: tile by tile through every pass into the film, with progress and cancellation callbacks.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "algray/device/cl_runtime.h"
#include "algray/device/program_cache.h"
#include "algray/io/image_io.h"
#include "algray/render/device_surface.h"
#include "algray/render/populated_pages.h"
#include "algray/render/precision_race.h"
#include "algray/render/render_plan.h"
#include "algray/render/trace_records.h"
#include "algray/scene/camera.h"
#include "algray/scene/scene.h"
#include "kernels/algray_shared.h"

namespace algray {

struct PassStats {
  std::string name;
  std::vector<std::string> program_keys;  // ProgramRecord::key of the kernels the pass launched, per surface
  std::vector<double> program_ms;         // device time of each of those kernels
  std::uint64_t rays = 0;                 // rays traced, each once however many surfaces it was tested against
  int launches = 0;
  double kernel_ms = 0;  // device time summed over launches (profiling events), escalations' included
  double wall_ms = 0;
  // Adaptive precision: the pass's rays the float kernel doubted and mixed precision traced again, and that
  // second pass's device time (also in kernel_ms).
  std::uint64_t escalated = 0;
  double escalation_ms = 0;
};

// One tile's camera rays as the primary pass left them, whole pixels of the traced grid, handed to
// RenderOptions::on_primary_tile before the tile's buffers are reused.
struct PrimaryTile {
  int x0 = 0, y0 = 0, width = 0, height = 0;  // in traced rays: plan.samples per pixel side
  int samples = 1;
  const HitRecord* hits = nullptr;  // width x height, row-major
};

// How far a render is: reported after each tile (adaptive antialiasing's second sweep counts its tiles again).
struct RenderProgress {
  int tiles_done = 0, tiles_total = 0;
};

// Thrown by a render whose RenderOptions::cancelled said so between two tiles; nothing of it is kept.
struct RenderCancelled : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The host memory one tile's camera-ray records take under `plan`.
std::size_t tile_memory_bytes(const RenderPlan& plan);

struct RenderOptions {
  // Called after each tile, on the rendering thread; the command line draws its progress line from it. With
  // several devices, each callback is called from their threads, one call at a time.
  std::function<void(const RenderProgress&)> on_progress;
  // Asked before each tile; true stops the render with RenderCancelled (Ctrl-C in a notebook, a closed viewer).
  std::function<bool()> cancelled;
  // Keep every ray's record in RenderResult (hits, shadows, secondary, refined), for tests and tools. Their
  // memory grows with pixels x samples x bounces; without them only the film and the totals are kept.
  bool keep_records = false;
  std::function<void(const PrimaryTile&)> on_primary_tile;  // e.g. the solver channels
  // Rays per launch of the shadow and trace kernels and per group of bounces. Only tests change it: the image
  // must not depend on it.
  std::size_t batch_rays = kBatchRays;
  // Gives the film to render into, made ahead by the caller: render_scene makes it while the device starts, so
  // that its zero-filling and page faults overlap the device's start on the other core. Called once; its film
  // is used when its size is the plan's, and may then lack depth and normal (PNG outputs only); otherwise, or
  // without it, the render makes its own.
  std::function<FrameImage()> film;
  // Gives host memory for one tile's camera-ray records, made ahead by the caller as the film is (page faults
  // overlapping the device's start, render_scene). Called once, by the first device; used when it holds the
  // plan's tile (tile_memory_bytes) and no more than twice that, else the render makes its own.
  std::function<PopulatedPages()> tile_memory;
  // Only the output rows [first, end) of the image, into a film of the band's height whose row 0 is image row
  // `first`: a band renders the pixels the whole image has there, bit for bit (MPI ranks render bands of one
  // image). Adaptive antialiasing then traces one more row beyond each inner edge, first colours only, so that
  // its choice there sees the neighbours the whole image has. Not with keep_records.
  struct RowBand {
    int first = 0, end = 0;
  };
  std::optional<RowBand> rows;
  // Bands one after another, as next_band gives them until it gives none, each handed to on_band in a film of
  // its own rows (row 0 is the band's first), with the kernels, buffers and screen form set up once for all
  // (MPI ranks take bands so). The result then holds no film, and its counts are the bands' together.
  std::function<std::optional<RowBand>()> next_band;
  std::function<void(const RowBand&, FrameImage&)> on_band;
  // A frame of a stream (the API's renders: `algray view`, Python): a preview whose scene leaves the precision
  // open, on devices where that means double, renders in double or adaptive, whichever this renderer measured
  // faster for frames like it (PrecisionRace); RenderResult::precision_reason says which and why. Final renders
  // and the command line keep `auto` as it is.
  bool race_precision = false;
};

// One device's share of a render of several: the tiles it took from the queue (the first sweep's, when
// adaptive antialiasing sweeps twice), its rays and device time over every pass, and its programs' load time.
struct DeviceShare {
  int rank = 0;   // the MPI rank whose device it is, when ranks share an image (0 otherwise)
  int index = 0;  // in enumerate_devices() of its process
  std::string name;
  int tiles = 0;
  std::uint64_t rays = 0;
  double kernel_ms = 0;
  double programs_ms = 0;
};

// Adds the counts of the same pass, or of the same device, from another device, band or rank: rays, launches,
// tiles and times (wall times too, so with several devices they are the devices' threads' added up).
void add_counts(PassStats& into, const PassStats& more);
void add_counts(DeviceShare& into, const DeviceShare& more);

struct RenderResult {
  RenderPlan plan;
  KernelConfig config;  // of the first surface's primary pass, with precision and tolerance as used
  RayBasis basis;       // of the traced rays (per antialiasing sample, not per pixel)
  std::vector<ProgramRecord> programs;
  std::vector<PassStats> passes;     // summed over the devices
  std::vector<DeviceShare> devices;  // in the order the renderer was given them
  // The film: RGBA, depth and normal per output pixel, as shade_frame would make them from the records.
  FrameImage image;
  PrimarySummary primary;
  // Shading's wall time within the render (the shading kernel's launches and read-backs, the host's shading of
  // bounces and refined pixels), and the shading kernel's device time within it; gathering a pass's rays is in
  // the pass's wall_ms.
  double shade_ms = 0;
  double shade_kernel_ms = 0;
  // Why the render is in its precision, where RenderOptions::race_precision chose it; empty elsewhere.
  std::string precision_reason;
  // The passes' device time summed (second passes included; the shading kernel's is shade_kernel_ms).
  double passes_kernel_ms() const {
    double ms = 0;
    for (const PassStats& pass : passes) ms += pass.kernel_ms;
    return ms;
  }

  // Kept only with RenderOptions::keep_records:
  HitBuffer hits;                         // one record per traced ray: plan.trace_width() x plan.trace_height()
  ShadowData shadows;                     // of the camera rays' hits
  std::vector<SecondaryBatch> secondary;  // per tile, in the order traced: by depth, reflection first
  // Adaptive antialiasing: 1 for the pixels (of hits) whose colour is the antialias batch's rays, not their own.
  std::vector<std::uint8_t> refined;
};

// fp64 counts as fast where double takes at most this many times float's time (device/fp64_speed.h): CPUs and
// datacenter GPUs measure 1-2 (an AMD EPYC 1.15, the lent H200 1.83 and 1.86), most other GPUs 16-64, where
// adaptive float costs about 1.1-1.3x plain float. The line sits between the two groups, not at the top of the
// first: at 2 it was within a measurement's jitter of the H200's figure, so `auto` could choose differently from
// one process to the next for the same scene on the same device.
inline constexpr double kFastFp64Slowdown = 4.0;

// Precision a scene renders in on a device: as asked; left open, double where the device's fp64 is fast
// (fp64_slowdown: fp64_slowdown()'s measure for it), else adaptive where the scene's surfaces allow it
// (adaptive_unsupported), else float. Throws DeviceError when double is asked of a device without fp64.
Precision resolve_precision(const Scene& scene, const DeviceInfo& device, std::optional<double> fp64_slowdown);
// The same, with the device's fp64 measured (once, then kept by the cache) where the scene leaves precision open.
Precision resolve_precision(const Scene& scene, const DeviceInfo& device, ProgramCache& cache);
// The precision adaptive precision traces doubted rays again in on a device: double where its fp64 is fast
// (resolve_precision's measure), else mixed. A render on several devices takes mixed unless all are fast.
Precision escalation_precision(const DeviceInfo& device, ProgramCache& cache);

// The precision left open resolves to on a device without fast fp64.
Precision float_precision_for(const Scene& scene);

// The output image from a render's records (RenderOptions::keep_records, or the reference's hits), shaded as
// the renderer shades its film.
FrameImage shade_frame(const Scene& scene, const RenderResult& result);

class Renderer {
 public:
  Renderer(ClSession& session, ProgramCache& cache);
  // Several devices render each image together. They take tiles from one queue, so a faster device takes more,
  // and the image is the one a single device of their kind renders, bit for bit. Precision left to the devices
  // is double only where every device has fast fp64; the tile size left to them gives each device about 8 tiles.
  Renderer(std::vector<ClSession*> sessions, ProgramCache& cache);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;
  // Runs every pass of the scene's plan, tile by tile, into the film. Each tile's camera rays, shadow rays and
  // bounces are traced and shaded before the device's next tile starts, so memory holds the film and one tile's
  // work per device.
  RenderResult render(const Scene& scene, const RenderOptions& options);
  // The same render keeping every ray's record (tests and tools).
  RenderResult render_with_records(const Scene& scene);
  // Whether the first device already holds host memory for a tile of `bytes` of camera-ray records: a renderer
  // keeps each device's tile buffers from one render to the next (a long-lived one renders frame after frame),
  // so a caller need not make that memory ahead (RenderOptions::tile_memory).
  bool holds_tile_memory(std::size_t bytes) const;

 private:
  struct Shared;
  struct DeviceKernels;
  struct TileWork;
  struct DeviceTally;
  struct Passes;
  struct Bounce;
  struct Tile;
  class TileHits;
  Precision precision_of(const Scene& scene) const;
  // The devices as make_render_plan takes them: with adaptive precision, each one's second-pass precision.
  std::vector<PlanDevice> plan_devices(Precision precision) const;
  // Deals `tiles` to the devices from one queue, each device's on its own thread, until every tile is done or one
  // fails; the first failure is thrown on.
  void sweep(std::vector<std::unique_ptr<Passes>>& devices, const std::vector<Tile>& tiles,
             const std::function<void(Passes&, const Tile&)>& work);
  // The output rows `rows` through every pass into a film of their own; the one `film` makes when its size is
  // the band's.
  FrameImage render_rows(std::vector<std::unique_ptr<Passes>>& devices, const RenderOptions::RowBand& rows,
                         const std::function<FrameImage()>& film);
  static void add_device_tallies(const std::vector<std::unique_ptr<Passes>>& devices, RenderResult& result);
  void prepare_passes(Passes& passes, bool first_device);
  void prepare_primary(Passes& passes, bool first_device);
  void prepare_shadows(Passes& passes, PassStats& stats);
  void prepare_escalation(Passes& passes);
  void prepare_secondary(Passes& passes);
  // The primary kernels' arguments for a band of tiles (a row of them), but the tile's own.
  void set_band_args(Passes& passes, const Tile& first);
  void trace_primary(Passes& passes, const Tile& tile);
  void trace_batch(Passes& passes, SecondaryBatch& batch);
  // A traced batch shaded into `colour`, its hits as the next bounces, and the batch kept in the result where the
  // caller keeps records (its samples as image positions: pixels for a refinement, rays otherwise).
  std::vector<Bounce> shade_batch(Passes& passes, const Tile& tile, SecondaryBatch& batch,
                                  std::vector<glm::dvec3>& colour);
  // The camera rays' shadows and bounces of one tile, and its pixels in the film.
  void finish_tile(Passes& passes, const Tile& tile);
  // Reflection and transmission rays, bounce by bounce from `depth`, from the hits in `current`.
  void run_bounces(Passes& passes, const Tile& tile, std::vector<Bounce> current, int depth, bool refinement);
  // Adaptive antialiasing in one tile: n x n more camera rays in the pixels `refine` marks.
  void refine_tile(Passes& passes, const Tile& tile, const std::vector<std::uint8_t>& refine);

  std::vector<ClSession*> sessions_;
  ProgramCache& cache_;
  // Per device, its tile buffers, kept from one render to the next: at 1024x768 the camera rays' records are
  // 25 MB, whose page faults cost a fifth of a preview frame's host time when made anew each frame.
  std::vector<std::unique_ptr<TileWork>> kept_work_;
  // Streams' frames, double against adaptive (RenderOptions::race_precision); one render at a time uses it.
  std::mutex race_mutex_;
  PrecisionRace race_;
};

}  // namespace algray
