// The certified reference solver: the smallest root of P on a ray segment, in exact rational arithmetic.
#pragma once

#include <gmpxx.h>

#include <array>
#include <functional>
#include <limits>
#include <vector>

#include "algray/math/polynomial.h"

namespace algray::ref {

// A ray as a kernel evaluated it, in floating point; every component is taken at its exact value.
struct ExactRay {
  std::array<double, 3> origin, direction;
};

enum class Classification {
  Miss,                       // certified: no real root in [t_in, t_out]
  SimpleRoot,                 // multiplicity 1: P* changes sign there
  MultipleRootOddSignChange,  // odd multiplicity >= 3: P* crosses zero, but the root is singular or inflectional
  EvenRootNoSignChange,       // even multiplicity: P* touches zero without crossing (tangent ray, isolated point)
  IdenticallyZero,            // P* == 0: the whole segment lies on the surface
};

const char* to_string(Classification kind);

struct Answer {
  Classification kind = Classification::Miss;
  // The smallest root lies in [lo, hi]; lo == hi when it is known exactly (a dyadic midpoint, or an end
  // point). For IdenticallyZero lo = hi = t_in; for a Miss both are 0 and meaningless.
  mpq_class lo, hi;
  // The double nearest to (lo + hi) / 2; it lies in [lo, hi] whenever any double does (a requested width
  // below the spacing of doubles leaves none). +infinity for a Miss.
  double t_nearest = std::numeric_limits<double>::infinity();
  int multiplicity = 0;                              // of the smallest root; 0 for Miss and IdenticallyZero
  bool root_at_t_in = false, root_at_t_out = false;  // the root is exactly that end point
};

// The polynomial as the kernels see it: each monomial's double coefficient, exactly (std::domain_error if not
// finite).
Polynomial from_monomials(const std::vector<Monomial>& monomials);

// P*(t) = P(o + t d), exactly: coefficients in the power basis of t, leading zeros removed (so the zero
// polynomial is empty). Throws std::domain_error on a non-finite ray component.
std::vector<mpq_class> restrict_exact(const Polynomial& p, const ExactRay& ray);

// The smallest root of P* in the closed interval [t_in, t_out], enclosed to hi - lo <= width (absolute, in t).
// Throws std::invalid_argument unless t_in <= t_out and width > 0.
Answer smallest_root(const Polynomial& p, const ExactRay& ray, const mpq_class& t_in, const mpq_class& t_out,
                     const mpq_class& width);
// The same for a univariate polynomial given by exact power-basis coefficients (poly[i] multiplies t^i).
Answer smallest_root(const std::vector<mpq_class>& poly, const mpq_class& t_in, const mpq_class& t_out,
                     const mpq_class& width);

// Every distinct root of poly in [t_in, t_out], in increasing order, each enclosed to width as smallest_root
// encloses its root, to visit, until visit returns false; false when it did. The first is smallest_root's answer
// on the same interval; the polynomial is prepared once for all (the reference's search for critical points).
bool for_each_root(const std::vector<mpq_class>& poly, const mpq_class& t_in, const mpq_class& t_out,
                   const mpq_class& width, const std::function<bool(const Answer&)>& visit);

// Whether poly has a root in the open interval (a, b), exactly; roots at a or b do not count. The zero
// polynomial has roots everywhere, so it answers a < b.
bool has_root_in_open(const std::vector<mpq_class>& poly, const mpq_class& a, const mpq_class& b);

}  // namespace algray::ref
