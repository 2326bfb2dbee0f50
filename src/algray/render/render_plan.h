// The render plan: which passes a scene needs, the kernel each builds and the buffers each allocates.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "algray/device/cl_runtime.h"
#include "algray/device/kernel_config.h"
#include "algray/scene/scene.h"

namespace algray {

// The passes a plan can hold, in the order a plan lists them. The renderer and the shader tell passes apart by
// kind; the names are only for --stats and messages.
enum class PassKind { Primary, Shadow, Reflection, Transmission, Antialias };

// The pass's name as --stats and the plan's JSON write it: "primary", "shadow", "reflection", "transmission",
// "antialias".
std::string to_string(PassKind kind);

// One pass: the rays it traces and the kernel it launches. Nothing outside the plan is built or launched.
struct PlannedPass {
  PassKind kind = PassKind::Primary;
  std::string purpose;                // why the scene needs it, for --stats
  std::vector<KernelConfig> kernels;  // one per surface of the scene, in scene order
  // Adaptive precision: per surface, the kernel, in mixed precision or double (escalate_in), that traces again
  // the rays `kernels` doubted (the trace kernel for ray passes, the shadow kernel for the shadow pass); in plain
  // float, float's own (float_measures_noise). Empty elsewhere.
  std::vector<KernelConfig> escalation;
  // Adaptive precision whose second pass is float-float: per surface, where the shadow pass's float kernel is the
  // point form, the float kernel of the extent construction that traces its doubted rays first. The point form's
  // noise grows with the segment's reach from its origin (kernels/shadow.h, PointTerms), the extent
  // construction's does not, so it settles most of them at a fraction of float-float's cost; what it doubts goes
  // on to `escalation`. Empty elsewhere (no entry for a surface without one).
  std::vector<std::optional<KernelConfig>> float_escalation;
};

struct PlannedBuffer {
  std::string name;
  std::size_t bytes = 0;
};

// Rays per launch of the shadow and trace kernels, and per group of bounces: small enough that one batch's work
// (some 600 bytes a ray with bounces, host and device together, the rays of the next bounce included) stays near
// 40 MB whatever the tile, the antialiasing and the bounces. Measured on the Barth sextic in full mode at
// 1024x768: shadow kernel time alike at 2^14, 2^16 and 2^18 (58, 16 and 8 launches); peak memory with
// reflection and transmission 90 MB lower at 2^16 than at 2^18.
inline constexpr std::size_t kBatchRays = std::size_t{1} << 16;

// Bytes per output pixel of the film: RGBA, depth and normal, in float.
inline constexpr std::uint64_t kFilmBytesPerPixel = 32;

struct RenderPlan {
  int width = 0, height = 0;  // the output image
  // Side of a tile in traced rays; a tile holds whole pixels, tile_pixels() per side. The render works through
  // every pass one tile at a time, so its memory is the film plus one tile's work.
  int tile_size = 1024;
  std::string tile_choice;  // why this size, for --stats: the scene's, or the devices' default and for which
  int tile_pixels() const { return std::max(1, tile_size / samples); }
  // Camera rays of the largest tile.
  std::size_t tile_rays() const {
    return static_cast<std::size_t>(std::min(tile_pixels(), width)) * samples * std::min(tile_pixels(), height) *
           samples;
  }
  int samples = 1;         // antialiasing: samples x samples camera rays per pixel, traced as one grid
  int refine_samples = 0;  // adaptive antialiasing: n x n rays later, in pixels that differ (0: off)
  double refine_threshold = 0;
  int trace_width() const { return width * samples; }
  int trace_height() const { return height * samples; }
  std::vector<PlannedPass> passes;
  std::vector<PlannedBuffer> buffers;
  std::vector<int> shadow_lights;  // indices into Scene::lights whose shadows the shadow pass traces
  // The extent's clipping planes (a, b, c, d), a*x + b*y + c*z + d <= 0 kept, which every pass's rays are cut by
  // (kernels/ray.h); --stats lists them.
  std::vector<glm::dvec4> clip_planes;
  // A gate (extent.gate): the far sphere that the rays passing it are traced within (kernels/ray.h), its centre and
  // radius, and its reach (the radius over the gate's own); --stats shows them. Off: no gate.
  struct Gate {
    bool on = false;
    glm::dvec3 far_centre{0};
    double far_radius = 0;
    double reach = 0;
  } gate;
  // The shading kernel (kernels/shade.cl) that turns each tile's camera rays into the film's pixels on the device,
  // and what it draws, for --stats.
  KernelConfig shading;
  std::string shading_purpose;
  // Everything left out, and why ("shadow: no light casts shadows"), so --stats explains the plan.
  std::vector<std::string> skipped;

  const PlannedPass* find(PassKind kind) const;  // nullptr when the plan has no such pass
  nlohmann::json json() const;

  std::uint64_t tile_host_bytes = 0;  // the host's share of one tile's work (hits, shadow answers, a batch)

  // The device buffers together (one tile's and one batch's), the film, and the peak memory of the whole render
  // on the host: a base for the process and the OpenCL runtime, the film, one tile's work on the host and on
  // the device (which on a CPU is host memory too), and the writers' strips. Checked against peak RSS by
  // bench/memory.py (bench/history/2026-12.md, "Memory: tile by tile"); kept on the generous side.
  std::uint64_t buffer_bytes() const;
  std::uint64_t film_bytes() const;
  std::uint64_t estimated_memory_bytes() const;
};

// Throws DeviceError, naming the estimate, when the plan cannot fit: more than the machine's available memory,
// or, on a device with its own memory, more than that memory or its largest allocation. Called before anything
// is allocated, so that a 32768 x 32768 render with antialiasing is refused at once rather than killed later.
void check_plan_fits(const RenderPlan& plan, const DeviceInfo& device);

// The passes and buffers `scene` calls for in `precision`, for a given tile size and lanes: the building block of
// the devices' plan below, and what tests pin down. The primary pass is always there; the shadow pass only when a
// light casts shadows and the scene is not a preview.
// tile_size: the tile side in traced rays; 0 takes the scene's render.tile_size, or a CPU's default_tile_size.
// lanes: rays per work-item of the primary and trace kernels where lanes_apply (kernel_config.h); the scene's
// render.lanes, when set, comes first. float_shadow_lanes: the most the float shadow kernel takes (shadow_lanes).
RenderPlan make_render_plan(const Scene& scene, Precision precision, int tile_size = 0, int lanes = 1,
                            int float_shadow_lanes = kMaxFloatShadowLanes);

// Whether plain float renders `scene` with adaptive precision's float kernels, which measure their noise and doubt
// what it could decide, and traces the doubted rays again in float's own kernels (make_render_plan plans it so,
// escalate_in(Float)): with an isolation method adaptive precision takes (Bernstein), at any degree (adaptive's
// own limit of 15 is its mixed second pass's; above 15 camera rays take the screen form one ray at a time, with
// its terms, kernels/surface.h), where the scene leaves the ray origin open. Each ray's answer is then adaptive's
// where it is sure and plain float's elsewhere, so the image is float's or nearer the truth, and float gets
// adaptive's fast forms: the screen form for camera rays, the point form for shadow rays (measured:
// bench/RESULTS.md, "Float first").
bool float_measures_noise(const Scene& scene);

// Whether RayOrigin::Auto means the screen form for camera rays: in double and adaptive precision, with the camera
// outside the extent, facing its centre. Measured to keep the double line at every degree. Adaptive's float pass
// measures the screen form's noise ray by ray (kernels/surface.h, screen_terms) and escalates the rays it doubts,
// as it does the extent construction's. Plain float has no such check: there the screen form is more accurate
// than the extent construction on the shipped scenes but far less on thin shells (bench/RESULTS.md), so plain
// float keeps the extent construction.
bool screen_form_applies(const Scene& scene, Precision precision);

// Whether RayOrigin::Auto means the point form for a shadow kernel (kernels/point_form.h: P expanded once about
// each surface point, restricted to its shadow rays in lanes): in double and adaptive precision with Bernstein
// isolation, up to the degree its vectors hold. Double's images are the extent construction's bit for bit on the
// shipped scenes; adaptive's float pass measures the point form's own noise (kernels/shadow.h, PointTerms) and its
// images are the extent form's on every shipped scene and hard surface but two, which differ by less than 1/255
// (test_shadows holds both to the certified reference). Plain float alone would not: its point form passes
// test_shadows, but shadows nine scenes' pixels differently at 400x300 (the Barth decic 518), and the extent
// form's are nearer double's in two thirds of them. So plain float's shadow pass runs adaptive's float kernel and
// sends what it doubts to float's extent form (float_measures_noise): its images are the extent form's.
inline constexpr int kMaxPointFormDegree = 15;
bool point_form_applies(const KernelConfig& shadow);

// The shading kernel for a device: in double where it has fp64 (the host's shading bit for bit), else in float;
// pixels side by side in vector lanes on CPUs, whose work-items run one after another.
KernelConfig shading_config(const DeviceInfo& device);

// What the plan needs to know of a device that will carry it out.
struct PlanDevice {
  DeviceInfo info;
  Precision escalation = Precision::Mixed;  // adaptive precision's second pass there (escalation_precision)
};

// Tile side, in traced rays, for a device when the scene leaves it open. GPUs get as many camera rays per launch
// as fill any of them many times over (2048^2 = 4M rays, 128 MB of records; a 1920x1080 preview is one launch per
// pass): the 256^2 tiles of before left an H200 idle between 35 launches, each pass's wall time 5-12 times its
// kernel time (bench/RESULTS.md, "A lent GPU"). A display whose watchdog stops long launches (double at high
// degree on a consumer GPU) takes a smaller render.tile_size. CPUs (PoCL) lose ~2 ms per launch and idle cores at
// each launch's tail, so they get few, large launches too: measured on the Barth sextic at 1024x768, 256-ray
// tiles 137 ms, one 1024-ray tile 109 ms.
inline constexpr int kGpuTileSize = 2048;
inline constexpr int kCpuTileSize = 1024;
int default_tile_size(const DeviceInfo& device);
// The extent form's shadow batch (KernelConfig::shadow_batch) a kernel of this precision gets on this device:
// shadow_batch_width of its native vector width and fused multiply-add in that precision; 0 for mixed precision,
// whose float-float accumulators keep one per ray.
int shadow_batch_on(const DeviceInfo& device, Precision precision);

// The render's plan, settled once for the devices that carry it out (at least one): its passes and their kernels,
// the lanes (the first device's kind's), the tile size (the scene's; else the devices' smallest default, halved
// until several devices have about 8 tiles each) and adaptive precision's second pass (double only where every
// device's fp64 is fast: escalate_in). The renderer, --stats and the api read it and change nothing.
RenderPlan make_render_plan(const Scene& scene, Precision precision, const std::vector<PlanDevice>& devices);

// Adaptive precision's escalation kernels in `precision` instead: double where every device's fp64 is fast (the
// doubted rays then cost about what float does; shadow rays in the point form where it applies), mixed otherwise
// (what make_render_plan plans); float for plain float (float_measures_noise).
void escalate_in(RenderPlan& plan, Precision precision);

// The kernel of the primary pass for one surface of `scene`.
KernelConfig primary_config(const Scene& scene, Precision precision, std::size_t surface = 0);

// How far a shadow ray's origin is moved off the surface, along the normal to the light's side, in units of
// the extent's radius (unit coordinates): well above the hit point's error in the precision, well below what
// shows in an image. Measured with test_shadows' 2000 seeded rays per precision: in float, 1e-4 left 6 origins
// within rounding of the surface and 4 self-shadowed; in double none down to 1e-13.
double shadow_offset_unit(Precision precision);

}  // namespace algray
