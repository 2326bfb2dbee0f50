// Solver diagnostics per pixel from the primary pass's hit records.
#include "algray/render/solver_aov.h"

#include <algorithm>
#include <sstream>

namespace algray {

std::string aov_choices(const char* last) {
  std::string out;
  for (std::size_t i = 0; i < kSolverAovs.size(); ++i) {
    if (i > 0) out += last && i + 1 == kSolverAovs.size() ? std::string(" ") + last + " " : std::string(", ");
    out += kSolverAovs[i].word;
  }
  return out;
}

bool parse_aov_list(const std::string& text, std::vector<SolverAov>& out, std::string& error) {
  std::istringstream in(text);
  std::string word;
  while (std::getline(in, word, ',')) {
    const auto known = std::find_if(kSolverAovs.begin(), kSolverAovs.end(),
                                    [&](const SolverAovName& n) { return word == n.word; });
    if (known == kSolverAovs.end()) {
      error = "unknown AOV '" + word + "': expected a comma-separated list of " + aov_choices();
      return false;
    }
    if (std::find(out.begin(), out.end(), known->aov) == out.end()) out.push_back(known->aov);
  }
  if (out.empty()) {
    error = "empty AOV list: expected " + aov_choices("or");
    return false;
  }
  return true;
}

SolverClass solver_class(const HitRecord& hit) {
  if (!(hit.flags & ALGRAY_HIT_IN_EXTENT)) return SolverClass::OutsideExtent;
  if (hit.flags & ALGRAY_HIT_BUDGET) return SolverClass::HalvingLimit;
  if (!(hit.flags & ALGRAY_HIT_FOUND)) return SolverClass::NoRoot;
  if (hit.flags & ALGRAY_HIT_CLUSTER) return SolverClass::Cluster;
  if (hit.flags & ALGRAY_HIT_EXACT) return SolverClass::ExactZero;
  return SolverClass::Isolated;
}

std::vector<std::uint32_t> SolverWork::total() const {
  std::vector<std::uint32_t> sum(isolation_steps.size());
  for (std::size_t i = 0; i < sum.size(); ++i) sum[i] = isolation_steps[i] + refine_iterations[i];
  return sum;
}

std::vector<std::uint8_t> SolverWork::in_extent() const {
  std::vector<std::uint8_t> in(flags.size());
  for (std::size_t i = 0; i < in.size(); ++i) in[i] = (flags[i] & ALGRAY_HIT_IN_EXTENT) != 0;
  return in;
}

SolverWork empty_solver_work(int width, int height, int samples) {
  SolverWork w;
  w.samples = std::max(samples, 1);
  w.width = width;
  w.height = height;
  const std::size_t n = static_cast<std::size_t>(w.width) * w.height;
  w.isolation_steps.assign(n, 0);
  w.refine_iterations.assign(n, 0);
  w.flags.assign(n, 0);
  w.classification.assign(n, 0);
  return w;
}

void add_tile_work(SolverWork& w, const PrimaryTile& tile) {
  for (int y = 0; y < tile.height; ++y) {
    for (int x = 0; x < tile.width; ++x) {
      const HitRecord& h = tile.hits[static_cast<std::size_t>(y) * tile.width + x];
      const int tx = tile.x0 + x, ty = tile.y0 + y;
      const std::size_t i = static_cast<std::size_t>(ty / w.samples) * w.width + tx / w.samples;
      w.isolation_steps[i] += ALGRAY_WORK_ISOLATION_STEPS(h.work);
      w.refine_iterations[i] += ALGRAY_WORK_REFINE_ITERATIONS(h.work);
      w.flags[i] |= h.flags;
      w.classification[i] = std::max(w.classification[i], static_cast<std::uint32_t>(solver_class(h)));
    }
  }
}

SolverWork solver_work(const RenderResult& result) {
  const HitBuffer& hits = result.hits;
  const int samples = std::max(result.plan.samples, 1);
  SolverWork w = empty_solver_work(hits.width / samples, hits.height / samples, samples);
  PrimaryTile whole;
  whole.width = hits.width;
  whole.height = hits.height;
  whole.samples = samples;
  whole.hits = hits.records.data();
  add_tile_work(w, whole);
  return w;
}

void add_solver_aovs(FrameImage& image, SolverWork&& work, const std::vector<SolverAov>& aovs) {
  for (SolverAov aov : aovs) {
    std::vector<std::uint32_t>* values = nullptr;
    switch (aov) {
      case SolverAov::Iterations: values = &work.refine_iterations; break;
      case SolverAov::Isolation: values = &work.isolation_steps; break;
      case SolverAov::Classification: values = &work.classification; break;
      case SolverAov::Flags: values = &work.flags; break;
    }
    for (const SolverAovName& n : kSolverAovs)
      if (n.aov == aov) image.uint_channels.push_back({n.channel, std::move(*values)});
  }
  work = SolverWork{};
}

}  // namespace algray
