/* What every root-isolation method returns, and the sign-variation count they share. */
#ifndef ALGRAY_ISOLATION_H
#define ALGRAY_ISOLATION_H

#include "lanes.h"
#include "probe_log.h"
#include "real.h"
#include "restrict.h"

#define ISOLATION_NONE ALGRAY_ISOLATED_NONE
#define ISOLATION_BRACKET ALGRAY_ISOLATED_BRACKET
#define ISOLATION_EXACT ALGRAY_ISOLATED_EXACT

/* lo, hi are fractions of [t_in, t_out]; f_lo, f_hi the polynomial's values there in the method's scaling. */
typedef struct {
  int status;
  int budget;  /* 1 when some interval hit the halving limit before reaching the tolerance */
  int cluster; /* 1 when the bracket is an interval that still held several roots (settle_cluster) */
  uint steps;  /* intervals examined */
  uint doubt;  /* adaptive builds: the ALGRAY_DOUBT_* that ended the search undecided (status NONE), else 0 */
  REAL noise;  /* adaptive builds: the search's noise where it found a root to refine (isolation_found) */
  REAL lo, hi;
  REAL f_lo, f_hi;
} Isolation;

/* The isolations of LANES rays side by side (the Bernstein search): each field Isolation's, lane j ray j's, in
 * vectors, so that the refinement and the records take them without a trip through memory; with LANES = 1, one
 * ray's. */
typedef struct {
  LREAL status, steps, lo, hi, f_lo, f_hi;
  LMASK budget, cluster;
  LREAL doubt, noise; /* adaptive builds; 0 elsewhere */
} LaneIsolation;

/* Lane j of lanes as one Isolation, and back. */
static Isolation lane_isolation(const LaneIsolation* lanes, uint j) {
  Isolation iso;
  iso.status = (int)lane_get(lanes->status, j);
  iso.budget = lane_get_mask(lanes->budget, j) != 0;
  iso.cluster = lane_get_mask(lanes->cluster, j) != 0;
  iso.steps = (uint)lane_get(lanes->steps, j);
  iso.doubt = (uint)lane_get(lanes->doubt, j);
  iso.noise = lane_get(lanes->noise, j);
  iso.lo = lane_get(lanes->lo, j);
  iso.hi = lane_get(lanes->hi, j);
  iso.f_lo = lane_get(lanes->f_lo, j);
  iso.f_hi = lane_get(lanes->f_hi, j);
  return iso;
}
static void set_lane_isolation(LaneIsolation* lanes, uint j, Isolation iso) {
  lane_set(&lanes->status, j, (REAL)iso.status);
  lane_set_mask(&lanes->budget, j, iso.budget);
  lane_set_mask(&lanes->cluster, j, iso.cluster);
  lane_set(&lanes->steps, j, (REAL)iso.steps);
  lane_set(&lanes->doubt, j, (REAL)iso.doubt);
  lane_set(&lanes->noise, j, iso.noise);
  lane_set(&lanes->lo, j, iso.lo);
  lane_set(&lanes->hi, j, iso.hi);
  lane_set(&lanes->f_lo, j, iso.f_lo);
  lane_set(&lanes->f_hi, j, iso.f_hi);
}

static Isolation isolation_none(void) {
  Isolation iso;
  iso.status = ISOLATION_NONE;
  iso.budget = 0;
  iso.cluster = 0;
  iso.steps = 0;
  iso.doubt = 0;
  iso.noise = 0;
  iso.lo = 0;
  iso.hi = 1;
  iso.f_lo = 0;
  iso.f_hi = 0;
  return iso;
}

/* Shadow kernels define ALGRAY_SHADOW_RAYS (build_switches.h). Their rays start off the surface on purpose (the
 * shadow offset), so P's value at their start, however small, is no sign of a root: the coefficient c_0 of an
 * interval starting there (lo == 0) does not count. And they ask only whether there is a root, not where. */
ALGRAY_INLINE int first_counted(REAL lo) { return ALGRAY_SHADOW_RAYS && lo == 0; }

/* The largest and the smallest |c_k|, by a tree of compares: fmin and fmax chains compiled to a dependent chain
 * with NaN fix-ups on each step (measured in PoCL's kernels: smallest_magnitude was 3% of the Barth decic's
 * adaptive render, its shadow pass 1023 -> 972 ms with the trees and local_scale unrolled). The same values as
 * the chains for finite coefficients. */
#define MAGNITUDE_TREE(t, pick)                                                        \
  do {                                                                                 \
    ALGRAY_UNROLL                                                                      \
    for (int s_ = 1; s_ <= DEGREE; s_ *= 2) ALGRAY_UNROLL                              \
    for (int k_ = 0; k_ + s_ <= DEGREE; k_ += 2 * s_) t[k_] = pick(t[k_], t[k_ + s_]); \
  } while (0)
#define PICK_LARGER(a, b) ((b) > (a) ? (b) : (a))
#define PICK_SMALLER(a, b) ((b) < (a) ? (b) : (a))
#define LANE_LARGER(a, b) LANE_SEL((a), (b), (b) > (a))
#define LANE_SMALLER(a, b) LANE_SEL((a), (b), (b) < (a))
ALGRAY_INLINE REAL largest_magnitude(const REAL* c) {
  REAL t[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) t[k] = fabs(c[k]);
  MAGNITUDE_TREE(t, PICK_LARGER);
  return t[0];
}

/* Adaptive precision (ALGRAY_ESCALATE): the float search stops where a decision rests on values within the
 * rounding noise of the coefficients it started from, and the host redoes the ray in float-float or double. The
 * noise is REAL_EPS * max(ALGRAY_DOUBT_FACTOR * DEGREE * max |b_k|, ALGRAY_TERMS_FACTOR * terms), b the segment's
 * coefficients and terms the size of the terms they were summed from (RayTerms in restrict.h): de Casteljau's
 * convex combinations add no more than that, so it bounds every subinterval's coefficients too. The factors were
 * measured on the scenes and tests/data/hard_surfaces at 160x120 against solver_ref
 * (bench/history/2026-12.md, "Adaptive precision"): at 1 and 1 the worst depth error was 7e-6 and the Barth decic doubted 17% of its camera rays; at
 * 0.5 and 0.25, 4e-5 and 10%; without the terms (max |b_k| alone) a Kummer shell ray's root was 1e-3 off. */
/* The noise for coefficients of largest size `scale` summed from terms of size `terms`: for REALs and lanes alike. */
#define DOUBT_NOISE(scale, terms) \
  (REAL_EPS * fmax((REAL)(ALGRAY_DOUBT_FACTOR * DEGREE) * (scale), (REAL)ALGRAY_TERMS_FACTOR * (terms)))

/* The noise of one ray's search (the Bernstein search's at LANES = 1): DOUBT_NOISE of its coefficients' size
 * and its ray's terms, on the terms' upper bound until a value falls within it (RayTerms in restrict.h). */
typedef struct {
  REAL scale;       /* max |b_k| of the coefficients the search starts from */
  const REAL* root; /* those coefficients, for the noise local to an interval */
  REAL noise;
  REAL part_lo, part_hi, part_noise; /* the last local noise computed (within_noise_at), and its part */
  RayTerms* terms;
} SearchNoise;

ALGRAY_INLINE SearchNoise search_noise(const REAL* c, RayTerms* terms) {
  SearchNoise n;
  n.scale = largest_magnitude(c);
  n.terms = terms;
  n.root = c;
  n.part_lo = n.part_hi = -1;
  n.part_noise = 0;
  n.noise = DOUBT_NOISE(n.scale, terms->value);
  return n;
}

/* An upper bound on the noise of any coefficients summed from terms of size at most `terms`. */
static REAL noise_bound(REAL terms) { return DOUBT_NOISE(terms, terms); }

/* The noise with the ray's terms summed: what a value within the upper bound's noise, and the refined root's
 * check (refine_rays), compare against. */
static REAL exact_noise(SearchNoise* n) {
  if (!n->terms->exact) n->noise = DOUBT_NOISE(n->scale, ray_terms_exact(n->terms));
  return n->noise;
}

/* Whether |value| is within the noise (a NaN is not). */
static int within_noise(SearchNoise* n, REAL value) { return fabs(value) <= n->noise && fabs(value) <= exact_noise(n); }

/* The largest Bernstein coefficient on [lo, hi] of sum_k |c_k| B_k, with room for its own rounding: the size
 * that de Casteljau's roundings on [lo, hi] are relative to; lane by lane (one ray: local_noise below). */
static LREAL local_scale(const LREAL* c, LREAL lo, LREAL hi) {
  LREAL t[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) t[k] = fabs(c[k]);
  const LREAL x1 = (REAL)1 - hi;
  ALGRAY_UNROLL
  for (int r = 1; r <= DEGREE; ++r) ALGRAY_UNROLL
  for (int k = DEGREE; k >= 1; --k)
    if (k >= r) t[k] = x1 * t[k - 1] + hi * t[k];
  const LMASK inner = lo > 0;
  if (LANE_ANY(inner)) {
    const LREAL x = lo / hi, y1 = (REAL)1 - x;
    LREAL u[NCOEF];
    ALGRAY_UNROLL
    for (int k = 0; k <= DEGREE; ++k) u[k] = t[k];
    ALGRAY_UNROLL
    for (int r = 1; r <= DEGREE; ++r) ALGRAY_UNROLL
    for (int k = 0; k < DEGREE; ++k)
      if (k <= DEGREE - r) u[k] = y1 * u[k] + x * u[k + 1];
    ALGRAY_UNROLL
    for (int k = 0; k <= DEGREE; ++k) t[k] = LANE_SEL(t[k], u[k], inner);
  }
  MAGNITUDE_TREE(t, LANE_LARGER);
  return t[0] * (REAL)(1 + 1.0 / 1024);
}

/* The noise local to the part [lo, hi] of the segment: DOUBT_NOISE of local_scale and of the terms there
 * (ray_terms_local), ALGRAY_LOCAL_FACTOR times. c: the segment's coefficients, scale their largest magnitude.
 * Only shadow rays take it (camera rays run from sphere to sphere: the local noise settled few of their doubts).
 * The factor, measured on shadow rays against the certified reference (tests/test_shadows, the settled doubts of the
 * Barth decic and the Endrass octic in the extent and point forms, 9,000-15,000 certified rays): at 0 (no doubt
 * near the start) 337 of its checks failed, at 0.25 17, at 0.5 4, at 1, 4 and 16 none; 4 keeps 4 times the smallest
 * safe factor (it was 16, four times a camera-ray trial's 4, until 2026-12-08: the Barth decic's float shadow pass
 * then sent 292 k rays to its second pass instead of 425 k, 0.92x the time, 0.90x without fp64; bench/history). */
static REAL local_noise(const REAL* c, REAL scale, RayTerms* terms, REAL lo, REAL hi) {
  LREAL lanes[NCOEF]; /* the ray in every lane, lane 0 read (in one-ray builds, the only lane) */
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) lanes[k] = c[k];
  const REAL size = lane_get(local_scale(lanes, (LREAL)lo, (LREAL)hi), 0);
  return (REAL)ALGRAY_LOCAL_FACTOR * DOUBT_NOISE(fmin(scale, size), ray_terms_local(terms, lo, hi));
}

/* The noise local to a part of a point-form shadow segment that ends at t (t >= 0, measured from the rays' shared
 * origin o), lane by lane: local_noise's, from two polynomials in t with nonnegative coefficients, whose values at
 * the part's far end bound those of the whole part (shadow.h, point_part_polys). part_terms: the terms, sum_m |a_m|
 * (|o| + t |d|)^m per axis, ray_terms_local's value there. part_scale: sum_k |c_k| t^k, c the power basis of P*
 * about o, which bounds local_scale: each Bernstein coefficient of P* on [t_a, t_b], 0 <= t_a, is a sum of c_k times
 * the nonnegative ones of t^k. Two Horner schemes in place of local_scale's de Casteljau and a sum over the
 * monomials (ray_terms_local): the Barth decic's float shadow pass with each part's noise from the search's start,
 * 1024x768 full mode, 2,790 -> 2,520 ms. */
ALGRAY_INLINE LREAL point_part_noise(LREAL scale, const LREAL* part_terms, const LREAL* part_scale, LREAL t) {
  LREAL terms = part_terms[DEGREE], size = part_scale[DEGREE];
  ALGRAY_UNROLL
  for (int k = DEGREE - 1; k >= 0; --k) {
    terms = terms * t + part_terms[k];
    size = size * t + part_scale[k];
  }
  /* sums of positive products: 2 DEGREE roundings of at most REAL_EPS / 2 each, far within the room */
  const REAL room = (REAL)(1 + 1.0 / 1024);
  return (REAL)ALGRAY_LOCAL_FACTOR * DOUBT_NOISE(fmin(scale, size * room), terms * room);
}

/* Whether |value|, on the part [lo, hi] of the segment, is within the noise: the segment's, and in shadow kernels
 * that settle doubts then the part's own (local_noise); a point form's shadow ray searched again (its terms carry
 * part_terms) takes the part's own from point_part_noise whatever the build settles. A shadow ray's terms and
 * coefficients grow by orders of magnitude from its start on the surface out to the extent's sphere, so the segment's
 * noise overstates the noise near its start, where most doubts arose. Measured on the Barth decic (1024x768, one ray
 * per pixel): shadow rays doubted 177 862 -> 23 609, with the same image, and adaptive over float 1.45x -> 1.32x where
 * the second pass is float-float; where it is double, 1.24x either way. Camera rays run from sphere to sphere: with the
 * local noise their doubts fell by 8% only (30 452 -> 28 131), which the checks cost back. */
static int within_noise_at(SearchNoise* n, REAL value, REAL lo, REAL hi) {
#if LANES == 1 /* builds in lanes search their point-form rays together (methods/bernstein.h, within_lanes_noise) */
  const RayTerms* t = n->terms;
  if (ALGRAY_SHADOW_RAYS && t->part_terms) {
    if (!within_noise(n, value)) return 0;
    if (lo != n->part_lo || hi != n->part_hi) {
      n->part_lo = lo;
      n->part_hi = hi;
      n->part_noise = point_part_noise(n->scale, t->part_terms, t->part_scale, t->t_in + hi * (t->t_out - t->t_in));
    }
    return fabs(value) <= n->part_noise;
  }
#endif
  const int local_too = ALGRAY_SHADOW_RAYS && ALGRAY_SETTLE_DOUBTS && RAY_ORIGIN != ALGRAY_ORIGIN_POINT;
  /* The cheap tests first, each of them enough to clear the value: the segment's noise on the terms' upper
   * bound, then an upper bound on the local noise that costs a few operations (terms_within at the part's
   * largest coordinate, which also bounds local_scale: every |b_k| is at most the terms); the sums after. */
  if (!(fabs(value) <= n->noise)) return 0;
  if (local_too) {
    const REAL terms_above = ray_terms_within_part(n->terms, lo, hi);
    if (fabs(value) > (REAL)ALGRAY_LOCAL_FACTOR * DOUBT_NOISE(fmin(n->scale, terms_above), terms_above)) return 0;
  }
  if (!within_noise(n, value)) return 0;
  if (!local_too) return 1;
  if (lo != n->part_lo || hi != n->part_hi) {
    n->part_lo = lo;
    n->part_hi = hi;
    n->part_noise = local_noise(n->root, n->scale, n->terms, lo, hi);
  }
  return fabs(value) <= n->part_noise;
}

/* Every isolation takes the ray's terms (RayTerms in restrict.h), which adaptive builds measure their noise by and
 * others never read: callers outside adaptive builds may pass a RayTerms they never filled. */

/* Whether an interval `width` (a fraction of [t_in, t_out], starting at fraction lo) is down to the stopping
 * width: then it is located, however many roots Descartes' rule still allows in it. */
static int interval_located(REAL width, REAL lo, REAL t_in, REAL len) {
  return width * len <= stop_width(t_in + lo * len);
}

/* An interval still holding several roots, or a complex pair, once it is located or at the halving limit: a
 * sign change between its ends is a root; without one it counts as no root. So a root of even multiplicity is
 * invisible, as on the true surface (an isolated point, a tangent ray), and a rounded double root that became
 * a complex pair is never reported. Returns 1 when it settled iso->status. */
static int settle_cluster(Isolation* iso, int located) {
  if (!located) iso->budget = 1;
  if ((iso->f_lo < 0) != (iso->f_hi < 0)) {
    iso->status = ISOLATION_BRACKET;
    iso->cluster = 1;
    return 1;
  }
  return 0;
}

/* Every interval before this one was root-free or without a sign change, so P should still have the sign it had
 * at t_in. If this interval starts with the other sign, P changed sign where two subdivisions meet, within
 * their rounding noise: that point is the root. Returns 1 when it settled iso->status. */
static int crossed_at_left_end(Isolation* iso, int start_sign) {
  const int s = (iso->f_lo > 0) - (iso->f_lo < 0);
  if (s == 0 || s == start_sign) return 0;
  iso->status = ISOLATION_EXACT;
  return 1;
}

/* The checks every subdividing method makes first on an interval (iso.lo, iso.f_lo set): P exactly zero at its
 * left end, or of the other sign there than at t_in. Returns 1 when it settled iso->status. */
static int settled_at_left_end(Isolation* iso, int start_sign, int level, ProbeLog* probe_log) {
  if (iso->f_lo == 0) {
    PROBE_STEP(*iso, -1, ALGRAY_STEP_EXACT_ZERO, level);
    iso->status = ISOLATION_EXACT;
    return 1;
  }
  if (crossed_at_left_end(iso, start_sign)) {
    PROBE_STEP(*iso, -1, ALGRAY_STEP_CROSSED, level);
    return 1;
  }
  return 0;
}

/* What to do with an interval that may hold several roots (`count` of them, as the method counts). */
#define INTERVAL_HALVE 0   /* halve it: go one level down, left half first */
#define INTERVAL_SETTLED 1 /* a cluster with a sign change: iso->status is set */
#define INTERVAL_NEXT 2    /* a cluster without one: go on to the next interval */
static int halve_or_settle(Isolation* iso, int count, int level, REAL width, REAL t_in, REAL len, ProbeLog* probe_log) {
  const int located = interval_located(width, iso->lo, t_in, len);
  if (!located && level < REAL_MAX_HALVINGS) {
    PROBE_STEP(*iso, count, ALGRAY_STEP_SPLIT, level);
    return INTERVAL_HALVE;
  }
  if (settle_cluster(iso, located)) {
    PROBE_STEP(*iso, count, ALGRAY_STEP_CLUSTER_ROOT, level);
    return INTERVAL_SETTLED;
  }
  PROBE_STEP(*iso, count, ALGRAY_STEP_CLUSTER_SKIP, level);
  return INTERVAL_NEXT;
}

/* Every interval has been searched. They are half open, so the far end is the one point left: a root when
 * `zero` (P there is f_end). */
static Isolation isolation_at_far_end(Isolation iso, int zero, REAL f_end, ProbeLog* probe_log) {
  iso.status = zero ? ISOLATION_EXACT : ISOLATION_NONE;
  PROBE(ALGRAY_EVENT_STEP, -1, zero ? ALGRAY_STEP_END_ZERO : ALGRAY_STEP_END_NONE, 0u, (REAL)1, (REAL)1, f_end, f_end);
  iso.lo = iso.hi = 1;
  iso.f_lo = iso.f_hi = 0;
  return iso;
}

/* The next dyadic interval (level, idx) in depth-first, left-first order: climb while a right child, then
 * step right. Returns 0 when the whole interval has been searched. */
static int next_interval(int* level, ulong* idx) {
  while (*idx & 1) {
    *idx >>= 1;
    --*level;
  }
  if (*level == 0) return 0;
  ++*idx;
  return 1;
}

/* Sign changes between consecutive nonzero coefficients: a zero keeps the previous sign, and a NaN counts as a
 * zero. Where every coefficient has a strict sign (nearly always), the count is the number of places where the
 * pattern of negative signs changes: one pass of compares into bit masks, then a popcount. The chain of signs,
 * each step waiting on the last, ran the Barth decic's shadow search a tenth of its time. */
#if DEGREE < 32
typedef uint SignBits;
#else
typedef ulong SignBits;
#endif
ALGRAY_INLINE int sign_variations(const REAL* c) {
  SignBits negative = 0, signless = 0;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) {
    negative |= (SignBits)(c[k] < 0) << k;
    signless |= (SignBits) !(c[k] > 0 || c[k] < 0) << k;
  }
  if (signless == 0) return popcount((negative ^ (negative >> 1)) & (((SignBits)1 << DEGREE) - 1));
  /* Branch-free: a change is a product of signs below zero (the first nonzero sign never counts, as prev starts
   * at 0). */
  int v = 0;
  int prev = 0; /* sign of the last nonzero coefficient, 0 before the first */
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) {
    const int s = (c[k] > 0) - (c[k] < 0);
    v += s * prev < 0;
    prev = s != 0 ? s : prev;
  }
  return v;
}

#endif /* ALGRAY_ISOLATION_H */
