// The named tolerances the accuracy tests hold the kernels to, in one place (issue 3).
#pragma once

namespace algray::testing {

// Certified image comparison (test_reference_agree): share of certified pixels that may disagree on hit or
// miss, and the largest relative depth error on certified simple hits.
struct ImageThresholds {
  double disagreement_share;
  double depth_error;
};
inline constexpr ImageThresholds kDoubleImage{0.0, 1e-7};
inline constexpr ImageThresholds kFloatImage{1e-3, 1e-3};

// Univariate cases (test_univariate): a simple root may be off by the stopping width times this factor, plus
// this factor times the evaluation noise (degree * epsilon * sum of |Bernstein coefficients|) divided by
// |P'| at the root: the root's own condition.
inline constexpr double kStopWidthFactor = 4;
inline constexpr double kNoiseFactor = 64;
// A root of multiplicity m > 1, when the kernel reports it, may be off by (noise / |P^(m)| m!)^(1/m) times this.
inline constexpr double kMultipleRootFactor = 8;

}  // namespace algray::testing
