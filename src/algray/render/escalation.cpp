// Adaptive precision's second pass: gathers the doubted rays, traces them in mixed precision, puts the answers back.
#include "algray/render/escalation.h"

#include <algorithm>
#include <bit>

namespace algray {

const DoubtReason* doubt_reason(unsigned id) {
  for (const DoubtReason& r : kDoubtReasons)
    if (r.id == id) return &r;
  return nullptr;
}

RayEscalation::RayEscalation(ClSession& session, ProgramCache& cache, const KernelConfig& config, const Scene& scene,
                             std::size_t surface)
    : surface_(session.context, scene, config.precision, surface), tracer_(session, cache, config, surface_) {}

EscalationCount RayEscalation::redo(HitRecord* records, std::size_t count,
                                    const std::function<PixelRay(std::size_t)>& ray_of, std::size_t batch_rays) {
  EscalationCount done;
  std::vector<std::size_t> doubted;
  for (std::size_t i = 0; i < count; ++i)
    if (records[i].flags & ALGRAY_HIT_DOUBT) doubted.push_back(i);
  std::vector<PixelRay> rays;
  for (std::size_t begin = 0; begin < doubted.size(); begin += batch_rays) {
    const std::size_t end = std::min(doubted.size(), begin + batch_rays);
    rays.clear();
    for (std::size_t k = begin; k < end; ++k) rays.push_back(ray_of(doubted[k]));
    TracedBatch traced = tracer_.trace(rays);
    done.kernel_ms += traced.kernel_ms;
    for (std::size_t k = begin; k < end; ++k) {
      HitRecord& r = records[doubted[k]];
      const HitRecord& again = traced.hits[k - begin];
      const std::uint32_t steps =
          std::min(ALGRAY_WORK_MAX, ALGRAY_WORK_ISOLATION_STEPS(r.work) + ALGRAY_WORK_ISOLATION_STEPS(again.work));
      r = again;
      r.work = ALGRAY_WORK_PACK(steps, ALGRAY_WORK_REFINE_ITERATIONS(again.work));
      r.flags |= ALGRAY_HIT_ESCALATED;
    }
  }
  done.rays = doubted.size();
  return done;
}

ShadowEscalation::ShadowEscalation(ClSession& session, ProgramCache& cache, const KernelConfig& config,
                                   const Scene& scene, std::size_t surface, double offset)
    : surface_(session.context, scene, config.precision, surface), tracer_(session, cache, config, surface_, offset) {}

EscalationCount ShadowEscalation::redo(const std::vector<glm::dvec3>& points, const std::vector<glm::vec3>& normals,
                                       const std::vector<glm::dvec3>& light_points,
                                       const std::vector<std::uint64_t>& undecided, std::vector<std::uint64_t>& masks,
                                       std::vector<std::uint64_t>* still_undecided) {
  EscalationCount done;
  if (still_undecided) still_undecided->assign(undecided.size(), 0);
  std::vector<std::size_t> doubted;
  std::vector<glm::dvec3> again_points;
  std::vector<glm::vec3> again_normals;
  std::vector<std::uint64_t> skip;  // every light point but the doubted ones counts as settled
  for (std::size_t i = 0; i < undecided.size(); ++i) {
    if (!undecided[i]) continue;
    doubted.push_back(i);
    again_points.push_back(points[i]);
    again_normals.push_back(normals[i]);
    skip.push_back(~undecided[i]);
    done.rays += static_cast<std::uint64_t>(std::popcount(undecided[i]));
  }
  if (doubted.empty()) return done;
  const ShadowAnswer answer = tracer_.trace(again_points, again_normals, light_points, skip);
  done.kernel_ms = answer.kernel_ms;
  for (std::size_t k = 0; k < doubted.size(); ++k) {
    const std::uint64_t bits = undecided[doubted[k]];
    std::uint64_t& m = masks[doubted[k]];
    m = (m & ~bits) | (answer.masks[k] & bits);
    if (still_undecided && !answer.undecided.empty()) (*still_undecided)[doubted[k]] = answer.undecided[k] & bits;
  }
  return done;
}

}  // namespace algray
