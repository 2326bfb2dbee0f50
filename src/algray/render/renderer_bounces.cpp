// A tile's reflected and transmitted rays, bounce by bounce, up to the plan's depth.
#include <utility>

#include "algray/render/renderer_parts.h"

namespace algray {
using namespace renderer_parts;

void Renderer::run_bounces(Passes& passes, const Tile& tile, std::vector<Bounce> current, int depth, bool refinement) {
  const Scene& scene = passes.scene;
  RenderResult& result = passes.result;
  if (current.empty() || depth > scene.render.max_depth) return;
  const std::size_t samples_in_tile = refinement ? tile.pixels() : tile.rays();
  if (current.size() > passes.options.batch_rays) {
    // A group at a time, to the last bounce, so that memory holds one group's rays however many a bounce makes.
    std::vector<std::vector<Bounce>> groups = split_by_sample(current, samples_in_tile, passes.options.batch_rays);
    for (std::vector<Bounce>& group : groups) run_bounces(passes, tile, std::move(group), depth, refinement);
    return;
  }
  const double offset = shadow_offset_unit(passes.precision) * scene.extent.unit_scale();
  // Below this a bounce cannot change a pixel's 8-bit colour.
  constexpr double kNegligibleWeight = 1.0 / 512;
  const double pixel_share =
      refinement ? static_cast<double>(result.plan.refine_samples) * result.plan.refine_samples : 1.0;
  const PassKind kinds[2] = {PassKind::Reflection, PassKind::Transmission};
  const bool wanted[2] = {passes.stats_of(kinds[0]) != nullptr, passes.stats_of(kinds[1]) != nullptr};
  std::vector<Bounce> next;
  for (int k = 0; k < 2; ++k) {
    if (!wanted[k]) continue;
    SecondaryBatch batch;
    batch.pass = kinds[k];
    batch.depth = depth;
    batch.refinement = refinement;
    for (const Bounce& b : current) {
      const Materials& sides = scene.surfaces[b.surface].materials;
      const Material& m = (b.hit.flags & ALGRAY_HIT_BACK) ? sides.back : sides.front;
      const double share = k == 0 ? m.reflectivity : m.transparency;
      // A refined pixel's rays carry 1/n^2 each: the cut-off is on the share of the pixel they stand for.
      if (b.weight * share * pixel_share < kNegligibleWeight) continue;
      const glm::dvec3 p = hit_point(b.ray, b.hit);
      const glm::dvec3 n(b.hit.normal_x, b.hit.normal_y, b.hit.normal_z);  // faces the incoming ray
      const glm::dvec3 d = b.ray.direction;
      // Off the surface on the side the new ray leaves into, as shadow rays are, so it cannot find its own hit.
      const PixelRay ray = k == 0 ? PixelRay{p + offset * n, d - 2 * glm::dot(d, n) * n} : PixelRay{p - offset * n, d};
      batch.sample.push_back(b.sample);
      batch.weight.push_back(b.weight * share);
      batch.rays.push_back(ray);
    }
    if (batch.rays.empty()) continue;
    trace_batch(passes, batch);
    std::vector<Bounce> found =
        shade_batch(passes, tile, batch, refinement ? passes.work.refined_colour : passes.work.secondary);
    passes.work.any_secondary = true;
    next.insert(next.end(), found.begin(), found.end());
  }
  // This bounce's rays are done with before the next bounce's are traced.
  current.clear();
  current.shrink_to_fit();
  run_bounces(passes, tile, std::move(next), depth + 1, refinement);
}

std::vector<Renderer::Bounce> Renderer::shade_batch(Passes& passes, const Tile& tile, SecondaryBatch& batch,
                                                    std::vector<glm::dvec3>& colour) {
  const auto start = std::chrono::steady_clock::now();
  passes.shader->add_batch(batch, colour, passes.work.refined_alpha);
  passes.tally.shade_ms += ms_since(start);
  std::vector<Bounce> found;
  for (std::size_t i = 0; i < batch.rays.size(); ++i)
    if (batch.hits[i].flags & ALGRAY_HIT_FOUND)
      found.push_back({batch.sample[i], batch.weight[i], batch.rays[i], batch.hits[i],
                       batch.hit_surface.empty() ? std::uint8_t{0} : batch.hit_surface[i]});
  if (passes.options.keep_records) {
    const RenderPlan& plan = passes.result.plan;
    const std::lock_guard<std::mutex> hold(passes.shared.lock);
    for (std::uint32_t& sample : batch.sample)
      sample = batch.refinement ? static_cast<std::uint32_t>(tile.pixel_in_image(sample, plan.width))
                                : tile.ray_in_image(sample, plan.trace_width());
    passes.result.secondary.push_back(std::move(batch));
  }
  return found;
}

}  // namespace algray
