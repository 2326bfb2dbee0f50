// Exact univariate polynomials with integer coefficients: the algebra the reference solver is built on.
#pragma once

#include <gmpxx.h>

#include <vector>

namespace algray::ref::detail {

// c[i] is the coefficient of t^i. Kept trimmed (no zero leading coefficient), so the zero polynomial is
// empty and degree() is exact. Working over Z rather than Q avoids a gcd per arithmetic operation, and
// primitive parts keep the numbers as small as the polynomial allows.
using ZPoly = std::vector<mpz_class>;

int degree(const ZPoly& p);  // -1 for the zero polynomial
void trim(ZPoly& p);
// Divides by the content and makes the leading coefficient positive; the roots are unchanged.
void make_primitive(ZPoly& p);
// The primitive integer polynomial with the same roots as the rational one.
ZPoly primitive_from_rational(const std::vector<mpq_class>& p);

ZPoly derivative(const ZPoly& p);
ZPoly subtract(const ZPoly& a, const ZPoly& b);
ZPoly multiply(const ZPoly& a, const ZPoly& b);
// a / b where b divides a in Z[t]; throws std::logic_error if it does not, since that is a bug here.
ZPoly divide_exact(const ZPoly& a, const ZPoly& b);
// The primitive gcd with a positive leading coefficient (primitive remainder sequence).
ZPoly gcd(const ZPoly& a, const ZPoly& b);

// True only if p (of degree >= 1) is certainly square-free, decided modulo a large prime: a common factor
// of p and p' over Q survives reduction modulo any prime that does not divide the leading coefficient.
// False means "not known", and the caller falls back to exact gcds.
bool certainly_square_free(const ZPoly& p);

// Yun's square-free factorisation of a primitive p of degree >= 1: p = const * prod factors[i]^(i+1),
// the factors primitive, square-free and pairwise coprime (some may be the constant 1).
std::vector<ZPoly> square_free_factors(const ZPoly& p);

// Sign of p(x) for a rational x, exactly.
int sign_at(const ZPoly& p, const mpq_class& x);
// Sign of p(m / 2^k), exactly; cheaper than sign_at because the denominator powers are shifts.
int sign_at_dyadic(const ZPoly& p, const mpz_class& m, unsigned long k);

// 2^n p(s/2) for n = degree(p): p on the left half of [0, 1], rescaled to [0, 1], still integral.
ZPoly left_half(const ZPoly& p);
// p(s + 1), by the O(n^2) additions of repeated synthetic division.
ZPoly taylor_shift_one(const ZPoly& p);
// Divides all coefficients by their largest common power of two: cheaper than the full content and enough
// to stop the growth that halving adds.
void remove_power_of_two(ZPoly& p);

// M^n p((A + H s) / M) with n = degree(p): p on the interval [A/M, (A+H)/M] mapped to s in [0, 1].
ZPoly to_unit_interval(const ZPoly& p, const mpz_class& A, const mpz_class& H, const mpz_class& M);

// Sign variations of the coefficients of (1 + x)^n p(1/(1 + x)), zeros skipped: by Descartes' rule an upper
// bound on the roots of p in the open interval (0, 1) with the same parity. Stops counting at cap.
int descartes_bound_unit(const ZPoly& p, int cap);

}  // namespace algray::ref::detail
