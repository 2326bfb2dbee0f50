/* The point form (RAY_ORIGIN=point): P expanded once about a shadow rays' shared origin, then restricted to each. */
#ifndef ALGRAY_POINT_FORM_H
#define ALGRAY_POINT_FORM_H

#include "lanes.h"
#include "real.h"
#include "restrict.h"

/* Every shadow ray of a surface point starts at the same origin o. Expanding P about o once,
 *   Q(v) = P(o + v) = sum q_abg x^a y^b z^g,
 * turns each ray's restriction into sums of Q's terms: P(o + t d) = sum_k t^k sum_(a+b+g=k) q_abg dx^a dy^b dz^g,
 * two vector operations per term over LANES rays, in place of a Horner scheme over every monomial of P per ray
 * (the Barth decic's shadow rays: about 2.3 s -> 0.5 s of restriction in full mode, bench/RESULTS.md "Shadow rays
 * from a shared expansion"). The origin lies on the surface, inside the extent, and the segment to the extent's edge is
 * at most its diameter long, so the power basis about o keeps the extent construction's digits: every term is
 * bounded by the same sums of |a_m| times powers of coordinates within the extent (up to the binomial weights
 * of the shift, at most 2^DEGREE in the worst case, which double precision absorbs). Float loses those digits: plain
 * float keeps the extent construction, and adaptive precision measures the point form's own noise (shadow.h,
 * PointTerms) and sends what it doubts to its second pass. */
#if DEGREE > 15
#error "the point form keeps its expansion in vectors of up to 16 coefficients (degree 15)"
#endif

/* The expansion's columns: column (a, b), a + b <= DEGREE, holds the coefficients of x^a y^b z^g,
 * g = 0 .. DEGREE - a - b, in one PolyVec (the lanes above are zero). */
#define POINT_FORM_COLUMNS ((DEGREE + 1) * (DEGREE + 2) / 2)
#define POINT_FORM_COLUMN(a, b) ((a) * (2 * DEGREE + 3 - (a)) / 2 + (b))

/* rows[k] = (s + v)^k as a vector of coefficients in v: C(k, g) s^(k - g) in lane g. */
ALGRAY_INLINE void shift_rows(REAL s, PolyVec* rows) {
  rows[0] = vec_constant(1);
  ALGRAY_UNROLL
  for (int k = 1; k <= DEGREE; ++k) rows[k] = s * rows[k - 1] + VEC_SHIFT(rows[k - 1]);
}

/* One of taylor_at_point's shifts by s, in place: along y, column (a, b0) gains C(b, b0) s^(b - b0) times each
 * column (a, b > b0); along x, column (a0, b) gains C(a, a0) s^(a - a0) times each column (a > a0, b). Each sum
 * reads only columns it has not yet overwritten, as `to` ascends. */
ALGRAY_INLINE void shift_columns(PolyVec* q, REAL s, int along_x) {
  PolyVec rows[NCOEF];
  shift_rows(s, rows);
  REAL weight[NCOEF][ACC_WIDTH]; /* weight[from][to] = C(from, to) s^(from - to) */
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) VEC_STORE(rows[k], weight[k]);
#define SHIFTED_COLUMN(outer, i) (along_x ? POINT_FORM_COLUMN(i, outer) : POINT_FORM_COLUMN(outer, i))
  ALGRAY_UNROLL
  for (int outer = 0; outer <= DEGREE; ++outer) ALGRAY_UNROLL
  for (int to = 0; to <= DEGREE; ++to) {
    if (outer + to > DEGREE) continue;
    PolyVec sum = q[SHIFTED_COLUMN(outer, to)];
    ALGRAY_UNROLL
    for (int from = 1; from <= DEGREE; ++from)
      if (from > to && outer + from <= DEGREE) sum += weight[from][to] * q[SHIFTED_COLUMN(outer, from)];
    q[SHIFTED_COLUMN(outer, to)] = sum;
  }
#undef SHIFTED_COLUMN
}

/* q: P(o + v) by columns, from P's monomials (exponents packed i | j<<8 | k<<16) in unit coordinates, or with
 * `absolute` Pabs(o + v), Pabs = sum_m |a_m| x^i y^j z^k (adaptive builds, o >= 0: every operation then adds and
 * multiplies nonnegative numbers, so the result is within a relative few REAL_EPS per monomial of the exact). The shift
 * is separable: along z while each monomial is added to its column (one vector operation per monomial), then
 * along y and along x, each a sum of vector products with independent accumulators (the nested Taylor shift
 * of one coefficient at a time was a chain of dependent operations, 3x slower). Every loop runs to DEGREE and
 * tests its bound inside: with bounds that depend on the outer indices LLVM unrolled the inner loops only partly
 * and kept the sums in memory (measured in PoCL's compiled kernel). */
ALGRAY_INLINE void taylor_at_point(__global const uint* exps, __global const REAL* coefs, uint count, REAL3 o,
                                   PolyVec* q, int absolute) {
  PolyVec rows[NCOEF];
  shift_rows(o.z, rows);
  ALGRAY_UNROLL
  for (int c = 0; c < POINT_FORM_COLUMNS; ++c) q[c] = (PolyVec)((REAL)0);
  for (uint m = 0; m < count; ++m) {
    const uint e = exps[m];
    const int i = (int)(e & 0xffu), j = (int)((e >> 8) & 0xffu), k = (int)((e >> 16) & 0xffu);
    q[POINT_FORM_COLUMN(i, j)] += (absolute ? fabs(coefs[m]) : coefs[m]) * rows[k];
  }
  shift_columns(q, o.y, 0);
  shift_columns(q, o.x, 1);
}

/* P(o + t d) = sum_k c[k] t^k for LANES directions d (unit coordinates), from taylor_at_point's q; its loops are
 * bounded as taylor_at_point's (left partly unrolled, the sums went through memory: four loads and stores a term). */
ALGRAY_INLINE void point_form_restrict(const PolyVec* columns, LREAL dx, LREAL dy, LREAL dz, LREAL* c) {
  const REAL* q = (const REAL*)columns;
  LREAL pz[NCOEF], sum[NCOEF];
  pz[0] = 1;
  ALGRAY_UNROLL
  for (int g = 1; g <= DEGREE; ++g) pz[g] = pz[g - 1] * dz;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) sum[k] = 0;
  LREAL px = 1;
  ALGRAY_UNROLL
  for (int a = 0; a <= DEGREE; ++a) {
    LREAL pxy = px;
    ALGRAY_UNROLL
    for (int b = 0; b <= DEGREE; ++b) {
      if (a + b > DEGREE) continue;
      ALGRAY_UNROLL
      for (int g = 0; g <= DEGREE; ++g)
        if (a + b + g <= DEGREE) sum[a + b + g] += q[POINT_FORM_COLUMN(a, b) * ACC_WIDTH + g] * (pxy * pz[g]);
      pxy *= dy;
    }
    px *= dx;
  }
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) c[k] = sum[k];
}

/* The power basis c of P*(t) turned into scaled Bernstein coefficients on [t_in, t_out] (C(n,k) b_k, as
 * restrict_to_rays leaves them): the homogeneous Horner scheme of restrict_from_taylor, lane by lane. */
static void point_form_segment(const LREAL* c, LREAL t_in, LREAL t_out, __constant const REAL* binomials, LREAL* out) {
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) out[k] = 0;
  out[0] = c[DEGREE];
  ALGRAY_UNROLL
  for (int n = 1; n <= DEGREE; ++n) {
    ALGRAY_UNROLL
    for (int j = DEGREE; j > 0; --j)
      if (j <= n) out[j] = t_in * out[j] + t_out * out[j - 1];
    out[0] = t_in * out[0];
    __constant const REAL* row = binomials + n * NCOEF;
    ALGRAY_UNROLL
    for (int j = 0; j <= DEGREE; ++j)
      if (j <= n) out[j] += c[DEGREE - n] * row[j];
  }
}

/* Whether P*(t), power basis c, changes sign within [t_in, t_out]: its value at seven evenly spaced points
 * against start, its value at t_in. A sign opposite to start's is a crossing, by the intermediate value theorem;
 * most shadow rays that meet the surface pass through it, so this settles them without the search (Barth
 * decic: the search took 55% of the shadow kernel, most of it on such rays). Adaptive builds count a value only
 * beyond Horner's rounding (2n + 1 roundings over the sum of |terms|, t >= 0, with room) plus `noise`, the
 * coefficients' own; other builds never read `noise`. */
static LMASK sign_change_sampled(const LREAL* c, LREAL t_in, LREAL t_out, LREAL start, LMASK open, LREAL noise) {
  LMASK crossed = open && !open; /* all lanes false, of the mask type */
  ALGRAY_UNROLL
  for (int j = 1; j < 8; ++j) {
    const LREAL t = t_in + (t_out - t_in) * ((REAL)j / 8);
    LREAL v = c[DEGREE], size = fabs(v); /* size: adaptive builds' only (others drop it) */
    ALGRAY_UNROLL
    for (int k = DEGREE - 1; k >= 0; --k) {
      v = v * t + c[k];
      size = size * t + fabs(c[k]);
    }
    if (ALGRAY_ESCALATE) v = LANE_SEL(v, (LREAL)0, fabs(v) <= size * (REAL)((2 * DEGREE + 2) * REAL_EPS) + noise);
    crossed = crossed || (start > 0 && v < 0) || (start < 0 && v > 0);
  }
  return open && crossed;
}

#endif /* ALGRAY_POINT_FORM_H */
