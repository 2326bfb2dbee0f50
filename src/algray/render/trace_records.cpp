// Totals over hit records, and the point a record stands for.
#include "algray/render/trace_records.h"

#include <algorithm>

namespace algray {

glm::dvec3 hit_point(const PixelRay& ray, const HitRecord& hit) {
  const double t = static_cast<double>(hit.t_hi) + static_cast<double>(hit.t_lo);
  return ray.origin + t * ray.direction;
}

void PrimarySummary::add(const HitRecord* records, int width, int height, int samples) {
  const std::size_t count = static_cast<std::size_t>(width) * height;
  std::uint64_t found = 0;
  rays += count;
  for (std::size_t i = 0; i < count; ++i) {
    const HitRecord& h = records[i];
    found += (h.flags & ALGRAY_HIT_FOUND) != 0;
    depth_limited += (h.flags & ALGRAY_HIT_BUDGET) != 0;
    isolation_steps += ALGRAY_WORK_ISOLATION_STEPS(h.work);
    refine_iterations += ALGRAY_WORK_REFINE_ITERATIONS(h.work);
  }
  hits += found;
  // A pixel shows the surface when any of its antialiasing samples hit it.
  if (samples == 1) {
    pixels += count;
    pixels_hit += found;
    return;
  }
  for (int y = 0; y + samples <= height; y += samples)
    for (int x = 0; x + samples <= width; x += samples) {
      bool any = false;
      for (int sy = 0; sy < samples; ++sy)
        for (int sx = 0; sx < samples; ++sx)
          any |= (records[static_cast<std::size_t>(y + sy) * width + x + sx].flags & ALGRAY_HIT_FOUND) != 0;
      ++pixels;
      pixels_hit += any;
    }
}

PrimarySummary& PrimarySummary::operator+=(const PrimarySummary& other) {
  rays += other.rays;
  hits += other.hits;
  depth_limited += other.depth_limited;
  isolation_steps += other.isolation_steps;
  refine_iterations += other.refine_iterations;
  pixels += other.pixels;
  pixels_hit += other.pixels_hit;
  return *this;
}

PrimarySummary summarise_hits(const HitBuffer& hits, int samples) {
  PrimarySummary s;
  s.add(hits.records.data(), hits.width, hits.height, std::max(samples, 1));
  return s;
}

}  // namespace algray
