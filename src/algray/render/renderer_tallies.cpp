// The devices' own tallies (pass statistics, shares, programs) added into the render's result.
#include "algray/render/renderer_parts.h"

namespace algray {
using namespace renderer_parts;

void add_counts(PassStats& into, const PassStats& more) {
  into.rays += more.rays;
  into.launches += more.launches;
  into.kernel_ms += more.kernel_ms;
  into.wall_ms += more.wall_ms;
  into.escalated += more.escalated;
  into.escalation_ms += more.escalation_ms;
  into.program_ms.resize(std::max(into.program_ms.size(), more.program_ms.size()));
  for (std::size_t k = 0; k < more.program_ms.size(); ++k) into.program_ms[k] += more.program_ms[k];
}

void add_counts(DeviceShare& into, const DeviceShare& more) {
  into.tiles += more.tiles;
  into.rays += more.rays;
  into.kernel_ms += more.kernel_ms;
  into.programs_ms += more.programs_ms;
}

void Renderer::add_device_tallies(const std::vector<std::unique_ptr<Passes>>& devices, RenderResult& result) {
  const RenderPlan& plan = result.plan;
  for (std::size_t i = 0; i < plan.passes.size(); ++i) {
    PassStats total = devices.front()->tally.stats[i];
    for (std::size_t d = 1; d < devices.size(); ++d) add_counts(total, devices[d]->tally.stats[i]);
    total.name = to_string(plan.passes[i].kind);
    result.passes.push_back(total);
  }
  // Every device loads the same programs; the first device's records stand for them, each device's load time
  // is in its share.
  result.programs = devices.front()->tally.programs;
  for (const auto& passes : devices) {
    result.primary += passes->tally.primary_summary;
    result.shade_ms += passes->tally.shade_ms;
    result.shade_kernel_ms += passes->tally.shade_kernel_ms;
    DeviceShare share;
    share.index = passes->session.info.index;
    share.name = passes->session.info.name;
    share.tiles = passes->tally.tiles;
    share.kernel_ms = passes->tally.shade_kernel_ms;
    for (const PassStats& pass : passes->tally.stats) {
      share.rays += pass.rays;
      share.kernel_ms += pass.kernel_ms;
    }
    for (const ProgramRecord& program : passes->tally.programs) share.programs_ms += program.build_ms;
    result.devices.push_back(share);
  }
}

}  // namespace algray
