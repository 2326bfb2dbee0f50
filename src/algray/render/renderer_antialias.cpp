// Adaptive antialiasing: the pixels of a tile whose colour differs from a neighbour's, traced again on the finer
// grid.
#include <utility>

#include "algray/render/renderer_parts.h"

namespace algray {
using namespace renderer_parts;

void Renderer::refine_tile(Passes& passes, const Tile& tile, const std::vector<std::uint8_t>& refine) {
  RenderResult& result = passes.result;
  const RenderPlan& plan = result.plan;
  const int n = plan.refine_samples;
  std::vector<std::uint32_t> pixels;  // the tile's pixels to refine, row-major
  for (std::size_t k = 0; k < tile.pixels(); ++k)
    if (refine[passes.film_pixel(tile.pixel_in_image(k, plan.width))]) pixels.push_back(static_cast<std::uint32_t>(k));
  if (pixels.empty()) return;
  passes.work.refined_colour.assign(tile.pixels(), glm::dvec3(0));
  passes.work.refined_alpha.assign(tile.pixels(), 0.0);
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
    run_bounces(passes, tile, shade_batch(passes, tile, batch, passes.work.refined_colour), 1, true);
  }
  const auto start = std::chrono::steady_clock::now();
  for (std::uint32_t k : pixels)
    passes.shader->resolve_refined(passes.film_pixel(tile.pixel_in_image(k, plan.width)), passes.work.refined_colour[k],
                                   passes.work.refined_alpha[k], result.image);
  passes.tally.shade_ms += ms_since(start);
}

}  // namespace algray
