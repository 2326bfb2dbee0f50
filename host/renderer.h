// Dispatch of the primary kernel over an image in tiles, and the surface data the kernels read.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "algray_shared.h"
#include "camera.h"
#include "cl_runtime.h"
#include "program_cache.h"
#include "scene.h"

namespace algray {

// The polynomial as the kernels see it: in unit coordinates of the extent, scaled to max |coefficient| = 1.
struct SurfaceData {
  int degree = 0;
  std::vector<cl_uint> exponents;  // i | j << 8 | k << 16, sorted by i, j, k descending
  std::vector<double> coefficients;
  cl_uint even_axes = 0;  // bit a set when every exponent of axis a is even (the kernels then step by squares)
};
SurfaceData prepare_surface(const Scene& scene);

struct HitBuffer {
  int width = 0, height = 0;
  std::vector<HitRecord> records;  // row-major, top row first
  const HitRecord& at(int x, int y) const { return records[static_cast<std::size_t>(y) * width + x]; }
};

struct PassStats {
  std::string name;
  std::string program_key;  // ProgramRecord::key of the kernel the pass launched
  std::uint64_t rays = 0;
  int launches = 0;
  double kernel_ms = 0;  // device time summed over launches (profiling events)
  double wall_ms = 0;
};

struct RenderResult {
  HitBuffer hits;
  KernelConfig config;  // of the primary pass, with precision and tolerance as used
  RayBasis basis;
  std::vector<ProgramRecord> programs;
  std::vector<PassStats> passes;
};

// Precision a scene renders in on a device: as asked, or double where fp64 exists. Throws DeviceError when
// double is asked of a device without fp64.
Precision resolve_precision(const Scene& scene, const DeviceInfo& device);
KernelConfig primary_config(const Scene& scene, Precision precision);

// Tile side for a device when the scene leaves it open. GPUs get launches short enough for display watchdogs;
// CPUs (PoCL) lose ~2 ms per launch and idle cores at each launch's tail, so they get few, large launches:
// measured on the Barth sextic at 1024x768, 256-pixel tiles 137 ms, one 1024-pixel tile 109 ms.
int default_tile_size(const DeviceInfo& device);

class Renderer {
 public:
  Renderer(ClSession& session, ProgramCache& cache) : session_(session), cache_(cache) {}
  // show_progress: print per-tile progress to stderr (for terminals).
  RenderResult render(const Scene& scene, bool show_progress);

 private:
  ClSession& session_;
  ProgramCache& cache_;
};

}  // namespace algray
