// What the passes find per ray: hit records of camera rays, shadow answers and groups of secondary rays.
#pragma once

#include <cstdint>
#include <vector>

#include "algray/render/render_plan.h"
#include "algray/scene/camera.h"
#include "kernels/algray_shared.h"

namespace algray {

struct HitBuffer {
  int width = 0, height = 0;
  std::vector<HitRecord> records;  // row-major, top row first
  std::vector<std::uint8_t> surface;  // which scene surface each record hit; empty when the scene has one
  const HitRecord& at(int x, int y) const { return records[static_cast<std::size_t>(y) * width + x]; }
  int surface_of(std::size_t i) const { return surface.empty() ? 0 : surface[i]; }
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

// One group of reflection, transmission or antialias rays: where each adds to the image and what it found.
struct SecondaryBatch {
  PassKind pass = PassKind::Reflection;  // Reflection, Transmission, or Antialias (camera rays)
  int depth = 1;                      // 1: spawned by the camera rays' hits; 0 for antialias batches
  bool refinement = false;            // part of adaptive antialiasing: replaces its pixel's first colour
  // The traced camera ray it contributes to (index into RenderResult::hits), or for refinement batches the
  // pixel. While a tile renders, the index is the tile's own.
  std::vector<std::uint32_t> sample;
  std::vector<double> weight;         // its share of that ray's colour
  std::vector<PixelRay> rays;
  std::vector<HitRecord> hits;
  std::vector<std::uint8_t> hit_surface;  // as HitBuffer::surface
  ShadowData shadows;
};

// Totals over the camera rays of the primary pass, for --stats, gathered tile by tile.
struct PrimarySummary {
  std::uint64_t rays = 0, hits = 0, depth_limited = 0, isolation_steps = 0, refine_iterations = 0;
  std::uint64_t pixels = 0, pixels_hit = 0;  // output pixels, and those some antialiasing sample hit
  // A block of whole pixels: width x height records, row-major, `samples` x `samples` per pixel.
  void add(const HitRecord* records, int width, int height, int samples);
  PrimarySummary& operator+=(const PrimarySummary& other);
};
PrimarySummary summarise_hits(const HitBuffer& hits, int samples);

// The world-space point a hit record stands for on the ray that produced it.
glm::dvec3 hit_point(const PixelRay& ray, const HitRecord& hit);

}  // namespace algray
