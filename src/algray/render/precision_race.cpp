// PrecisionRace: double against adaptive over the first frames of a stream, then the faster of the two.
#include "algray/render/precision_race.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace algray {

namespace {

double fastest(const std::vector<double>& ms) { return *std::min_element(ms.begin(), ms.end()); }

std::string milliseconds(double ms) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g ms", ms);
  return text;
}

}  // namespace

Precision PrecisionRace::next(const std::string& key) const {
  const auto it = entries_.find(key);
  if (it == entries_.end()) return Precision::Double;
  const Entry& e = it->second;
  if (e.chosen) return *e.chosen;
  return e.adaptive_ms.size() < e.double_ms.size() ? Precision::Adaptive : Precision::Double;
}

void PrecisionRace::record(const std::string& key, Precision precision, double kernel_ms) {
  if (precision != Precision::Double && precision != Precision::Adaptive) return;
  auto it = entries_.find(key);
  if (it == entries_.end()) {
    if (entries_.size() >= kKeys) {
      entries_.erase(std::min_element(entries_.begin(), entries_.end(), [](const auto& a, const auto& b) {
        return a.second.last_used < b.second.last_used;
      }));
    }
    it = entries_.emplace(key, Entry{}).first;
  }
  Entry& e = it->second;
  e.last_used = ++clock_;
  if (e.chosen) {
    if (precision != *e.chosen) return;
    const double other = fastest(*e.chosen == Precision::Double ? e.adaptive_ms : e.double_ms);
    e.slow_in_a_row = kernel_ms > kReopen * other ? e.slow_in_a_row + 1 : 0;
    if (e.slow_in_a_row >= kRounds) {  // race again
      const std::size_t used = e.last_used;
      e = Entry{};
      e.last_used = used;
    }
    return;
  }
  (precision == Precision::Double ? e.double_ms : e.adaptive_ms).push_back(kernel_ms);
  const std::size_t rounds = static_cast<std::size_t>(kRounds);
  if (e.double_ms.size() >= rounds && e.adaptive_ms.size() >= rounds)
    e.chosen = fastest(e.adaptive_ms) <= fastest(e.double_ms) ? Precision::Adaptive : Precision::Double;
}

std::string PrecisionRace::reason(const std::string& key) const {
  const auto it = entries_.find(key);
  if (it == entries_.end()) return "racing double against adaptive: this surface's first frame";
  const Entry& e = it->second;
  const auto best = [](const std::vector<double>& ms) {
    return ms.empty() ? std::string("-") : milliseconds(fastest(ms));
  };
  if (!e.chosen)
    return "racing double against adaptive (fastest frames so far: double " + best(e.double_ms) + ", adaptive " +
           best(e.adaptive_ms) + ")";
  const bool adaptive = *e.chosen == Precision::Adaptive;
  return std::string(adaptive ? "adaptive" : "double") + ": its fastest of " + std::to_string(kRounds) +
         " frames took " + best(adaptive ? e.adaptive_ms : e.double_ms) + " of device time, " +
         (adaptive ? "double's " : "adaptive's ") + best(adaptive ? e.double_ms : e.adaptive_ms);
}

std::string PrecisionRace::key_of(const Scene& scene) {
  // A stream rather than string sums: GCC 12 warns falsely on `" " + std::to_string(...)` (-Wstringop-overflow).
  std::ostringstream key;
  key << to_string(scene.render.isolation) << ' ' << scene.image.width << 'x' << scene.image.height << " samples "
      << (scene.render.preview ? 1 : scene.antialias.samples);
  for (const SceneSurface& surface : scene.surfaces) {
    key << " |";
    for (const Monomial& m : surface.polynomial.monomials()) key << ' ' << m.i << ',' << m.j << ',' << m.k;
  }
  return key.str();
}

}  // namespace algray
