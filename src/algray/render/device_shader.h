// Shading on the device: kernels/shade.cl turns a tile's camera-ray records into the film's pixels where they lie.
#pragma once

#include <cstdint>
#include <vector>

#include "algray/device/cl_runtime.h"
#include "algray/device/program_cache.h"
#include "algray/io/image_io.h"
#include "algray/render/device_surface.h"
#include "algray/render/shade.h"
#include "algray/render/trace_records.h"

namespace algray {

// One tile's camera rays as the shading kernel takes them.
struct ShadeTile {
  int trace_x0 = 0, trace_y0 = 0, trace_w = 0, trace_h = 0;  // in traced rays: whole pixels of samples x samples
  const cl::Buffer* hits = nullptr;        // the primary kernel's records, trace_w x trace_h, row-major
  const std::uint8_t* surface = nullptr;   // which surface each hit; null when the scene has one
  const ShadowData* shadows = nullptr;     // the tile's shadow pass; null without one
  const glm::dvec3* secondary = nullptr;   // per ray, what its bounces brought back; null without bounces
  int kept_first = 0, kept_end = 0;        // the image rows whose camera rays the totals count
};

// The shading kernel of one device for one render: the scene's materials, lights and sections uploaded once, the
// film bound per band of rows, then tile after tile. It shades as `shader` does (same formulas, in the same order,
// in double where the device has fp64, else in float): colours within rounding of the host's, depth and normal
// the records' own.
class DeviceShader {
 public:
  DeviceShader(ClSession& session, ProgramCache& cache, const Scene& scene, const Shader& shader);
  DeviceShader(const DeviceShader&) = delete;
  DeviceShader& operator=(const DeviceShader&) = delete;
  const ProgramRecord& program() const { return program_; }

  // The film the tiles' pixels go to, image rows [film_y0, film_y0 + film.height). `alone`: this device shades
  // every tile of it, and the kernel writes the film's own memory (on a CPU without a copy; a GPU copies it back
  // once, in finish_film). Otherwise the device shades into memory of its own and each tile's pixels are read
  // back as soon as it is shaded.
  void bind_film(FrameImage& film, int film_y0, bool alone);
  // Shades one tile into the bound film. Returns its camera rays' totals; adds the kernel's device time to kernel_ms.
  PrimarySummary shade(const ShadeTile& tile, double& kernel_ms);
  // Every pixel shaded so far in the film's host memory, which the device then no longer writes.
  void finish_film();

 private:
  // `buffer` with room for at least `bytes` (grown, never shrunk: the next tile reuses it).
  void ensure(cl::Buffer& buffer, std::size_t& capacity, std::size_t bytes, cl_mem_flags flags);
  void upload_shadows(const ShadeTile& tile);
  void read_back_tile(const ShadeTile& tile);

  ClSession& session_;
  ProgramRecord program_;
  cl::Kernel kernel_;
  Precision precision_ = Precision::Double;  // the kernel's REAL: double where the device has fp64
  int samples_ = 1;
  int lanes_ = 1;  // pixels of a row per work-item
  std::vector<int> occlusion_row_;  // per scene light: its row in a tile's ShadowData::occlusion, or -1
  // The render's constants, uploaded once.
  cl::Buffer materials_, light_colours_, light_first_, light_occlusion_, light_points_;
  cl::Buffer section_planes_, section_looks_, section_surfaces_;
  // Per tile, grown to the largest tile.
  cl::Buffer surface_, point_of_hit_, masks_, secondary_, summary_;
  std::size_t surface_bytes_ = 0, point_of_hit_bytes_ = 0, masks_bytes_ = 0, secondary_bytes_ = 0,
              summary_bytes_ = 0;
  std::vector<std::uint32_t> point_of_hit_staging_;
  std::vector<std::uint64_t> masks_staging_;
  Real4Staging secondary_staging_;  // in the kernel's REAL, so that the sum is the host's
  std::vector<cl_uint> summary_staging_;
  // The bound film: its host memory, and the device's buffers of its channels.
  FrameImage* film_ = nullptr;
  int film_y0_ = 0;
  bool alone_ = true;
  cl::Buffer film_rgba_, film_depth_, film_normal_;
  std::size_t film_rgba_bytes_ = 0, film_depth_bytes_ = 0, film_normal_bytes_ = 0;  // memory of its own (not alone)
};

}  // namespace algray
