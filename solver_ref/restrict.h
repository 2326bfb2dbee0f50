// Internal: exact restriction of P to a ray, kept as an integer polynomial and a scale factor.
#pragma once

#include "solver_ref.h"
#include "univariate.h"

namespace algray::ref::detail {

// P*(t) = poly(t) / divisor exactly, divisor > 0. Staying in Z[t] spares the solver a gcd per coefficient.
struct ScaledRestriction {
  ZPoly poly;
  mpz_class divisor = 1;
};

ScaledRestriction restrict_integer(const Polynomial& p, const ExactRay& ray);

}  // namespace algray::ref::detail
