// Sweeps over degrees and other ordered cases: a seeded sample that keeps the ends on every run, everything
// under the `exhaustive` label.
#pragma once

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace algray::testing {

// Whether this run sweeps every case: ALGRAY_EXHAUSTIVE=1, as CTest sets it for the tests labelled `exhaustive`
// (`ctest --test-dir build -L exhaustive`; README.md, "Tests").
inline bool exhaustive_run() {
  const char* value = std::getenv("ALGRAY_EXHAUSTIVE");
  return value && *value && std::string(value) != "0";
}

// The seed the samples of this process are drawn with: ALGRAY_SAMPLE_SEED to repeat a run, else a new one every
// run, so that runs together cover every case. Apart from ALGRAY_TEST_SEED, which draws the cases themselves.
inline unsigned sample_seed() {
  static const unsigned seed = [] {
    const char* given = std::getenv("ALGRAY_SAMPLE_SEED");
    return given && *given ? static_cast<unsigned>(std::strtoul(given, nullptr, 10)) : std::random_device{}();
  }();
  return seed;
}

// The values of `all` that this run covers: every one in an exhaustive run; otherwise each of `always` that is
// in `all`, and `extra` more drawn from the rest with sample_seed() and `what` (so that one sweep's draw does not
// depend on the others'). Prints the choice and how to repeat it; `what` names the sweep there.
inline std::vector<int> sampled(const std::string& what, const std::vector<int>& all, const std::vector<int>& always,
                                int extra) {
  std::vector<int> chosen;
  if (exhaustive_run()) {
    chosen = all;
  } else {
    std::vector<int> rest;
    for (int v : all) {
      if (std::find(always.begin(), always.end(), v) != always.end())
        chosen.push_back(v);
      else
        rest.push_back(v);
    }
    std::mt19937 rng(sample_seed() ^ static_cast<unsigned>(std::hash<std::string>{}(what)));
    std::shuffle(rest.begin(), rest.end(), rng);
    rest.resize(std::min(rest.size(), static_cast<std::size_t>(std::max(extra, 0))));
    chosen.insert(chosen.end(), rest.begin(), rest.end());
    std::sort(chosen.begin(), chosen.end());
  }
  std::printf("%s:", what.c_str());
  for (int v : chosen) std::printf(" %d", v);
  if (exhaustive_run())
    std::printf(" (all %zu: ALGRAY_EXHAUSTIVE=1)\n", all.size());
  else
    std::printf(" (%zu of %zu; ALGRAY_SAMPLE_SEED=%u repeats this draw, ALGRAY_EXHAUSTIVE=1 takes all)\n",
                chosen.size(), all.size(), sample_seed());
  std::fflush(stdout);
  return chosen;
}

// Of costly alternatives (`names` of `values`, such as the precisions of a degree-32 case), the ones this run
// covers: all in an exhaustive run, else `extra` drawn, as sampled() draws them (and prints the draw by index).
template <typename T>
std::vector<T> sampled_choices(const std::string& what, const std::vector<T>& values, int extra) {
  std::vector<int> indices;
  for (std::size_t i = 0; i < values.size(); ++i) indices.push_back(static_cast<int>(i));
  std::vector<T> chosen;
  for (int i : sampled(what, indices, {}, extra)) chosen.push_back(values[static_cast<std::size_t>(i)]);
  return chosen;
}

// Degrees 1 to `max_degree`: 1, 2 and `max_degree` on every run, and `extra` others.
inline std::vector<int> sampled_degrees(const std::string& what, int max_degree, int extra = 3) {
  std::vector<int> all;
  for (int d = 1; d <= max_degree; ++d) all.push_back(d);
  return sampled(what, all, {1, 2, max_degree}, extra);
}

}  // namespace algray::testing
