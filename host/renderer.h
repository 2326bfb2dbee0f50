// Dispatch of the primary kernel over an image in tiles, and the surface data the kernels read.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "algray_shared.h"
#include "camera.h"
#include "cl_runtime.h"
#include "device_surface.h"
#include "program_cache.h"
#include "render_plan.h"
#include "scene.h"

namespace algray {

struct HitBuffer {
  int width = 0, height = 0;
  std::vector<HitRecord> records;  // row-major, top row first
  std::vector<std::uint8_t> surface;  // which scene surface each record hit; empty when the scene has one
  const HitRecord& at(int x, int y) const { return records[static_cast<std::size_t>(y) * width + x]; }
  int surface_of(std::size_t i) const { return surface.empty() ? 0 : surface[i]; }
};

struct PassStats {
  std::string name;
  std::vector<std::string> program_keys;  // ProgramRecord::key of the kernels the pass launched, per surface
  std::vector<double> program_ms;         // device time of each of those kernels
  std::uint64_t rays = 0;                 // rays traced, each once however many surfaces it was tested against
  int launches = 0;
  double kernel_ms = 0;  // device time summed over launches (profiling events)
  double wall_ms = 0;
};

// What the shadow pass found for one light: for each surface point, bit s set when sample point s is hidden.
struct LightOcclusion {
  int light = 0;                     // index into Scene::lights
  std::vector<std::uint64_t> masks;  // indexed like ShadowData::points
};

// The shadow pass's answers for one batch of hits.
struct ShadowData {
  std::vector<std::uint32_t> points;     // the index in its batch of each hit the pass traced from
  std::vector<LightOcclusion> occlusion;  // one per shadow-casting light
};

// One bounce's reflection or transmission rays: where each adds to the image and what it found.
struct SecondaryBatch {
  std::string pass;                   // "reflection", "transmission", or "antialias" (camera rays)
  int depth = 1;                      // 1: spawned by the camera rays' hits; 0 for antialias batches
  bool refinement = false;            // part of adaptive antialiasing: replaces its pixel's first colour
  std::vector<std::uint32_t> sample;  // the traced camera ray (index into RenderResult::hits) it contributes to
  std::vector<double> weight;         // its share of that ray's colour
  std::vector<PixelRay> rays;
  std::vector<HitRecord> hits;
  std::vector<std::uint8_t> hit_surface;  // as HitBuffer::surface
  ShadowData shadows;
};

struct RenderResult {
  RenderPlan plan;
  HitBuffer hits;       // one record per traced ray: plan.trace_width() x plan.trace_height()
  KernelConfig config;  // of the first surface's primary pass, with precision and tolerance as used
  RayBasis basis;       // of the traced rays (per antialiasing sample, not per pixel)
  std::vector<ProgramRecord> programs;
  std::vector<PassStats> passes;
  ShadowData shadows;                    // of the camera rays' hits
  std::vector<SecondaryBatch> secondary;  // in the order traced: by depth, reflection before transmission
  // Adaptive antialiasing: 1 for the pixels (of hits) whose colour is the antialias batch's rays, not their own.
  std::vector<std::uint8_t> refined;
};

// Precision a scene renders in on a device: as asked, or double where fp64 exists. Throws DeviceError when
// double is asked of a device without fp64.
Precision resolve_precision(const Scene& scene, const DeviceInfo& device);

// The world-space point a hit record stands for on the ray that produced it.
glm::dvec3 hit_point(const PixelRay& ray, const HitRecord& hit);

// Tile side for a device when the scene leaves it open. GPUs get launches short enough for display watchdogs;
// CPUs (PoCL) lose ~2 ms per launch and idle cores at each launch's tail, so they get few, large launches:
// measured on the Barth sextic at 1024x768, 256-pixel tiles 137 ms, one 1024-pixel tile 109 ms.
int default_tile_size(const DeviceInfo& device);

class Renderer {
 public:
  Renderer(ClSession& session, ProgramCache& cache) : session_(session), cache_(cache) {}
  // Runs every pass of the scene's plan. show_progress: print per-tile progress to stderr (for terminals).
  RenderResult render(const Scene& scene, bool show_progress);

 private:
  struct Passes;
  struct Bounce;
  void run_primary(Passes& passes, bool show_progress);
  void trace_batch(Passes& passes, SecondaryBatch& batch);
  // Reflection and transmission rays, bounce by bounce, from the hits in `current`.
  void run_bounces(Passes& passes, std::vector<Bounce> current, bool refinement);
  // Adaptive antialiasing: n x n more camera rays in the pixels that differ from a neighbour.
  void run_antialias(Passes& passes);

  ClSession& session_;
  ProgramCache& cache_;
};

}  // namespace algray
