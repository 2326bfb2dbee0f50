// The mapping of a KernelConfig onto OpenCL build options.
#include "algray/device/kernel_config.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

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

// Every -D switch the host sets, in the order the options name them, and its value for a config. Each is declared
// once, with its default, legal values and meaning, in kernels/build_switches.h (test_config holds the two lists
// to each other); the host writes every one on every build, so no kernel default decides a render.
struct BuildSwitch {
  const char* name;
  std::string (*value)(const KernelConfig&);
};
std::string flag(bool on) { return on ? "1" : "0"; }
const BuildSwitch kBuildSwitches[] = {
    {"DEGREE", [](const KernelConfig& c) { return std::to_string(c.degree); }},
    {"ALGRAY_DOUBLE", [](const KernelConfig& c) { return flag(c.precision == Precision::Double); }},
    {"ALGRAY_COMPENSATED", [](const KernelConfig& c) { return flag(c.precision == Precision::Mixed); }},
    {"ALGRAY_ESCALATE", [](const KernelConfig& c) { return flag(c.precision == Precision::Adaptive); }},
    {"ISOLATION", [](const KernelConfig& c) { return std::to_string(kernel_id(kIsolationIds, c.isolation)); }},
    {"ISOLATION_POWER_BASIS", [](const KernelConfig& c) { return flag(abilities(c.isolation).power_basis); }},
    {"ISOLATION_ADAPTIVE", [](const KernelConfig& c) { return flag(abilities(c.isolation).adaptive); }},
    {"ISOLATION_POINT_FORM", [](const KernelConfig& c) { return flag(abilities(c.isolation).point_form); }},
    {"SOLVER_LANES", [](const KernelConfig& c) { return flag(lanes_supported(c.isolation, c.refinement)); }},
    {"REFINEMENT", [](const KernelConfig& c) { return std::to_string(kernel_id(kRefinementIds, c.refinement)); }},
    {"RAY_ORIGIN", [](const KernelConfig& c) { return std::to_string(kernel_id(kOriginIds, c.ray_origin)); }},
    // Hexadecimal literals carry the tolerance bit for bit; float builds get a float literal, as devices without
    // fp64 need not accept double constants.
    {"TOLERANCE",
     [](const KernelConfig& c) {
       return c.precision == Precision::Double ? hex_double(c.tolerance)
                                               : hex_double(static_cast<float>(c.tolerance)) + "f";
     }},
    {"MAX_ITERATIONS", [](const KernelConfig& c) { return std::to_string(c.max_iterations); }},
    {"LANES", [](const KernelConfig& c) { return std::to_string(c.lanes); }},
    {"ALGRAY_SETTLE_DOUBTS", [](const KernelConfig& c) { return flag(c.settle_doubts); }},
    {"ALGRAY_SHADOW_BATCH", [](const KernelConfig& c) { return std::to_string(c.shadow_batch); }},
};

}  // namespace

int default_lanes(const std::string& device_type) { return device_type == "CPU" ? 16 : 1; }
int float_shadow_lanes(unsigned native_float_width) {
  if (native_float_width == 0) return kMaxFloatShadowLanes;
  return native_float_width <= 8 ? 8 : kMaxFloatShadowLanes;
}
int shadow_lanes(int lanes, Precision precision, int float_lanes) {
  return std::min(lanes, precision == Precision::Double ? kMaxShadowLanes : float_lanes);
}
int escalation_lanes(int lanes, unsigned native_width) {
  return native_width == 0 ? lanes : std::min(lanes, static_cast<int>(native_width));
}
int shadow_batch_width(unsigned native_width, bool fused_multiply_add) {
  const bool vector_type = native_width == 2 || native_width == 4 || native_width == 8 || native_width == 16;
  return fused_multiply_add && vector_type ? static_cast<int>(native_width) : 0;
}
bool lanes_apply(const KernelConfig& c) {
  if (c.entry == "shadow") return c.ray_origin == RayOrigin::Point;  // the extent form batches its own way
  return (c.entry == "primary" || c.entry == "trace") && lanes_supported(c.isolation, c.refinement);
}

std::string KernelConfig::build_options() const {
  std::string options = "-cl-std=CL1.2";
  for (const BuildSwitch& s : kBuildSwitches) options += std::string(" -D ") + s.name + "=" + s.value(*this);
  // PoCL prints its compiler's warning count ("4 warnings generated.") straight to stderr on a cold cache; a
  // successful command says nothing, and a failed build still reports its errors and log.
  return options + " -w";
}

std::vector<std::string> build_switch_names() {
  std::vector<std::string> names;
  for (const BuildSwitch& s : kBuildSwitches) names.emplace_back(s.name);
  return names;
}

std::string KernelConfig::key() const {
  return entry + " degree=" + std::to_string(degree) + " precision=" + to_string(precision) +
         " isolation=" + to_string(isolation) + " refinement=" + to_string(refinement) +
         " origin=" + to_string(ray_origin) + " tolerance=" + hex_double(tolerance) +
         " max_iterations=" + std::to_string(max_iterations) + (lanes != 1 ? " lanes=" + std::to_string(lanes) : "") +
         (settle_doubts ? " settle_doubts" : "") + (shadow_batch != 0 ? " batch=" + std::to_string(shadow_batch) : "");
}

}  // namespace algray
