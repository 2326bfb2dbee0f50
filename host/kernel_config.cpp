// Names of the solver choices and the mapping of a KernelConfig onto OpenCL build options.
#include "kernel_config.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <utility>

#include "algray_shared.h"

namespace algray {
namespace {

template <typename E, std::size_t N>
bool parse_enum(const std::array<std::pair<const char*, E>, N>& names, const std::string& name, E& out) {
  for (const auto& [text, value] : names)
    if (name == text) {
      out = value;
      return true;
    }
  return false;
}

template <typename E, std::size_t N>
std::string enum_name(const std::array<std::pair<const char*, E>, N>& names, E value) {
  for (const auto& [text, v] : names)
    if (v == value) return text;
  return "?";
}

template <typename E, std::size_t N>
std::string enum_choices(const std::array<std::pair<const char*, E>, N>& names) {
  std::string s;
  for (const auto& [text, v] : names) s += (s.empty() ? "" : ", ") + std::string(text);
  return s;
}

constexpr std::array<std::pair<const char*, Precision>, 3> kPrecisions{
    {{"float", Precision::Float}, {"double", Precision::Double}, {"mixed", Precision::Mixed}}};
// Each choice: its name in scenes and on the command line, and its id in the kernels (algray_shared.h).
constexpr std::array<std::pair<const char*, Isolation>, 4> kIsolations{
    {{"bernstein", Isolation::Bernstein},
     {"descartes", Isolation::PowerDescartes},
     {"sturm", Isolation::Sturm},
     {"derivative-chain", Isolation::DerivativeChain}}};
constexpr std::array<std::pair<Isolation, int>, 4> kIsolationIds{
    {{Isolation::Bernstein, ALGRAY_ISOLATION_BERNSTEIN},
     {Isolation::PowerDescartes, ALGRAY_ISOLATION_POWER},
     {Isolation::Sturm, ALGRAY_ISOLATION_STURM},
     {Isolation::DerivativeChain, ALGRAY_ISOLATION_DERIVATIVE_CHAIN}}};
constexpr std::array<std::pair<const char*, Refinement>, 5> kRefinements{{{"brent", Refinement::Brent},
                                                                          {"bisection", Refinement::Bisection},
                                                                          {"regula-falsi", Refinement::RegulaFalsi},
                                                                          {"illinois", Refinement::Illinois},
                                                                          {"newton", Refinement::Newton}}};
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
constexpr std::array<std::pair<const char*, RayOrigin>, 4> kOrigins{{{"auto", RayOrigin::Auto},
                                                                      {"extent", RayOrigin::Extent},
                                                                      {"eye", RayOrigin::Eye},
                                                                      {"screen", RayOrigin::Screen}}};
// Auto never reaches a kernel: primary_config resolves it.
constexpr std::array<std::pair<RayOrigin, int>, 3> kOriginIds{{{RayOrigin::Extent, ALGRAY_ORIGIN_EXTENT},
                                                               {RayOrigin::Eye, ALGRAY_ORIGIN_EYE},
                                                               {RayOrigin::Screen, ALGRAY_ORIGIN_SCREEN}}};

std::string hex_double(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

}  // namespace

std::string to_string(Precision p) { return enum_name(kPrecisions, p); }
std::string to_string(Isolation i) { return enum_name(kIsolations, i); }
std::string to_string(Refinement r) { return enum_name(kRefinements, r); }
std::string to_string(RayOrigin o) { return enum_name(kOrigins, o); }
bool parse_precision(const std::string& n, Precision& out) { return parse_enum(kPrecisions, n, out); }
bool parse_isolation(const std::string& n, Isolation& out) { return parse_enum(kIsolations, n, out); }
bool parse_refinement(const std::string& n, Refinement& out) { return parse_enum(kRefinements, n, out); }
bool parse_ray_origin(const std::string& n, RayOrigin& out) { return parse_enum(kOrigins, n, out); }
std::string precision_choices() { return enum_choices(kPrecisions); }
std::string isolation_choices() { return enum_choices(kIsolations); }
std::string refinement_choices() { return enum_choices(kRefinements); }
std::string ray_origin_choices() { return enum_choices(kOrigins); }

// OpenCL C's vector widths, and 1 (kernels/lanes.h).
constexpr std::array<int, 5> kLanes{1, 2, 4, 8, 16};
bool valid_lanes(int lanes) { return std::find(kLanes.begin(), kLanes.end(), lanes) != kLanes.end(); }
std::string lanes_choices() {
  std::string out;
  for (std::size_t i = 0; i < kLanes.size(); ++i)
    out += (i == 0 ? "" : i + 1 == kLanes.size() ? " or " : ", ") + std::to_string(kLanes[i]);
  return out;
}
int default_lanes(const std::string& device_type) { return device_type == "CPU" ? 8 : 1; }
bool lanes_apply(const KernelConfig& c) {
  return c.entry == "primary" && c.isolation == Isolation::Bernstein && c.refinement == Refinement::Brent;
}

int default_max_iterations(Refinement r) { return r == Refinement::RegulaFalsi ? 1000 : 100; }

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
         " -D ISOLATION=" + std::to_string(isolation_id) + " -D REFINEMENT=" + std::to_string(refinement_id) +
         " -D RAY_ORIGIN=" + std::to_string(origin_id) + " -D TOLERANCE=" + tolerance_literal +
         " -D MAX_ITERATIONS=" + std::to_string(max_iterations) + " -D LANES=" + std::to_string(lanes) +
         // PoCL prints its compiler's warning count ("4 warnings generated.") straight to stderr on a cold cache;
         // a successful command says nothing, and a failed build still reports its errors and log.
         " -w";
}

std::string KernelConfig::key() const {
  return entry + " degree=" + std::to_string(degree) + " precision=" + to_string(precision) +
         " isolation=" + to_string(isolation) + " refinement=" + to_string(refinement) +
         " origin=" + to_string(ray_origin) + " tolerance=" + hex_double(tolerance) +
         " max_iterations=" + std::to_string(max_iterations) + (lanes != 1 ? " lanes=" + std::to_string(lanes) : "");
}

}  // namespace algray
