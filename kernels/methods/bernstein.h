/* Root isolation by Descartes' rule on Bernstein coefficients over [t_in, t_out], with de Casteljau halving. */
#ifndef ALGRAY_BERNSTEIN_H
#define ALGRAY_BERNSTEIN_H

#include "float_float.h"
#include "isolation.h"
#include "lanes.h"
#include "point_values.h"

/* Mixed precision isolates in float-float: every Bernstein coefficient is an unevaluated sum hi + lo, and the
 * *_lo arrays below hold the low parts (other builds never touch them). Rounding the coefficients to float
 * before isolating was not enough: on the Endrass octic, rays that pass a node come within 1e-9 of the
 * coefficients' size of zero, so float noise faked sign changes there and hid thin pairs of roots (measured:
 * one hit on the wrong sheet, depth error 0.17). Sign variations read the hi parts, which carry the sign.
 *
 * Everything from here to the search is written over LREAL (lanes.h): one ray where LANES = 1, LANES rays side by
 * side otherwise, each lane with one ray's operations, so that a lane's result is the one-ray build's bit for bit
 * (tests/test_lanes compares the widths). */
/* hi + lo = x1 a + x b, for float-float a, b and weights x1, x given as float-float too (lo 0 when exact). */
ALGRAY_INLINE void ff_combine(LREAL a, LREAL a_lo, LREAL x1, LREAL x1_lo, LREAL b, LREAL b_lo, LREAL x, LREAL x_lo,
                              LREAL* hi, LREAL* lo) {
  const LREAL p = x1 * a, q = x * b;
  const LREAL s = p + q, bb = s - p;
  /* The rounding errors and the low parts' products summed apart from the two-sum's chain, then added to it
   * once: each row of de Casteljau's triangle waits on the one before, so the chain's latency sets the pace.
   * Summed left to right in one chain, the Endrass octic's mixed render (512x384, with shadows) took 10% longer;
   * the images came out bit-identical. */
  const LREAL lows = (fma(x1, a, -p) + fma(x, b, -q)) + ((x1 * a_lo + x * b_lo) + (x1_lo * a + x_lo * b));
  const LREAL e = ((p - (s - bb)) + (q - bb)) + lows;
  *hi = s + e;
  *lo = e - (*hi - s);
}

/* x1 a + x b: de Casteljau's recurrence in plain arithmetic. */
#define CASTELJAU_COMBINE(x1, a, x, b) ((x1) * (a) + (x) * (b))

/* c[k] = x1 c[a] + x c[b]: one step of de Casteljau's recurrence, in the build's arithmetic. */
ALGRAY_INLINE void casteljau_step(LREAL* c, LREAL* c_lo, int k, int a, int b, LREAL x1, LREAL x1_lo, LREAL x,
                                  LREAL x_lo) {
  if (ALGRAY_COMPENSATED)
    ff_combine(c[a], c_lo[a], x1, x1_lo, c[b], c_lo[b], x, x_lo, &c[k], &c_lo[k]);
  else
    c[k] = CASTELJAU_COMBINE(x1, c[a], x, c[b]);
}

/* dst = src, and dst_lo = src_lo in mixed precision. */
ALGRAY_INLINE void coefs_copy(LREAL* dst, LREAL* dst_lo, const LREAL* src, const LREAL* src_lo) {
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) {
    dst[k] = src[k];
    if (ALGRAY_COMPENSATED) dst_lo[k] = src_lo[k];
  }
}

/* dst = src in the lanes of `take`. */
ALGRAY_INLINE void coefs_select(LREAL* dst, LREAL* dst_lo, const LREAL* src, const LREAL* src_lo, LMASK take) {
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) {
    dst[k] = LANE_SEL(dst[k], src[k], take);
    if (ALGRAY_COMPENSATED) dst_lo[k] = LANE_SEL(dst_lo[k], src_lo[k], take);
  }
}

/* The triangles below run every inner loop to a constant bound and test the row's end inside: a bound that
 * depends on the outer index kept LLVM from unrolling fully, and the rows then went through memory (measured in
 * PoCL's compiled kernels). The operations and their order are the same. */

/* Keeps the part of the curve on [0, x], x dyadic (so 1 - x is exact). In place: after pass r, c[r] is the
 * r-th left coefficient. */
ALGRAY_INLINE void casteljau_keep_left(LREAL* c, LREAL* c_lo, LREAL x) {
  const LREAL x1 = (REAL)1 - x;
  ALGRAY_UNROLL
  for (int r = 1; r <= DEGREE; ++r) ALGRAY_UNROLL
  for (int k = DEGREE; k >= 1; --k)
    if (k >= r) casteljau_step(c, c_lo, k, k - 1, k, x1, 0, x, 0);
}

/* Keeps the part on [x + x_lo, 1], for x >= 1/2 (so 1 - x is exact). */
ALGRAY_INLINE void casteljau_keep_right(LREAL* c, LREAL* c_lo, LREAL x, LREAL x_lo) {
  const LREAL x1 = (REAL)1 - x;
  ALGRAY_UNROLL
  for (int r = 1; r <= DEGREE; ++r) ALGRAY_UNROLL
  for (int k = 0; k < DEGREE; ++k)
    if (k <= DEGREE - r) casteljau_step(c, c_lo, k, k, k + 1, x1, -x_lo, x, x_lo);
}

/* Halves c at 1/2 in one de Casteljau triangle: c becomes the left half, right the right half; row by row, over
 * lanes or one ray. */
ALGRAY_INLINE void casteljau_halve_rows(LREAL* c, LREAL* c_lo, LREAL* right, LREAL* right_lo) {
  LREAL t[NCOEF], t_lo[NCOEF];
  coefs_copy(t, t_lo, c, c_lo);
  right[DEGREE] = t[DEGREE];
  if (ALGRAY_COMPENSATED) right_lo[DEGREE] = t_lo[DEGREE];
  ALGRAY_UNROLL
  for (int r = 1; r <= DEGREE; ++r) {
    ALGRAY_UNROLL
    for (int k = 0; k < DEGREE; ++k)
      if (k <= DEGREE - r) casteljau_step(t, t_lo, k, k, k + 1, (REAL)0.5, 0, (REAL)0.5, 0);
    c[r] = t[0];
    right[DEGREE - r] = t[DEGREE - r];
    if (ALGRAY_COMPENSATED) {
      c_lo[r] = t_lo[0];
      right_lo[DEGREE - r] = t_lo[DEGREE - r];
    }
  }
}

/* casteljau_halve_rows for the search. One ray's search takes each row of the triangle as one vector operation on a
 * register, instead of a row of scalars through memory (measured: the halving was a fifth of the Barth decic's
 * shadow kernel). The same products and sums as the rows: 0.5 t_k + 0.5 t_(k+1) per lane. Lanes past the row's end
 * are never read. */
#if LANES == 1 && DEGREE <= 15 && !ALGRAY_COMPENSATED
ALGRAY_INLINE void casteljau_halve(LREAL* c, LREAL* c_lo, LREAL* right, LREAL* right_lo) {
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
#define casteljau_halve casteljau_halve_rows
#endif

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

/* The coefficients on [lo, lo + width] (dyadic fractions of the segment), recomputed from the whole segment's
 * (root, root_lo), into out and out_lo for the lanes in `take`. */
ALGRAY_INLINE void bernstein_restrict(const LREAL* root, const LREAL* root_lo, LREAL lo, LREAL width, LMASK take,
                                      LREAL* out, LREAL* out_lo) {
  LREAL o[NCOEF], o_lo[NCOEF];
  coefs_copy(o, o_lo, root, root_lo);
  const LREAL hi = lo + width;
  const LMASK left = take && hi < (REAL)1;
  if (LANE_ANY(left)) {
    LREAL t[NCOEF], t_lo[NCOEF];
    coefs_copy(t, t_lo, o, o_lo);
    casteljau_keep_left(t, t_lo, hi);
    coefs_select(o, o_lo, t, t_lo, left);
  }
  const LMASK right = take && lo > (REAL)0;
  if (LANE_ANY(right)) {
    /* lo / hi = idx / (idx + 1) >= 1/2, and its rounding error recovered exactly by fma */
    const LREAL x = lo / hi;
    LREAL t[NCOEF], t_lo[NCOEF];
    coefs_copy(t, t_lo, o, o_lo);
    casteljau_keep_right(t, t_lo, x, fma(-x, hi, lo) / hi);
    coefs_select(o, o_lo, t, t_lo, right);
  }
  coefs_select(out, out_lo, o, o_lo, take);
}

/* Whether float refinement can find the root bracketed by c's end values. Always in plain builds. In mixed
 * precision the rounded coefficients are only good to eps of their largest, so an end value below that noise
 * could stop the refinement at the wrong end (measured: an Endrass octic hit 0.19 from its root); the
 * interval is halved further instead, in float-float, until its ends stand clear of the noise. */
ALGRAY_INLINE LMASK refinable_in_float(const LREAL* c) {
  LREAL scale = 0;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) scale = fmax(scale, fabs(c[k]));
  return !ALGRAY_COMPENSATED || fmin(fabs(c[0]), fabs(c[DEGREE])) > (REAL)(4 * DEGREE) * REAL_EPS * scale;
}

/* sign_variations (isolation.h) of each lane's coefficients. One ray counts by bit masks; lanes carry the last
 * sign seen by selections alone and sum the changes as a tree (added one after another, each waiting on the last,
 * they were the longest chain of the search's step). The same counts: a NaN counts as a zero. */
ALGRAY_INLINE LREAL bernstein_sign_variations(const LREAL* c) {
  if (LANES == 1) return (REAL)sign_variations((const REAL*)c);
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

/* The search's next interval after the one ending at next_at: next_interval (isolation.h) without its loop. It
 * climbs while the interval is a right child, then steps right, so the next interval is as wide as the largest
 * power of two that divides next_at (its lowest set bit in units of the finest intervals). */
ALGRAY_INLINE LREAL next_interval_width(LREAL next_at) {
#if LANES == 1
  const long units = (long)(next_at * (REAL)FINEST_UNITS);
  return (REAL)(units & -units) * ((REAL)1 / (REAL)FINEST_UNITS);
#else
  const LANE_INT_VEC units = LANE_TO_INT(next_at * (REAL)FINEST_UNITS);
  return LANE_TO_REAL(units & -units) * ((REAL)1 / (REAL)FINEST_UNITS);
#endif
}

/* isolation.h's PICK_LARGER and PICK_SMALLER, lane by lane */

/* The smallest |c_k| that counts (first_counted, isolation.h: an interval whose coefficients all stand clear of the
 * noise keeps its sign variations), or the smallest inner one (ends = 0); and the smaller |P| at the interval's
 * ends that counts (c_0 and c_n are P's values there). Lane by lane; lo: the interval's left end. */
ALGRAY_INLINE LREAL lanes_smallest_magnitude(const LREAL* c, LREAL lo, int ends) {
  LREAL t[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) t[k] = fabs(c[k]);
  t[0] = LANE_SEL(t[0], (LREAL)INFINITY, !ends || (ALGRAY_SHADOW_RAYS && lo == 0));
  if (!ends) t[DEGREE] = INFINITY;
  MAGNITUDE_TREE(t, LANE_SMALLER);
  return t[0];
}
ALGRAY_INLINE LREAL lanes_smaller_end(const LREAL* c, LREAL lo) {
  return LANE_SEL(fmin(fabs(c[0]), fabs(c[DEGREE])), fabs(c[DEGREE]), ALGRAY_SHADOW_RAYS && lo == 0);
}

/* What the search of an adaptive build needs of its rays: their terms, which it measures its noise by, and the
 * rays in unit coordinates with the monomials, where it evaluates P (point_values.h, float_float.h). One ray takes
 * RayTerms (restrict.h) and sums its terms only when a value falls within their upper bound's noise; lanes take
 * every lane's terms summed. Other builds never read it. */
#if LANES == 1
typedef RayTerms LaneTerms;
ALGRAY_INLINE LaneRays terms_rays(const LaneTerms* t) { return one_lane_rays(t->o, t->d); }
ALGRAY_INLINE LMASK terms_have_rays(const LaneTerms* t) { return t->has_ray; }
/* isolate_bernstein's ray as the search takes its terms: as they are */
ALGRAY_INLINE LaneTerms* one_ray_terms(RayTerms* terms, LaneTerms* lanes, LaneRays* rays) {
  (void)lanes;
  (void)rays;
  return terms;
}
#else
typedef struct {
  LREAL value;
  const LaneRays* rays;
  __global const uint* exps;
  __global const REAL* coefs;
  uint count;
  /* The point form's shadow rays searched again (shadow.h, point_part_polys): each lane's noise local to a part of
   * its segment [seg_in, seg_out], as one ray's (isolation.h, within_noise_at), from its two polynomials; 0
   * elsewhere. */
  int by_part;
  const LREAL* part_terms;
  const LREAL* part_scale;
  LREAL seg_in, seg_out;
} LaneTerms;
ALGRAY_INLINE LaneRays terms_rays(const LaneTerms* t) { return *t->rays; }
ALGRAY_INLINE LMASK terms_have_rays(const LaneTerms* t) {
  (void)t;
  return (LMASK)(-1); /* every lane */
}
/* Lanes builds search their rays together (surface.h); isolate_bernstein's one ray, in lane 0, measures its noise as
 * lanes do. Only adaptive builds read the terms. */
ALGRAY_INLINE LaneTerms* one_ray_terms(RayTerms* terms, LaneTerms* lanes, LaneRays* rays) {
  if (!ALGRAY_ESCALATE) return (LaneTerms*)0;
  *rays = one_lane_rays(terms->o, terms->d);
  lanes->value = ray_terms_exact(terms);
  lanes->by_part = 0;
  lanes->rays = rays;
  lanes->exps = terms->exps;
  lanes->coefs = terms->coefs;
  lanes->count = terms->count;
  return lanes;
}
#endif

/* The search's noise (isolation.h, DOUBT_NOISE), and P's signs proven in float-float at interval ends
 * (discards_settled): lanes_noise starts it, within_lanes_noise asks whether a value on the part [lo, hi] of the
 * segment is within it, and found_noise gives the noise a found root's refinement checks against (isolation_found),
 * where `found`. terms_rays and terms_have_rays: the rays of the terms, and whether there are any (one ray's terms
 * may come without). Builds without adaptive precision doubt nothing: no value is within their noise. */
#if ALGRAY_ESCALATE && LANES == 1
/* One ray: its SearchNoise, on the terms' upper bound until a value falls within it, and for shadow rays local to
 * each interval (within_noise_at). */
typedef struct {
  SearchNoise one;
  LREAL noise;
  ProvenEnds proven;
} LaneNoise;

static LaneNoise lanes_noise(const LREAL* root, LaneTerms* terms) {
  LaneNoise n;
  no_proven_ends(&n.proven);
  n.one = search_noise(root, terms);
  n.noise = n.one.noise;
  return n;
}
ALGRAY_INLINE LMASK within_lanes_noise(LaneNoise* n, LREAL value, LREAL lo, LREAL hi) {
  const int within = within_noise_at(&n->one, value, lo, hi);
  n->noise = n->one.noise;
  return within;
}
ALGRAY_INLINE LREAL found_noise(LaneNoise* n, LMASK found) { return found ? exact_noise(&n->one) : (REAL)0; }
#elif ALGRAY_ESCALATE
/* Lanes: every lane's noise on its terms summed; for the point form's shadow rays also local to each part of the
 * segment (LaneTerms' by_part), with the operations of one ray's within_noise_at, so that a lane decides as the
 * one-ray build does. */
typedef struct {
  LREAL noise;
  LREAL scale; /* max |b_k| of the coefficients the search starts from */
  const LaneTerms* terms;
  LREAL part_lo, part_hi, part_noise; /* the last local noise computed, and its part */
  ProvenEnds proven;
} LaneNoise;

static LaneNoise lanes_noise(const LREAL* root, LaneTerms* terms) {
  LaneNoise n;
  no_proven_ends(&n.proven);
  LREAL magnitude[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) magnitude[k] = fabs(root[k]);
  MAGNITUDE_TREE(magnitude, LANE_LARGER);
  n.scale = magnitude[0];
  n.terms = terms;
  n.part_lo = n.part_hi = -1;
  n.part_noise = 0;
  n.noise = DOUBT_NOISE(magnitude[0], terms->value);
  return n;
}
ALGRAY_INLINE LMASK within_lanes_noise(LaneNoise* n, LREAL value, LREAL lo, LREAL hi) {
  LMASK within = fabs(value) <= n->noise;
  const LaneTerms* t = n->terms;
  if (!t->by_part || !LANE_ANY(within)) return within;
  /* the part's own noise, computed once per part as one ray's (a search step asks about one part several times) */
  if (LANE_ANY(lo != n->part_lo || hi != n->part_hi)) {
    n->part_lo = lo;
    n->part_hi = hi;
    n->part_noise = point_part_noise(n->scale, t->part_terms, t->part_scale, t->seg_in + hi * (t->seg_out - t->seg_in));
  }
  return within && fabs(value) <= n->part_noise;
}
ALGRAY_INLINE LREAL found_noise(LaneNoise* n, LMASK found) { return LANE_SEL((LREAL)0, n->noise, found); }
#else
typedef struct {
  LREAL noise;
  ProvenEnds proven; /* never filled: discards_settled, which reads it, returns first in these builds */
} LaneNoise;
ALGRAY_INLINE LaneNoise lanes_noise(const LREAL* root, LaneTerms* terms) {
  (void)root;
  (void)terms;
  LaneNoise n;
  n.noise = 0;
  return n;
}
ALGRAY_INLINE LMASK within_lanes_noise(LaneNoise* n, LREAL value, LREAL lo, LREAL hi) {
  (void)lo;
  (void)hi;
  (void)n;
  (void)value;
  return (LMASK)0; /* no lane */
}
ALGRAY_INLINE LREAL found_noise(LaneNoise* n, LMASK found) {
  (void)found;
  return n->noise;
}
#endif

/* The search's state for each lane: the interval [at, at + width] and its coefficients cur (cur_lo), the cached
 * right half of the latest split [sib_at, sib_at + sib_width] (none: width 0), and the Isolation's fields so far.
 * A lane that stops (done) keeps its interval and coefficients, which are what it reports, unless it ended past
 * the far end (searched_all). */
typedef struct {
  LREAL cur[NCOEF], cur_lo[NCOEF], sib[NCOEF], sib_lo[NCOEF];
  LREAL at, width, sib_at, sib_width;
  LREAL status, steps, doubt, start_sign;
  LMASK budget, cluster, searched_all, done, brackets_doubted;
} BernsteinSearch;

/* The halving level of the search's interval (the probe's events name it). */
#define SEARCH_LEVEL(s) ((uint)(-ilogb((s)->width)))
/* A probe event of the search's interval: a step that saw `count` sign variations, or a doubt for `value` within
 * the noise. Only one-ray builds record. */
#define PROBE_SEARCH_STEP(s, count, decision) \
  PROBE(ALGRAY_EVENT_STEP, count, decision, SEARCH_LEVEL(s), (s)->at, (s)->at + (s)->width, (s)->cur[0], (s)->cur[DEGREE])
#define PROBE_SEARCH_DOUBT(s, reason, value, noise)                                                           \
  PROBE(ALGRAY_EVENT_DOUBT, 0, reason, SEARCH_LEVEL(s), (s)->at, (s)->at + (s)->width, value, (noise)->noise)
#if ALGRAY_PROBE && LANES != 1
#error "the probe records one ray: LANES=1"
#endif

/* Ends the search undecided for `reason` in the lanes of `doubted`. */
ALGRAY_INLINE void mark_doubted(BernsteinSearch* s, LMASK doubted, uint reason) {
  s->doubt = LANE_SEL(s->doubt, (LREAL)reason, doubted);
  s->status = LANE_SEL(s->status, (LREAL)ISOLATION_NONE, doubted);
  s->done = s->done || doubted;
}

/* settled_at_left_end (isolation.h): P exactly zero at the interval's left end, or of the other sign there than at
 * t_in, is a root there; in doubt where P there is within the noise. */
ALGRAY_INLINE void settle_at_left_end(BernsteinSearch* s, LaneNoise* noise, ProbeLog* probe_log) {
  const LREAL f_lo = s->cur[0];
  const LREAL sign = LANE_SEL((LREAL)0, (LREAL)1, f_lo > 0) - LANE_SEL((LREAL)0, (LREAL)1, f_lo < 0);
  const LMASK exact = !s->done && (f_lo == 0 || (sign != 0 && sign != s->start_sign));
  if (!LANE_ANY(exact)) return;
  PROBE_SEARCH_STEP(s, -1, f_lo == 0 ? ALGRAY_STEP_EXACT_ZERO : ALGRAY_STEP_CROSSED);
  s->status = LANE_SEL(s->status, (LREAL)ISOLATION_EXACT, exact);
  s->done = s->done || exact;
  const LMASK doubted = exact && within_lanes_noise(noise, f_lo, s->at, s->at + s->width);
  if (LANE_ANY(doubted)) PROBE_SEARCH_DOUBT(s, ALGRAY_DOUBT_ACCEPT, f_lo, noise);
  mark_doubted(s, doubted, ALGRAY_DOUBT_ACCEPT);
}

/* One sign variation (and P not zero at the right end): the isolating interval. In doubt where an end value is
 * within the noise, unless P's values there in float-float settle it after the search (brackets_settled). */
ALGRAY_INLINE void settle_isolated(BernsteinSearch* s, LREAL v, LaneNoise* noise, ProbeLog* probe_log) {
  const LMASK isolated = !s->done && v == 1 && s->cur[DEGREE] != 0 && refinable_in_float(s->cur);
  if (!LANE_ANY(isolated)) return;
  PROBE_SEARCH_STEP(s, (int)v, ALGRAY_STEP_ISOLATED);
  s->status = LANE_SEL(s->status, (LREAL)ISOLATION_BRACKET, isolated);
  s->done = s->done || isolated;
  const LREAL end = lanes_smaller_end(s->cur, s->at);
  const LMASK doubted = isolated && within_lanes_noise(noise, end, s->at, s->at + s->width);
  if (LANE_ANY(doubted)) PROBE_SEARCH_DOUBT(s, ALGRAY_DOUBT_ACCEPT, end, noise);
  s->brackets_doubted = s->brackets_doubted || doubted;
  mark_doubted(s, doubted, ALGRAY_DOUBT_ACCEPT);
}

/* Camera and secondary rays of adaptive builds that settle doubts (ALGRAY_SETTLE_DOUBTS: where the second pass runs
 * in float-float; in double, tracing the ray again costs less than these checks) settle discard doubts by P's signs
 * in float-float. */
#define ALGRAY_SETTLES_DISCARDS (ALGRAY_ESCALATE && !ALGRAY_SHADOW_RAYS && ALGRAY_SETTLE_DOUBTS)

/* The end value of an interval at fraction `end` as the probe shows a settled discard doubt: P in float-float and
 * its rounding where that end was within the noise (in proven), else float's value c and the noise it stood clear
 * of. */
ALGRAY_INLINE void settled_end(const ProvenEnds* proven, LREAL end, LREAL c, LREAL noise, LREAL* value, LREAL* bound) {
  *value = c;
  *bound = noise;
  for (int e = 0; e < 2; ++e) {
    *value = LANE_SEL(*value, proven->value[e], proven->at[e] == end);
    *bound = LANE_SEL(*bound, proven->rounding[e], proven->at[e] == end);
  }
}

/* discards_settled: whether intervals without sign variations, in doubt for an end value within the noise, are
 * root-free after all (the lanes of end_doubted): every coefficient inside stands clear of the noise, and P in
 * float-float at each end within it (proven, evaluated where not there yet) has the sign float gave there, beyond
 * its rounding. Then every Bernstein coefficient has that one sign for certain. (Where one inside is within the
 * noise too, P itself is, and halving down to the stopping width measured no better than tracing the ray again.)
 * The probe sees what settled it (ALGRAY_EVENT_CONFIRMED, decision 3). */
ALGRAY_INLINE LMASK discards_settled(const BernsteinSearch* s, LMASK end_doubted, LaneNoise* noise, LaneTerms* terms, LREAL t_in,
                       LREAL t_out, ProbeLog* probe_log) {
  if (!ALGRAY_SETTLES_DISCARDS) return (LMASK)0;
  const LREAL at = s->at, hi = s->at + s->width;
  const LMASK inner_clear = end_doubted && terms_have_rays(terms) &&
                            !within_lanes_noise(noise, lanes_smallest_magnitude(s->cur, at, 0), at, hi);
  if (!LANE_ANY(inner_clear)) return inner_clear;
  const LMASK lo_doubted = within_lanes_noise(noise, s->cur[0], at, hi);
  const LMASK hi_doubted = within_lanes_noise(noise, s->cur[DEGREE], at, hi);
  /* one evaluation for the lanes that need either end, a second for those that need both */
  const LaneRays rays = terms_rays(terms);
  ProvenEnds* proven = &noise->proven;
  const LMASK lo_needed = inner_clear && lo_doubted && !proven_at(proven, at);
  const LMASK hi_needed = inner_clear && hi_doubted && !proven_at(proven, hi);
  if (LANE_ANY(lo_needed || hi_needed))
    prove_end(lo_needed || hi_needed, &rays, t_in, t_out, LANE_SEL(hi, at, lo_needed), LANE_SEL(at, hi, lo_needed),
              terms->exps, terms->coefs, terms->count, proven);
  if (LANE_ANY(lo_needed && hi_needed))
    prove_end(lo_needed && hi_needed, &rays, t_in, t_out, hi, at, terms->exps, terms->coefs, terms->count, proven);
  const LMASK settled = inner_clear && (!lo_doubted || proven_sign_of(proven, at, s->cur[0])) &&
                        (!hi_doubted || proven_sign_of(proven, hi, s->cur[DEGREE]));
  if (LANE_ANY(settled)) {
    LREAL v_lo, bound_lo, v_hi, bound_hi;
    settled_end(proven, at, s->cur[0], noise->noise, &v_lo, &bound_lo);
    settled_end(proven, hi, s->cur[DEGREE], noise->noise, &v_hi, &bound_hi);
    PROBE(ALGRAY_EVENT_CONFIRMED, 0, 3u, 0u, v_lo, bound_lo, v_hi, bound_hi);
  }
  return settled;
}

/* Adaptive builds: no sign variation, but a coefficient within the noise of zero: the interval is not yet shown
 * root-free. Its end coefficients are P's values: near zero there, float cannot tell, and the search ends in doubt
 * unless P's signs there are proven in float-float (discards_settled); an inner one is halved until it stands clear,
 * as de Casteljau's coefficients close in on P's values (fewer rays doubted: on the Barth decic's shadow rays, 10%
 * of them doubted without this). Returns the lanes to halve. */
ALGRAY_INLINE LMASK halve_near_zero(BernsteinSearch* s, LREAL v, LaneNoise* noise, LaneTerms* terms, LREAL t_in,
                                    LREAL t_out, ProbeLog* probe_log) {
  const LREAL at = s->at, hi = s->at + s->width;
  const LMASK near_zero = !s->done && v == 0 &&
                          within_lanes_noise(noise, lanes_smallest_magnitude(s->cur, at, 1), at, hi);
  if (!LANE_ANY(near_zero)) return near_zero;
  const LREAL end = lanes_smaller_end(s->cur, at);
  const LMASK end_doubted = near_zero && within_lanes_noise(noise, end, at, hi);
  if (!LANE_ANY(end_doubted)) return near_zero;
  PROBE_SEARCH_DOUBT(s, ALGRAY_DOUBT_DISCARD, end, noise);
  const LMASK settled = discards_settled(s, end_doubted, noise, terms, t_in, t_out, probe_log);
  mark_doubted(s, end_doubted && !settled, ALGRAY_DOUBT_DISCARD);
  return near_zero && !end_doubted; /* the settled ones are root-free */
}

/* halve_or_settle (isolation.h) for the lanes that may hold several roots: halved until located at the stopping
 * width or at the halving limit; then a sign change between the ends is a root (a cluster), and none is skipped.
 * A cluster is always in doubt: float cannot tell a close pair from a complex one there. Returns the lanes to
 * halve. */
ALGRAY_INLINE LMASK halve_or_settle_several(BernsteinSearch* s, LMASK several, LREAL v, LREAL t_in, LREAL len,
                                          LaneNoise* noise, ProbeLog* probe_log) {
  const LMASK located = several && s->width * len <= STOP_WIDTH(t_in + s->at * len);
  const LMASK halve = several && !located && s->width > (REAL)1 / (REAL)FINEST_UNITS; /* level < REAL_MAX_HALVINGS */
  const LMASK settle = several && !halve;
  s->budget = s->budget || (settle && !located);
  const LMASK cluster_root = settle && ((s->cur[0] < 0) != (s->cur[DEGREE] < 0));
  s->status = LANE_SEL(s->status, (LREAL)ISOLATION_BRACKET, cluster_root);
  s->cluster = s->cluster || cluster_root;
  s->done = s->done || cluster_root;
  if (LANE_ANY(several))
    PROBE_SEARCH_STEP(s, (int)v, halve ? ALGRAY_STEP_SPLIT : cluster_root ? ALGRAY_STEP_CLUSTER_ROOT
                                                                          : ALGRAY_STEP_CLUSTER_SKIP);
  const LMASK doubted = settle && within_lanes_noise(noise, (LREAL)0, s->at, s->at + s->width);
  if (LANE_ANY(doubted)) PROBE_SEARCH_DOUBT(s, ALGRAY_DOUBT_CLUSTER, (REAL)0, noise);
  mark_doubted(s, doubted, ALGRAY_DOUBT_CLUSTER);
  return halve;
}

/* The lanes of `halve` go one level down, left half first; the right half is kept for later. */
ALGRAY_INLINE void halve_intervals(BernsteinSearch* s, LMASK halve) {
  LREAL left[NCOEF], left_lo[NCOEF], right[NCOEF], right_lo[NCOEF];
  coefs_copy(left, left_lo, s->cur, s->cur_lo);
  casteljau_halve(left, left_lo, right, right_lo);
  coefs_select(s->cur, s->cur_lo, left, left_lo, halve);
  coefs_select(s->sib, s->sib_lo, right, right_lo, halve);
  s->width = LANE_SEL(s->width, s->width * (REAL)0.5, halve);
  s->sib_width = LANE_SEL(s->sib_width, s->width, halve);
  s->sib_at = LANE_SEL(s->sib_at, s->at + s->width, halve);
}

/* The lanes of `move` go on to the next interval: the cached right half where it is that one, else recomputed from
 * the segment's coefficients. Past the far end the whole segment is searched (isolation_at_far_end): its far end is
 * a root only where P is zero there. */
ALGRAY_INLINE void move_on(BernsteinSearch* s, LMASK move, const LREAL* root, const LREAL* root_lo,
                           ProbeLog* probe_log) {
  const LREAL next_at = s->at + s->width;
  s->width = LANE_SEL(s->width, next_interval_width(next_at), move);
  const LMASK finished = move && next_at == 1;
  if (LANE_ANY(finished))
    PROBE(ALGRAY_EVENT_STEP, -1, root[DEGREE] == 0 ? ALGRAY_STEP_END_ZERO : ALGRAY_STEP_END_NONE, 0u, (REAL)1,
          (REAL)1, root[DEGREE], root[DEGREE]);
  s->status = LANE_SEL(s->status, LANE_SEL((LREAL)ISOLATION_NONE, (LREAL)ISOLATION_EXACT, root[DEGREE] == 0), finished);
  s->searched_all = s->searched_all || finished;
  s->done = s->done || finished;
  move = move && !finished;
  s->at = LANE_SEL(s->at, next_at, move);
  const LMASK from_sib = move && s->sib_width == s->width && s->sib_at == s->at;
  coefs_select(s->cur, s->cur_lo, s->sib, s->sib_lo, from_sib);
  const LMASK from_root = move && !from_sib;
  if (LANE_ANY(from_root)) bernstein_restrict(root, root_lo, s->at, s->width, from_root, s->cur, s->cur_lo);
}

/* Adaptive camera and secondary rays: the brackets doubted for an end value within the noise (brackets_doubted) are
 * settled after all where P's values at their ends from the monomials, in float or else in float-float, have float's
 * signs beyond their rounding (point_values.h, bracket_ends_proven). A stopped lane keeps its interval and
 * coefficients, so they are checked here together, rather than in each step that doubted some. The probe sees what
 * settled it (ALGRAY_EVENT_CONFIRMED, decision 2; level 1 where float-float did). */
ALGRAY_INLINE void settle_brackets(BernsteinSearch* s, LaneTerms* terms, LREAL t_in, LREAL t_out,
                                   ProbeLog* probe_log) {
  if (!ALGRAY_ESCALATE || ALGRAY_SHADOW_RAYS) return;
  const LMASK doubted = s->brackets_doubted && terms_have_rays(terms);
  if (!LANE_ANY(doubted)) return;
  const LaneRays rays = terms_rays(terms);
  LREAL v_lo, rounding_lo, v_hi, rounding_hi;
  LMASK in_float_float;
  const LMASK settled =
      bracket_ends_proven(doubted, &rays, t_in, t_out, s->at, s->at + s->width, s->cur[0], s->cur[DEGREE], terms->exps,
                          terms->coefs, terms->count, &v_lo, &rounding_lo, &v_hi, &rounding_hi, &in_float_float);
  if (LANE_ANY(settled))
    PROBE(ALGRAY_EVENT_CONFIRMED, 0, 2u, LANE_ANY(in_float_float) ? 1u : 0u, v_lo, rounding_lo, v_hi, rounding_hi);
  s->status = LANE_SEL(s->status, (LREAL)ISOLATION_BRACKET, settled);
  s->doubt = LANE_SEL(s->doubt, (LREAL)0, settled);
}

/* Where a search starts, lane by lane: the interval [at, at + width] of a dyadic depth-first search of [0, 1] and
 * its coefficients cur, as an earlier search of the same root stopped there (its iso lo and hi, and cur_out). The
 * intervals before it are root-free, as that search showed; the first interval's cached sibling is not known, so
 * the next one is made from the root. Not in mixed precision, whose coefficients have low parts. */
typedef struct {
  const LREAL* cur;
  LREAL at, width;
} SearchStart;

/* Finds the leftmost subinterval of [0,1] that isolates the smallest root of the polynomial with Bernstein
 * coefficients `root` (+ `root_lo` in mixed precision), for the lanes in `running` (the others are left alone),
 * from the start of [0, 1] or from `start` (null: [0, 1]).
 * Depth-first, left half first. The right half of the latest split is cached, as the left half is usually rejected
 * at once. The position is kept as the interval's left end and width, REALs that are exact for these dyadic
 * numbers, so that all the state is in registers: the path (level, idx) of a depth-first search is (-log2 width,
 * left end / width). On return each running lane of iso is that lane's Isolation, and cur_out holds its
 * coefficients on [iso.lo, iso.hi] (rounded to float in mixed precision, where they are accurate relative to their
 * own size). Over lanes, a halving, a recomputation from `root` and a copy of the cached sibling each cost every
 * lane, so this pays where neighbouring rays take similar searches (bench/history/2026-12.md, "Lock-step lanes"). */
static ALGRAY_NOINLINE void isolate_bernstein_search(LMASK running, const LREAL* root, const LREAL* root_lo, LREAL t_in,
                                                     LREAL t_out, const SearchStart* start, LaneIsolation* iso,
                                                     LREAL* cur_out, LaneTerms* terms, ProbeLog* probe_log) {
  BernsteinSearch s;
  coefs_copy(s.cur, s.cur_lo, start ? start->cur : root, root_lo);
  coefs_copy(s.sib, s.sib_lo, root, root_lo);
  s.at = start ? start->at : (LREAL)0;
  s.width = start ? start->width : (LREAL)1;
  s.sib_at = s.sib_width = 0;
  s.status = ISOLATION_NONE;
  s.steps = s.doubt = 0;
  s.start_sign = LANE_SEL((LREAL)0, (LREAL)1, root[0] > 0) - LANE_SEL((LREAL)0, (LREAL)1, root[0] < 0);
  s.budget = s.cluster = s.searched_all = s.brackets_doubted = 0;
  s.done = !running;
  const LREAL len = t_out - t_in;
  LaneNoise noise = lanes_noise(root, terms);
  for (;;) {
    s.steps += LANE_SEL((LREAL)0, (LREAL)1, !s.done);
    /* One ray stops at its first decision, as the steps after it would change nothing (lanes go on together). */
    settle_at_left_end(&s, &noise, probe_log);
    if (LANES == 1 && LANE_ALL(s.done)) break;
    const LREAL v = bernstein_sign_variations(s.cur);
    settle_isolated(&s, v, &noise, probe_log);
    if (LANES == 1 && LANE_ALL(s.done)) break;
    const LMASK near_zero = ALGRAY_ESCALATE && halve_near_zero(&s, v, &noise, terms, t_in, t_out, probe_log);
    const LMASK several = !s.done && (v >= 1 || near_zero);
    const LMASK root_free = !s.done && !several;
    if (LANE_ANY(root_free)) PROBE_SEARCH_STEP(&s, (int)v, ALGRAY_STEP_NO_ROOT);
    const LMASK halve = halve_or_settle_several(&s, several, v, t_in, len, &noise, probe_log);
    if (LANE_ALL(s.done)) break;
    if (LANE_ANY(halve)) halve_intervals(&s, halve);
    if (LANES == 1 && LANE_ALL(halve)) continue;
    const LMASK move = !s.done && !halve;
    if (LANE_ANY(move)) move_on(&s, move, root, root_lo, probe_log);
  }
  settle_brackets(&s, terms, t_in, t_out, probe_log);
  iso->status = s.status;
  iso->steps = s.steps;
  /* isolation_at_far_end reports [1, 1] with zero values */
  iso->lo = LANE_SEL(s.at, (LREAL)1, s.searched_all);
  iso->hi = LANE_SEL(s.at + s.width, (LREAL)1, s.searched_all);
  iso->f_lo = LANE_SEL(s.cur[0], (LREAL)0, s.searched_all);
  iso->f_hi = LANE_SEL(s.cur[DEGREE], (LREAL)0, s.searched_all);
  iso->budget = s.budget;
  iso->cluster = s.cluster;
  iso->doubt = s.doubt;
  iso->noise = found_noise(&noise, !ALGRAY_SHADOW_RAYS && s.status == (REAL)ISOLATION_BRACKET);
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) cur_out[k] = s.cur[k];
}

/* The search for one ray (the method's entry, isolate.h; shadow rays): its coefficients in lane 0. */
static Isolation isolate_bernstein(const REAL* root, const REAL* root_lo, REAL t_in, REAL t_out, REAL* cur,
                                   RayTerms* terms, ProbeLog* probe_log) {
  LREAL r[NCOEF], r_lo[NCOEF], c[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) {
    r[k] = root[k];
    r_lo[k] = ALGRAY_COMPENSATED ? root_lo[k] : (REAL)0;
  }
  LaneIsolation iso;
  LaneRays rays;
  LaneTerms ray_lanes;
  LaneTerms* lane_terms = one_ray_terms(terms, &ray_lanes, &rays);
  isolate_bernstein_search(lanes_of_bits(1u), r, r_lo, t_in, t_out, (const SearchStart*)0, &iso, c, lane_terms,
                           probe_log);
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) cur[k] = lane_get(c[k], 0);
  return lane_isolation(&iso, 0);
}

/* The method's entry (isolate.h). */
static Isolation isolate_method(REAL* root, REAL* root_lo, REAL t_in, REAL t_out, REAL* iso_c, RayTerms* terms,
                                ProbeLog* probe_log) {
  return isolate_bernstein(root, root_lo, t_in, t_out, iso_c, terms, probe_log);
}
#if LANES > 1
/* isolate_rays (surface.h) for lanes: the rays' segment coefficients root[j], root_lo[j] (consumed) and segments
 * gathered into lanes, with adaptive builds' terms summed together, then searched together. */
static void isolate_rays_together(uint count, const int* in_extent, const LaneRays* rays, REAL (*root)[NCOEF],
                                  REAL (*root_lo)[NCOEF], const REAL* t_in, const REAL* t_out, LaneIsolation* iso,
                                  LREAL* c, RayTerms* terms, ProbeLog* probe_log) {
  for (int k = 0; k <= DEGREE; ++k) c[k] = 0;
  LREAL lane_root[NCOEF], lane_root_lo[NCOEF], lane_t_in = 0, lane_t_out = 1, lane_terms = 0;
  for (int k = 0; k <= DEGREE; ++k) lane_root[k] = lane_root_lo[k] = 0;
  LMASK running = 0;
  /* adaptive builds: each ray's largest coordinates, where its terms are summed, and the first ray in the extent,
   * whose terms name the monomials */
  LREAL x = 0, y = 0, z = 0;
  uint first = LANES;
  for (uint j = 0; j < count; ++j) {
    if (!in_extent[j]) continue;
    lane_set_mask(&running, j, 1);
    for (int k = 0; k <= DEGREE; ++k) {
      lane_set(&lane_root[k], j, root[j][k]);
      if (ALGRAY_COMPENSATED) lane_set(&lane_root_lo[k], j, root_lo[j][k]);
    }
    lane_set(&lane_t_in, j, t_in[j]);
    lane_set(&lane_t_out, j, t_out[j]);
    if (ALGRAY_ESCALATE) {
      if (first == LANES) first = j;
      lane_set(&x, j, terms[j].x);
      lane_set(&y, j, terms[j].y);
      lane_set(&z, j, terms[j].z);
    }
  }
  if (ALGRAY_ESCALATE && LANE_ANY(running)) {
    lane_terms = terms_sum(terms[first].exps, terms[first].coefs, terms[first].count, x, y, z);
    REAL terms_of[LANES];
    LANES_STORE(lane_terms, terms_of);
    for (uint j = 0; j < count; ++j) {
      if (!in_extent[j]) continue;
      terms[j].value = terms_of[j];
      terms[j].exact = 1;
    }
  }
  if (LANE_ANY(running)) {
    LaneTerms search_terms; /* read by adaptive builds only */
    if (ALGRAY_ESCALATE) {
      search_terms.value = lane_terms;
      search_terms.by_part = 0;
      search_terms.rays = rays;
      search_terms.exps = terms[first].exps;
      search_terms.coefs = terms[first].coefs;
      search_terms.count = terms[first].count;
    }
    isolate_bernstein_search(running, lane_root, lane_root_lo, lane_t_in, lane_t_out, (const SearchStart*)0, iso, c,
                             &search_terms, probe_log);
  }
}
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
static int bernstein_root_by_signs(const REAL* c) {
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
static LREAL isolated_start(const LREAL* c) {
  if (DEGREE != 2) return -1;
  /* c0 (1 - y)^2 + 2 c1 y (1 - y) + c2 y^2 = a y^2 + b y + c0 */
  const LREAL a = (c[0] - (REAL)2 * c[1]) + c[DEGREE], b = (REAL)2 * (c[1] - c[0]);
  const LREAL q = (REAL)-0.5 * (b + copysign(sqrt(b * b - (REAL)4 * a * c[0]), b));
  const LREAL near = c[0] / q, far = q / a;
  return LANE_SEL(LANE_SEL((LREAL)-1, far, far > 0 && far < 1), near, near > 0 && near < 1);
}

/* Turns Bernstein coefficients into the form isolated_value() expects: c_k * C(n,k); over lanes, each lane's. */
static void prepare_isolated(LREAL* c, __constant const REAL* binomials) {
  __constant const REAL* row = binomials + DEGREE * NCOEF;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) c[k] *= row[k];
}

/* x^DEGREE by repeated multiplication: pown() goes through exp and log on some devices. */
static LREAL power_of(LREAL x) {
  LREAL p = 1;
  ALGRAY_UNROLL
  for (int k = 0; k < DEGREE; ++k) p *= x;
  return p;
}

/* Value at y in [0,1] of a prepared polynomial in O(n): Horner in y/(1-y), mirrored past 1/2 so the ratio
 * stays at most 1. Over lanes (lanes.h), each lane picks its side by selection; the ratio is then one
 * division of the selected numerator by the selected denominator, the same operations as either side alone. */
static LREAL isolated_value(const LREAL* c, LREAL y) {
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
static LREAL isolated_magnitude(const LREAL* c, LREAL y) {
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
 * the value; over lanes, each lane's. */
static LREAL isolated_value_slope(const LREAL* c, LREAL y, LREAL* slope) {
  if (DEGREE == 1) {
    *slope = c[1] - c[0];
    return c[0] * ((REAL)1 - y) + c[1] * y;
  }
  const LMASK mirrored = y > (REAL)0.5;
  const LREAL u = LANE_SEL((REAL)1 - y, y, mirrored); /* the factor raised to the power n */
  const LREAL r = LANE_SEL(y, (REAL)1 - y, mirrored) / u;
  LREAL h = 0, d = 0;
  ALGRAY_UNROLL
  for (int k = DEGREE; k >= 0; --k) {
    d = d * r + h;
    h = h * r + LANE_SEL(c[k], c[DEGREE - k], mirrored);
  }
  LREAL un2 = 1; /* u^(n-2) */
  ALGRAY_UNROLL
  for (int k = 0; k < DEGREE - 2; ++k) un2 *= u;
  /* dr/dy = 1/(1-y)^2 unmirrored, -1/y^2 mirrored */
  *slope = LANE_SEL(un2 * (d - (REAL)DEGREE * u * h), un2 * ((REAL)DEGREE * u * h - d), mirrored);
  return h * un2 * u * u;
}

#endif /* ALGRAY_BERNSTEIN_H */
