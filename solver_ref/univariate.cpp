// Exact integer polynomial algebra for the reference solver: gcds, square-free factorisation, exact signs.
#include "univariate.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <utility>

namespace algray::ref::detail {

int degree(const ZPoly& p) { return static_cast<int>(p.size()) - 1; }

void trim(ZPoly& p) {
  while (!p.empty() && sgn(p.back()) == 0) p.pop_back();
}

void make_primitive(ZPoly& p) {
  trim(p);
  if (p.empty()) return;
  mpz_class g = 0;
  for (const mpz_class& c : p) {
    if (sgn(c) == 0) continue;
    mpz_gcd(g.get_mpz_t(), g.get_mpz_t(), c.get_mpz_t());
    if (g == 1) break;
  }
  if (sgn(p.back()) < 0) g = -g;
  if (g != 1)
    for (mpz_class& c : p) mpz_divexact(c.get_mpz_t(), c.get_mpz_t(), g.get_mpz_t());
}

ZPoly primitive_from_rational(const std::vector<mpq_class>& p) {
  mpz_class common = 1;
  for (const mpq_class& c : p) mpz_lcm(common.get_mpz_t(), common.get_mpz_t(), c.get_den_mpz_t());
  ZPoly out(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    // The input need not be canonical, so divide rather than assume the denominator divides exactly.
    mpq_class scaled = p[i] * common;
    scaled.canonicalize();
    out[i] = scaled.get_num();
  }
  make_primitive(out);
  return out;
}

ZPoly derivative(const ZPoly& p) {
  if (p.size() <= 1) return {};
  ZPoly d(p.size() - 1);
  for (std::size_t i = 1; i < p.size(); ++i) d[i - 1] = p[i] * static_cast<unsigned long>(i);
  trim(d);
  return d;
}

ZPoly subtract(const ZPoly& a, const ZPoly& b) {
  ZPoly r(std::max(a.size(), b.size()));
  for (std::size_t i = 0; i < a.size(); ++i) r[i] = a[i];
  for (std::size_t i = 0; i < b.size(); ++i) r[i] -= b[i];
  trim(r);
  return r;
}

ZPoly multiply(const ZPoly& a, const ZPoly& b) {
  if (a.empty() || b.empty()) return {};
  ZPoly r(a.size() + b.size() - 1);
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (sgn(a[i]) == 0) continue;
    for (std::size_t j = 0; j < b.size(); ++j) mpz_addmul(r[i + j].get_mpz_t(), a[i].get_mpz_t(), b[j].get_mpz_t());
  }
  return r;
}

ZPoly divide_exact(const ZPoly& a, const ZPoly& b) {
  if (b.empty()) throw std::logic_error("divide_exact: division by the zero polynomial");
  if (a.size() < b.size()) {
    if (!a.empty()) throw std::logic_error("divide_exact: not divisible");
    return {};
  }
  ZPoly rem = a;
  ZPoly q(a.size() - b.size() + 1);
  const std::size_t nb = b.size() - 1;
  for (std::size_t k = q.size(); k-- > 0;) {
    mpz_class& top = rem[k + nb];
    if (!mpz_divisible_p(top.get_mpz_t(), b.back().get_mpz_t())) throw std::logic_error("divide_exact: not divisible");
    mpz_divexact(q[k].get_mpz_t(), top.get_mpz_t(), b.back().get_mpz_t());
    for (std::size_t j = 0; j <= nb; ++j) mpz_submul(rem[k + j].get_mpz_t(), q[k].get_mpz_t(), b[j].get_mpz_t());
  }
  for (const mpz_class& c : rem)
    if (sgn(c) != 0) throw std::logic_error("divide_exact: not divisible");
  trim(q);
  return q;
}

namespace {

// A multiple of the remainder of a by b (deg a >= deg b >= 0). Each step scales by lc(b)/g instead of lc(b),
// g the gcd with the leading term: any nonzero multiple serves a primitive remainder sequence.
ZPoly pseudo_remainder(ZPoly a, const ZPoly& b) {
  const std::size_t nb = b.size() - 1;
  mpz_class g, fa, fb;
  while (!a.empty() && a.size() > nb) {
    const std::size_t shift = a.size() - 1 - nb;
    mpz_gcd(g.get_mpz_t(), a.back().get_mpz_t(), b.back().get_mpz_t());
    mpz_divexact(fa.get_mpz_t(), b.back().get_mpz_t(), g.get_mpz_t());
    mpz_divexact(fb.get_mpz_t(), a.back().get_mpz_t(), g.get_mpz_t());
    if (fa != 1)
      for (mpz_class& c : a) c *= fa;
    for (std::size_t j = 0; j <= nb; ++j) mpz_submul(a[shift + j].get_mpz_t(), fb.get_mpz_t(), b[j].get_mpz_t());
    trim(a);
  }
  return a;
}

}  // namespace

ZPoly gcd(const ZPoly& a_in, const ZPoly& b_in) {
  ZPoly a = a_in, b = b_in;
  make_primitive(a);
  make_primitive(b);
  if (a.size() < b.size()) std::swap(a, b);
  while (!b.empty()) {
    if (b.size() == 1) return ZPoly{1};  // a nonzero constant divides everything: the gcd is 1
    ZPoly r = pseudo_remainder(std::move(a), b);
    make_primitive(r);
    a = std::move(b);
    b = std::move(r);
  }
  return a;
}

namespace {

// Arithmetic modulo primes below 2^31, so that products fit in 64 bits.
struct ModP {
  std::uint64_t p;
  std::uint64_t mul(std::uint64_t x, std::uint64_t y) const { return x * y % p; }
  std::uint64_t sub(std::uint64_t x, std::uint64_t y) const { return x >= y ? x - y : x + p - y; }
  std::uint64_t inverse(std::uint64_t x) const {  // Fermat: x^(p-2)
    std::uint64_t r = 1, e = p - 2;
    while (e) {
      if (e & 1) r = mul(r, x);
      x = mul(x, x);
      e >>= 1;
    }
    return r;
  }
};

void trim_mod(std::vector<std::uint64_t>& v) {
  while (!v.empty() && v.back() == 0) v.pop_back();
}

// Degree of gcd(a, b) over Z/p, by Euclid; a and b trimmed, not both zero.
int gcd_degree_mod(std::vector<std::uint64_t> a, std::vector<std::uint64_t> b, const ModP& f) {
  while (!b.empty()) {
    const std::uint64_t inv = f.inverse(b.back());
    while (a.size() >= b.size()) {
      const std::uint64_t factor = f.mul(a.back(), inv);
      const std::size_t shift = a.size() - b.size();
      for (std::size_t j = 0; j < b.size(); ++j) a[shift + j] = f.sub(a[shift + j], f.mul(factor, b[j]));
      trim_mod(a);
    }
    std::swap(a, b);
  }
  return static_cast<int>(a.size()) - 1;
}

}  // namespace

bool certainly_square_free(const ZPoly& p) {
  // Primes just below 2^31. One that divides the leading coefficient is useless (the degree would drop);
  // a square-free p whose discriminant all of them divide just takes the exact path.
  static constexpr std::array<std::uint64_t, 3> primes{2147483647u, 2147483629u, 2147483587u};
  if (degree(p) < 1) return true;
  for (const std::uint64_t prime : primes) {
    const ModP f{prime};
    std::vector<std::uint64_t> a(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) a[i] = mpz_fdiv_ui(p[i].get_mpz_t(), static_cast<unsigned long>(prime));
    if (a.back() == 0) continue;
    std::vector<std::uint64_t> d(a.size() - 1);
    for (std::size_t i = 1; i < a.size(); ++i) d[i - 1] = f.mul(a[i], i % prime);
    trim_mod(d);  // not empty: p does not divide n * lc(p), as n <= 32 here and lc(p) != 0 mod p
    return gcd_degree_mod(a, d, f) == 0;
  }
  return false;
}

std::vector<ZPoly> square_free_factors(const ZPoly& p) {
  // Yun's algorithm. Every quotient is by a primitive divisor, so it stays in Z[t] (Gauss's lemma); the
  // constant factors the primitive gcds drop scale c and d alike and so cancel out.
  std::vector<ZPoly> factors;
  const ZPoly dp = derivative(p);
  const ZPoly g = gcd(p, dp);
  ZPoly c = divide_exact(p, g);
  ZPoly d = subtract(divide_exact(dp, g), derivative(c));
  for (;;) {
    ZPoly a = d.empty() ? c : gcd(c, d);
    make_primitive(a);
    c = divide_exact(c, a);
    if (degree(c) <= 0) {
      factors.push_back(std::move(a));
      break;
    }
    d = subtract(divide_exact(d, a), derivative(c));
    factors.push_back(std::move(a));
  }
  return factors;
}

int sign_at(const ZPoly& p, const mpq_class& x) {
  // sum c_i num^i den^(n-i): den^n p(x), with the sign of p(x) since den > 0.
  if (p.empty()) return 0;
  const mpz_class& num = x.get_num();
  const mpz_class& den = x.get_den();
  mpz_class v = p.back();
  mpz_class den_power = den;
  for (std::size_t i = p.size() - 1; i-- > 0;) {
    v *= num;
    mpz_addmul(v.get_mpz_t(), p[i].get_mpz_t(), den_power.get_mpz_t());
    if (i > 0) den_power *= den;
  }
  return sgn(v);
}

int sign_at_dyadic(const ZPoly& p, const mpz_class& m, unsigned long k) {
  if (p.empty()) return 0;
  mpz_class v = p.back(), term;
  const std::size_t n = p.size() - 1;
  for (std::size_t i = n; i-- > 0;) {
    v *= m;
    if (sgn(p[i]) == 0) continue;
    mpz_mul_2exp(term.get_mpz_t(), p[i].get_mpz_t(), k * (n - i));
    v += term;
  }
  return sgn(v);
}

ZPoly left_half(const ZPoly& p) {
  ZPoly r = p;
  const std::size_t n = p.size() - 1;
  for (std::size_t i = 0; i < n; ++i) mpz_mul_2exp(r[i].get_mpz_t(), r[i].get_mpz_t(), n - i);
  return r;
}

ZPoly taylor_shift_one(const ZPoly& p) {
  ZPoly a = p;
  const std::size_t n = a.size();
  for (std::size_t i = 0; i + 1 < n; ++i)
    for (std::size_t j = n - 1; j-- > i;) a[j] += a[j + 1];
  return a;
}

void remove_power_of_two(ZPoly& p) {
  mp_bitcnt_t shift = ~mp_bitcnt_t{0};
  for (const mpz_class& c : p)
    if (sgn(c) != 0) shift = std::min(shift, mpz_scan1(c.get_mpz_t(), 0));
  if (shift == 0 || shift == ~mp_bitcnt_t{0}) return;
  for (mpz_class& c : p) mpz_fdiv_q_2exp(c.get_mpz_t(), c.get_mpz_t(), shift);
}

ZPoly to_unit_interval(const ZPoly& p, const mpz_class& A, const mpz_class& H, const mpz_class& M) {
  // Homogenised Horner: S = c_n; S = S * (A + H s) + c_i M^(n-i).
  if (p.empty()) return {};
  const std::size_t n = p.size() - 1;
  ZPoly s(n + 1);
  s[0] = p[n];
  mpz_class m_power = M;
  for (std::size_t i = n; i-- > 0;) {
    const std::size_t len = n - i;  // s currently has degree len - 1
    for (std::size_t j = len; j > 0; --j) {
      s[j] *= A;
      mpz_addmul(s[j].get_mpz_t(), H.get_mpz_t(), s[j - 1].get_mpz_t());
    }
    s[0] *= A;
    mpz_addmul(s[0].get_mpz_t(), p[i].get_mpz_t(), m_power.get_mpz_t());
    if (i > 0) m_power *= M;
  }
  return s;
}

int descartes_bound_unit(const ZPoly& p, int cap) {
  // No sign variation in p itself means no root in (0, inf), hence none in (0, 1), without the O(n^2) shift.
  int first = 0;
  bool mixed = false;
  for (const mpz_class& c : p) {
    const int s = sgn(c);
    if (s == 0) continue;
    if (first == 0)
      first = s;
    else if (s != first) {
      mixed = true;
      break;
    }
  }
  if (!mixed) return 0;
  const ZPoly t = taylor_shift_one(ZPoly(p.rbegin(), p.rend()));
  int variations = 0, last = 0;
  for (const mpz_class& c : t) {
    const int s = sgn(c);
    if (s == 0) continue;
    if (last != 0 && s != last && ++variations >= cap) return variations;
    last = s;
  }
  return variations;
}

}  // namespace algray::ref::detail
