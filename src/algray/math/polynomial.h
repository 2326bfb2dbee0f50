// Exact trivariate polynomials over the rationals (GMP), and their rounding to doubles.
#pragma once

#include <gmpxx.h>

#include <array>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace algray {

// coef * x^i y^j z^k, with the exact coefficient rounded to the nearest double.
struct Monomial {
  int i, j, k;
  double coef;
};

// Thrown by a product that an ExpansionWatch of its thread stopped.
struct ExpansionStopped : std::runtime_error {
  ExpansionStopped() : std::runtime_error("the expansion was stopped") {}
};

// While a watch is alive, this thread's products ask its `keep_going` between rows of terms and throw
// ExpansionStopped when it answers false. An equation the parser's budget admits can still take seconds to expand:
// a server stops it when the client that asked has left (apps/algray/view_command.cpp).
class ExpansionWatch {
 public:
  explicit ExpansionWatch(std::function<bool()> keep_going);
  ~ExpansionWatch();
  ExpansionWatch(const ExpansionWatch&) = delete;
  ExpansionWatch& operator=(const ExpansionWatch&) = delete;
  // Throws ExpansionStopped when the innermost watch of this thread says stop; nothing without one.
  static void check();

 private:
  std::function<bool()> keep_going_;
  ExpansionWatch* outer_;
};

class Polynomial {
 public:
  using Exponents = std::array<int, 3>;

  Polynomial() = default;  // the zero polynomial

  static Polynomial constant(const mpq_class& c);
  static Polynomial variable(int axis);  // 0=x, 1=y, 2=z

  Polynomial operator+(const Polynomial& other) const;
  Polynomial operator-(const Polynomial& other) const;
  Polynomial operator-() const;
  Polynomial operator*(const Polynomial& other) const;
  Polynomial pow(unsigned e) const;  // p^0 == 1, also for p == 0

  int degree() const;  // total degree, -1 for the zero polynomial
  bool is_zero() const;
  bool is_constant() const;  // the zero polynomial counts as constant
  std::optional<mpq_class> constant_value() const;

  // Only nonzero coefficients are ever stored, so equality of maps is equality of polynomials.
  const std::map<Exponents, mpq_class>& terms() const { return terms_; }
  void add_term(int i, int j, int k, const mpq_class& c);  // throws std::invalid_argument on negative exponents

  bool operator==(const Polynomial& other) const { return terms_ == other.terms_; }

  // Q(u) = P(centre + scale*u), exactly.
  Polynomial translated_scaled(const std::array<mpq_class, 3>& centre, const mpq_class& scale) const;

  // Sorted by i desc, then j desc, then k desc; coefficients rounded to nearest double.
  std::vector<Monomial> monomials() const;

  double evaluate(double x, double y, double z) const;  // long double internally
  std::string to_string() const;                        // e.g. "x^4 + y^4 - x^2"

 private:
  std::map<Exponents, mpq_class> terms_;
};

// The powers 0 .. degree of each coordinate of a point, in long double: the tables the host's sums over monomials
// read (powers[axis][n] = coordinate^n, by repeated multiplication).
std::array<std::vector<long double>, 3> axis_powers(long double x, long double y, long double z, int degree);

// The exact value of a finite double; throws std::domain_error on nan/inf.
mpq_class exact_rational(double v);

// Correctly rounded (to nearest, ties to even) conversions; out of range gives +-inf, GMP's own
// mpq_get_d truncates instead.
double nearest_double(const mpq_class& q);
long double nearest_long_double(const mpq_class& q);

}  // namespace algray
