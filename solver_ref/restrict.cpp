// Restriction of a trivariate polynomial to a floating-point ray, exactly, as an integer polynomial in t.
#include "restrict.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace algray::ref::detail {

namespace {

// value = mantissa * 2^exponent with an odd mantissa (or 0): every finite double is one.
struct Dyadic {
  mpz_class mantissa;
  long exponent = 0;
};

Dyadic split(double v) {
  if (!std::isfinite(v)) throw std::domain_error("restrict_exact: ray component is not finite");
  if (v == 0) return {};
  int e = 0;
  const double m = std::frexp(v, &e);
  auto mantissa = static_cast<long>(std::ldexp(m, 53));  // exact: at most 53 significant bits
  long exponent = static_cast<long>(e) - 53;
  while (mantissa % 2 == 0) {
    mantissa /= 2;
    ++exponent;
  }
  return {mpz_class(mantissa), exponent};
}

// base^0 .. base^max_power.
std::vector<ZPoly> powers(const ZPoly& base, int max_power) {
  std::vector<ZPoly> out{ZPoly{1}};
  for (int k = 1; k <= max_power; ++k) out.push_back(multiply(out.back(), base));
  return out;
}

}  // namespace

ScaledRestriction restrict_integer(const Polynomial& p, const ExactRay& ray) {
  const int n = p.degree();
  ScaledRestriction out;
  std::array<Dyadic, 6> parts;
  for (int a = 0; a < 3; ++a) {
    parts[a] = split(ray.origin[a]);
    parts[3 + a] = split(ray.direction[a]);
  }
  if (n < 0) return out;

  // One power of two 2^E (E <= 0) for all six components turns x = o_x + t d_x into 2^E (X0 + X1 t) with
  // integers X0, X1; multiplying P* by 2^(-E n) then makes every monomial integral.
  long e_min = 0;
  for (const Dyadic& d : parts)
    if (sgn(d.mantissa) != 0) e_min = std::min(e_min, d.exponent);
  std::array<ZPoly, 3> base;
  for (int a = 0; a < 3; ++a) {
    mpz_class o, d;
    mpz_mul_2exp(o.get_mpz_t(), parts[a].mantissa.get_mpz_t(), static_cast<mp_bitcnt_t>(parts[a].exponent - e_min));
    mpz_mul_2exp(d.get_mpz_t(), parts[3 + a].mantissa.get_mpz_t(),
                 static_cast<mp_bitcnt_t>(parts[3 + a].exponent - e_min));
    base[a] = ZPoly{o, d};
    trim(base[a]);
  }

  std::array<int, 3> max_exp{0, 0, 0};
  mpz_class common_den = 1;
  for (const auto& [e, c] : p.terms()) {
    for (int a = 0; a < 3; ++a) max_exp[a] = std::max(max_exp[a], e[a]);
    mpz_lcm(common_den.get_mpz_t(), common_den.get_mpz_t(), c.get_den_mpz_t());
  }
  std::array<std::vector<ZPoly>, 3> pw;
  for (int a = 0; a < 3; ++a) pw[a] = powers(base[a], max_exp[a]);

  // terms() is ordered by (i, j, k), so the terms sharing x^i y^j come together: sum their z parts first
  // and multiply by x^i y^j once per group.
  ZPoly sum(static_cast<std::size_t>(n) + 1);
  const auto& terms = p.terms();
  for (auto it = terms.begin(); it != terms.end();) {
    const int i = it->first[0], j = it->first[1];
    ZPoly z_part;
    for (; it != terms.end() && it->first[0] == i && it->first[1] == j; ++it) {
      const int k = it->first[2];
      const mpq_class& c = it->second;
      mpz_class coef = common_den / c.get_den() * c.get_num();
      mpz_mul_2exp(coef.get_mpz_t(), coef.get_mpz_t(), static_cast<mp_bitcnt_t>(-e_min * (n - i - j - k)));
      const ZPoly& zk = pw[2][k];
      if (z_part.size() < zk.size()) z_part.resize(zk.size());
      for (std::size_t m = 0; m < zk.size(); ++m)
        mpz_addmul(z_part[m].get_mpz_t(), coef.get_mpz_t(), zk[m].get_mpz_t());
    }
    const ZPoly term = multiply(multiply(pw[0][i], pw[1][j]), z_part);
    for (std::size_t m = 0; m < term.size(); ++m) sum[m] += term[m];
  }
  trim(sum);
  out.poly = std::move(sum);
  mpz_mul_2exp(out.divisor.get_mpz_t(), common_den.get_mpz_t(), static_cast<mp_bitcnt_t>(-e_min * n));
  return out;
}

}  // namespace algray::ref::detail
