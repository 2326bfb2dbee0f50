/* A shadow ray's segment: from a lit surface point, moved off the surface, to one light sample, inside the extent. */
#ifndef ALGRAY_SHADOW_H
#define ALGRAY_SHADOW_H

#include "algray_shared.h"
#include "ray.h"
#include "real.h"

#define SHADOW_SELF 0  /* the light sample is behind the point's tangent plane: hidden by the surface itself */
#define SHADOW_CLEAR 1 /* the segment misses the extent: nothing hides the sample */
#define SHADOW_TRACE 2 /* the roots of P* on [*t_in, *t_out] of o_unit + t * *d_unit decide */

/* C(DEGREE, k): a constant wherever k is one (the loops that call it unroll), so no division is left at run time. */
ALGRAY_INLINE REAL degree_binomial(int k) {
  ulong c = 1;
  ALGRAY_UNROLL
  for (int j = 0; j < DEGREE; ++j)
    if (j < k) c = c * (ulong)(DEGREE - j) / (ulong)(j + 1);
  return (REAL)c;
}

/* An upper bound on the scale of the search's noise (isolation.h, search_noise): the largest |b_k|, b_k = c_k /
 * C(n,k) the Bernstein coefficients of the scaled coefficients c (bernstein_from_scaled), lane by lane.
 * Multiplied by the reciprocals instead of divided: the four divisions per ray were most of what the shortcut cost
 * the Cayley cubic's shadow pass, which it settles almost whole. The room of 8 REAL_EPS covers the product's
 * roundings and the search's own division, which OpenCL lets be 2.5 ulp off. */
ALGRAY_INLINE LREAL search_scale_bound(const LREAL* c) {
  LREAL t[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) t[k] = fabs(c[k]) * ((REAL)1 / degree_binomial(k));
  MAGNITUDE_TREE(t, LANE_LARGER);
  return t[0] * (REAL)(1 + 8 * REAL_EPS);
}

/* p: the surface point (world), n its unit normal on the camera's side, o = p moved along n, o_unit the same in
 * unit coordinates; light: the sample point. The segment runs from o (t = 0) to the sample (t = 1). */
static int shadow_segment(REAL3 p, REAL3 n, REAL3 o, REAL3 o_unit, REAL3 light, REAL extent_inv_scale, int extent_kind,
                          REAL3 extent_box_half, __global const REAL4* clip_planes, uint clip_count, REAL3* d_unit,
                          REAL* t_in, REAL* t_out) {
  /* A light behind the tangent plane is hidden by the surface itself, whatever the roots say. The plane is the
   * surface point's, as in the shading, not the offset origin's. */
  if (dot(light - p, n) <= 0) return SHADOW_SELF;
  *d_unit = (light - o) * extent_inv_scale;
  if (!clip_to_extent(o_unit, *d_unit, extent_kind, extent_box_half, clip_planes, clip_count, t_in, t_out))
    return SHADOW_CLEAR;
  *t_in = fmax(*t_in, (REAL)0);
  *t_out = fmin(*t_out, (REAL)1);
  return *t_out > *t_in ? SHADOW_TRACE : SHADOW_CLEAR;
}

/* Work-item i's surface point p and normal n, and the shadow rays' origin o off the surface to the camera's side
 * (the point's own root moves behind the ray's start), in world and unit coordinates. */
static void shadow_origin(__global const REAL4* points, __global const float4* normals, uint i, REAL offset,
                          REAL4 extent_centre, REAL extent_inv_scale, REAL3* p, REAL3* n, REAL3* o, REAL3* o_unit) {
  *p = points[i].xyz;
  const float4 nf = normals[i];
  *n = (REAL3)((REAL)nf.x, (REAL)nf.y, (REAL)nf.z);
  *o = *p + offset * *n;
  *o_unit = (*o - extent_centre.xyz) * extent_inv_scale;
}

/* The extent form's shadow rays with Bernstein isolation, in plain float, adaptive or double, look for a certain
 * sign change at a few points of the segment before the search (shadow_isolation). Mixed precision's answers
 * stay its float-float search's. */
#if RAY_ORIGIN != ALGRAY_ORIGIN_POINT && ISOLATION == ALGRAY_ISOLATION_BERNSTEIN && !ALGRAY_COMPENSATED
#define SHADOW_SAMPLED 1
#else
#define SHADOW_SAMPLED 0
#endif

#if SHADOW_SAMPLED
#include "methods/bernstein.h"
#include "isolation.h"

/* How many pieces a shadow ray's segment is sampled in before its search: values at 0, 1/n, ..., 1. Measured on
 * the Barth decic (1024x768, one ray per pixel): 8 settled a third of the searched rays in float, and took the
 * float shadow pass from 887 to 823 ms, adaptive's from 1042 to 1004. */
#define SHADOW_SAMPLE_PIECES 8
/* How many a doubted one is sampled in (ALGRAY_SETTLE_DOUBTS). Of the Barth decic's doubted shadow rays
 * (512x384, one ray per pixel), 8 pieces settled 33%, 16 settled 45%, 32 settled 53%; 16 measured a little faster
 * than 8 at 1024x768 with a float-float second pass. */
#define SHADOW_DOUBT_PIECES 16

/* Whether two of P*'s values at the points j / pieces of the segment (Bernstein coefficients b), each beyond its
 * evaluation's rounding and, in adaptive builds, beyond the search's noise (isolation.h), have opposite signs:
 * then P* has a root between them whatever the rounding, and the shadow ray is hidden however a search would
 * go. Inside, the value is Horner's on sum_k C(n,k) b_k u^k, u = s / (1 - s): P*(s) / (1 - s)^n, of P*'s sign,
 * which an error e in every b_k moves by at most e (1 + u)^n. pieces: at most SHADOW_DOUBT_PIECES. */
ALGRAY_INLINE int sampled_sign_change(const REAL* b, int pieces, __constant const REAL* binomials, RayTerms* terms) {
  __constant const REAL* row = binomials + DEGREE * NCOEF;
  /* sure[j]: the part of value j's magnitude that its rounding cannot take away, with its sign; scale[j] turns a
   * coefficient's error into the value's */
  REAL sure[SHADOW_DOUBT_PIECES + 1], scale[SHADOW_DOUBT_PIECES + 1];
  int positive = 0, negative = 0;
  ALGRAY_UNROLL
  for (int j = 0; j <= pieces; ++j) {
    REAL value, rounding = 0;
    scale[j] = 1;
    if (j == 0 || j == pieces) {
      value = j == 0 ? b[0] : b[DEGREE]; /* the ends are P's values, unrounded */
    } else {
      const REAL u = (REAL)j / (REAL)(pieces - j);
      REAL size = fabs(b[DEGREE]);
      value = b[DEGREE];
      ALGRAY_UNROLL
      for (int k = DEGREE - 1; k >= 0; --k) {
        const REAL term = b[k] * row[k];
        value = value * u + term;
        size = size * u + fabs(term);
        scale[j] *= 1 + u;
      }
      /* Horner's error bound, 2n + 1 roundings of at most REAL_EPS / 2 each over the sum of |terms|, with room */
      rounding = size * (REAL)(2 * DEGREE + 2) * REAL_EPS;
      scale[j] *= (REAL)1.01f;
    }
    sure[j] = copysign(fmax(fabs(value) - rounding, (REAL)0), value);
    positive |= sure[j] > 0;
    negative |= sure[j] < 0;
  }
  if (!(positive && negative)) return 0;
  if (!ALGRAY_ESCALATE) return 1;
  /* The noise only where the signs change at all: it may need the ray's terms summed. The value at the start,
   * P at the shadow ray's origin, counts with the sign it has, as the search takes it (first_counted): measured
   * on the Barth decic (1024x768, no fp64), its noise check cost 20 ms of the shadow pass and moved no ray to
   * the second pass. */
  SearchNoise noise = search_noise(b, terms);
  int seen = 0;
  ALGRAY_UNROLL
  for (int j = 0; j <= pieces; ++j) {
    const REAL at = (REAL)j / (REAL)pieces;
    if (sure[j] == 0 || (!first_counted(at) && within_noise_at(&noise, sure[j] / scale[j], at, at))) continue;
    const int sign = sure[j] > 0 ? 1 : -1;
    if (seen && sign != seen) return 1;
    seen = sign;
  }
  return 0;
}

/* A shadow ray's answer from its segment's Bernstein coefficients b (and b_lo): a root where
 * sampled_sign_change finds one, else the search's; in builds that settle doubts by signs, a doubt settled as a
 * root where a finer sampling finds one. What shadow and shadow_serial both answer. */
static ALGRAY_NOINLINE Isolation shadow_isolation(const REAL* b, const REAL* b_lo, REAL t_in, REAL t_out,
                                                  __constant const REAL* binomials, REAL* iso_c, RayTerms* terms) {
  Isolation iso = isolation_none();
  if (sampled_sign_change(b, SHADOW_SAMPLE_PIECES, binomials, terms)) {
    iso.status = ISOLATION_BRACKET;
    return iso;
  }
  iso = isolate_bernstein(b, b_lo, t_in, t_out, iso_c, terms, NO_PROBE); /* leaves b as it was */
#if ALGRAY_ESCALATE && ALGRAY_SETTLE_DOUBTS
  if (iso.doubt && sampled_sign_change(b, SHADOW_DOUBT_PIECES, binomials, terms)) {
    iso.doubt = 0;
    iso.status = ISOLATION_BRACKET;
  }
#endif
  return iso;
}
#endif

#if RAY_ORIGIN == ALGRAY_ORIGIN_POINT
#include "methods/bernstein.h"
#include "point_form.h"

#if ALGRAY_COMPENSATED || !ISOLATION_POINT_FORM
#error "the point form is built in plain float, adaptive or double, for isolation methods with ISOLATION_POINT_FORM"
#endif

/* shadow_segment for LANES light samples (lx, ly, lz), each lane its result bit for bit: *self where the sample is
 * behind the tangent plane, and the lanes returned where the segment from o (t = 0) to the sample (t = 1) holds
 * [*t_in, *t_out] of the extent. */
static LMASK shadow_segments(REAL3 p, REAL3 n, REAL3 o, REAL3 o_unit, LREAL lx, LREAL ly, LREAL lz,
                             REAL extent_inv_scale, int extent_kind, REAL3 box_half, __global const REAL4* clip_planes,
                             uint clip_count, LMASK* self, LREAL* dx, LREAL* dy, LREAL* dz, LREAL* t_in, LREAL* t_out) {
  {
    /* as dot() sums them: three products, added left to right */
#pragma OPENCL FP_CONTRACT OFF
    *self = ((lx - p.x) * n.x + (ly - p.y) * n.y) + (lz - p.z) * n.z <= 0;
  }
  *dx = (lx - o.x) * extent_inv_scale;
  *dy = (ly - o.y) * extent_inv_scale;
  *dz = (lz - o.z) * extent_inv_scale;
  LREAL lo, hi;
  const LMASK hit = clip_lanes_to_extent((LREAL)o_unit.x, (LREAL)o_unit.y, (LREAL)o_unit.z, *dx, *dy, *dz, extent_kind,
                                         box_half, clip_planes, clip_count, &lo, &hi);
  /* a lane that misses the extent gets [0, 1], not the clip's NaNs, for the lanes' arithmetic that follows */
  *t_in = LANE_SEL((LREAL)0, fmax(lo, (LREAL)0), hit);
  *t_out = LANE_SEL((LREAL)1, fmin(hi, (LREAL)1), hit);
  return !*self && hit && *t_out > *t_in;
}

/* Measured on the Barth sextic and decic (full mode, 1024x768): 3 levels saved the most at degree 6, 2 at degree
 * 10, where 3 cost more than they saved. */
#define SHADOW_PIECE_LEVELS (DEGREE <= 7 ? 3 : 2)
/* Whether every one of the 2^SHADOW_PIECE_LEVELS equal pieces of the segment has Bernstein coefficients of one
 * strict sign (c: scaled coefficients on the whole segment): then no piece, and so no part of the segment, holds
 * a root. De Casteljau's halving keeps a piece of one sign so, so this is what the search concludes after as many
 * halvings, without its bookkeeping: most segments the search excludes are settled by one or two halvings.
 * Adaptive builds also want every coefficient beyond `noise` but the first, P at the ray's start (first_counted);
 * other builds never read it. */
static LMASK no_root_in_pieces(const LREAL* c, __constant const REAL* binomials, LREAL noise) {
  __constant const REAL* row = binomials + DEGREE * NCOEF;
  LREAL piece[1 << SHADOW_PIECE_LEVELS][NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) piece[0][k] = c[k] / row[k]; /* bernstein_from_scaled */
  ALGRAY_UNROLL
  for (int level = 0; level < SHADOW_PIECE_LEVELS; ++level) {
    /* Pieces 0 .. 2^level - 1 become 0 .. 2^(level + 1) - 1, from the right so none is overwritten unread. */
    ALGRAY_UNROLL
    for (int p = (1 << level) - 1; p >= 0; --p) {
      LREAL left[NCOEF], right[NCOEF];
      coefs_copy(left, (LREAL*)0, piece[p], (LREAL*)0); /* the point form has no mixed precision: no low parts */
      casteljau_halve_rows(left, (LREAL*)0, right, (LREAL*)0);
      ALGRAY_UNROLL
      for (int k = 0; k <= DEGREE; ++k) {
        piece[2 * p][k] = left[k];
        piece[2 * p + 1][k] = right[k];
      }
    }
  }
  LMASK all_clear = c[0] == c[0]; /* every lane set (the coefficients are finite) */
  ALGRAY_UNROLL
  for (int p = 0; p < (1 << SHADOW_PIECE_LEVELS); ++p) {
    all_clear = all_clear && one_strict_sign(piece[p]);
    if (ALGRAY_ESCALATE) {
      ALGRAY_UNROLL
      for (int k = p == 0 ? 1 : 0; k <= DEGREE; ++k) all_clear = all_clear && fabs(piece[p][k]) > noise;
    }
  }
  return all_clear;
}

/* Adaptive builds measure the point form's noise as the extent construction's (isolation.h, DOUBT_NOISE): by the
 * size of the terms its coefficients were summed from. Expanding P about o (taylor_at_point), restricting it to d
 * (point_form_restrict) and changing to the segment's Bernstein basis (point_form_segment, t_in >= 0) multiply and
 * add |a_m|, binomials, powers of |o| and of t |d|, and all those products together come to
 * Pabs(|o| + t_out |d|), Pabs = sum_m |a_m| x^i y^j z^k, axis by axis: the point form's terms. They exceed the extent
 * construction's, Pabs at |o + t d|, as a segment from o reaches further than o + t d does from the centre. */
typedef struct {
  LREAL x, y, z; /* |o| + t_out |d| per axis, where Pabs is summed */
  LREAL value;   /* an upper bound (terms_within at each lane's largest coordinate) until `exact` */
  int exact;
} PointTerms;

static PointTerms point_terms(REAL3 o, LREAL dx, LREAL dy, LREAL dz, LREAL t_out, __global const REAL* coefs,
                              uint count) {
  PointTerms t;
  t.x = fabs(o.x) + t_out * fabs(dx);
  t.y = fabs(o.y) + t_out * fabs(dy);
  t.z = fabs(o.z) + t_out * fabs(dz);
  t.value = terms_within(coefs, count, fmax(t.x, fmax(t.y, t.z)));
  t.exact = 0;
  return t;
}

/* The terms summed, every lane at once (terms_sum), with room for the sum's rounding as terms_within's. */
static void point_terms_exact(PointTerms* t, __global const uint* exps, __global const REAL* coefs, uint count) {
  t->value = terms_sum(exps, coefs, count, t->x, t->y, t->z) * (REAL)(1 + 1.0 / 1024);
  t->exact = 1;
}

/* The noise adaptive builds' shortcuts measure against, for coefficients of largest Bernstein magnitude `scale`
 * summed from terms of size `terms`: the search's for coefficients, and noise_bound's for P's values (any scale). */
typedef struct {
  LREAL coefficient, value;
} SettleNoise;

ALGRAY_INLINE SettleNoise settle_noise(LREAL scale, LREAL terms) {
  SettleNoise n;
  n.coefficient = DOUBT_NOISE(scale, terms) * (REAL)(1 + 8 * REAL_EPS);
  n.value = DOUBT_NOISE(terms, terms);
  return n;
}

/* The signs of segment_roots_settled for adaptive builds: each answers a lane only where the values it reads stand
 * beyond the noise, as the search would (its first interval's coefficients all clear of its noise and of one sign;
 * P at the far end beyond the noise for any scale; P at the start counts with the sign it has). Returns the lanes
 * with a root; *open gets the traced lanes these signs leave open. */
static LMASK segment_roots_settled_by_signs(const LREAL* c, LMASK traced, LMASK* open, SettleNoise noise) {
  LMASK none = one_strict_sign(c);
  ALGRAY_UNROLL
  for (int k = 1; k <= DEGREE; ++k) none = none && fabs(c[k]) > noise.coefficient * degree_binomial(k);
  const LREAL start = c[0], end = c[DEGREE];
  const LMASK root =
      traced && start != 0 && ((start < 0 && end > 0) || (start > 0 && end < 0)) && fabs(end) > noise.value;
  *open = traced && !none && !root;
  return root;
}

/* segment_roots_settled_by_signs, then, for the lanes they leave open, a sign change at seven points and the
 * pieces' signs, each value beyond the same noise. The others are left to the search (*open), which doubts what
 * it cannot settle. */
static LMASK segment_roots_settled_clear(const LREAL* c, const LREAL* power, LREAL t_in, LREAL t_out, LMASK traced,
                                         LMASK* open, __constant const REAL* binomials, SettleNoise noise) {
  const LMASK root = segment_roots_settled_by_signs(c, traced, open, noise);
  if (!LANE_ANY(*open)) return root;
  const LMASK crossed = sign_change_sampled(power, t_in, t_out, c[0], *open, noise.value);
  *open = *open && !crossed;
  if (LANE_ANY(*open)) *open = *open && !no_root_in_pieces(c, binomials, noise.coefficient);
  return root || crossed;
}

/* Which of the traced lanes' segments a cheap test shows to hold a root, from the scaled Bernstein coefficients c
 * on [t_in, t_out] (power basis power, the same polynomial); *open gets the lanes only the search can settle. The
 * signs of c settle most (bernstein_root_by_signs' answers), and a sign change at seven points of the segment
 * most of the rest. Adaptive builds ask the same of values beyond their noise: the signs on the terms' upper bound
 * first, and where they leave a lane open, every test on the terms summed (*terms made exact, kept no larger than
 * the bound: both bound the terms). The sampled tests ran on the bound first until 2026-12-07 and again on the sum
 * for what the bound left open; once on the sum settles every lane they did (each value is beyond a noise no larger)
 * and took the Barth decic's float shadow pass (first pass) from 1,758 to 1,464 ms (bench/history/2026-12.md,
 * "Shadow shortcuts on the summed terms"). */
static LMASK segment_roots_settled(const LREAL* c, const LREAL* power, LREAL t_in, LREAL t_out, LMASK traced,
                                   LMASK* open, __constant const REAL* binomials, PointTerms* terms,
                                   __global const uint* exps, __global const REAL* coefs, uint count) {
  if (ALGRAY_ESCALATE) {
    const LREAL scale = search_scale_bound(c);
    const LMASK root = segment_roots_settled_by_signs(c, traced, open, settle_noise(scale, terms->value));
    if (!LANE_ANY(*open)) return root;
    const LREAL bound = terms->value;
    point_terms_exact(terms, exps, coefs, count);
    terms->value = fmin(terms->value, bound);
    return segment_roots_settled_clear(c, power, t_in, t_out, traced, open, binomials,
                                       settle_noise(scale, terms->value));
  }
  const LREAL start = c[0], end = c[DEGREE];
  const LMASK none = one_strict_sign(c);
  LMASK root = traced && !none && (start == 0 || end == 0 || (start < 0 && end > 0) || (start > 0 && end < 0));
  *open = traced && !none && !root;
  if (!LANE_ANY(*open)) return root;
  const LMASK crossed = sign_change_sampled(power, t_in, t_out, start, *open, (LREAL)0);
  *open = *open && !crossed;
  if (LANE_ANY(*open)) *open = *open && !no_root_in_pieces(c, binomials, (LREAL)0);
  return root || crossed;
}

/* P expanded about a surface point's shadow origin o (taylor_at_point) when its first ray is traced, and in
 * adaptive builds that settle doubts Pabs = sum_m |a_m| x^i y^j z^k expanded about |o| when the point first searches
 * a ray again (point_part_polys). Only those builds hold the second expansion: a GPU keeps a work-item's arrays in
 * its registers or spills them. */
#define POINT_SEARCHES_AGAIN (ALGRAY_ESCALATE && ALGRAY_SETTLE_DOUBTS)
typedef struct {
  PolyVec q[POINT_FORM_COLUMNS];
#if POINT_SEARCHES_AGAIN
  PolyVec terms[POINT_FORM_COLUMNS];
#endif
  int made, terms_made;
  uint doubts; /* the point's rays doubted so far */
  REAL3 o;
} PointExpansion;

/* A point's doubted rays are searched again from its third on; the first two go to the second pass as they are,
 * so that a point that doubts few pays for no expansion of Pabs. Float, 1024x768 full mode, 3 rounds against
 * searching every one again: Chebyshev nonic (a doubted ray in ninety) 1,481 -> 1,450 ms, Barth decic 2,598 ->
 * 2,534 ms, though 1.70 M of its rays go to the second pass where 1.35 M did. */
#define POINT_SEARCH_AGAIN_FROM 3

/* Adaptive builds that settle doubts (POINT_SEARCHES_AGAIN) search a point form's doubted segments again, with the
 * noise local to each part of the segment (isolation.h, point_part_noise), from where the first search stopped
 * (methods/bernstein.h, SearchStart). The segment's noise is its largest coefficients' and the terms at its far end on
 * the extent's sphere, and a shadow ray starts on the surface, where both are orders of magnitude smaller: the
 * search doubts P near the start for the far end's noise. The part's noise comes from two polynomials in t with
 * nonnegative coefficients per lane: the terms Pabs(|o| + t |d|) (Pabs expanded about |o|, restricted to |d|), and
 * sum_k |c_k| t^k of the power basis c about o (the restriction again, bit for bit). Searching again only the doubted
 * rays decides each as one search with the part's noise throughout would (a ray with no value within the segment's
 * noise never asks for the part's; only the interval after the one it stopped at is made from the segment's
 * coefficients rather than from a cached half), and costs little where little is doubted. Barth decic at 1024x768, full mode:
 * its doubted shadow rays 4.08 M of 25.4 M -> 1.70 M, all passes 0.94x in float and 0.89x without fp64; Endrass
 * octic 0.90x and 0.89x; the Chebyshev nonic, which doubts one ray in ninety, 0.99x and 1.05x: Pabs's expansion
 * for a point costs about what its few rays save (bench/history/2026-12.md, "Point-form shadow rays searched
 * again"). */
static ALGRAY_NOINLINE void point_part_polys(PointExpansion* e, __global const uint* exps, __global const REAL* coefs,
                                             uint count, LREAL dx, LREAL dy, LREAL dz, LREAL* part_terms,
                                             LREAL* part_scale) {
#if POINT_SEARCHES_AGAIN
  if (!e->terms_made) {
    taylor_at_point(exps, coefs, count, fabs(e->o), e->terms, 1);
    e->terms_made = 1;
  }
  point_form_restrict(e->terms, fabs(dx), fabs(dy), fabs(dz), part_terms);
#endif
  point_form_restrict(e->q, dx, dy, dz, part_scale);
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) part_scale[k] = fabs(part_scale[k]);
}

/* Segments waiting for the search, gathered from the blocks of lanes of one surface point until they fill a block:
 * the search in lanes costs every lane while any runs, and a block holds two open segments on average. Adaptive
 * builds keep each segment's terms (summed) and its direction, and a second queue the segments searched again with
 * their two polynomials (point_part_polys). */
typedef struct {
  LREAL b[NCOEF]; /* Bernstein coefficients (bernstein_from_scaled's) */
  LREAL t_in, t_out;
  uint sample[LANES];
  uint count;
  LREAL terms;                                /* adaptive builds' */
  LREAL dx, dy, dz;                           /* builds that search again */
  LREAL part_terms[NCOEF], part_scale[NCOEF]; /* the second queue's: the two polynomials */
  /* where each lane's last search stopped, and in the second queue where its first one did (SearchStart) */
  LREAL stop[NCOEF], stop_at, stop_width;
} SearchQueue;

/* An empty queue. Lanes a search leaves empty are never decided on, but keep them defined: copies of a harmless
 * segment at first, then of earlier ones. */
ALGRAY_INLINE void empty_queue(SearchQueue* queue) {
  queue->count = 0;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) queue->b[k] = queue->part_terms[k] = queue->part_scale[k] = queue->stop[k] = 1;
  queue->stop_at = 0;
  queue->stop_width = 1;
  queue->t_in = 0;
  queue->t_out = 1;
  queue->terms = 1;
  queue->dx = queue->dy = queue->dz = 0;
}

/* Appends lane j of a segment (b: Bernstein coefficients) as sample `sample`; returns whether the queue is full. */
ALGRAY_INLINE int queue_lane(SearchQueue* queue, const LREAL* b, LREAL t_in, LREAL t_out, LREAL terms, LREAL dx,
                             LREAL dy, LREAL dz, uint j, uint sample) {
  const uint at = queue->count;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) lane_set(&queue->b[k], at, lane_get(b[k], j));
  lane_set(&queue->t_in, at, lane_get(t_in, j));
  lane_set(&queue->t_out, at, lane_get(t_out, j));
  if (ALGRAY_ESCALATE) lane_set(&queue->terms, at, lane_get(terms, j));
  if (POINT_SEARCHES_AGAIN) {
    lane_set(&queue->dx, at, lane_get(dx, j));
    lane_set(&queue->dy, at, lane_get(dy, j));
    lane_set(&queue->dz, at, lane_get(dz, j));
  }
  queue->sample[at] = sample;
  return ++queue->count == LANES;
}

/* What the search of the queue's lanes measures its noise by (adaptive builds; methods/bernstein.h, LaneTerms):
 * one ray's RayTerms, or the lanes' own; by their parts' noise in the second queue (`again`). */
ALGRAY_INLINE LaneTerms queued_terms(const SearchQueue* queue, int again, __global const uint* exps,
                                     __global const REAL* coefs, uint count) {
#if LANES == 1
  LaneTerms t = known_terms(queue->terms);
  t.part_terms = again ? queue->part_terms : (const REAL*)0;
  t.part_scale = queue->part_scale;
  t.t_in = queue->t_in;
  t.t_out = queue->t_out;
#else
  LaneTerms t;
  t.value = queue->terms;
  t.rays = (const LaneRays*)0; /* shadow rays' searches evaluate nothing in float-float */
  t.by_part = again;
  t.part_terms = queue->part_terms;
  t.part_scale = queue->part_scale;
  t.seg_in = queue->t_in;
  t.seg_out = queue->t_out;
#endif
  t.exps = exps;
  t.coefs = coefs;
  t.count = count;
  return t;
}

/* The Bernstein search over the queue's lanes: the lanes it finds a root in (*found) and, in adaptive builds, those
 * it doubts (*doubted), as bits of the queue's entries. The first queue's search runs from the start of each
 * segment, the second queue's from where the first stopped; each leaves in the queue where it stopped. */
static void queue_search(SearchQueue* queue, int again, __global const uint* exps, __global const REAL* coefs,
                         uint count, uint* found, uint* doubted) {
  const LMASK running = lanes_of_bits((1u << queue->count) - 1);
  LaneIsolation iso;
  LaneTerms terms = queued_terms(queue, again, exps, coefs, count);
  SearchStart start;
  start.cur = queue->stop;
  start.at = queue->stop_at;
  start.width = queue->stop_width;
  isolate_bernstein_search(running, queue->b, queue->b, queue->t_in, queue->t_out,
                           again ? &start : (const SearchStart*)0, &iso, queue->stop,
                           ALGRAY_ESCALATE ? &terms : (LaneTerms*)0, NO_PROBE);
  queue->stop_at = iso.lo;
  queue->stop_width = iso.hi - iso.lo;
  *found = lane_mask_bits(running && iso.status != (REAL)ISOLATION_NONE);
  *doubted = ALGRAY_ESCALATE ? lane_mask_bits(running && iso.doubt != (REAL)0) : 0u;
}

/* The samples of the queue's entries in `bits`. */
ALGRAY_INLINE ulong queued_samples(const SearchQueue* queue, uint bits) {
  ulong samples = 0;
  for (uint j = 0; j < queue->count; ++j)
    if ((bits >> j) & 1u) samples |= (ulong)1 << queue->sample[j];
  return samples;
}

/* The samples whose segments in the second queue hold a root; *doubted gets those it doubts still. Emptied. */
static ulong search_again(SearchQueue* again, PointExpansion* e, ulong* doubted, __global const uint* exps,
                          __global const REAL* coefs, uint count) {
  point_part_polys(e, exps, coefs, count, again->dx, again->dy, again->dz, again->part_terms, again->part_scale);
  uint found_bits, doubt_bits;
  queue_search(again, 1, exps, coefs, count, &found_bits, &doubt_bits);
  const ulong found = queued_samples(again, found_bits);
  *doubted |= queued_samples(again, doubt_bits);
  again->count = 0;
  return found;
}

/* The samples whose queued segments hold a root, by the Bernstein search over the queue's lanes; in adaptive builds
 * *doubted gets those it doubts, or, where the build settles doubts, those that doubts still after the second queue
 * (point_part_polys) searched them again. The queue is emptied. */
static ulong search_queued(SearchQueue* queue, SearchQueue* again, PointExpansion* e, ulong* doubted,
                           __global const uint* exps, __global const REAL* coefs, uint count) {
  uint found_bits, doubt_bits;
  queue_search(queue, 0, exps, coefs, count, &found_bits, &doubt_bits);
  ulong found = queued_samples(queue, found_bits);
  if (!POINT_SEARCHES_AGAIN) *doubted |= queued_samples(queue, doubt_bits);
  if (POINT_SEARCHES_AGAIN && doubt_bits)
    for (uint j = 0; j < queue->count; ++j) {
      if (!((doubt_bits >> j) & 1u)) continue;
      /* a point's first doubted rays go to the second pass as they are (POINT_SEARCH_AGAIN_FROM) */
      if (++e->doubts < POINT_SEARCH_AGAIN_FROM) {
        *doubted |= (ulong)1 << queue->sample[j];
        continue;
      }
      const uint at = again->count;
      ALGRAY_UNROLL
      for (int k = 0; k <= DEGREE; ++k) lane_set(&again->stop[k], at, lane_get(queue->stop[k], j));
      lane_set(&again->stop_at, at, lane_get(queue->stop_at, j));
      lane_set(&again->stop_width, at, lane_get(queue->stop_width, j));
      if (queue_lane(again, queue->b, queue->t_in, queue->t_out, queue->terms, queue->dx, queue->dy, queue->dz, j,
                     queue->sample[j]))
        found |= search_again(again, e, doubted, exps, coefs, count);
    }
  queue->count = 0;
  return found;
}

/* Queues the open lanes of the block of samples s0 .. (directions dx, dy, dz); searches whenever the queue fills.
 * Returns the samples found hidden; *doubted gets those the searches doubt. */
static ulong queue_for_search(SearchQueue* queue, SearchQueue* again, PointExpansion* e, const LREAL* c, LREAL t_in,
                              LREAL t_out, LREAL dx, LREAL dy, LREAL dz, uint open_bits, uint s0,
                              __constant const REAL* binomials, ulong* doubted, const PointTerms* terms,
                              __global const uint* exps, __global const REAL* coefs, uint count) {
  __constant const REAL* row = binomials + DEGREE * NCOEF;
  LREAL b[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) b[k] = c[k] / row[k]; /* bernstein_from_scaled */
  ulong found = 0;
  for (uint j = 0; j < LANES; ++j) {
    if (!((open_bits >> j) & 1)) continue;
    if (queue_lane(queue, b, t_in, t_out, terms->value, dx, dy, dz, j, s0 + j))
      found |= search_queued(queue, again, e, doubted, exps, coefs, count);
  }
  return found;
}

/* The shadow kernels' answer for surface point i in the point form: its occlusion mask, with the number of rays
 * traced added to *traced, and in adaptive builds the samples whose answers the float search doubted in
 * *undecided. LANES light samples at a time, so the one-lane build (shadow_serial, GPUs) takes the same decisions
 * ray by ray. P is expanded about the origin once, when the first ray is traced. */
static ulong shadow_mask_point_form(__global const REAL4* points, __global const float4* normals, uint i,
                                    __global const REAL4* light_points, uint light_count, REAL offset,
                                    REAL4 extent_centre, REAL extent_inv_scale, REAL4 extent_box_half, int extent_kind,
                                    __global const REAL4* clip_planes, uint clip_count, __global const uint* mono_exps,
                                    __global const REAL* mono_coefs, uint mono_count, __constant const REAL* binomials,
                                    ulong mask, uint* traced, ulong* undecided) {
  REAL3 p, n, o, o_unit;
  shadow_origin(points, normals, i, offset, extent_centre, extent_inv_scale, &p, &n, &o, &o_unit);
  PointExpansion e;
  e.made = e.terms_made = 0;
  e.doubts = 0;
  e.o = o_unit;
  SearchQueue queue, again;
  empty_queue(&queue);
  empty_queue(&again);
  for (uint s0 = 0; s0 < light_count; s0 += LANES) {
    /* The host pads the light points to a multiple of 16, so a block may read past light_count. */
#define LIGHT_X(j) light_points[s0 + (j)].x
#define LIGHT_Y(j) light_points[s0 + (j)].y
#define LIGHT_Z(j) light_points[s0 + (j)].z
    const LREAL Lx = LANES_OF(LREAL, LIGHT_X), Ly = LANES_OF(LREAL, LIGHT_Y), Lz = LANES_OF(LREAL, LIGHT_Z);
#undef LIGHT_X
#undef LIGHT_Y
#undef LIGHT_Z
    const uint in_block = light_count - s0 >= LANES ? (1u << LANES) - 1 : (1u << (light_count - s0)) - 1;
    const LMASK wanted = lanes_of_bits(~(uint)(mask >> s0) & in_block);
    LMASK self;
    LREAL dx, dy, dz, t_in, t_out;
    LMASK trace = shadow_segments(p, n, o, o_unit, Lx, Ly, Lz, extent_inv_scale, extent_kind, extent_box_half.xyz,
                                  clip_planes, clip_count, &self, &dx, &dy, &dz, &t_in, &t_out);
    mask |= (ulong)lane_mask_bits(wanted && self) << s0;
    trace = trace && wanted;
    if (!LANE_ANY(trace)) continue;
    *traced += popcount(lane_mask_bits(trace));
    if (!e.made) {
      taylor_at_point(mono_exps, mono_coefs, mono_count, o_unit, e.q, 0);
      e.made = 1;
    }
    LREAL power[NCOEF], c[NCOEF];
    point_form_restrict(e.q, dx, dy, dz, power);
    point_form_segment(power, t_in, t_out, binomials, c);
    PointTerms terms;
    if (ALGRAY_ESCALATE) terms = point_terms(o_unit, dx, dy, dz, t_out, mono_coefs, mono_count);
    LMASK open;
    mask |= (ulong)lane_mask_bits(segment_roots_settled(c, power, t_in, t_out, trace, &open, binomials, &terms,
                                                        mono_exps, mono_coefs, mono_count))
            << s0;
    if (LANE_ANY(open))
      mask |= queue_for_search(&queue, &again, &e, c, t_in, t_out, dx, dy, dz, lane_mask_bits(open), s0, binomials,
                               undecided, &terms, mono_exps, mono_coefs, mono_count);
  }
  if (queue.count) mask |= search_queued(&queue, &again, &e, undecided, mono_exps, mono_coefs, mono_count);
  if (again.count) mask |= search_again(&again, &e, undecided, mono_exps, mono_coefs, mono_count);
  return mask;
}

/* The point form's work-item of the shadow kernels, whose arguments these are (shadow.cl): surface point i's mask,
 * its traced rays counted, and in adaptive builds its doubted samples. */
static void shadow_point_form_item(__global const REAL4* points, __global const float4* normals, uint point_count,
                                   __global const REAL4* light_points, uint light_count, REAL offset,
                                   REAL4 extent_centre, REAL extent_inv_scale, REAL4 extent_box_half, int extent_kind,
                                   __global const REAL4* clip_planes, uint clip_count, __global const uint* mono_exps,
                                   __global const REAL* mono_coefs, uint mono_count, __constant const REAL* binomials,
                                   __global ulong* occluded, __global uint* rays_traced, __global ulong* undecided) {
  const uint i = launch_item_index();
  if (i >= point_count) return;
  uint traced = 0;
  ulong unsure = 0;
  occluded[i] = shadow_mask_point_form(points, normals, i, light_points, light_count, offset, extent_centre,
                                       extent_inv_scale, extent_box_half, extent_kind, clip_planes, clip_count,
                                       mono_exps, mono_coefs, mono_count, binomials, occluded[i], &traced, &unsure);
  if (ALGRAY_ESCALATE) undecided[i] = unsure;
  if (traced) atomic_add(rays_traced, traced);
}
#endif

#endif /* ALGRAY_SHADOW_H */
