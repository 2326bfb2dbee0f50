// Exact trivariate polynomial arithmetic, change of coordinates and correctly rounded output.
#include "algray/math/polynomial.h"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace algray {

namespace {

// Round |q| (q != 0) to the floating type T, to nearest with ties to even, honouring T's subnormals
// and overflowing to infinity. Done by hand because mpq_get_d truncates, and the kernels' accuracy
// budget assumes coefficients are the nearest doubles.
template <class T>
T round_rational(const mpq_class& q) {
  using limits = std::numeric_limits<T>;
  constexpr long digits = limits::digits;
  static_assert(sizeof(unsigned long) * CHAR_BIT >= static_cast<std::size_t>(digits),
                "the rounded significand must fit an unsigned long");
  const int sign = sgn(q);
  if (sign == 0) return T(0);
  const mpz_class a = abs(q.get_num());
  const mpz_class& b = q.get_den();

  // e = floor(log2(a/b)): the bit lengths pin it down to one of two values.
  long e =
      static_cast<long>(mpz_sizeinbase(a.get_mpz_t(), 2)) - static_cast<long>(mpz_sizeinbase(b.get_mpz_t(), 2)) - 1;
  {
    mpz_class lhs = a, rhs = b;
    if (e + 1 >= 0)
      mpz_mul_2exp(rhs.get_mpz_t(), rhs.get_mpz_t(), static_cast<mp_bitcnt_t>(e + 1));
    else
      mpz_mul_2exp(lhs.get_mpz_t(), lhs.get_mpz_t(), static_cast<mp_bitcnt_t>(-(e + 1)));
    if (lhs >= rhs) ++e;
  }
  if (e >= limits::max_exponent) return sign * limits::infinity();
  // Weight of the last significand bit; below the normal range the spacing stays fixed.
  const long min_lsb = static_cast<long>(limits::min_exponent) - 1 - (digits - 1);
  if (e < min_lsb - 2) return sign * T(0);  // below half the smallest subnormal
  long lsb = std::max(e - (digits - 1), min_lsb);

  mpz_class num = a, den = b;
  if (lsb < 0)
    mpz_mul_2exp(num.get_mpz_t(), num.get_mpz_t(), static_cast<mp_bitcnt_t>(-lsb));
  else
    mpz_mul_2exp(den.get_mpz_t(), den.get_mpz_t(), static_cast<mp_bitcnt_t>(lsb));
  mpz_class quot, rem;
  mpz_fdiv_qr(quot.get_mpz_t(), rem.get_mpz_t(), num.get_mpz_t(), den.get_mpz_t());
  rem *= 2;
  const int c = cmp(rem, den);
  if (c > 0 || (c == 0 && mpz_odd_p(quot.get_mpz_t()))) ++quot;
  if (mpz_sizeinbase(quot.get_mpz_t(), 2) > static_cast<std::size_t>(digits)) {
    // Rounded up to the next power of two; keep the significand within an unsigned long.
    quot >>= 1;
    ++lsb;
  }
  const T significand = static_cast<T>(quot.get_ui());
  return sign * std::ldexp(significand, static_cast<int>(lsb));
}

// Coefficients as rationals in a dense cube, because the change of coordinates touches nearly every
// monomial of degree <= D anyway and map lookups would dominate.
struct DenseCube {
  int n;  // degree + 1
  std::vector<mpq_class> c;
  explicit DenseCube(int degree) : n(degree + 1), c(static_cast<std::size_t>(n) * n * n) {}
  mpq_class& at(int i, int j, int k) { return c[(static_cast<std::size_t>(i) * n + j) * n + k]; }
};

std::string format_magnitude(const mpq_class& v) {
  const mpz_class& num = v.get_num();
  const mpz_class& den = v.get_den();
  if (den == 1) return num.get_str();

  // Scene coefficients are usually decimal literals; show those as the user wrote them.
  mpz_class odd = den;
  const unsigned long twos = mpz_scan1(odd.get_mpz_t(), 0);
  odd >>= twos;
  unsigned long fives = 0;
  while (mpz_divisible_ui_p(odd.get_mpz_t(), 5)) {
    odd /= 5;
    ++fives;
  }
  const unsigned long places = std::max(twos, fives);
  if (odd == 1 && places <= 24) {
    mpz_class ten_pow;
    mpz_ui_pow_ui(ten_pow.get_mpz_t(), 10, places);
    const mpz_class scaled = num * ten_pow / den;
    std::string digits = scaled.get_str();
    if (digits.size() <= places) digits = std::string(places + 1 - digits.size(), '0') + digits;
    const std::size_t point = digits.size() - places;
    return digits.substr(0, point) + "." + digits.substr(point);
  }
  if (mpz_sizeinbase(num.get_mpz_t(), 10) <= 12 && mpz_sizeinbase(den.get_mpz_t(), 10) <= 12)
    return num.get_str() + "/" + den.get_str();

  // Long exact fractions are unreadable; the nearest double is what the renderer uses anyway.
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, nearest_double(v));
  return std::string(buf, res.ptr);
}

}  // namespace

double nearest_double(const mpq_class& q) { return round_rational<double>(q); }

long double nearest_long_double(const mpq_class& q) { return round_rational<long double>(q); }

mpq_class exact_rational(double v) {
  if (!std::isfinite(v)) throw std::domain_error("exact_rational: value is not finite");
  return mpq_class(v);  // mpq_set_d is exact for finite doubles
}

Polynomial Polynomial::constant(const mpq_class& c) {
  Polynomial p;
  p.add_term(0, 0, 0, c);
  return p;
}

Polynomial Polynomial::variable(int axis) {
  if (axis < 0 || axis > 2) throw std::invalid_argument("Polynomial::variable: axis must be 0, 1 or 2");
  Polynomial p;
  Exponents e{0, 0, 0};
  e[static_cast<std::size_t>(axis)] = 1;
  p.terms_.emplace(e, mpq_class(1));
  return p;
}

void Polynomial::add_term(int i, int j, int k, const mpq_class& c) {
  if (i < 0 || j < 0 || k < 0) throw std::invalid_argument("Polynomial::add_term: negative exponent");
  if (sgn(c) == 0) return;
  auto [it, inserted] = terms_.try_emplace(Exponents{i, j, k}, c);
  if (!inserted) {
    it->second += c;
    if (sgn(it->second) == 0) terms_.erase(it);
  }
}

Polynomial Polynomial::operator+(const Polynomial& other) const {
  Polynomial r = *this;
  for (const auto& [e, c] : other.terms_) r.add_term(e[0], e[1], e[2], c);
  return r;
}

Polynomial Polynomial::operator-(const Polynomial& other) const {
  Polynomial r = *this;
  for (const auto& [e, c] : other.terms_) r.add_term(e[0], e[1], e[2], -c);
  return r;
}

Polynomial Polynomial::operator-() const {
  Polynomial r = *this;
  for (auto& [e, c] : r.terms_) c = -c;
  return r;
}

namespace {
thread_local ExpansionWatch* innermost_watch = nullptr;
}  // namespace

ExpansionWatch::ExpansionWatch(std::function<bool()> keep_going)
    : keep_going_(std::move(keep_going)), outer_(innermost_watch) {
  innermost_watch = this;
}

ExpansionWatch::~ExpansionWatch() { innermost_watch = outer_; }

void ExpansionWatch::check() {
  if (innermost_watch && !innermost_watch->keep_going_()) throw ExpansionStopped();
}

Polynomial Polynomial::operator*(const Polynomial& other) const {
  Polynomial r;
  for (const auto& [ea, ca] : terms_) {
    ExpansionWatch::check();  // a row is other.terms_.size() products: milliseconds at most
    for (const auto& [eb, cb] : other.terms_) {
      const Exponents e{ea[0] + eb[0], ea[1] + eb[1], ea[2] + eb[2]};
      auto [it, inserted] = r.terms_.try_emplace(e);
      if (inserted)
        it->second = ca * cb;
      else
        it->second += ca * cb;
    }
  }
  // Cancellation is only final once every product has been summed.
  std::erase_if(r.terms_, [](const auto& t) { return sgn(t.second) == 0; });
  return r;
}

Polynomial Polynomial::pow(unsigned e) const {
  Polynomial result = constant(1);
  Polynomial base = *this;
  while (e > 0) {
    if (e & 1u) result = result * base;
    e >>= 1;
    if (e > 0) base = base * base;
  }
  return result;
}

int Polynomial::degree() const {
  int d = -1;
  for (const auto& [e, c] : terms_) d = std::max(d, e[0] + e[1] + e[2]);
  return d;
}

bool Polynomial::is_zero() const { return terms_.empty(); }

bool Polynomial::is_constant() const {
  return terms_.empty() || (terms_.size() == 1 && terms_.begin()->first == Exponents{0, 0, 0});
}

std::optional<mpq_class> Polynomial::constant_value() const {
  if (terms_.empty()) return mpq_class(0);
  if (!is_constant()) return std::nullopt;
  return terms_.begin()->second;
}

Polynomial Polynomial::translated_scaled(const std::array<mpq_class, 3>& centre, const mpq_class& scale) const {
  const int d = degree();
  if (d < 0) return {};
  DenseCube cube(d);
  for (const auto& [e, c] : terms_) cube.at(e[0], e[1], e[2]) = c;

  // Substituting one axis at a time turns the job into a Taylor shift of each line of the cube,
  // O(n^2) additions per line, instead of multiplying out binomial expansions term by term.
  std::vector<mpq_class*> line;
  line.reserve(static_cast<std::size_t>(d) + 1);
  for (int axis = 0; axis < 3; ++axis) {
    const mpq_class& c = centre[static_cast<std::size_t>(axis)];
    if (sgn(c) == 0) continue;
    for (int p = 0; p <= d; ++p) {
      for (int q = 0; p + q <= d; ++q) {
        line.clear();
        int top = -1;
        for (int t = 0; p + q + t <= d; ++t) {
          mpq_class* slot = axis == 0 ? &cube.at(t, p, q) : axis == 1 ? &cube.at(p, t, q) : &cube.at(p, q, t);
          line.push_back(slot);
          if (sgn(*slot) != 0) top = t;
        }
        // Horner-style shift: after it, line[t] holds the coefficient of v^t in L(c + v).
        for (int i = 0; i < top; ++i)
          for (int j = top - 1; j >= i; --j) *line[j] += c * *line[j + 1];
      }
    }
  }

  std::vector<mpq_class> scale_pow(static_cast<std::size_t>(d) + 1);
  scale_pow[0] = 1;
  for (int t = 1; t <= d; ++t) scale_pow[t] = scale_pow[t - 1] * scale;

  Polynomial result;
  for (int i = 0; i <= d; ++i)
    for (int j = 0; i + j <= d; ++j)
      for (int k = 0; i + j + k <= d; ++k) {
        const mpq_class& v = cube.at(i, j, k);
        if (sgn(v) == 0) continue;
        mpq_class scaled = v * scale_pow[i + j + k];
        if (sgn(scaled) != 0) result.terms_.emplace_hint(result.terms_.end(), Exponents{i, j, k}, std::move(scaled));
      }
  return result;
}

std::vector<Monomial> Polynomial::monomials() const {
  std::vector<Monomial> out;
  out.reserve(terms_.size());
  // The map orders exponent triples lexicographically ascending; walking it backwards gives the
  // documented i desc, j desc, k desc order.
  for (auto it = terms_.rbegin(); it != terms_.rend(); ++it)
    out.push_back(Monomial{it->first[0], it->first[1], it->first[2], nearest_double(it->second)});
  return out;
}

double Polynomial::evaluate(double x, double y, double z) const {
  const int d = degree();
  if (d < 0) return 0.0;
  const auto [px, py, pz] = axis_powers(x, y, z, d);
  long double sum = 0.0L;
  for (const auto& [e, c] : terms_) sum += nearest_long_double(c) * px[e[0]] * py[e[1]] * pz[e[2]];
  return static_cast<double>(sum);
}

std::array<std::vector<long double>, 3> axis_powers(long double x, long double y, long double z, int degree) {
  const std::size_t n = static_cast<std::size_t>(std::max(degree, 0)) + 1;
  std::array<std::vector<long double>, 3> powers;
  const long double at[3] = {x, y, z};
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<long double>& p = powers[axis];
    p.assign(n, 1.0L);
    for (std::size_t t = 1; t < n; ++t) p[t] = p[t - 1] * at[axis];
  }
  return powers;
}

std::string Polynomial::to_string() const {
  if (terms_.empty()) return "0";
  // Highest total degree first reads like the way equations are usually written.
  std::vector<const std::pair<const Exponents, mpq_class>*> order;
  order.reserve(terms_.size());
  for (const auto& t : terms_) order.push_back(&t);
  std::sort(order.begin(), order.end(), [](const auto* a, const auto* b) {
    const int da = a->first[0] + a->first[1] + a->first[2];
    const int db = b->first[0] + b->first[1] + b->first[2];
    if (da != db) return da > db;
    return a->first > b->first;
  });

  static const char* const names[3] = {"x", "y", "z"};
  std::string out;
  bool first = true;
  for (const auto* t : order) {
    const bool negative = sgn(t->second) < 0;
    if (first)
      out += negative ? "-" : "";
    else
      out += negative ? " - " : " + ";
    first = false;

    std::string vars;
    for (std::size_t a = 0; a < 3; ++a) {
      const int e = t->first[a];
      if (e == 0) continue;
      if (!vars.empty()) vars += "*";
      vars += names[a];
      if (e > 1) {
        vars += '^';
        vars += std::to_string(e);
      }
    }
    const mpq_class magnitude = abs(t->second);
    if (vars.empty())
      out += format_magnitude(magnitude);
    else if (magnitude == 1)
      out += vars;
    else
      out += format_magnitude(magnitude) + "*" + vars;
  }
  return out;
}

}  // namespace algray
