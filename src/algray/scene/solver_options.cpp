// Names of the solver choices: parsing, printing and the lists of accepted names.
#include "algray/scene/solver_options.h"

#include <algorithm>
#include <vector>

namespace algray {
namespace {

template <typename E, std::size_t N>
bool parse_enum(const std::array<NamedChoice<E>, N>& choices, const std::string& name, E& out) {
  for (const auto& c : choices)
    if (name == c.name) {
      out = c.value;
      return true;
    }
  return false;
}

template <typename E, std::size_t N>
std::string enum_name(const std::array<NamedChoice<E>, N>& choices, E value) {
  for (const auto& c : choices)
    if (c.value == value) return c.name;
  return "?";
}

// The names of the choices `keep` accepts, in the table's order.
template <typename E, std::size_t N, typename Keep>
std::string enum_choices(const std::array<NamedChoice<E>, N>& choices, const char* last, Keep keep) {
  std::vector<const char*> names;
  for (const auto& c : choices)
    if (keep(c.value)) names.push_back(c.name);
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0 && last && i + 1 == names.size())
      s.append(" ").append(last).append(" ");
    else if (i > 0)
      s.append(", ");
    s.append(names[i]);
  }
  return s;
}

template <typename E, std::size_t N>
std::string enum_choices(const std::array<NamedChoice<E>, N>& choices, const char* last = nullptr) {
  return enum_choices(choices, last, [](E) { return true; });
}

// "a" or "a", "b": the names `keep` accepts, quoted as a scene file writes them.
template <typename E, std::size_t N, typename Keep>
std::string quoted_names(const std::array<NamedChoice<E>, N>& choices, Keep keep) {
  std::string s;
  for (const auto& c : choices)
    if (keep(c.value)) s += (s.empty() ? "\"" : ", \"") + std::string(c.name) + "\"";
  return s;
}

}  // namespace

std::string to_string(Precision p) { return enum_name(kPrecisions, p); }
std::string to_string(Isolation i) { return enum_name(kIsolations, i); }
std::string to_string(Refinement r) { return enum_name(kRefinements, r); }
std::string to_string(RayOrigin o) { return o == RayOrigin::Point ? "point" : enum_name(kRayOrigins, o); }
bool parse_precision(const std::string& n, Precision& out) { return parse_enum(kPrecisions, n, out); }
bool parse_isolation(const std::string& n, Isolation& out) { return parse_enum(kIsolations, n, out); }
bool parse_refinement(const std::string& n, Refinement& out) { return parse_enum(kRefinements, n, out); }
bool parse_ray_origin(const std::string& n, RayOrigin& out) { return parse_enum(kRayOrigins, n, out); }
std::string precision_choices(const char* last) { return enum_choices(kPrecisions, last); }
std::string isolation_choices(const char* last) { return enum_choices(kIsolations, last); }
std::string refinement_choices(const char* last) { return enum_choices(kRefinements, last); }
std::string ray_origin_choices() { return enum_choices(kRayOrigins); }
const IsolationAbilities& abilities(Isolation i) {
  for (const IsolationAbilities& a : kIsolationAbilities)
    if (a.method == i) return a;
  return kIsolationAbilities.front();  // unreachable: every Isolation has its row (test_config)
}
const RefinementAbilities& abilities(Refinement r) {
  for (const RefinementAbilities& a : kRefinementAbilities)
    if (a.method == r) return a;
  return kRefinementAbilities.front();  // unreachable: every Refinement has its row (test_config)
}
bool lanes_supported(Isolation i, Refinement r) { return abilities(i).lanes && abilities(r).lanes; }
std::string lanes_methods() {
  return "isolation = " + quoted_names(kIsolations, [](Isolation i) { return abilities(i).lanes; }) +
         " and refinement = " + quoted_names(kRefinements, [](Refinement r) { return abilities(r).lanes; });
}
bool isolates_in_power_basis(Isolation i) { return abilities(i).power_basis; }
std::string power_basis_isolation_choices(const char* last) {
  return enum_choices(kIsolations, last, isolates_in_power_basis);
}

// OpenCL C's vector widths, and 1 (kernels/lanes.h).
constexpr std::array<int, 5> kLanes{1, 2, 4, 8, 16};
bool valid_lanes(int lanes) { return std::find(kLanes.begin(), kLanes.end(), lanes) != kLanes.end(); }
std::string lanes_choices() {
  std::string out;
  for (std::size_t i = 0; i < kLanes.size(); ++i)
    out += (i == 0 ? "" : i + 1 == kLanes.size() ? " or " : ", ") + std::to_string(kLanes[i]);
  return out;
}

int default_max_iterations(Refinement r) { return r == Refinement::RegulaFalsi ? 1000 : 100; }

std::string adaptive_unsupported(int degree, Isolation isolation) {
  if (!abilities(isolation).adaptive)
    return "adaptive precision needs render.isolation = " +
           quoted_names(kIsolations, [](Isolation i) { return abilities(i).adaptive; }) +
           ", whose search it checks against rounding noise";
  if (degree > kMaxMixedDegree)
    return "adaptive precision escalates to mixed, which supports degrees up to " + std::to_string(kMaxMixedDegree) +
           "; this surface has degree " + std::to_string(degree);
  return "";
}

}  // namespace algray
