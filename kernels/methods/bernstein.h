/* Root isolation by Descartes' rule on Bernstein coefficients over [t_in, t_out], with de Casteljau halving. */
#ifndef ALGRAY_BERNSTEIN_H
#define ALGRAY_BERNSTEIN_H

#include "float_float.h"
#include "isolation.h"
#include "lanes.h"

/* Mixed precision isolates in float-float: every Bernstein coefficient is an unevaluated sum hi + lo, and the
 * *_lo arrays below hold the low parts (other builds never touch them). Rounding the coefficients to float
 * before isolating was not enough: on the Endrass octic, rays that pass a node come within 1e-9 of the
 * coefficients' size of zero, so float noise faked sign changes there and hid thin pairs of roots (measured:
 * one hit on the wrong sheet, depth error 0.17). Sign variations read the hi parts, which carry the sign. */
#if ALGRAY_COMPENSATED
/* hi + lo = x1 a + x b, for float-float a, b and weights x1, x given as float-float too (lo 0 when exact). */
ALGRAY_INLINE void ff_combine(REAL a, REAL a_lo, REAL x1, REAL x1_lo, REAL b, REAL b_lo, REAL x, REAL x_lo, REAL* hi,
                              REAL* lo) {
  const REAL p = x1 * a, q = x * b;
  const REAL s = p + q, bb = s - p;
  /* The rounding errors and the low parts' products summed apart from the two-sum's chain, then added to it
   * once: each row of de Casteljau's triangle waits on the one before, so the chain's latency sets the pace.
   * Summed left to right in one chain, the Endrass octic's mixed render (512x384, with shadows) took 10% longer;
   * the images came out bit-identical. */
  const REAL lows = (fma(x1, a, -p) + fma(x, b, -q)) + ((x1 * a_lo + x * b_lo) + (x1_lo * a + x_lo * b));
  const REAL e = ((p - (s - bb)) + (q - bb)) + lows;
  *hi = s + e;
  *lo = e - (*hi - s);
}
#endif

/* The restriction produced scaled coefficients c_k = C(n,k) b_k; Descartes' rule and de Casteljau want b_k. */
void bernstein_from_scaled(REAL* c, REAL* c_lo, __constant const REAL* binomials) {
  __constant const REAL* row = binomials + DEGREE * NCOEF;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) {
#if ALGRAY_COMPENSATED
    const REAL q = c[k] / row[k];
    c_lo[k] = (fma(-q, row[k], c[k]) + c_lo[k]) / row[k]; /* the division's remainder is exact */
    c[k] = q;
#else
    (void)c_lo;
    c[k] /= row[k];
#endif
  }
}

/* x1 a + x b: de Casteljau's recurrence in plain arithmetic, for REALs and for lanes of them alike. */
#define CASTELJAU_COMBINE(x1, a, x, b) ((x1) * (a) + (x) * (b))

/* c = x1 a + x b: one step of de Casteljau's recurrence, in the build's arithmetic. */
ALGRAY_INLINE void casteljau_step(REAL* c, REAL* c_lo, int k, int a, int b, REAL x1, REAL x1_lo, REAL x, REAL x_lo) {
#if ALGRAY_COMPENSATED
  ff_combine(c[a], c_lo[a], x1, x1_lo, c[b], c_lo[b], x, x_lo, &c[k], &c_lo[k]);
#else
  (void)c_lo;
  (void)x1_lo;
  (void)x_lo;
  c[k] = CASTELJAU_COMBINE(x1, c[a], x, c[b]);
#endif
}

ALGRAY_INLINE void coefs_copy(REAL* dst, REAL* dst_lo, const REAL* src, const REAL* src_lo) {
  poly_copy(dst, src);
#if ALGRAY_COMPENSATED
  poly_copy(dst_lo, src_lo);
#else
  (void)dst_lo;
  (void)src_lo;
#endif
}

/* The triangles below run every inner loop to a constant bound and test the row's end inside: a bound that
 * depends on the outer index kept LLVM from unrolling fully, and the rows then went through memory (measured in
 * PoCL's compiled kernels). The operations and their order are the same. */

/* Keeps the part of the curve on [0, x], x dyadic (so 1 - x is exact). In place: after pass r, c[r] is the
 * r-th left coefficient. */
void casteljau_keep_left(REAL* c, REAL* c_lo, REAL x) {
  const REAL x1 = (REAL)1 - x;
  ALGRAY_UNROLL
  for (int r = 1; r <= DEGREE; ++r) ALGRAY_UNROLL
  for (int k = DEGREE; k >= 1; --k)
    if (k >= r) casteljau_step(c, c_lo, k, k - 1, k, x1, 0, x, 0);
}

/* Keeps the part on [x + x_lo, 1], for x >= 1/2 (so 1 - x is exact). */
void casteljau_keep_right(REAL* c, REAL* c_lo, REAL x, REAL x_lo) {
  const REAL x1 = (REAL)1 - x;
  ALGRAY_UNROLL
  for (int r = 1; r <= DEGREE; ++r) ALGRAY_UNROLL
  for (int k = 0; k < DEGREE; ++k)
    if (k <= DEGREE - r) casteljau_step(c, c_lo, k, k, k + 1, x1, -x_lo, x, x_lo);
}

/* Halves c at 1/2 in one de Casteljau triangle: c becomes the left half, right the right half. */
#if DEGREE <= 15 && !ALGRAY_COMPENSATED
/* Each row of the triangle as one vector operation on a register, instead of a row of scalars through memory
 * (measured: casteljau_halve was a fifth of the Barth decic's shadow kernel). The same products and sums as
 * the scalar rows below: 0.5 t_k + 0.5 t_(k+1) per lane. Lanes past the row's end are never read. */
void casteljau_halve(REAL* c, REAL* c_lo, REAL* right, REAL* right_lo) {
  (void)c_lo;
  (void)right_lo;
  REAL row[ACC_WIDTH];
  ALGRAY_UNROLL
  for (int k = 0; k < ACC_WIDTH; ++k) row[k] = k <= DEGREE ? c[k] : (REAL)0;
  PolyVec t = VEC_LOAD(row);
  right[DEGREE] = c[DEGREE];
  ALGRAY_UNROLL
  for (int r = 1; r <= DEGREE; ++r) {
    t = CASTELJAU_COMBINE((REAL)0.5, t, (REAL)0.5, VEC_SHIFT_DOWN(t));
    VEC_STORE(t, row);
    c[r] = row[0];
    right[DEGREE - r] = row[DEGREE - r];
  }
}
#else
void casteljau_halve(REAL* c, REAL* c_lo, REAL* right, REAL* right_lo) {
  REAL t[NCOEF], t_lo[NCOEF];
  coefs_copy(t, t_lo, c, c_lo);
  right[DEGREE] = t[DEGREE];
#if ALGRAY_COMPENSATED
  right_lo[DEGREE] = t_lo[DEGREE];
#endif
  ALGRAY_UNROLL
  for (int r = 1; r <= DEGREE; ++r) {
    ALGRAY_UNROLL
    for (int k = 0; k < DEGREE; ++k)
      if (k <= DEGREE - r) casteljau_step(t, t_lo, k, k, k + 1, (REAL)0.5, 0, (REAL)0.5, 0);
    c[r] = t[0];
    right[DEGREE - r] = t[DEGREE - r];
#if ALGRAY_COMPENSATED
    c_lo[r] = t_lo[0];
    right_lo[DEGREE - r] = t_lo[DEGREE - r];
#else
    (void)right_lo;
#endif
  }
}
#endif

/* Coefficients on the dyadic interval [idx/2^level, (idx+1)/2^level], recomputed from the whole interval's. */
void bernstein_restrict(const REAL* root, const REAL* root_lo, int level, ulong idx, REAL* out, REAL* out_lo) {
  coefs_copy(out, out_lo, root, root_lo);
  const REAL width = ldexp((REAL)1, -level);
  const REAL lo = (REAL)idx * width, hi = lo + width;
  if (hi < (REAL)1) casteljau_keep_left(out, out_lo, hi);
  if (lo > (REAL)0) {
    /* lo / hi = idx / (idx + 1) >= 1/2, and its rounding error recovered exactly by fma */
    const REAL x = lo / hi;
    casteljau_keep_right(out, out_lo, x, fma(-x, hi, lo) / hi);
  }
}

/* Whether float refinement can find the root bracketed by cur's end values. Always in plain builds. In mixed
 * precision the rounded coefficients are only good to eps of their largest, so an end value below that noise
 * could stop the refinement at the wrong end (measured: an Endrass octic hit 0.19 from its root); the
 * interval is halved further instead, in float-float, until its ends stand clear of the noise. */
int refinable_in_float(const REAL* c) {
#if ALGRAY_COMPENSATED
  REAL scale = 0;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) scale = fmax(scale, fabs(c[k]));
  return fmin(fabs(c[0]), fabs(c[DEGREE])) > (REAL)(4 * DEGREE) * REAL_EPS * scale;
#else
  (void)c;
  return 1;
#endif
}

/* Adaptive builds, one ray per work-item (camera and secondary rays): whether an isolated bracket [iso.lo, iso.hi]
 * whose end values are within the noise (an accept doubt) is settled after all by P's values at its ends in
 * float-float (float_float.h, bracket_ends_in_float_float). The probe sees the doubt, then what settled it
 * (ALGRAY_EVENT_CONFIRMED, decision 2). Other builds and shadow rays never settle one so. */
#if ALGRAY_ESCALATE && LANES == 1 && !ALGRAY_SHADOW_RAYS
int bracket_settled(const Isolation* iso, const REAL* cur, SearchNoise* noise, int level, ProbeLog* probe_log) {
  const RayTerms* terms = noise->terms;
  const REAL end = smaller_end(cur, iso->lo);
  if (!terms->has_ray || !within_noise_at(noise, end, iso->lo, iso->hi)) return 0;
  const LaneRays r = one_lane_rays(terms->o, terms->d);
  REAL v_lo, rounding_lo, v_hi, rounding_hi;
  if (!bracket_ends_in_float_float(1, &r, terms->t_in, terms->t_out, iso->lo, iso->hi, cur[0], cur[DEGREE],
                                   terms->exps, terms->coefs, terms->count, &v_lo, &rounding_lo, &v_hi, &rounding_hi))
    return 0;
  PROBE(ALGRAY_EVENT_DOUBT, 0, ALGRAY_DOUBT_ACCEPT, (uint)level, iso->lo, iso->hi, end, noise->noise);
  PROBE(ALGRAY_EVENT_CONFIRMED, 0, 2u, 0u, v_lo, rounding_lo, v_hi, rounding_hi);
  return 1;
}
#else
#define bracket_settled(iso, cur, noise, level, probe_log) 0
#endif

/* Camera and secondary rays of adaptive builds that settle doubts (ALGRAY_SETTLE_DOUBTS: where the second pass runs
 * in float-float; in double, tracing the ray again costs less than these checks) settle discard doubts by P's signs
 * in float-float (discard_settled). */
#define ALGRAY_SETTLES_DISCARDS (ALGRAY_ESCALATE && !ALGRAY_SHADOW_RAYS && ALGRAY_SETTLE_DOUBTS)
#if ALGRAY_SETTLES_DISCARDS && LANES == 1

/* The end value of an interval at fraction s as the probe shows a settled discard doubt: P in float-float and its
 * rounding where that end was within the noise (in proven), else float's value c and the noise it stood clear of. */
void settled_end(const ProvenEnds* proven, REAL s, REAL c, REAL noise, REAL* value, REAL* bound) {
  *value = c;
  *bound = noise;
  for (int e = 0; e < 2; ++e)
    if (proven->at[e] == s) {
      *value = proven->value[e];
      *bound = proven->rounding[e];
    }
}

/* One ray per work-item (camera and secondary rays): whether an interval without sign variations doubted for an
 * end value within the noise (a discard doubt) is root-free after all: every coefficient inside stands clear of the
 * noise, and P in float-float at each end within it (proven, evaluated where not there yet) has the sign float
 * gave there, beyond its rounding. Then every Bernstein coefficient has that one sign for certain. (Where one
 * inside is within the noise too, P itself is, and halving down to the stopping width measured no better than
 * tracing the ray again.) The probe sees the doubt, then what settled it (ALGRAY_EVENT_CONFIRMED, decision 3). */
int discard_settled(const Isolation* iso, const REAL* cur, SearchNoise* noise, ProvenEnds* proven,
                    int level, ProbeLog* probe_log) {
  const RayTerms* terms = noise->terms;
  if (!terms->has_ray || within_noise_at(noise, inner_smallest_magnitude(cur), iso->lo, iso->hi)) return 0;
  const int lo_doubted = within_noise_at(noise, cur[0], iso->lo, iso->hi);
  const int hi_doubted = within_noise_at(noise, cur[DEGREE], iso->lo, iso->hi);
  const LaneRays r = one_lane_rays(terms->o, terms->d);
  if (lo_doubted && !proven_at(proven, iso->lo))
    prove_end(1, &r, terms->t_in, terms->t_out, iso->lo, iso->hi, terms->exps, terms->coefs, terms->count, proven);
  if (hi_doubted && !proven_at(proven, iso->hi))
    prove_end(1, &r, terms->t_in, terms->t_out, iso->hi, iso->lo, terms->exps, terms->coefs, terms->count, proven);
  if ((lo_doubted && !proven_sign_of(proven, iso->lo, cur[0])) ||
      (hi_doubted && !proven_sign_of(proven, iso->hi, cur[DEGREE])))
    return 0;
#if ALGRAY_PROBE
  REAL v_lo, bound_lo, v_hi, bound_hi;
  settled_end(proven, iso->lo, cur[0], noise->noise, &v_lo, &bound_lo);
  settled_end(proven, iso->hi, cur[DEGREE], noise->noise, &v_hi, &bound_hi);
  PROBE(ALGRAY_EVENT_DOUBT, 0, ALGRAY_DOUBT_DISCARD, (uint)level, iso->lo, iso->hi, smaller_end(cur, iso->lo),
        noise->noise);
  PROBE(ALGRAY_EVENT_CONFIRMED, 0, 3u, 0u, v_lo, bound_lo, v_hi, bound_hi);
#else
  (void)level;
#endif
  return 1;
}
#else
#define discard_settled(iso, cur, noise, proven, level, probe_log) 0
#endif

/* Finds the leftmost subinterval of [0,1] that isolates the smallest root of the polynomial with Bernstein
 * coefficients `root` (+ `root_lo` in mixed precision). Depth-first, left half first; the path is the pair
 * (level, idx), so no stack is kept. The right half of the latest split is cached, as the left half is usually
 * rejected at once. On return `cur` holds the Bernstein coefficients on [iso.lo, iso.hi] (rounded to float in
 * mixed precision, where they are accurate relative to their own size). */
Isolation isolate_bernstein(const REAL* root, const REAL* root_lo, REAL t_in, REAL t_out,
                            REAL* cur, RayTerms* terms, ProbeLog* probe_log) {
  Isolation iso = isolation_none();
  REAL cur_lo[NCOEF], sib[NCOEF], sib_lo[NCOEF];
  int sib_level = -1;
  ulong sib_idx = 0;
  int level = 0;
  ulong idx = 0;
  const REAL len = t_out - t_in;
  const int start_sign = (root[0] > 0) - (root[0] < 0);
  coefs_copy(cur, cur_lo, root, root_lo);
#if ALGRAY_ESCALATE
  SearchNoise noise_of_search = search_noise(root, terms);
  SearchNoise* noise = &noise_of_search;
#endif
#if ALGRAY_SETTLES_DISCARDS
  ProvenEnds proven;
  no_proven_ends(&proven);
#endif

  for (;;) {
    ++iso.steps;
    const REAL width = ldexp((REAL)1, -level);
    iso.lo = (REAL)idx * width;
    iso.hi = iso.lo + width;
    iso.f_lo = cur[0];
    iso.f_hi = cur[DEGREE];
    if (settled_at_left_end(&iso, start_sign, level, probe_log)) {
      doubted(&iso, ALGRAY_DOUBT_ACCEPT, iso.f_lo, noise, level, probe_log);
      return isolation_found(iso, noise);
    }
    const int v = sign_variations(cur);
    if (v == 1 && cur[DEGREE] != 0 && refinable_in_float(cur)) {
      PROBE_STEP(iso, v, ALGRAY_STEP_ISOLATED, level);
      iso.status = ISOLATION_BRACKET;
      if (!bracket_settled(&iso, cur, noise, level, probe_log))
        doubted(&iso, ALGRAY_DOUBT_ACCEPT, smaller_end(cur, iso.lo), noise, level, probe_log);
      return isolation_found(iso, noise);
    }
#if ALGRAY_ESCALATE
    /* No sign variation, but a coefficient within the noise of zero: the interval is not yet shown root-free.
     * Its end coefficients are P's values: near zero there, float cannot tell; an inner one is halved until it
     * stands clear, as de Casteljau's coefficients close in on P's values (fewer rays doubted: on the Barth
     * decic's shadow rays, 10% of them doubted without this), unless P's signs there are proven in float-float
     * (discard_settled). */
    int near_zero = v == 0 && within_noise_at(noise, smallest_magnitude(cur, iso.lo), iso.lo, iso.hi);
    if (near_zero && within_noise_at(noise, smaller_end(cur, iso.lo), iso.lo, iso.hi)) {
      if (!discard_settled(&iso, cur, noise, &proven, level, probe_log)) {
        doubted(&iso, ALGRAY_DOUBT_DISCARD, smaller_end(cur, iso.lo), noise, level, probe_log);
        return iso;
      }
      near_zero = 0; /* root-free */
    }
#else
    const int near_zero = 0;
#endif
    if (v >= 1 || near_zero) {
      const int next = halve_or_settle(&iso, v, level, width, t_in, len, probe_log);
      if (next == INTERVAL_HALVE) {
        casteljau_halve(cur, cur_lo, sib, sib_lo);
        ++level;
        idx *= 2;
        sib_level = level;
        sib_idx = idx + 1;
        continue;
      }
      /* A cluster is always in doubt: float cannot tell a close pair from a complex one there. */
      if (doubted(&iso, ALGRAY_DOUBT_CLUSTER, 0, noise, level, probe_log)) return iso;
      if (next == INTERVAL_SETTLED) return isolation_found(iso, noise);
    } else {
      PROBE_STEP(iso, v, ALGRAY_STEP_NO_ROOT, level);
    }
    if (!next_interval(&level, &idx)) return isolation_at_far_end(iso, root[DEGREE] == 0, root[DEGREE], probe_log);
    if (sib_level == level && sib_idx == idx)
      coefs_copy(cur, cur_lo, sib, sib_lo);
    else
      bernstein_restrict(root, root_lo, level, idx, cur, cur_lo);
  }
}

/* The method's entry (isolate.h). */
Isolation isolate_method(REAL* root, REAL* root_lo, REAL t_in, REAL t_out, REAL* iso_c, RayTerms* terms,
                         ProbeLog* probe_log) {
  return isolate_bernstein(root, root_lo, t_in, t_out, iso_c, terms, probe_log);
}

#if !ALGRAY_COMPENSATED
/* casteljau_halve over lanes: c's halves at 1/2 into left and right, by the same rows of the triangle (the same
 * products and sums per lane). */
ALGRAY_INLINE void casteljau_halve_lanes(const LREAL* c, LREAL* left, LREAL* right) {
  LREAL t[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) t[k] = c[k];
  left[0] = t[0];
  right[DEGREE] = t[DEGREE];
  ALGRAY_UNROLL
  for (int r = 1; r <= DEGREE; ++r) {
    ALGRAY_UNROLL
    for (int k = 0; k < DEGREE; ++k)
      if (k <= DEGREE - r) t[k] = CASTELJAU_COMBINE((REAL)0.5, t[k], (REAL)0.5, t[k + 1]);
    left[r] = t[0];
    right[DEGREE - r] = t[DEGREE - r];
  }
}

/* Whether every coefficient of c has one strict sign, lane by lane: then the polynomial has no root on the
 * interval (and de Casteljau's pieces of it keep the sign). */
ALGRAY_INLINE LMASK one_strict_sign(const LREAL* c) {
  LMASK positive = c[0] > 0, negative = c[0] < 0;
  ALGRAY_UNROLL
  for (int k = 1; k <= DEGREE; ++k) {
    positive = positive && c[k] > 0;
    negative = negative && c[k] < 0;
  }
  return positive || negative;
}
#endif

#if LANES > 1 && !ALGRAY_COMPENSATED
/* isolation.h's PICK_LARGER and PICK_SMALLER, lane by lane */
#define LANE_LARGER(a, b) LANE_SEL((a), (b), (b) > (a))
#define LANE_SMALLER(a, b) LANE_SEL((a), (b), (b) < (a))
/* What the lanes' search of an adaptive build needs of its rays: their terms (the noise), and the rays in unit
 * coordinates with the monomials, for bracket_ends_in_float_float as bracket_settled uses it. Other builds never
 * read it. */
typedef struct {
  LREAL value;
  const LaneRays* rays;
  __global const uint* exps;
  __global const REAL* coefs;
  uint count;
} LaneTerms;
/* isolate_bernstein for LANES polynomials at once (lanes.h), lanes where `running` is clear left alone: each
 * lane takes the scalar search's decisions in its order, with the same arithmetic, so it ends with the scalar
 * result bit for bit (tests/test_lanes). The search's position is kept as the interval's left end and width,
 * REALs that are exact for these dyadic numbers, so that all the state is in vector registers: (level, idx) is
 * (-log2 width, left end / width).
 * A halving, a recomputation from `root` and a copy of the cached sibling each cost every lane, so this pays
 * where neighbouring rays take similar searches (bench/history/2026-12.md, "Lock-step lanes"). Mixed precision keeps
 * the scalar search per lane. */

/* Sign changes between consecutive nonzero coefficients, per lane, as sign_variations counts them (a NaN counts
 * as a zero). The last sign seen is carried by selections alone, and the changes are summed as a tree: added one
 * after another, each waiting on the last, they were the longest chain of the search's step. */
ALGRAY_INLINE LREAL sign_variations_lanes(const LREAL* c) {
  LREAL change[NCOEF];
  LMASK seen = c[0] > 0 || c[0] < 0, prev_negative = c[0] < 0;
  ALGRAY_UNROLL
  for (int k = 1; k <= DEGREE; ++k) {
    const LMASK negative = c[k] < 0, strict = negative || c[k] > 0;
    change[k] = LANE_SEL((LREAL)0, (LREAL)1, strict && seen && negative != prev_negative);
    prev_negative = LANE_SEL(prev_negative, negative, strict);
    seen = seen || strict;
  }
  change[0] = 0;
  ALGRAY_UNROLL
  for (int span = 1; span <= DEGREE; span *= 2) ALGRAY_UNROLL
  for (int k = 0; k + span <= DEGREE; k += 2 * span) change[k] += change[k + span];
  return change[0];
}

/* bernstein_restrict per lane: the coefficients on [lo, lo + width] from the whole interval's, into out for the
 * lanes in `take`. */
void bernstein_restrict_lanes(const LREAL* root, LREAL lo, LREAL width, LMASK take, LREAL* out) {
  LREAL o[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) o[k] = root[k];
  const LREAL hi = lo + width;
  const LMASK left = take && hi < (REAL)1;
  if (LANE_ANY(left)) {
    const LREAL x1 = (REAL)1 - hi;
    LREAL t[NCOEF];
    ALGRAY_UNROLL
    for (int k = 0; k <= DEGREE; ++k) t[k] = o[k];
    ALGRAY_UNROLL
    for (int r = 1; r <= DEGREE; ++r) ALGRAY_UNROLL
    for (int k = DEGREE; k >= 1; --k)
      if (k >= r) t[k] = CASTELJAU_COMBINE(x1, t[k - 1], hi, t[k]);
    ALGRAY_UNROLL
    for (int k = 0; k <= DEGREE; ++k) o[k] = LANE_SEL(o[k], t[k], left);
  }
  const LMASK right = take && lo > (REAL)0;
  if (LANE_ANY(right)) {
    const LREAL x = lo / hi, x1 = (REAL)1 - x;
    LREAL t[NCOEF];
    ALGRAY_UNROLL
    for (int k = 0; k <= DEGREE; ++k) t[k] = o[k];
    ALGRAY_UNROLL
    for (int r = 1; r <= DEGREE; ++r) ALGRAY_UNROLL
    for (int k = 0; k < DEGREE; ++k)
      if (k <= DEGREE - r) t[k] = CASTELJAU_COMBINE(x1, t[k], x, t[k + 1]);
    ALGRAY_UNROLL
    for (int k = 0; k <= DEGREE; ++k) o[k] = LANE_SEL(o[k], t[k], right);
  }
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) out[k] = LANE_SEL(out[k], o[k], take);
}

/* root: each lane's Bernstein coefficients on [t_in, t_out]. On return each running lane of iso is that lane's
 * Isolation (the others mean nothing), and cur_out holds each lane's coefficients on its isolating interval. */
void isolate_bernstein_lanes(LMASK running, const LREAL* root, LREAL t_in, LREAL t_out, LaneIsolation* iso,
                             LREAL* cur_out, const LaneTerms* terms) {
  LREAL cur[NCOEF], sib[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) cur[k] = sib[k] = root[k];
  const LREAL len = t_out - t_in;
  const LREAL start_sign = LANE_SEL((LREAL)0, (LREAL)1, root[0] > 0) - LANE_SEL((LREAL)0, (LREAL)1, root[0] < 0);
  /* the interval searched, [at, at + width], and the cached right half of the latest split (none yet) */
  LREAL at = 0, width = 1, sib_at = 0, sib_width = 0;
  LREAL status = ISOLATION_NONE, steps = 0;
  /* A lane that stops keeps its interval [at, at + width] and its coefficients cur, which are what it reports,
   * unless it ended past the far end (searched_all). */
  LMASK budget = 0, cluster = 0, searched_all = 0, done = !running;
#if ALGRAY_ESCALATE
  /* doubt_noise and doubted per lane: a doubted lane stops with status NONE and its ALGRAY_DOUBT_* */
  LREAL magnitude[NCOEF], doubt = 0;
  LMASK brackets_doubted = 0; /* the lanes doubted at an isolated bracket */
#if ALGRAY_SETTLES_DISCARDS
  ProvenEnds proven;
  no_proven_ends(&proven);
#endif
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) magnitude[k] = fabs(root[k]);
  MAGNITUDE_TREE(magnitude, LANE_LARGER);
  const LREAL noise = DOUBT_NOISE(magnitude[0], terms->value);
#define DOUBT_LANES(mask, reason)                               \
  do {                                                          \
    const LMASK doubted_ = (mask);                              \
    doubt = LANE_SEL(doubt, (LREAL)(reason), doubted_);         \
    status = LANE_SEL(status, (LREAL)ISOLATION_NONE, doubted_); \
    done = done || doubted_;                                    \
  } while (0)
#else
#define DOUBT_LANES(mask, reason) ((void)0)
#endif
  for (;;) {
    const LMASK active = !done;
    steps += LANE_SEL((LREAL)0, (LREAL)1, active);
    const LREAL f_lo = cur[0], f_hi = cur[DEGREE];
    /* settled_at_left_end: an exact zero, or the other sign than at t_in */
    const LREAL s = LANE_SEL((LREAL)0, (LREAL)1, f_lo > 0) - LANE_SEL((LREAL)0, (LREAL)1, f_lo < 0);
    const LMASK exact = active && (f_lo == 0 || (s != 0 && s != start_sign));
    status = LANE_SEL(status, (LREAL)ISOLATION_EXACT, exact);
    done = done || exact;
    DOUBT_LANES(exact && fabs(f_lo) <= noise, ALGRAY_DOUBT_ACCEPT);
    const LREAL v = sign_variations_lanes(cur);
    const LMASK isolated = !done && v == 1 && cur[DEGREE] != 0;
    status = LANE_SEL(status, (LREAL)ISOLATION_BRACKET, isolated);
    done = done || isolated;
#if ALGRAY_ESCALATE
    /* doubted for now; bracket_settled's check comes once for all such lanes, after the search */
    const LMASK bracket_doubt = isolated && fmin(fabs(cur[0]), fabs(cur[DEGREE])) <= noise;
    brackets_doubted = brackets_doubted || bracket_doubt;
    DOUBT_LANES(bracket_doubt, ALGRAY_DOUBT_ACCEPT);
    /* isolate_bernstein's near_zero: doubted at an end unless discard_settled's float-float signs settle it,
     * halved inside */
    ALGRAY_UNROLL
    for (int k = 0; k <= DEGREE; ++k) magnitude[k] = fabs(cur[k]);
    MAGNITUDE_TREE(magnitude, LANE_SMALLER);
    LMASK near_zero = !done && v == 0 && magnitude[0] <= noise;
    const LMASK lo_doubted = fabs(cur[0]) <= noise, hi_doubted = fabs(cur[DEGREE]) <= noise;
    const LMASK end_doubted = near_zero && (lo_doubted || hi_doubted);
#if ALGRAY_SETTLES_DISCARDS
    if (LANE_ANY(end_doubted)) {
      /* inner_smallest_magnitude first: where it is within the noise, nothing is evaluated */
      ALGRAY_UNROLL
      for (int k = 0; k <= DEGREE; ++k) magnitude[k] = fabs(cur[k]);
      magnitude[0] = magnitude[DEGREE] = INFINITY;
      MAGNITUDE_TREE(magnitude, LANE_SMALLER);
      const LMASK inner_clear = end_doubted && magnitude[0] > noise;
      /* one evaluation for the lanes that need either end, a second for those that need both */
      const LREAL hi = at + width;
      const LMASK lo_needed = inner_clear && lo_doubted && !proven_at(&proven, at);
      const LMASK hi_needed = inner_clear && hi_doubted && !proven_at(&proven, hi);
      if (LANE_ANY(lo_needed || hi_needed))
        prove_end(lo_needed || hi_needed, terms->rays, t_in, t_out, LANE_SEL(hi, at, lo_needed),
                  LANE_SEL(at, hi, lo_needed), terms->exps, terms->coefs, terms->count, &proven);
      if (LANE_ANY(lo_needed && hi_needed))
        prove_end(lo_needed && hi_needed, terms->rays, t_in, t_out, hi, at, terms->exps, terms->coefs, terms->count,
                  &proven);
      const LMASK settled = inner_clear && (!lo_doubted || proven_sign_of(&proven, at, cur[0])) &&
                            (!hi_doubted || proven_sign_of(&proven, hi, cur[DEGREE]));
      DOUBT_LANES(end_doubted && !settled, ALGRAY_DOUBT_DISCARD);
      near_zero = near_zero && !settled; /* root-free */
    }
#else
    DOUBT_LANES(end_doubted, ALGRAY_DOUBT_DISCARD);
#endif
    /* halve_or_settle for the lanes that may hold several roots */
    const LMASK several = !done && (v >= 1 || near_zero);
#else
    /* halve_or_settle for the lanes that may hold several roots */
    const LMASK several = !done && v >= 1;
#endif
    const LMASK located = width * len <= STOP_WIDTH(t_in + at * len);
    const LMASK halve = several && !located && width > (REAL)1 / (REAL)FINEST_UNITS; /* level < REAL_MAX_HALVINGS */
    const LMASK settle = several && !halve;
    budget = budget || (settle && !located);
    const LMASK cluster_root = settle && ((f_lo < 0) != (f_hi < 0));
    status = LANE_SEL(status, (LREAL)ISOLATION_BRACKET, cluster_root);
    cluster = cluster || cluster_root;
    done = done || cluster_root;
    DOUBT_LANES(settle, ALGRAY_DOUBT_CLUSTER);
    if (LANE_ALL(done)) break;
    if (LANE_ANY(halve)) {
      LREAL left[NCOEF], right[NCOEF];
      casteljau_halve_lanes(cur, left, right);
      ALGRAY_UNROLL
      for (int k = 0; k <= DEGREE; ++k) {
        cur[k] = LANE_SEL(cur[k], left[k], halve);
        sib[k] = LANE_SEL(sib[k], right[k], halve);
      }
      width = LANE_SEL(width, width * (REAL)0.5, halve);
      sib_width = LANE_SEL(sib_width, width, halve);
      sib_at = LANE_SEL(sib_at, at + width, halve);
    }
    /* next_interval for the lanes moving on, without its loop: it climbs while the interval is a right child
     * (idx odd), then steps right, so the next interval starts where this one ends, and is as wide as the
     * largest power of two that divides that end (idx + 1's lowest set bit, in units of width). */
    LMASK move = !done && !halve;
    if (!LANE_ANY(move)) continue;
    const LREAL next_at = at + width;
    const LANE_INT_VEC units = LANE_TO_INT(next_at * (REAL)FINEST_UNITS);
    width = LANE_SEL(width, LANE_TO_REAL(units & -units) * ((REAL)1 / (REAL)FINEST_UNITS), move);
    /* isolation_at_far_end: the whole interval searched; its far end is a root only where P is zero there */
    const LMASK finished = move && next_at == 1;
    status = LANE_SEL(status, LANE_SEL((LREAL)ISOLATION_NONE, (LREAL)ISOLATION_EXACT, root[DEGREE] == 0), finished);
    searched_all = searched_all || finished;
    done = done || finished;
    move = move && !finished;
    at = LANE_SEL(at, next_at, move);
    const LMASK from_sib = move && sib_width == width && sib_at == at;
    ALGRAY_UNROLL
    for (int k = 0; k <= DEGREE; ++k) cur[k] = LANE_SEL(cur[k], sib[k], from_sib);
    const LMASK from_root = move && !from_sib;
    if (LANE_ANY(from_root)) bernstein_restrict_lanes(root, at, width, from_root, cur);
  }
#if ALGRAY_ESCALATE && !ALGRAY_SHADOW_RAYS
  /* bracket_settled: a stopped lane keeps its interval and coefficients, so the brackets doubted in any step are
   * checked here together, in one evaluation for the lanes rather than one per step that doubted some */
  if (LANE_ANY(brackets_doubted)) {
    LREAL v_lo, rounding_lo, v_hi, rounding_hi;
    const LMASK settled =
        bracket_ends_in_float_float(brackets_doubted, terms->rays, t_in, t_out, at, at + width, cur[0], cur[DEGREE],
                                    terms->exps, terms->coefs, terms->count, &v_lo, &rounding_lo, &v_hi, &rounding_hi);
    status = LANE_SEL(status, (LREAL)ISOLATION_BRACKET, settled);
    doubt = LANE_SEL(doubt, (LREAL)0, settled);
  }
#endif
  iso->status = status;
  iso->steps = steps;
  /* isolation_at_far_end reports [1, 1] with zero values */
  iso->lo = LANE_SEL(at, (LREAL)1, searched_all);
  iso->hi = LANE_SEL(at + width, (LREAL)1, searched_all);
  iso->f_lo = LANE_SEL(cur[0], (LREAL)0, searched_all);
  iso->f_hi = LANE_SEL(cur[DEGREE], (LREAL)0, searched_all);
  iso->budget = budget;
  iso->cluster = cluster;
#if ALGRAY_ESCALATE
  iso->doubt = doubt;
  iso->noise = noise;
#else
  iso->doubt = iso->noise = 0;
#endif
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) cur_out[k] = cur[k];
}
#undef DOUBT_LANES
#endif

/* Whether isolate_bernstein would find a root at all, read off the signs of the scaled coefficients c (as the
 * restriction leaves them, before bernstein_from_scaled) where they settle it without subdividing:
 *  - ISOLATION_NONE when every c_k has one strict sign: the search's first interval has no sign variation, and
 *    with it the whole of [0,1] is searched. Dividing by the positive C(n,k) keeps each sign, or underflows a
 *    middle one to zero, which adds no variation; the ends are divided by 1;
 *  - ISOLATION_BRACKET when an end is zero or the ends differ in sign: a root of P* on the segment, and the
 *    search reports one too, because every interval it searches keeps c_n as its right end, unrounded, so the
 *    last one it reaches holds the sign change (or the zero) that it reports;
 *  - -1 otherwise, NaN included: only the search can tell.
 * A shadow ray asks for nothing more, so most of its rays skip the division and the search. */
int bernstein_root_by_signs(const REAL* c) {
  int positive = 1, negative = 1;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) {
    positive &= c[k] > 0;
    negative &= c[k] < 0;
  }
  if (positive || negative) return ISOLATION_NONE;
  const REAL a = c[0], b = c[DEGREE];
  if (a == 0 || b == 0 || (a < 0 && b > 0) || (a > 0 && b < 0)) return ISOLATION_BRACKET;
  return -1;
}

/* The refinement's first estimate of the root (refine.h), from the Bernstein coefficients c of the isolating
 * interval before prepare_isolated, or -1 for none. Degree 2: the quadratic's root in (0, 1) by the formula that
 * avoids cancellation; rounded, it is a start, not an answer: Brent evaluates it and goes on until its own stopping
 * rule holds, as from any start (near a double root the formula loses digits, and the search then finds them). A
 * start moves where in the stopping width a root lands, so other degrees keep the paper's start (bench/RESULTS.md:
 * the control polygon's crossing as a start, measured and not kept). Over lanes, each lane's. */
#if DEGREE == 2
LREAL isolated_start(const LREAL* c) {
  /* c0 (1 - y)^2 + 2 c1 y (1 - y) + c2 y^2 = a y^2 + b y + c0 */
  const LREAL a = (c[0] - (REAL)2 * c[1]) + c[2], b = (REAL)2 * (c[1] - c[0]);
  const LREAL q = (REAL)-0.5 * (b + copysign(sqrt(b * b - (REAL)4 * a * c[0]), b));
  const LREAL near = c[0] / q, far = q / a;
  return LANE_SEL(LANE_SEL((LREAL)-1, far, far > 0 && far < 1), near, near > 0 && near < 1);
}
#else
LREAL isolated_start(const LREAL* c) {
  (void)c;
  return -1;
}
#endif

/* Turns Bernstein coefficients into the form isolated_value() expects: c_k * C(n,k); over lanes, each lane's. */
void prepare_isolated(LREAL* c, __constant const REAL* binomials) {
  __constant const REAL* row = binomials + DEGREE * NCOEF;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) c[k] *= row[k];
}

/* x^DEGREE by repeated multiplication: pown() goes through exp and log on some devices. */
LREAL power_of(LREAL x) {
  LREAL p = 1;
  ALGRAY_UNROLL
  for (int k = 0; k < DEGREE; ++k) p *= x;
  return p;
}

/* Value at y in [0,1] of a prepared polynomial in O(n): Horner in y/(1-y), mirrored past 1/2 so the ratio
 * stays at most 1. Over lanes (lanes.h), each lane picks its side by selection; the ratio is then one
 * division of the selected numerator by the selected denominator, the same operations as either side alone. */
LREAL isolated_value(const LREAL* c, LREAL y) {
  const LMASK mirrored = !(y <= (REAL)0.5);
  const LREAL u = LANE_SEL((REAL)1 - y, y, mirrored); /* the factor raised to the power n */
  const LREAL r = LANE_SEL(y, (REAL)1 - y, mirrored) / u;
  LREAL h = LANE_SEL(c[DEGREE], c[0], mirrored);
  ALGRAY_UNROLL
  for (int k = DEGREE - 1; k >= 0; --k) h = h * r + LANE_SEL(c[k], c[DEGREE - k], mirrored);
  return h * power_of(u);
}

/* The size of the terms isolated_value(c, y) sums, sum |c_k| r^k times the same power: its rounding error is
 * a small multiple of REAL_EPS times this, so a value below REAL_EPS times it has no reliable sign. */
LREAL isolated_magnitude(const LREAL* c, LREAL y) {
  const LMASK mirrored = y > (REAL)0.5;
  const LREAL u = LANE_SEL((REAL)1 - y, y, mirrored);
  const LREAL r = LANE_SEL(y, (REAL)1 - y, mirrored) / u;
  LREAL h = 0;
  ALGRAY_UNROLL
  for (int k = DEGREE; k >= 0; --k) h = h * r + fabs(LANE_SEL(c[k], c[DEGREE - k], mirrored));
  return h * power_of(u);
}

/* Value and slope at y in [0,1] of a prepared polynomial, for Newton's method and adaptive builds' flat check. With
 * r = y/(1-y) and H(r) = sum c_k r^k, P = (1-y)^n H and P' = (1-y)^(n-2) (H' - n (1-y) H); mirrored past 1/2 like
 * the value. Defined for one ray and, in lane builds, for lanes (each lane with one ray's operations, the sides
 * picked by `pick`). */
#if DEGREE == 1
#define DEFINE_VALUE_SLOPE(name, T, M, pick) \
  T name(const T* c, T y, T* slope) {        \
    *slope = c[1] - c[0];                    \
    return c[0] * ((REAL)1 - y) + c[1] * y;  \
  }
#else
#define DEFINE_VALUE_SLOPE(name, T, M, pick)                                                                   \
  T name(const T* c, T y, T* slope) {                                                                          \
    const M mirrored = y > (REAL)0.5;                                                                          \
    const T u = pick(mirrored, y, (REAL)1 - y); /* the factor raised to the power n */                        \
    const T r = pick(mirrored, (REAL)1 - y, y) / u;                                                            \
    T h = 0, d = 0;                                                                                            \
    ALGRAY_UNROLL                                                                                              \
    for (int k = DEGREE; k >= 0; --k) {                                                                        \
      d = d * r + h;                                                                                           \
      h = h * r + pick(mirrored, c[DEGREE - k], c[k]);                                                         \
    }                                                                                                          \
    T un2 = 1; /* u^(n-2) */                                                                                   \
    ALGRAY_UNROLL                                                                                              \
    for (int k = 0; k < DEGREE - 2; ++k) un2 *= u;                                                             \
    /* dr/dy = 1/(1-y)^2 unmirrored, -1/y^2 mirrored */                                                        \
    *slope = pick(mirrored, un2 * ((REAL)DEGREE * u * h - d), un2 * (d - (REAL)DEGREE * u * h));              \
    return h * un2 * u * u;                                                                                    \
  }
#endif
#define PICK_OF_ONE(m, a, b) ((m) ? (a) : (b))
DEFINE_VALUE_SLOPE(isolated_value_slope, REAL, int, PICK_OF_ONE)
#if LANES > 1
#define PICK_OF_LANES(m, a, b) LANE_SEL((b), (a), (m))
DEFINE_VALUE_SLOPE(isolated_value_slope_lanes, LREAL, LMASK, PICK_OF_LANES)
#endif

#endif /* ALGRAY_BERNSTEIN_H */
