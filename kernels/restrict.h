/* Restriction of P(x,y,z) to a ray: the coefficients of P*(s) in the basis the isolation method works in. */
#ifndef ALGRAY_RESTRICT_H
#define ALGRAY_RESTRICT_H

#include "algray_shared.h"
#include "lanes.h"
#include "real.h"

/* Which basis the restriction builds: Bernstein for Bernstein isolation, the power basis for the others. */
#define RESTRICT_BERNSTEIN (!ISOLATION_POWER_BASIS)

/* Every coordinate along the ray is a linear polynomial in s. Multiplying by linear factors and adding
 * constants builds P*(s) from the monomial list by a sparse, homogeneous Horner scheme.
 *
 * Two bases share the code; they differ only in what "one" is:
 *  - power basis: c_0 + c_1 s + ... ; a linear factor is (l0, l1) = l0 + l1*s; one = (1, 0).
 *  - scaled Bernstein basis on [0,1]: sum c_k (1-s)^(n-k) s^k ; (l0, l1) = l0*(1-s) + l1*s; one = (1, 1).
 * Homogenising with w = one makes every partial sum of a Horner level the same degree, so sums never need
 * degree elevation, and in the Bernstein basis all arithmetic stays a sum of products of nearby values. */

/* One coordinate along the segment: the linear factor l0 + l1 s (or l0 (1-s) + l1 s) and its square. */
typedef struct {
  REAL l0, l1;
  REAL q0, q1, q2;
  int even; /* every exponent of this coordinate in P is even: Horner steps by the square */
} AxisFactor;

static AxisFactor axis_factor(REAL l0, REAL l1, int even) {
  AxisFactor f;
  f.l0 = l0;
  f.l1 = l1;
  f.q0 = l0 * l0;
  f.q1 = (REAL)2 * l0 * l1;
  f.q2 = l1 * l1;
  f.even = even;
  return f;
}

/* The size of the terms P*(s)'s coefficients are sums of, for the coordinates' factors fx, fy, fz (their l0, l1:
 * the coordinate at the segment's ends, Bernstein form): sum_m |a_m| X^i Y^j Z^k, X = max(|l0|, |l1|) of x and so
 * on. It bounds each monomial's Bernstein coefficients on the segment, so every coefficient of P* is computed to a
 * small multiple of REAL_EPS times it. Cancelling monomials make it far larger than P* itself (a Kummer shell
 * ray: 30 times its largest coefficient). Adaptive builds measure their noise by it (isolation.h).
 *
 * Its sum is a loop over every monomial that most decisions do not need (a third of the Barth decic's searched
 * shadow rays need it), so a ray carries the cheap upper bound sum_d S_d R^d first, S_d the
 * sum of |a_m| of degree d (the host appends them to the coefficients) and R the largest of X, Y, Z, and computes
 * the sum only when a value falls within the noise of that bound (ray_terms_exact). The decisions are the same as
 * with the sum from the start. */
typedef struct {
  REAL value; /* the sum once `exact`; before, an upper bound on it */
  int exact;
  __global const uint* exps;
  __global const REAL* coefs;
  uint count;
  REAL x, y, z;
  REAL x0, x1, y0, y1, z0, z1; /* |x|, |y|, |z| at the segment's ends, for ray_terms_local */
  /* a point form's shadow ray searched again (shadow.h, point_part_polys): its local noise's two polynomials in t
   * over [t_in, t_out]; null elsewhere */
  const REAL* part_terms;
  const REAL* part_scale;
  /* camera and secondary rays: the ray o + t d in unit coordinates and its segment, where P is evaluated again
   * from the monomials (point_values.h, float_float.h; has_ray 0 elsewhere) */
  int has_ray;
  REAL3 o, d;
  REAL t_in, t_out;
} RayTerms;

/* Terms of a known size (exact from the start): coefficients given as they are. */
static RayTerms known_terms(REAL value) {
  RayTerms t;
  t.value = value;
  t.exact = 1;
  t.exps = 0;
  t.coefs = 0;
  t.count = 0;
  t.x = t.y = t.z = 0;
  t.x0 = t.x1 = t.y0 = t.y1 = t.z0 = t.z1 = 0;
  t.part_terms = t.part_scale = 0;
  t.has_ray = 0;
  return t;
}

/* An upper bound on the terms of any ray whose coordinates are all at most r: the per-degree sums at r. Its
 * rounding could put it a few ulps of count below the exact sum's (both are sums of positive products): 2^-10
 * more covers every degree up to 32. Over lanes, each lane's r; one ray's is lane 0 of its r in every lane.
 * Estrin's scheme: pairs of degrees joined by r, then pairs of those by r^2, and so on, log2(DEGREE) steps deep.
 * Horner's rule was a chain of DEGREE dependent multiply-adds that every shadow ray reaching its terms waited
 * on: 12% of the Endrass octic's adaptive shadow kernel body in perf. */
static LREAL terms_within(__global const REAL* coefs, uint count, LREAL r) {
  LREAL part[NCOEF];
  ALGRAY_UNROLL
  for (int d = 0; d <= DEGREE; ++d) part[d] = coefs[count + (uint)d];
  LREAL power = r; /* r^step */
  ALGRAY_UNROLL
  for (int step = 1; step <= DEGREE; step *= 2) {
    ALGRAY_UNROLL
    for (int d = 0; d + step <= DEGREE; d += 2 * step) part[d] = fma(part[d + step], power, part[d]);
    power *= power;
  }
  return part[0] * (REAL)(1 + 1.0 / 1024);
}
ALGRAY_INLINE REAL one_ray_terms_within(__global const REAL* coefs, uint count, REAL r) {
  return lane_get(terms_within(coefs, count, (LREAL)r), 0);
}

/* A ray's terms, with the upper bound of terms_within its largest coordinate. */
static RayTerms ray_terms(__global const uint* exps, __global const REAL* coefs, uint count, AxisFactor fx,
                          AxisFactor fy, AxisFactor fz) {
  RayTerms t;
  t.exact = 0;
  t.exps = exps;
  t.coefs = coefs;
  t.count = count;
  t.x = fmax(fabs(fx.l0), fabs(fx.l1));
  t.y = fmax(fabs(fy.l0), fabs(fy.l1));
  t.z = fmax(fabs(fz.l0), fabs(fz.l1));
  t.x0 = fabs(fx.l0);
  t.x1 = fabs(fx.l1);
  t.y0 = fabs(fy.l0);
  t.y1 = fabs(fy.l1);
  t.z0 = fabs(fz.l0);
  t.z1 = fabs(fz.l1);
  t.value = one_ray_terms_within(coefs, count, fmax(t.x, fmax(t.y, t.z)));
  t.part_terms = t.part_scale = 0;
  t.has_ray = 0;
  return t;
}

/* The powers 0 .. DEGREE of q's coordinates, for sums over the monomials (exponents packed as i | j<<8 | k<<16). */
ALGRAY_INLINE void axis_powers(REAL3 q, REAL* px, REAL* py, REAL* pz) {
  px[0] = py[0] = pz[0] = 1;
  ALGRAY_UNROLL
  for (int n = 1; n <= DEGREE; ++n) {
    px[n] = px[n - 1] * q.x;
    py[n] = py[n - 1] * q.y;
    pz[n] = pz[n - 1] * q.z;
  }
}

/* sum_m |a_m| x^i y^j z^k over the monomials, of one ray or of lanes (each lane with one ray's operations). Four
 * partial sums: one would be a chain of dependent additions, each waiting for the last (measured on the Barth
 * decic's adaptive render: 1.5% of its kernel time less). Power tables measured faster than a nested Horner scheme
 * in scalars (like restrict_to_rays'). Over lanes, every lane's ray terms are summed at once: summed one lane at a
 * time, they were a tenth of the Endrass octic's adaptive camera pass. */
static LREAL terms_sum(__global const uint* exps, __global const REAL* coefs, uint count, LREAL x, LREAL y, LREAL z) {
  LREAL px[NCOEF], py[NCOEF], pz[NCOEF];
  px[0] = py[0] = pz[0] = 1;
  ALGRAY_UNROLL
  for (int n = 1; n <= DEGREE; ++n) {
    px[n] = px[n - 1] * x;
    py[n] = py[n - 1] * y;
    pz[n] = pz[n - 1] * z;
  }
  LREAL sum[4] = {(LREAL)0, (LREAL)0, (LREAL)0, (LREAL)0};
  uint m = 0;
#define TERMS_SUM_TERM(m) \
  (fabs(coefs[m]) * px[exps[m] & 0xffu] * py[(exps[m] >> 8) & 0xffu] * pz[(exps[m] >> 16) & 0xffu])
  for (; m + 4 <= count; m += 4) {
    sum[0] += TERMS_SUM_TERM(m);
    sum[1] += TERMS_SUM_TERM(m + 1);
    sum[2] += TERMS_SUM_TERM(m + 2);
    sum[3] += TERMS_SUM_TERM(m + 3);
  }
  for (; m < count; ++m) sum[0] += TERMS_SUM_TERM(m);
#undef TERMS_SUM_TERM
  return (sum[0] + sum[1]) + (sum[2] + sum[3]);
}

/* One ray's terms at q: terms_sum with the ray in every lane, lane 0 read (in one-ray builds, the only lane). */
static REAL terms_at(const RayTerms* t, REAL3 q) {
  return lane_get(terms_sum(t->exps, t->coefs, t->count, (LREAL)q.x, (LREAL)q.y, (LREAL)q.z), 0);
}

/* The ray's terms summed (terms_at its largest coordinates), computed once. */
static REAL ray_terms_exact(RayTerms* t) {
  if (t->exact) return t->value;
  t->value = terms_at(t, (REAL3)(t->x, t->y, t->z));
  t->exact = 1;
  return t->value;
}

/* The terms over the part [lo, hi] of the segment (fractions of it): sum_m |a_m| X^i Y^j Z^k with X the larger of
 * |x0| (1 - s) + |x1| s at s = lo and hi, x0 and x1 the coordinate at the segment's ends. That linear bound is at
 * least |x| on [lo, hi] (|x| is convex along the segment), so these terms bound the part's coefficients as
 * ray_terms_exact's bound the segment's. Terms of a known size have no parts. */
ALGRAY_INLINE REAL3 part_coordinates(const RayTerms* t, REAL lo, REAL hi) {
  return (REAL3)(fmax(mix(t->x0, t->x1, lo), mix(t->x0, t->x1, hi)), fmax(mix(t->y0, t->y1, lo), mix(t->y0, t->y1, hi)),
                 fmax(mix(t->z0, t->z1, lo), mix(t->z0, t->z1, hi)));
}
static REAL ray_terms_local(const RayTerms* t, REAL lo, REAL hi) {
  if (t->coefs == 0) return t->value;
  /* room for the sum's own rounding, as in terms_within */
  return terms_at(t, part_coordinates(t, lo, hi)) * (REAL)(1 + 1.0 / 1024);
}

/* The restriction produced scaled coefficients c_k = C(n,k) b_k; the Bernstein
 * methods' Descartes' rule and de Casteljau want b_k. */
static void bernstein_from_scaled(REAL* c, REAL* c_lo, __constant const REAL* binomials) {
  __constant const REAL* row = binomials + DEGREE * NCOEF;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) {
    const REAL q = c[k] / row[k];
    if (ALGRAY_COMPENSATED) c_lo[k] = (fma(-q, row[k], c[k]) + c_lo[k]) / row[k]; /* the division's remainder is exact */
    c[k] = q;
  }
}

/* An upper bound on ray_terms_local from the per-degree sums (terms_within) at the part's largest coordinate. */
static REAL ray_terms_within_part(const RayTerms* t, REAL lo, REAL hi) {
  if (t->coefs == 0) return t->value;
  const REAL3 q = part_coordinates(t, lo, hi);
  return one_ray_terms_within(t->coefs, t->count, fmax(q.x, fmax(q.y, q.z)));
}

ALGRAY_INLINE void poly_copy(REAL* dst, const REAL* src) {
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) dst[k] = src[k];
}

/* The Horner accumulators of the restriction, in one of three representations, each providing acc_mul_linear,
 * acc_mul_quadratic (when ACC_SQUARES), acc_add_constant, acc_add, acc_copy, acc_set_constant and acc_store:
 *  - up to degree 15, one vector holds a whole polynomial, so each step is a few vector instructions (measured
 *    on PoCL: Barth sextic kernel 105 ms -> 77 ms). Lanes above the degree may hold garbage, which only ever
 *    moves to higher lanes, never into the coefficients; the host pads the binomial table so that any row
 *    loads as one vector;
 *  - mixed precision: the same vectors as unevaluated float sums hi + lo;
 *  - above degree 15, several vectors (below).
 * A linear step takes c (degree < DEGREE) times (l0 + l1 s), or times (l0 (1-s) + l1 s) in the scaled Bernstein
 * form, by the same recurrence c_k = l0 c_k + l1 c_(k-1); a quadratic step times (q0 + q1 s + q2 s^2). Every step
 * runs over all the coefficients, zeros above the current degree included: fixed widths beat skipping the zeros. */
#if DEGREE <= 15
#if DEGREE <= 7
#define ACC_WIDTH 8
typedef REAL8 PolyVec;
#define VEC_SHIFT(c) ((PolyVec)((REAL)0, (c).s0, (c).s1, (c).s2, (c).s3, (c).s4, (c).s5, (c).s6))
/* The other way, lane k from lane k + 1: de Casteljau's halving (methods/bernstein.h). */
#define VEC_SHIFT_DOWN(c) ((PolyVec)((c).s1, (c).s2, (c).s3, (c).s4, (c).s5, (c).s6, (c).s7, (REAL)0))
#define VEC_LOAD(p) vload8(0, p)
#define VEC_STORE(v, p) vstore8(v, 0, p)
#else
#define ACC_WIDTH 16
typedef REAL16 PolyVec;
#define VEC_SHIFT(c)                                                                                                  \
  ((PolyVec)((REAL)0, (c).s0, (c).s1, (c).s2, (c).s3, (c).s4, (c).s5, (c).s6, (c).s7, (c).s8, (c).s9, (c).sa, (c).sb, \
             (c).sc, (c).sd, (c).se))
#define VEC_SHIFT_DOWN(c)                                                                                            \
  ((PolyVec)((c).s1, (c).s2, (c).s3, (c).s4, (c).s5, (c).s6, (c).s7, (c).s8, (c).s9, (c).sa, (c).sb, (c).sc, (c).sd, \
             (c).se, (c).sf, (REAL)0))
#define VEC_LOAD(p) vload16(0, p)
#define VEC_STORE(v, p) vstore16(v, 0, p)
#endif
#define ACC_SLOTS 1

ALGRAY_INLINE PolyVec vec_constant(REAL a) {
  PolyVec v = (PolyVec)((REAL)0);
  v.s0 = a;
  return v;
}

ALGRAY_INLINE void vec_store(REAL* out, PolyVec v) {
  REAL t[ACC_WIDTH];
  VEC_STORE(v, t);
  for (int k = 0; k <= DEGREE; ++k) out[k] = t[k];
}

#if ALGRAY_COMPENSATED
/* Mixed precision: float everywhere but here. Expanded polynomials such as 64 L - Q^2 are sums of large terms
 * that cancel; in plain float their rounding swamps P*(t). Each accumulator is an unevaluated sum hi + lo of
 * two float vectors (error-free transformations with fma), so cancellation happens at ~48 bits; the result is
 * rounded to float once, relative to its own size. Coefficients arrive as hi/lo pairs for the same reason.
 * Squared factors would be rounded to float, bringing back the error this avoids: linear steps only. */
#define ACC_SQUARES 0
typedef struct {
  PolyVec hi, lo;
} Acc;

/* hi + lo = x + y exactly (Knuth's two-sum), then renormalised with the low parts. */
ALGRAY_INLINE Acc acc_sum(Acc x, Acc y) {
  const PolyVec s = x.hi + y.hi;
  const PolyVec bb = s - x.hi;
  /* the low parts summed apart from the two-sum's chain, as in ff_combine (bernstein): 5% of the Endrass octic's
   * mixed render */
  const PolyVec e = ((x.hi - (s - bb)) + (y.hi - bb)) + (x.lo + y.lo);
  Acc r;
  r.hi = s + e;
  r.lo = e - (r.hi - s);
  return r;
}
/* x * f for a float vector f, the product's rounding error recovered by fma. Not renormalised: its only use is
 * a term of acc_sum, which renormalises the sum, and |lo| stays within an ulp or so of hi. */
ALGRAY_INLINE Acc acc_scale(Acc x, PolyVec f) {
  Acc r;
  r.hi = x.hi * f;
  r.lo = fma(x.hi, f, -r.hi) + x.lo * f;
  return r;
}
ALGRAY_INLINE Acc acc_shifted(Acc x) {
  Acc r;
  r.hi = VEC_SHIFT(x.hi);
  r.lo = VEC_SHIFT(x.lo);
  return r;
}
/* Scaling c before shifting it keeps the dependency chains short: measured 20% faster than the reverse. */
ALGRAY_INLINE void acc_mul_linear(Acc* c, REAL l0, REAL l1) {
  *c = acc_sum(acc_scale(*c, (PolyVec)(l0)), acc_scale(acc_shifted(*c), (PolyVec)(l1)));
}
ALGRAY_INLINE void acc_add_constant(Acc* c, int n, REAL a, REAL a_lo, __constant const REAL* binomials) {
  Acc term;
  if (RESTRICT_BERNSTEIN) {
    term.hi = (PolyVec)(a);
    term.lo = (PolyVec)(a_lo);
    term = acc_scale(term, VEC_LOAD(binomials + n * NCOEF)); /* binomials are exact in float up to degree 15 */
  } else {
    term.hi = vec_constant(a);
    term.lo = vec_constant(a_lo);
  }
  *c = acc_sum(*c, term);
}
ALGRAY_INLINE void acc_add(Acc* c, const Acc* other) { *c = acc_sum(*c, *other); }
ALGRAY_INLINE void acc_copy(Acc* dst, const Acc* src) { *dst = *src; }
ALGRAY_INLINE void acc_set_constant(Acc* c, REAL a, REAL a_lo) {
  c->hi = vec_constant(a);
  c->lo = vec_constant(a_lo);
}
/* out = hi + lo rounded to float; out_lo what the rounding lost, so out + out_lo keeps ~48 bits. */
ALGRAY_INLINE void acc_store(REAL* out, REAL* out_lo, const Acc* c) {
  const PolyVec rounded = c->hi + c->lo;
  vec_store(out, rounded);
  vec_store(out_lo, (c->hi - rounded) + c->lo);
}
#else
#define ACC_SQUARES 1
typedef PolyVec Acc;
ALGRAY_INLINE void acc_mul_linear(Acc* c, REAL l0, REAL l1) { *c = l0 * *c + l1 * VEC_SHIFT(*c); }
ALGRAY_INLINE void acc_mul_quadratic(Acc* c, REAL q0, REAL q1, REAL q2) {
  const Acc s1 = VEC_SHIFT(*c);
  *c = q0 * *c + q1 * s1 + q2 * VEC_SHIFT(s1);
}
ALGRAY_INLINE void acc_add_constant(Acc* c, int n, REAL a, REAL a_lo, __constant const REAL* binomials) {
  (void)a_lo;
  if (RESTRICT_BERNSTEIN)
    *c += a * VEC_LOAD(binomials + n * NCOEF);
  else
    (*c).s0 += a;
}
ALGRAY_INLINE void acc_add(Acc* c, const Acc* other) { *c += *other; }
ALGRAY_INLINE void acc_copy(Acc* dst, const Acc* src) { *dst = *src; }
ALGRAY_INLINE void acc_set_constant(Acc* c, REAL a, REAL a_lo) {
  (void)a_lo;
  *c = vec_constant(a);
}
ALGRAY_INLINE void acc_store(REAL* out, REAL* out_lo, const Acc* c) {
  (void)out_lo;
  vec_store(out, *c);
}
#endif
#else
#if ALGRAY_COMPENSATED
#error "mixed precision supports degrees up to 15"
#endif
/* Above degree 15 a polynomial takes ACC_FULL 16-wide vectors and a tail of the narrowest vector type that holds
 * the rest, coefficient k in lane k % 16 of vector k / 16, and a step is the vector step below degree 16 on each of
 * them, a shift carrying the top lane of one vector into the bottom of the next: the same operations per coefficient,
 * the shifted-in zero added as there. In scalar arrays (until 2026-12-07) LLVM left the restriction unvectorised,
 * 94% of a degree-24 shadow pass, and float ran at 1.1x to 1.3x double's rate (bench/history/2026-12.md,
 * "Restriction above degree 15 in vectors"); a whole 16-wide tail made degree 16's double pass 12% slower than the
 * scalars. Lanes above the degree hold garbage (the binomial rows read on into the next row and the padding), which
 * shifts only move higher. */
#define ACC_FULL ((NCOEF - 1) / 16)
#define ACC_TAIL (NCOEF - 16 * ACC_FULL) /* 1 to 16 coefficients */
#if ACC_TAIL <= 2
typedef REAL2 AccTail;
#define TAIL_WIDTH 2
#define TAIL_SHIFT(c, below) ((AccTail)((below), (c).s0))
#define TAIL_LOAD(p) vload2(0, p)
#define TAIL_STORE(v, p) vstore2(v, 0, p)
#elif ACC_TAIL <= 4
typedef REAL4 AccTail;
#define TAIL_WIDTH 4
#define TAIL_SHIFT(c, below) ((AccTail)((below), (c).s0, (c).s1, (c).s2))
#define TAIL_LOAD(p) vload4(0, p)
#define TAIL_STORE(v, p) vstore4(v, 0, p)
#elif ACC_TAIL <= 8
typedef REAL8 AccTail;
#define TAIL_WIDTH 8
#define TAIL_SHIFT(c, below) ((AccTail)((below), (c).s0, (c).s1, (c).s2, (c).s3, (c).s4, (c).s5, (c).s6))
#define TAIL_LOAD(p) vload8(0, p)
#define TAIL_STORE(v, p) vstore8(v, 0, p)
#else
typedef REAL16 AccTail;
#define TAIL_WIDTH 16
#define TAIL_SHIFT(c, below) shift_in(c, below)
#define TAIL_LOAD(p) vload16(0, p)
#define TAIL_STORE(v, p) vstore16(v, 0, p)
#endif
#define ACC_SLOTS 1
#define ACC_SQUARES 1
typedef struct {
  REAL16 v[ACC_FULL];
  AccTail tail;
} Acc;
ALGRAY_INLINE REAL16 shift_in(REAL16 c, REAL below) {
  return (REAL16)(below, c.s0, c.s1, c.s2, c.s3, c.s4, c.s5, c.s6, c.s7, c.s8, c.s9, c.sa, c.sb, c.sc, c.sd, c.se);
}
/* c shifted up one coefficient, a zero below */
ALGRAY_INLINE Acc acc_shifted(const Acc* c) {
  Acc r;
  r.v[0] = shift_in(c->v[0], (REAL)0);
  ALGRAY_UNROLL
  for (int i = 1; i < ACC_FULL; ++i) r.v[i] = shift_in(c->v[i], c->v[i - 1].sf);
  r.tail = TAIL_SHIFT(c->tail, c->v[ACC_FULL - 1].sf);
  return r;
}
ALGRAY_INLINE void acc_mul_linear(Acc* c, REAL l0, REAL l1) {
  const Acc s = acc_shifted(c);
  ALGRAY_UNROLL
  for (int i = 0; i < ACC_FULL; ++i) c->v[i] = l0 * c->v[i] + l1 * s.v[i];
  c->tail = l0 * c->tail + l1 * s.tail;
}
ALGRAY_INLINE void acc_mul_quadratic(Acc* c, REAL q0, REAL q1, REAL q2) {
  const Acc s1 = acc_shifted(c);
  const Acc s2 = acc_shifted(&s1);
  ALGRAY_UNROLL
  for (int i = 0; i < ACC_FULL; ++i) c->v[i] = q0 * c->v[i] + q1 * s1.v[i] + q2 * s2.v[i];
  c->tail = q0 * c->tail + q1 * s1.tail + q2 * s2.tail;
}
ALGRAY_INLINE void acc_add_constant(Acc* c, int n, REAL a, REAL a_lo, __constant const REAL* binomials) {
  (void)a_lo;
  if (RESTRICT_BERNSTEIN) {
    __constant const REAL* row = binomials + n * NCOEF;
    ALGRAY_UNROLL
    for (int i = 0; i < ACC_FULL; ++i) c->v[i] += a * vload16(i, row);
    c->tail += a * TAIL_LOAD(row + 16 * ACC_FULL);
  } else {
    c->v[0].s0 += a;
  }
}
ALGRAY_INLINE void acc_add(Acc* c, const Acc* other) {
  ALGRAY_UNROLL
  for (int i = 0; i < ACC_FULL; ++i) c->v[i] += other->v[i];
  c->tail += other->tail;
}
ALGRAY_INLINE void acc_copy(Acc* dst, const Acc* src) { *dst = *src; }
ALGRAY_INLINE void acc_set_constant(Acc* c, REAL a, REAL a_lo) {
  (void)a_lo;
  ALGRAY_UNROLL
  for (int i = 0; i < ACC_FULL; ++i) c->v[i] = (REAL16)((REAL)0);
  c->tail = (AccTail)((REAL)0);
  c->v[0].s0 = a;
}
ALGRAY_INLINE void acc_store(REAL* out, REAL* out_lo, const Acc* c) {
  (void)out_lo;
  REAL t[16 * ACC_FULL + TAIL_WIDTH];
  ALGRAY_UNROLL
  for (int i = 0; i < ACC_FULL; ++i) vstore16(c->v[i], i, t);
  TAIL_STORE(c->tail, t + 16 * ACC_FULL);
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) out[k] = t[k];
}
#endif

/* How many rays restrict_to_rays expands side by side: RESTRICT_RAYS (build_switches.h; the entry file sets it).
 * One ray's Horner scheme is a chain of dependent vector operations, so a core waits on their latency; the
 * rays of a batch share the walk over the monomials and interleave their chains. Every ray gets exactly the
 * operations it would get alone. The walk (restrict_to_rays) takes its batch through the batch_* operations below,
 * in one of two layouts:
 *  - one accumulator per ray (Acc above), each step the ray's vector step;
 *  - with ALGRAY_SHADOW_BATCH (the host's choice for the extent form's shadow rays on devices whose vector
 *    registers hold several rays and that fuse multiply-adds): coefficient k of every ray in the lanes of one
 *    vector, so a step is one operation per coefficient for the whole batch, with no shifts across lanes and no
 *    chain between the coefficients. Degree 16 and 24 shadow passes 0.65x in float, 0.55-0.8x in double with AVX2
 *    (bench/history/2026-12.md, "Shadow rays restricted side by side in lanes"). Each step is written with fma()
 *    in the vector step's order: as plain expressions the compiler fused them otherwise than the vector step's,
 *    and most coefficients differed in their last bits; so written, on a device that fuses (the host's
 *    condition), not one differed. */
#define FOR_EACH_RAY(statement) \
  ALGRAY_UNROLL                 \
  for (int r = 0; r < RESTRICT_RAYS; ++r) statement

#if ALGRAY_SHADOW_BATCH > 1
#if ALGRAY_COMPENSATED
#error "mixed precision keeps one float-float accumulator per ray: the host sets no batch for it"
#endif
#if RESTRICT_RAYS != ALGRAY_SHADOW_BATCH
#error "the lanes' batch is RESTRICT_RAYS rays"
#endif
#if RESTRICT_RAYS == 2
typedef REAL2 BatchLanes;
#define BATCH_LOAD(p) vload2(0, p)
#define BATCH_STORE(v, p) vstore2(v, 0, p)
#elif RESTRICT_RAYS == 4
typedef REAL4 BatchLanes;
#define BATCH_LOAD(p) vload4(0, p)
#define BATCH_STORE(v, p) vstore4(v, 0, p)
#elif RESTRICT_RAYS == 8
typedef REAL8 BatchLanes;
#define BATCH_LOAD(p) vload8(0, p)
#define BATCH_STORE(v, p) vstore8(v, 0, p)
#elif RESTRICT_RAYS == 16
typedef REAL16 BatchLanes;
#define BATCH_LOAD(p) vload16(0, p)
#define BATCH_STORE(v, p) vstore16(v, 0, p)
#else
#error "ALGRAY_SHADOW_BATCH is 2, 4, 8 or 16"
#endif
typedef BatchLanes RayBatch[NCOEF];
/* One coordinate's factors, ray r's in lane r. */
typedef struct {
  BatchLanes l0, l1, q0, q1, q2;
  int even;
} BatchFactor;
ALGRAY_INLINE BatchFactor batch_factor(const AxisFactor* f) {
  REAL t[5][RESTRICT_RAYS];
  ALGRAY_UNROLL
  for (int r = 0; r < RESTRICT_RAYS; ++r) {
    t[0][r] = f[r].l0;
    t[1][r] = f[r].l1;
    t[2][r] = f[r].q0;
    t[3][r] = f[r].q1;
    t[4][r] = f[r].q2;
  }
  BatchFactor b;
  b.l0 = BATCH_LOAD(t[0]);
  b.l1 = BATCH_LOAD(t[1]);
  b.q0 = BATCH_LOAD(t[2]);
  b.q1 = BATCH_LOAD(t[3]);
  b.q2 = BATCH_LOAD(t[4]);
  b.even = f[0].even;
  return b;
}
/* acc_mul_linear lane by lane: c_k = l0 c_k + l1 c_(k-1), the zero below added as the vector step adds it */
ALGRAY_INLINE void batch_mul_linear(BatchLanes* c, BatchLanes l0, BatchLanes l1) {
  const BatchLanes zero = (BatchLanes)((REAL)0);
  ALGRAY_UNROLL
  for (int k = DEGREE; k > 0; --k) c[k] = fma(l0, c[k], l1 * c[k - 1]);
  c[0] = fma(l0, c[0], l1 * zero);
}
/* acc_mul_quadratic lane by lane */
ALGRAY_INLINE void batch_mul_quadratic(BatchLanes* c, BatchLanes q0, BatchLanes q1, BatchLanes q2) {
  const BatchLanes zero = (BatchLanes)((REAL)0);
  ALGRAY_UNROLL
  for (int k = DEGREE; k > 1; --k) c[k] = fma(q2, c[k - 2], fma(q0, c[k], q1 * c[k - 1]));
  c[1] = fma(q2, zero, fma(q0, c[1], q1 * c[0]));
  c[0] = fma(q2, zero, fma(q0, c[0], q1 * zero));
}
ALGRAY_INLINE void batch_mul_axis(RayBatch c, const BatchFactor* f, int times) {
  if (f->even) {
    for (int q = 0; q < times; q += 2) batch_mul_quadratic(c, f->q0, f->q1, f->q2);
    return;
  }
  for (int q = 0; q < times; ++q) batch_mul_linear(c, f->l0, f->l1);
}
/* times one: the vector step's c + (c shifted), the products by one exact */
ALGRAY_INLINE void batch_mul_one(RayBatch c, int times) {
  if (!RESTRICT_BERNSTEIN) return;
  for (int q = 0; q < times; ++q) {
    ALGRAY_UNROLL
    for (int k = DEGREE; k > 0; --k) c[k] = c[k] + c[k - 1];
    c[0] = c[0] + (BatchLanes)((REAL)0);
  }
}
ALGRAY_INLINE void batch_copy(RayBatch dst, const RayBatch src) {
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) dst[k] = src[k];
}
ALGRAY_INLINE void batch_add(RayBatch dst, const RayBatch src) {
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) dst[k] += src[k];
}
ALGRAY_INLINE void batch_set_constant(RayBatch c, REAL a, REAL a_lo) {
  (void)a_lo;
  ALGRAY_UNROLL
  for (int k = 1; k <= DEGREE; ++k) c[k] = (BatchLanes)((REAL)0);
  c[0] = (BatchLanes)(a);
}
ALGRAY_INLINE void batch_add_constant(RayBatch c, int n, REAL a, REAL a_lo, __constant const REAL* binomials) {
  (void)a_lo;
  if (RESTRICT_BERNSTEIN) {
    ALGRAY_UNROLL
    for (int k = 0; k <= DEGREE; ++k) c[k] = fma((BatchLanes)(a), (BatchLanes)(binomials[n * NCOEF + k]), c[k]);
  } else {
    c[0] += a;
  }
}
ALGRAY_INLINE void batch_store(REAL (*out)[NCOEF], REAL (*out_lo)[NCOEF], const RayBatch c) {
  (void)out_lo;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) {
    REAL t[RESTRICT_RAYS];
    BATCH_STORE(c[k], t);
    ALGRAY_UNROLL
    for (int r = 0; r < RESTRICT_RAYS; ++r) out[r][k] = t[r];
  }
}
#else
/* One accumulator per ray of the batch. The batch loops are unrolled so that the accumulators stay in registers
 * (measured: left as loops, they went through the stack and the batch gained nothing). */
typedef Acc RayBatch[RESTRICT_RAYS][ACC_SLOTS];
typedef const AxisFactor* BatchFactor; /* ray r's at [r] */
ALGRAY_INLINE BatchFactor batch_factor(const AxisFactor* f) { return f; }

/* Every c[r] times its ray's L^times. With only even exponents (the same for every ray: they are the surface's)
 * every gap is even, and one quadratic pass replaces two linear ones: fewer flops and half the sweeps over c. */
ALGRAY_INLINE void batch_mul_axis(RayBatch c, const BatchFactor* factor, int times) {
  const AxisFactor* f = *factor;
#if ACC_SQUARES
  if (f[0].even) {
    for (int q = 0; q < times; q += 2) FOR_EACH_RAY(acc_mul_quadratic(c[r], f[r].q0, f[r].q1, f[r].q2));
    return;
  }
#endif
  for (int q = 0; q < times; ++q) FOR_EACH_RAY(acc_mul_linear(c[r], f[r].l0, f[r].l1));
}

/* Every c[r] times one^times: degree elevation in the Bernstein form; nothing to do in the power basis. */
ALGRAY_INLINE void batch_mul_one(RayBatch c, int times) {
  if (!RESTRICT_BERNSTEIN) return;
  for (int q = 0; q < times; ++q) FOR_EACH_RAY(acc_mul_linear(c[r], (REAL)1, (REAL)1));
}
ALGRAY_INLINE void batch_copy(RayBatch dst, RayBatch src) { FOR_EACH_RAY(acc_copy(dst[r], src[r])); }
ALGRAY_INLINE void batch_add(RayBatch dst, RayBatch src) { FOR_EACH_RAY(acc_add(dst[r], src[r])); }
ALGRAY_INLINE void batch_set_constant(RayBatch c, REAL a, REAL a_lo) { FOR_EACH_RAY(acc_set_constant(c[r], a, a_lo)); }
ALGRAY_INLINE void batch_add_constant(RayBatch c, int n, REAL a, REAL a_lo, __constant const REAL* binomials) {
  FOR_EACH_RAY(acc_add_constant(c[r], n, a, a_lo, binomials));
}
ALGRAY_INLINE void batch_store(REAL (*out)[NCOEF], REAL (*out_lo)[NCOEF], RayBatch c) {
  FOR_EACH_RAY(acc_store(out[r], out_lo[r], c[r]));
}
#endif

/* Monomials arrive sorted by i, then j, then k, all descending, exponents packed as i | j<<8 | k<<16.
 * P = sum_i x^i sum_j y^j sum_k a_ijk z^k w^(D-i-j-k), evaluated as three nested Horner levels, each
 * accumulator homogeneous of one degree so that sums need no elevation.
 * fx[r], fy[r], fz[r]: ray r's coordinates' factors along its segment, r < RESTRICT_RAYS. Result: out[r][0..DEGREE];
 * mixed precision also writes out_lo[r], the low parts of the compensated result (other builds leave it alone). */
static ALGRAY_NOINLINE void restrict_to_rays(__global const uint* exps, __global const REAL* coefs, uint count,
                                             __constant const REAL* binomials, const AxisFactor* fx,
                                             const AxisFactor* fy, const AxisFactor* fz, REAL (*out)[NCOEF],
                                             REAL (*out_lo)[NCOEF]) {
  RayBatch acc_z, acc_y, acc_x;
  const BatchFactor bx = batch_factor(fx), by = batch_factor(fy), bz = batch_factor(fz);
  int deg_z = -1;             /* degree of acc_z; -1 while the (i, j) group is empty */
  int have_y = 0, have_x = 0; /* acc_y, out hold a partial sum */
  int cur_i = -1, cur_j = -1, cur_k = -1;
  int prev_i = -1, prev_j = -1;

  for (uint m = 0; m <= count; ++m) {
    int i = -1, j = -1, k = -1;
    REAL a = 0, a_lo = 0;
    if (m < count) {
      const uint e = exps[m];
      i = (int)(e & 0xffu);
      j = (int)((e >> 8) & 0xffu);
      k = (int)((e >> 16) & 0xffu);
      a = coefs[m];
      if (ALGRAY_COMPENSATED) a_lo = coefs[count + m]; /* the coefficient's low part: hi + lo carries ~48 bits */
    }
    /* Close the z-level group (cur_i, cur_j) when (i, j) changes or the list ends. */
    if (deg_z >= 0 && (i != cur_i || j != cur_j)) {
      batch_mul_axis(acc_z, &bz, cur_k);
      batch_mul_one(acc_z, DEGREE - cur_i - cur_j - (deg_z + cur_k)); /* B_ij has degree D - i - j */
      if (!have_y) {
        batch_copy(acc_y, acc_z);
        have_y = 1;
      } else {
        batch_mul_axis(acc_y, &by, prev_j - cur_j);
        batch_add(acc_y, acc_z);
      }
      prev_j = cur_j;
      deg_z = -1;
    }
    /* Close the y-level group cur_i when i changes or the list ends. */
    if (have_y && i != cur_i) {
      batch_mul_axis(acc_y, &by, prev_j);
      if (!have_x) {
        batch_copy(acc_x, acc_y);
        have_x = 1;
      } else {
        batch_mul_axis(acc_x, &bx, prev_i - cur_i);
        batch_add(acc_x, acc_y);
      }
      prev_i = cur_i;
      have_y = 0;
    }
    if (m == count) break;
    /* Add a_ijk to the z-level Horner sum of group (i, j). */
    if (deg_z < 0) {
      batch_set_constant(acc_z, a, a_lo);
      deg_z = 0;
    } else {
      batch_mul_axis(acc_z, &bz, cur_k - k);
      deg_z += cur_k - k;
      batch_add_constant(acc_z, deg_z, a, a_lo, binomials);
    }
    cur_i = i;
    cur_j = j;
    cur_k = k;
  }
  /* No monomials: the host never sends this, but stay defined. */
  if (!have_x) batch_set_constant(acc_x, 0, 0);
  batch_mul_axis(acc_x, &bx, prev_i);
  batch_store(out, out_lo, acc_x);
}

/* One ray: restrict_to_rays with every ray of the batch the same (a build with RESTRICT_RAYS = 1, as every
 * kernel but the shadow rays', pays nothing for the batch). */
static void restrict_to_ray(__global const uint* exps, __global const REAL* coefs, uint count,
                            __constant const REAL* binomials, AxisFactor fx, AxisFactor fy, AxisFactor fz, REAL* out,
                            REAL* out_lo) {
  AxisFactor bx[RESTRICT_RAYS], by[RESTRICT_RAYS], bz[RESTRICT_RAYS];
  REAL c[RESTRICT_RAYS][NCOEF], c_lo[RESTRICT_RAYS][NCOEF];
  FOR_EACH_RAY({
    bx[r] = fx;
    by[r] = fy;
    bz[r] = fz;
  });
  restrict_to_rays(exps, coefs, count, binomials, bx, by, bz, c, c_lo);
  poly_copy(out, c[0]);
  if (ALGRAY_COMPENSATED) poly_copy(out_lo, c_lo[0]);
}

/* The screen form (RAY_ORIGIN=screen): P*(t) = sum_k taylor[k] (t - t0)^k around a point of the ray near the
 * extent's middle. Over the segment t - t0 runs linearly from tau_in to tau_out, so Horner's scheme in t - t0 on
 * the homogeneous accumulators gives the coefficients in the isolation's basis directly: D linear steps instead
 * of one per monomial. */
static void restrict_from_taylor(const REAL* taylor, REAL tau_in, REAL tau_out, __constant const REAL* binomials,
                                 REAL* out) {
  Acc acc[ACC_SLOTS];
  const REAL l0 = tau_in, l1 = RESTRICT_BERNSTEIN ? tau_out : tau_out - tau_in;
  acc_set_constant(acc, taylor[DEGREE], 0);
  ALGRAY_UNROLL
  for (int k = DEGREE - 1; k >= 0; --k) {
    acc_mul_linear(acc, l0, l1);
    acc_add_constant(acc, DEGREE - k, taylor[k], 0, binomials);
  }
  acc_store(out, out, acc);
}

/* The Taylor coefficients of one camera ray from its image row's polynomials in the column xi (in [-1, 1]):
 * row[j * NCOEF + k] is the xi^j coefficient of taylor[k]. One vector Horner step per power of xi. */
static void screen_taylor(__global const REAL* row, REAL xi, REAL* taylor) {
#if DEGREE <= 15
  /* Lanes above the degree read the next power's coefficients; they never reach taylor[0..DEGREE]. The host
   * pads the rows' buffer so that the last power loads as one vector. */
  PolyVec h = VEC_LOAD(row + DEGREE * NCOEF);
  ALGRAY_UNROLL
  for (int j = DEGREE - 1; j >= 0; --j) h = h * xi + VEC_LOAD(row + j * NCOEF);
  vec_store(taylor, h);
#else
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) taylor[k] = row[DEGREE * NCOEF + k];
  for (int j = DEGREE - 1; j >= 0; --j) ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) taylor[k] = taylor[k] * xi + row[j * NCOEF + k];
#endif
}

#endif /* ALGRAY_RESTRICT_H */
