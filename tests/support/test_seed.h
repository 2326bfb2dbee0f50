// Seeds for randomised tests: ALGRAY_TEST_SEED reruns a reported failure, or sweeps seeds by hand.
#pragma once

#include <cstdlib>
#include <random>

namespace algray::testing {

// The seed a test draws its random cases from: ALGRAY_TEST_SEED if set, else `otherwise`.
inline unsigned test_seed(unsigned otherwise) {
  const char* given = std::getenv("ALGRAY_TEST_SEED");
  return given ? static_cast<unsigned>(std::strtoul(given, nullptr, 10)) : otherwise;
}

// A new seed every run (so runs together cover more cases), unless ALGRAY_TEST_SEED names one.
inline unsigned fresh_test_seed() { return test_seed(std::random_device{}()); }

}  // namespace algray::testing
