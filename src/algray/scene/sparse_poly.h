// Polynomials in x, y, z with double coefficients, as surf and POV-Ray scenes state them: sums, products and
// affine substitution under a work budget, for the readers that move surfaces before algray sees them.
#pragma once

#include <array>
#include <map>
#include <stdexcept>

#include "algray/scene/solver_options.h"

namespace algray {

struct SparsePoly {
  using Exponents = std::array<int, 3>;
  std::map<Exponents, double> terms;  // no zero coefficients

  int degree() const;  // -1 for the zero polynomial
  void add(const Exponents& e, double c);
  static SparsePoly constant(double c);
  static SparsePoly variable(int axis);  // 0 = x, 1 = y, 2 = z
};

// Thrown when a product would pass the degree limit or the budget; the reader says where, with `what()`.
struct PolyTooLarge : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Counts coefficient products so that no input expands for minutes; shared by all the operations of one file.
struct PolyBudget {
  double work = 0;
  double limit = 1e8;  // under a second in Release; a dense poly of degree 32 moved by a transform needs more
                       // (substitute refuses such a move before it starts, from the term counts)
  int max_degree = kMaxDegree;
};

SparsePoly multiply(const SparsePoly& a, const SparsePoly& b, PolyBudget& budget);
SparsePoly power(const SparsePoly& p, long e, PolyBudget& budget);
// P(M x + b), M and b the rows of `m` (3 x 3, then b in the fourth column).
SparsePoly substitute(const SparsePoly& p, const std::array<std::array<double, 4>, 3>& m, PolyBudget& budget);

}  // namespace algray
