/* A shadow ray's segment: from a lit surface point, moved off the surface, to one light sample, inside the extent. */
#ifndef ALGRAY_SHADOW_H
#define ALGRAY_SHADOW_H

#include "algray_shared.h"
#include "ray.h"
#include "real.h"

#define SHADOW_SELF 0  /* the light sample is behind the point's tangent plane: hidden by the surface itself */
#define SHADOW_CLEAR 1 /* the segment misses the extent: nothing hides the sample */
#define SHADOW_TRACE 2 /* the roots of P* on [*t_in, *t_out] of o_unit + t * *d_unit decide */

/* p: the surface point (world), n its unit normal on the camera's side, o = p moved along n, o_unit the same in
 * unit coordinates; light: the sample point. The segment runs from o (t = 0) to the sample (t = 1). */
int shadow_segment(REAL3 p, REAL3 n, REAL3 o, REAL3 o_unit, REAL3 light, REAL extent_inv_scale, int extent_kind,
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
void shadow_origin(__global const REAL4* points, __global const float4* normals, uint i, REAL offset,
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
Isolation shadow_isolation(const REAL* b, const REAL* b_lo, REAL t_in, REAL t_out, __constant const REAL* binomials,
                           REAL* iso_c, RayTerms* terms) {
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

#if ALGRAY_ESCALATE || ALGRAY_COMPENSATED || !ISOLATION_POINT_FORM
#error "the point form is built in plain float or double, for isolation methods with ISOLATION_POINT_FORM"
#endif

/* shadow_segment for LANES light samples (lx, ly, lz), each lane its result bit for bit: *self where the sample is
 * behind the tangent plane, and the lanes returned where the segment from o (t = 0) to the sample (t = 1) holds
 * [*t_in, *t_out] of the extent. */
LMASK shadow_segments(REAL3 p, REAL3 n, REAL3 o, REAL3 o_unit, LREAL lx, LREAL ly, LREAL lz, REAL extent_inv_scale,
                      int extent_kind, REAL3 box_half, __global const REAL4* clip_planes, uint clip_count,
                      LMASK* self, LREAL* dx, LREAL* dy, LREAL* dz, LREAL* t_in, LREAL* t_out) {
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
 * halvings, without its bookkeeping: most segments the search excludes are settled by one or two halvings. */
LMASK no_root_in_pieces(const LREAL* c, __constant const REAL* binomials) {
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
  for (int p = 0; p < (1 << SHADOW_PIECE_LEVELS); ++p) all_clear = all_clear && one_strict_sign(piece[p]);
  return all_clear;
}

/* Which of the traced lanes' segments a cheap test shows to hold a root, from the scaled Bernstein coefficients c
 * on [t_in, t_out] (power basis power, the same polynomial); *open gets the lanes only the search can settle. The
 * signs of c settle most (bernstein_root_by_signs' answers), and a sign change at seven points of the segment
 * most of the rest. */
LMASK segment_roots_settled(const LREAL* c, const LREAL* power, LREAL t_in, LREAL t_out, LMASK traced, LMASK* open,
                            __constant const REAL* binomials) {
  const LREAL start = c[0], end = c[DEGREE];
  const LMASK none = one_strict_sign(c);
  LMASK root = traced && !none && (start == 0 || end == 0 || (start < 0 && end > 0) || (start > 0 && end < 0));
  *open = traced && !none && !root;
  if (!LANE_ANY(*open)) return root;
  const LMASK crossed = sign_change_sampled(power, t_in, t_out, start, *open);
  *open = *open && !crossed;
  if (LANE_ANY(*open)) *open = *open && !no_root_in_pieces(c, binomials);
  return root || crossed;
}

/* Segments waiting for the search, gathered from the blocks of lanes of one surface point until they fill a block:
 * the search in lanes costs every lane while any runs, and a block holds two open segments on average. */
typedef struct {
  LREAL b[NCOEF]; /* Bernstein coefficients (bernstein_from_scaled's) */
  LREAL t_in, t_out;
  uint sample[LANES];
  uint count;
} SearchQueue;

/* The samples whose queued segments hold a root, by the Bernstein search over the queue's lanes; the queue is
 * emptied. */
ulong search_queued(SearchQueue* queue) {
  ulong found = 0;
  LREAL cur[NCOEF];
  const LMASK running = lanes_of_bits((1u << queue->count) - 1);
  LaneIsolation iso;
  isolate_bernstein_search(running, queue->b, queue->b, queue->t_in, queue->t_out, &iso, cur, (LaneTerms*)0,
                           NO_PROBE);
  const uint found_bits = lane_mask_bits(running && iso.status != (REAL)ISOLATION_NONE);
  for (uint j = 0; j < queue->count; ++j)
    if ((found_bits >> j) & 1u) found |= (ulong)1 << queue->sample[j];
  queue->count = 0;
  return found;
}

/* Queues the open lanes of the block of samples s0 ..; searches whenever the queue fills. Returns the samples
 * found hidden. */
ulong queue_for_search(SearchQueue* queue, const LREAL* c, LREAL t_in, LREAL t_out, uint open_bits, uint s0,
                       __constant const REAL* binomials) {
  __constant const REAL* row = binomials + DEGREE * NCOEF;
  LREAL b[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) b[k] = c[k] / row[k]; /* bernstein_from_scaled */
  ulong found = 0;
  for (uint j = 0; j < LANES; ++j) {
    if (!((open_bits >> j) & 1)) continue;
    const uint at = queue->count;
    ALGRAY_UNROLL
    for (int k = 0; k <= DEGREE; ++k) lane_set(&queue->b[k], at, lane_get(b[k], j));
    lane_set(&queue->t_in, at, lane_get(t_in, j));
    lane_set(&queue->t_out, at, lane_get(t_out, j));
    queue->sample[at] = s0 + j;
    if (++queue->count == LANES) found |= search_queued(queue);
  }
  return found;
}

/* The shadow kernels' answer for surface point i in the point form: its occlusion mask, with the number of rays
 * traced added to *traced. LANES light samples at a time, so the one-lane build (shadow_serial, GPUs) takes the
 * same decisions ray by ray. P is expanded about the origin once, when the first ray is traced. */
ulong shadow_mask_point_form(__global const REAL4* points, __global const float4* normals, uint i,
                             __global const REAL4* light_points, uint light_count, REAL offset, REAL4 extent_centre,
                             REAL extent_inv_scale, REAL4 extent_box_half, int extent_kind,
                             __global const REAL4* clip_planes, uint clip_count, __global const uint* mono_exps,
                             __global const REAL* mono_coefs, uint mono_count, __constant const REAL* binomials,
                             ulong mask, uint* traced) {
  REAL3 p, n, o, o_unit;
  shadow_origin(points, normals, i, offset, extent_centre, extent_inv_scale, &p, &n, &o, &o_unit);
  PolyVec q[POINT_FORM_COLUMNS];
  int expanded = 0;
  SearchQueue queue;
  queue.count = 0;
  /* Lanes the queue leaves empty are never read, but keep them defined: copies of a harmless segment. */
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) queue.b[k] = 1;
  queue.t_in = 0;
  queue.t_out = 1;
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
    if (!expanded) {
      taylor_at_point(mono_exps, mono_coefs, mono_count, o_unit, q);
      expanded = 1;
    }
    LREAL power[NCOEF], c[NCOEF];
    point_form_restrict(q, dx, dy, dz, power);
    point_form_segment(power, t_in, t_out, binomials, c);
    LMASK open;
    mask |= (ulong)lane_mask_bits(segment_roots_settled(c, power, t_in, t_out, trace, &open, binomials)) << s0;
    if (LANE_ANY(open)) mask |= queue_for_search(&queue, c, t_in, t_out, lane_mask_bits(open), s0, binomials);
  }
  if (queue.count) mask |= search_queued(&queue);
  return mask;
}

/* One work-item of the point form's kernels (shadow.cl, and shadow_serial.cl with one lane): surface point i's
 * mask, and its traced rays counted. */
/* The point form's work-item of the shadow kernels, whose arguments these are (shadow.cl). */
void shadow_point_form_item(__global const REAL4* points, __global const float4* normals, uint point_count,
                            __global const REAL4* light_points, uint light_count, REAL offset, REAL4 extent_centre,
                            REAL extent_inv_scale, REAL4 extent_box_half, int extent_kind,
                            __global const REAL4* clip_planes, uint clip_count, __global const uint* mono_exps,
                            __global const REAL* mono_coefs, uint mono_count, __constant const REAL* binomials,
                            __global ulong* occluded, __global uint* rays_traced) {
  const uint i = get_global_id(0);
  if (i >= point_count) return;
  uint traced = 0;
  occluded[i] = shadow_mask_point_form(points, normals, i, light_points, light_count, offset, extent_centre,
                                       extent_inv_scale, extent_box_half, extent_kind, clip_planes, clip_count,
                                       mono_exps, mono_coefs, mono_count, binomials, occluded[i], &traced);
  if (traced) atomic_add(rays_traced, traced);
}
#endif

#endif /* ALGRAY_SHADOW_H */
