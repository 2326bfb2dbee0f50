// The reference solver: exact isolation (Vincent-Collins-Akritas), exact bisection and classification.
#include "solver_ref.h"

#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <utility>

#include "restrict.h"
#include "univariate.h"

namespace algray::ref {

using detail::ZPoly;

const char* to_string(Classification kind) {
  switch (kind) {
    case Classification::Miss:
      return "miss";
    case Classification::SimpleRoot:
      return "simple root";
    case Classification::MultipleRootOddSignChange:
      return "multiple root, odd (sign change)";
    case Classification::EvenRootNoSignChange:
      return "multiple root, even (no sign change)";
    case Classification::IdenticallyZero:
      return "identically zero";
  }
  return "?";
}

Polynomial from_monomials(const std::vector<Monomial>& monomials) {
  Polynomial p;
  for (const Monomial& m : monomials) p.add_term(m.i, m.j, m.k, exact_rational(m.coef));
  return p;
}

std::vector<mpq_class> restrict_exact(const Polynomial& p, const ExactRay& ray) {
  const detail::ScaledRestriction r = detail::restrict_integer(p, ray);
  std::vector<mpq_class> out(r.poly.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = mpq_class(r.poly[i], r.divisor);
    out[i].canonicalize();
  }
  return out;
}

namespace {

// Round to nearest, ties to even. mpq_get_d truncates, so the answer is it or its neighbour away from zero.
double nearest_double(const mpq_class& q) {
  const double toward_zero = q.get_d();
  if (!std::isfinite(toward_zero) || mpq_class(toward_zero) == q) return toward_zero;
  const double away = std::nextafter(toward_zero, sgn(q) > 0 ? HUGE_VAL : -HUGE_VAL);
  if (!std::isfinite(away)) return toward_zero;
  const mpq_class gap_toward = abs(q - mpq_class(toward_zero));
  const mpq_class gap_away = abs(mpq_class(away) - q);
  if (gap_toward != gap_away) return gap_toward < gap_away ? toward_zero : away;
  return (std::bit_cast<std::uint64_t>(toward_zero) & 1) == 0 ? toward_zero : away;
}

Classification classify(int multiplicity) {
  if (multiplicity == 1) return Classification::SimpleRoot;
  return multiplicity % 2 == 0 ? Classification::EvenRootNoSignChange : Classification::MultipleRootOddSignChange;
}

// A root known exactly: its multiplicity is the order of the first derivative that does not vanish there.
Answer exact_root(const ZPoly& p, const mpq_class& t, const mpq_class& t_in, const mpq_class& t_out) {
  Answer a;
  ZPoly d = p;
  while (detail::sign_at(d, t) == 0) {
    ++a.multiplicity;
    d = detail::derivative(d);
  }
  a.kind = classify(a.multiplicity);
  a.lo = a.hi = t;
  a.t_nearest = nearest_double(t);
  a.root_at_t_in = t == t_in;
  a.root_at_t_out = t == t_out;
  return a;
}

// The square-free part, which has the same distinct roots, and the factorisation that gives multiplicities.
struct SquareFree {
  ZPoly part;
  std::vector<ZPoly> factors;  // factors[i] holds the roots of multiplicity i + 1; empty: all are simple
};

SquareFree square_free(const ZPoly& p) {
  // The modular test settles almost every ray's polynomial without a single exact gcd.
  if (detail::certainly_square_free(p)) return {p, {}};
  std::vector<ZPoly> factors = detail::square_free_factors(p);
  if (factors.size() == 1) return {p, {}};
  ZPoly part{1};
  for (const ZPoly& f : factors)
    if (detail::degree(f) > 0) part = detail::multiply(part, f);
  detail::make_primitive(part);
  return {std::move(part), std::move(factors)};
}

// [t_in, t_out] = [A/M, (A+H)/M] with integers, M, H > 0, so a point s in [0, 1] is t = (A 2^D + H k) / (M 2^D)
// when s = k / 2^D.
struct Segment {
  mpz_class A, H, M;

  Segment(const mpq_class& t_in, const mpq_class& t_out) {
    mpz_lcm(M.get_mpz_t(), t_in.get_den_mpz_t(), t_out.get_den_mpz_t());
    A = t_in.get_num() * (M / t_in.get_den());
    H = t_out.get_num() * (M / t_out.get_den()) - A;
  }

  mpq_class t_of(const mpz_class& k, unsigned long depth) const {
    mpz_class num, den;
    mpz_mul_2exp(num.get_mpz_t(), A.get_mpz_t(), depth);
    mpz_addmul(num.get_mpz_t(), H.get_mpz_t(), k.get_mpz_t());
    mpz_mul_2exp(den.get_mpz_t(), M.get_mpz_t(), depth);
    mpq_class t(num, den);
    t.canonicalize();
    return t;
  }

  // The smallest D with (t_out - t_in) / 2^D <= width.
  unsigned long depth_for(const mpq_class& width) const {
    const mpz_class num = H * width.get_den();
    const mpz_class den = M * width.get_num();
    const long bits =
        static_cast<long>(mpz_sizeinbase(num.get_mpz_t(), 2)) - static_cast<long>(mpz_sizeinbase(den.get_mpz_t(), 2));
    auto d = static_cast<unsigned long>(std::max(0L, bits - 1));
    mpz_class scaled;
    for (;; ++d) {
      mpz_mul_2exp(scaled.get_mpz_t(), den.get_mpz_t(), d);
      if (scaled >= num) return d;
    }
  }
};

// A root of r in the open unit interval, isolated: `local` is r moved to the interval (num / 2^depth,
// (num + 1) / 2^depth), where it has exactly one root, simple.
struct Isolated {
  mpz_class num;
  unsigned long depth = 0;
  ZPoly local;
};

// Whether square-free r has a root in the open unit interval. An odd Descartes bound already proves one.
bool any_root(const ZPoly& r) {
  const int v = detail::descartes_bound_unit(r, INT_MAX);
  if (v == 0) return false;
  if (v % 2 == 1) return true;
  ZPoly left = detail::left_half(r);
  detail::remove_power_of_two(left);
  if (any_root(left)) return true;
  ZPoly right = detail::taylor_shift_one(left);
  if (sgn(right[0]) == 0) return true;
  detail::remove_power_of_two(right);
  return any_root(right);
}

int multiplicity_in(const std::vector<ZPoly>& factors, const mpq_class& lo, const mpq_class& hi) {
  // Every factor divides the square-free part, which is nonzero at lo and hi and has one simple root
  // between them; so the factor holding that root is the one that changes sign.
  for (std::size_t i = 0; i < factors.size(); ++i)
    if (detail::degree(factors[i]) > 0 && detail::sign_at(factors[i], lo) * detail::sign_at(factors[i], hi) < 0)
      return static_cast<int>(i) + 1;
  throw std::logic_error("solver_ref: isolated root belongs to no square-free factor");
}

Answer identically_zero(const mpq_class& t_in, const mpq_class& t_out) {
  Answer a;
  a.kind = Classification::IdenticallyZero;
  a.lo = a.hi = t_in;
  a.t_nearest = nearest_double(t_in);
  a.root_at_t_in = true;
  a.root_at_t_out = t_in == t_out;
  return a;
}

void check_arguments(const mpq_class& t_in, const mpq_class& t_out, const mpq_class& width) {
  if (t_out < t_in) throw std::invalid_argument("smallest_root: t_in > t_out");
  if (sgn(width) <= 0) throw std::invalid_argument("smallest_root: width must be positive");
}

// Where in (0, 1) the one root of `local` lies, to about long double's precision where it is well conditioned: a
// bisection of local's values in long double (coefficients scaled by a common power of two). Only a guess: refine
// checks it exactly.
long double approximate_root(const ZPoly& local, int sign_lo) {
  std::vector<long> exponents(local.size());
  std::vector<double> mantissas(local.size());
  long top = LONG_MIN;
  for (std::size_t i = 0; i < local.size(); ++i) {
    mantissas[i] = mpz_get_d_2exp(&exponents[i], local[i].get_mpz_t());
    if (mantissas[i] != 0) top = std::max(top, exponents[i]);
  }
  std::vector<long double> c(local.size());
  for (std::size_t i = 0; i < local.size(); ++i)
    c[i] = std::ldexp(static_cast<long double>(mantissas[i]), static_cast<int>(std::max(exponents[i] - top, -20000L)));
  long double lo = 0, hi = 1;
  for (int step = 0; step < 70; ++step) {
    const long double mid = (lo + hi) / 2;
    long double v = c.back();
    for (std::size_t i = c.size() - 1; i-- > 0;) v = v * mid + c[i];
    if (v == 0) return mid;
    ((v > 0) == (sign_lo > 0) ? lo : hi) = mid;
  }
  return (lo + hi) / 2;
}

// The root of p that `found` isolates, enclosed to `width`: bisection at dyadic points of the isolating interval,
// in its local coordinate, [L, L + 1] / 2^j. The left end never vanishes (it is t_in or a midpoint already
// tested); the right end may be a root further on, and the multiplicity test needs both ends nonzero, so a zero
// there forces one more halving. The first steps are skipped where a guess of the root checks out: the cell of
// depth j at the guess holds the root when local's signs at its ends are sign_lo's and the other one, both nonzero;
// then no dyadic point of depth j or less is the root, and bisection would have come to that cell with the same
// signs, so the answer is bisection's bit for bit (two exact evaluations at depth j in place of j growing ones).
Answer refine(const ZPoly& p, const SquareFree& sf, const Segment& seg, const Isolated& found, const mpq_class& t_in,
              const mpq_class& t_out, const mpq_class& width) {
  const ZPoly& local = found.local;
  const int sign_lo = sgn(local.front());
  mpz_class at_one = 0;  // the value at the right end is the sum of the coefficients
  for (const mpz_class& c : local) at_one += c;
  bool hi_is_root = sgn(at_one) == 0;
  const unsigned long needed = seg.depth_for(width);
  mpz_class L = 0;
  unsigned long j = 0;
  const unsigned long remaining = needed > found.depth ? needed - found.depth : 0;
  if (!hi_is_root && remaining >= 8) {
    const unsigned long guess_depth = std::min<unsigned long>(remaining, 48);
    const long double at = std::ldexp(approximate_root(local, sign_lo), static_cast<int>(guess_depth));
    const unsigned long cells = 1UL << guess_depth;
    const unsigned long cell = std::min(cells - 1, static_cast<unsigned long>(std::max<long double>(at, 0)));
    const mpz_class left(cell), right(cell + 1);
    if ((cell == 0 || detail::sign_at_dyadic(local, left, guess_depth) == sign_lo) &&
        (cell + 1 == cells ? sgn(at_one) : detail::sign_at_dyadic(local, right, guess_depth)) == -sign_lo) {
      L = left;
      j = guess_depth;
    }
  }
  const auto global = [&](const mpz_class& k, unsigned long jj) {  // local k / 2^jj as s = num' / 2^depth'
    mpz_class g;
    mpz_mul_2exp(g.get_mpz_t(), found.num.get_mpz_t(), jj);
    return std::pair<mpz_class, unsigned long>(g + k, found.depth + jj);
  };
  while (found.depth + j < needed || hi_is_root) {
    const mpz_class mid = 2 * L + 1;
    ++j;
    const int s = detail::sign_at_dyadic(local, mid, j);
    if (s == 0) {
      const auto [k, d] = global(mid, j);
      return exact_root(p, seg.t_of(k, d), t_in, t_out);
    }
    if (s == sign_lo) {
      L = mid;
    } else {
      L = 2 * L;
      hi_is_root = false;
    }
  }
  const auto [k, d] = global(L, j);
  Answer a;
  a.lo = seg.t_of(k, d);
  a.hi = seg.t_of(k + 1, d);
  a.multiplicity = sf.factors.empty() ? 1 : multiplicity_in(sf.factors, a.lo, a.hi);
  a.kind = classify(a.multiplicity);
  a.t_nearest = nearest_double((a.lo + a.hi) / 2);
  return a;
}

// Every root of p in the open unit interval of `seg`, in increasing order, to `visit`: a descent by halves, left
// half first, so that the first interval with one sign variation holds the smallest root; it carries on past each
// root until visit says stop, so the polynomial is made square-free and moved to the unit interval once for all of
// them. A root exactly at a midpoint shows as a zero constant term between the two halves.
struct RootWalk {
  const ZPoly& p;
  const SquareFree& sf;
  const Segment& seg;
  const mpq_class &t_in, &t_out, &width;
  const std::function<bool(const Answer&)>& visit;

  // r square-free, r(0) != 0: its roots in (0, 1), the interval (num, num + 1) / 2^depth of the segment's. False
  // once visit has asked to stop.
  bool descend(const ZPoly& r, const mpz_class& num, unsigned long depth) const {
    const int v = detail::descartes_bound_unit(r, 2);
    if (v == 0) return true;
    if (v == 1) return visit(refine(p, sf, seg, Isolated{num, depth, r}, t_in, t_out, width));
    ZPoly left = detail::left_half(r);
    detail::remove_power_of_two(left);
    if (!descend(left, 2 * num, depth + 1)) return false;
    ZPoly right = detail::taylor_shift_one(left);
    if (sgn(right[0]) == 0) {  // a root at the midpoint: visited, then divided out (s > 0 keeps the signs)
      if (!visit(exact_root(p, seg.t_of(2 * num + 1, depth + 1), t_in, t_out))) return false;
      right.erase(right.begin());
    }
    detail::remove_power_of_two(right);
    return descend(right, 2 * num + 1, depth + 1);
  }
};

// for_each_root on p's integer coefficients; smallest_root is its first visit.
bool walk_roots(const ZPoly& p, const mpq_class& t_in, const mpq_class& t_out, const mpq_class& width,
                const std::function<bool(const Answer&)>& visit) {
  check_arguments(t_in, t_out, width);
  if (p.empty()) return visit(identically_zero(t_in, t_out));
  if (detail::degree(p) == 0) return true;
  if (detail::sign_at(p, t_in) == 0 && !visit(exact_root(p, t_in, t_in, t_out))) return false;
  if (t_in == t_out) return true;
  const SquareFree sf = square_free(p);
  const Segment seg(t_in, t_out);
  ZPoly r = detail::to_unit_interval(sf.part, seg.A, seg.H, seg.M);
  detail::make_primitive(r);
  if (sgn(r[0]) == 0) r.erase(r.begin());  // the root at t_in, visited above
  if (!RootWalk{p, sf, seg, t_in, t_out, width, visit}.descend(r, 0, 0)) return false;
  return detail::sign_at(sf.part, t_out) != 0 || visit(exact_root(p, t_out, t_in, t_out));
}

Answer solve(const ZPoly& p, const mpq_class& t_in, const mpq_class& t_out, const mpq_class& width) {
  Answer smallest;  // a Miss unless a root is visited
  walk_roots(p, t_in, t_out, width, [&](const Answer& a) {
    smallest = a;
    return false;
  });
  return smallest;
}

}  // namespace

bool for_each_root(const std::vector<mpq_class>& poly, const mpq_class& t_in, const mpq_class& t_out,
                   const mpq_class& width, const std::function<bool(const Answer&)>& visit) {
  return walk_roots(detail::primitive_from_rational(poly), t_in, t_out, width, visit);
}

Answer smallest_root(const std::vector<mpq_class>& poly, const mpq_class& t_in, const mpq_class& t_out,
                     const mpq_class& width) {
  return solve(detail::primitive_from_rational(poly), t_in, t_out, width);
}

Answer smallest_root(const Polynomial& p, const ExactRay& ray, const mpq_class& t_in, const mpq_class& t_out,
                     const mpq_class& width) {
  ZPoly r = detail::restrict_integer(p, ray).poly;
  detail::make_primitive(r);
  return solve(r, t_in, t_out, width);
}

bool has_root_in_open(const std::vector<mpq_class>& poly, const mpq_class& a, const mpq_class& b) {
  if (!(a < b)) return false;
  const ZPoly p = detail::primitive_from_rational(poly);
  if (p.empty()) return true;
  if (detail::degree(p) == 0) return false;
  const SquareFree sf = square_free(p);
  const Segment seg(a, b);
  ZPoly r = detail::to_unit_interval(sf.part, seg.A, seg.H, seg.M);
  detail::make_primitive(r);
  return any_root(r);
}

}  // namespace algray::ref
