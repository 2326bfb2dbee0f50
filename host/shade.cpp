// Preview shading and the assembly of a frame's channels from the primary pass.
#include "shade.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

namespace algray {

glm::dvec3 pixel_direction(const RayBasis& basis, int px, int py) {
  const double fx = px + 0.5, fy = py + 0.5;
  return glm::normalize(basis.d00 + fx * basis.du + fy * basis.dv);
}

FrameImage shade_preview(const Scene& scene, const RenderResult& result) {
  const HitBuffer& hits = result.hits;
  FrameImage img;
  img.width = hits.width;
  img.height = hits.height;
  const std::size_t n = hits.records.size();
  img.rgba.resize(4 * n);
  img.depth.resize(n);
  img.normal.resize(3 * n);
  FrameImage::UintChannel steps{"solver.isolationSteps", std::vector<std::uint32_t>(n)};
  FrameImage::UintChannel iterations{"solver.refineIterations", std::vector<std::uint32_t>(n)};
  FrameImage::UintChannel flags{"solver.flags", std::vector<std::uint32_t>(n)};
  // Rows are independent; shading a 1024x768 frame on one core costs as much as a fifth of the kernel.
  auto shade_rows = [&](int y_begin, int y_end) {
    for (int y = y_begin; y < y_end; ++y) {
      for (int x = 0; x < hits.width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * hits.width + x;
        const HitRecord& h = hits.records[i];
        steps.values[i] = h.work & 0xffffu;
        iterations.values[i] = h.work >> 16;
        flags.values[i] = h.flags;
        glm::dvec4 c = scene.image.background;
        if (h.flags & ALGRAY_HIT_FOUND) {
          const glm::dvec3 normal(h.normal_x, h.normal_y, h.normal_z);
          const double facing = std::fabs(glm::dot(normal, pixel_direction(result.basis, x, y)));
          const glm::dvec3 base = (h.flags & ALGRAY_HIT_BACK) ? scene.colours.back : scene.colours.front;
          c = glm::dvec4(base * (kPreviewAmbient + (1 - kPreviewAmbient) * facing), 1);
          img.normal[3 * i] = h.normal_x;
          img.normal[3 * i + 1] = h.normal_y;
          img.normal[3 * i + 2] = h.normal_z;
        }
        img.depth[i] = h.depth;
        for (int k = 0; k < 4; ++k) img.rgba[4 * i + k] = static_cast<float>(c[k]);
      }
    }
  };
  const int threads = static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 16u));
  std::vector<std::thread> workers;
  for (int t = 1; t < threads; ++t)
    workers.emplace_back(shade_rows, hits.height * t / threads, hits.height * (t + 1) / threads);
  shade_rows(0, hits.height / threads);
  for (std::thread& w : workers) w.join();
  img.uint_channels = {std::move(steps), std::move(iterations), std::move(flags)};
  return img;
}

}  // namespace algray
