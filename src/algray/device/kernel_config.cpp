// The mapping of a KernelConfig onto OpenCL build options.
#include "algray/device/kernel_config.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <utility>

#include "kernels/algray_shared.h"

namespace algray {
namespace {

// Each choice's id in the kernels (algray_shared.h).
constexpr std::array<std::pair<Isolation, int>, 4> kIsolationIds{
    {{Isolation::Bernstein, ALGRAY_ISOLATION_BERNSTEIN},
     {Isolation::PowerDescartes, ALGRAY_ISOLATION_POWER},
     {Isolation::Sturm, ALGRAY_ISOLATION_STURM},
     {Isolation::DerivativeChain, ALGRAY_ISOLATION_DERIVATIVE_CHAIN}}};
constexpr std::array<std::pair<Refinement, int>, 5> kRefinementIds{
    {{Refinement::Brent, ALGRAY_REFINEMENT_BRENT},
     {Refinement::Bisection, ALGRAY_REFINEMENT_BISECTION},
     {Refinement::RegulaFalsi, ALGRAY_REFINEMENT_REGULA_FALSI},
     {Refinement::Illinois, ALGRAY_REFINEMENT_ILLINOIS},
     {Refinement::Newton, ALGRAY_REFINEMENT_NEWTON}}};

template <typename Enum, std::size_t N>
int kernel_id(const std::array<std::pair<Enum, int>, N>& table, Enum value) {
  for (const auto& [e, id] : table)
    if (e == value) return id;
  return 0;
}
// Auto never reaches a kernel: primary_config resolves it.
constexpr std::array<std::pair<RayOrigin, int>, 4> kOriginIds{{{RayOrigin::Extent, ALGRAY_ORIGIN_EXTENT},
                                                               {RayOrigin::Eye, ALGRAY_ORIGIN_EYE},
                                                               {RayOrigin::Screen, ALGRAY_ORIGIN_SCREEN},
                                                               {RayOrigin::Point, ALGRAY_ORIGIN_POINT}}};

std::string hex_double(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

}  // namespace

int default_lanes(const std::string& device_type) { return device_type == "CPU" ? 16 : 1; }
int shadow_lanes(int lanes) { return lanes < kMaxShadowLanes ? lanes : kMaxShadowLanes; }
bool lanes_apply(const KernelConfig& c) {
  if (c.entry == "shadow") return c.ray_origin == RayOrigin::Point;  // the extent form batches its own way
  return (c.entry == "primary" || c.entry == "trace") && c.isolation == Isolation::Bernstein &&
         c.refinement == Refinement::Brent;
}

std::string KernelConfig::build_options() const {
  const int isolation_id = kernel_id(kIsolationIds, isolation);
  const int refinement_id = kernel_id(kRefinementIds, refinement);
  const int origin_id = kernel_id(kOriginIds, ray_origin);
  // Hexadecimal literals carry the tolerance bit for bit; float builds get a float literal, as devices
  // without fp64 need not accept double constants.
  const std::string tolerance_literal =
      precision == Precision::Double ? hex_double(tolerance) : hex_double(static_cast<float>(tolerance)) + "f";
  return "-cl-std=CL1.2 -D DEGREE=" + std::to_string(degree) +
         " -D ALGRAY_DOUBLE=" + (precision == Precision::Double ? "1" : "0") +
         " -D ALGRAY_COMPENSATED=" + (precision == Precision::Mixed ? "1" : "0") +
         " -D ALGRAY_ESCALATE=" + (precision == Precision::Adaptive ? "1" : "0") +
         " -D ISOLATION=" + std::to_string(isolation_id) + " -D REFINEMENT=" + std::to_string(refinement_id) +
         " -D RAY_ORIGIN=" + std::to_string(origin_id) + " -D TOLERANCE=" + tolerance_literal +
         " -D MAX_ITERATIONS=" + std::to_string(max_iterations) + " -D LANES=" + std::to_string(lanes) +
         (settle_doubts ? " -D ALGRAY_SETTLE_DOUBTS=1" : "") +
         // PoCL prints its compiler's warning count ("4 warnings generated.") straight to stderr on a cold cache;
         // a successful command says nothing, and a failed build still reports its errors and log.
         " -w";
}

std::string KernelConfig::key() const {
  return entry + " degree=" + std::to_string(degree) + " precision=" + to_string(precision) +
         " isolation=" + to_string(isolation) + " refinement=" + to_string(refinement) +
         " origin=" + to_string(ray_origin) + " tolerance=" + hex_double(tolerance) +
         " max_iterations=" + std::to_string(max_iterations) + (lanes != 1 ? " lanes=" + std::to_string(lanes) : "") +
         (settle_doubts ? " settle_doubts" : "");
}

}  // namespace algray
