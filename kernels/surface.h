/* Rays against one surface: clip, restrict, isolate the smallest root, refine it; then the normal and side. One ray, or
 * LANES rays side by side (lanes.h), through the same code. */
#ifndef ALGRAY_SURFACE_H
#define ALGRAY_SURFACE_H

#include "algray_shared.h"
#include "float_float.h"
#include "lanes.h"
#include "point_values.h"
#include "ray.h"
#include "real.h"
#include "restrict.h"

#if RAY_ORIGIN == ALGRAY_ORIGIN_EYE && !ISOLATION_POWER_BASIS
#error "RAY_ORIGIN=eye needs a power-basis isolation method"
#endif
#if ALGRAY_ESCALATE && !ISOLATION_ADAPTIVE
#error "adaptive precision needs an isolation method that doubts (ISOLATION_ADAPTIVE)"
#endif
#if RAY_ORIGIN != ALGRAY_ORIGIN_EXTENT && RAY_ORIGIN != ALGRAY_ORIGIN_SCREEN && RAY_ORIGIN != ALGRAY_ORIGIN_POINT && \
    ALGRAY_ESCALATE
#error "adaptive precision measures its noise by the terms of the extent construction, the screen form or the point form"
#endif
#if RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN && ALGRAY_COMPENSATED
#error "RAY_ORIGIN=screen is built in plain float or double"
#endif

/* The screen form hands each camera ray's Taylor coefficients, about t = taylor_t, to the solver (taylor and
 * taylor_t, which other builds pass as 0 and never read). Its kernels take the image rows' polynomials:
 * screen_rows[(py - screen_row0) * NCOEF * NCOEF + j * NCOEF + k] is the xi^j coefficient of row py's taylor[k],
 * expanded about t = screen_t; a pixel's xi = (px + 1/2) * xi_scale + xi_offset. */

/* The xi of a pixel column whose centre is `centre` ((REAL)px + 0.5, as camera_rays'), where its row's polynomials
 * are evaluated; of one column or of lanes (lane_pixel_centres). */
#define SCREEN_COLUMN(centre, xi_scale, xi_offset) ((centre) * (xi_scale) + (xi_offset))

ALGRAY_INLINE REAL screen_column(uint px, REAL xi_scale, REAL xi_offset) {
  return SCREEN_COLUMN((REAL)px + (REAL)0.5, xi_scale, xi_offset);
}

/* Image row py's polynomials in xi (screen_taylor's row). */
ALGRAY_INLINE __global const REAL* screen_row(__global const REAL* rows, uint py, uint row0) {
  return rows + (size_t)(py - row0) * (NCOEF * NCOEF);
}

/* Adaptive builds: the size of the terms the screen form sums a ray's coefficients from, of one ray or of lanes:
 * sum over k of (sum over j of |row's xi^j coefficient of tau^k| |xi|^j) reach^k, reach the larger |tau| at the
 * segment's ends. Each Bernstein coefficient on the segment is a sum of the Taylor coefficients times products of
 * |tau| <= reach, and each Taylor coefficient a Horner sum of the row's, so this bounds what every coefficient was
 * summed from, as RayTerms' sum does for the extent construction; the noise is measured alike (isolation.h,
 * DOUBT_NOISE), with ALGRAY_SCREEN_TERMS_WEIGHT for the screen form's two Horner chains where the extent
 * construction has one, and 2^-10 more for this sum's own rounding. */
static LREAL screen_terms(__global const REAL* row, LREAL xi, LREAL tau_in, LREAL tau_out) {
  const LREAL ax = fabs(xi), reach = fmax(fabs(tau_in), fabs(tau_out));
  LREAL total = 0;
  for (int k = DEGREE; k >= 0; --k) {
    LREAL coefficient = fabs((LREAL)row[DEGREE * NCOEF + k]);
    for (int j = DEGREE - 1; j >= 0; --j) coefficient = coefficient * ax + fabs(row[j * NCOEF + k]);
    total = total * reach + coefficient;
  }
  return total * (REAL)(ALGRAY_SCREEN_TERMS_WEIGHT * (1 + 1.0 / 1024));
}

/* Adaptive builds: a camera ray's terms in the screen form (screen_terms, exact from the start) with what the search
 * evaluates P from in float-float: the ray in unit coordinates, its segment, and the monomials. */
static RayTerms screen_ray_terms(REAL value, REAL3 o, REAL3 d, REAL t_in, REAL t_out, __global const uint* exps,
                                 __global const REAL* coefs, uint count) {
  RayTerms t = known_terms(value);
  t.exps = exps;
  t.coefs = coefs;
  t.count = count;
  t.has_ray = 1;
  t.o = o;
  t.d = d;
  t.t_in = t_in;
  t.t_out = t_out;
  return t;
}

/* Pixel (px, py)'s Taylor coefficients; returns the t they are expanded about. */
static REAL screen_ray_taylor(uint px, uint py, __global const REAL* rows, uint row0, REAL t0, REAL xi_scale,
                              REAL xi_offset, REAL* taylor) {
  screen_taylor(screen_row(rows, py, row0), screen_column(px, xi_scale, xi_offset), taylor);
  return t0;
}

/* The outcome of isolating and refining the smallest root of P*(t) on [t_in, t_out], for LANES rays side by side
 * (lane j ray j's; with LANES = 1, one ray's). */
typedef struct {
  LREAL t;        /* the root; meaningful with ALGRAY_HIT_FOUND */
  LREAL f_before; /* P at the left end of the isolating interval */
  LANE_INT_VEC flags;      /* ALGRAY_HIT_FOUND, ALGRAY_HIT_BUDGET, ALGRAY_HIT_IN_EXTENT, ... */
  LANE_INT_VEC steps;      /* isolation intervals examined */
  LANE_INT_VEC iterations; /* refinement iterations */
} LaneRoots;

/* The probe records the coefficients the isolation starts from, in its basis; in a render build this is empty. */
ALGRAY_INLINE void probe_coefficients(const REAL* c, const REAL* c_lo, uint basis, ProbeLog* probe_log) {
  for (int k = 0; k <= DEGREE; ++k)
    PROBE(ALGRAY_EVENT_COEFFICIENT, k, basis, 0u, c[k], ALGRAY_COMPENSATED ? c_lo[k] : (REAL)0, (REAL)0, (REAL)0);
}

/* The refinement's stopping width in y on the isolating interval [lo, hi] of the segment [t_in, t_out] (lo and hi
 * fractions of it): the stopping width at the interval's left end over the interval's width in t. Of one ray or
 * of lanes. */
#define ISOLATED_TOL_Y(lo, hi, t_in, t_out) \
  (STOP_WIDTH((t_in) + (lo) * ((t_out) - (t_in))) / (((hi) - (lo)) * ((t_out) - (t_in))))

/* The hit record of a ray that misses the extent: hit_records starts every record from it. */
ALGRAY_INLINE HitRecord missed_record(void) {
  HitRecord r;
  r.flags = 0;
  r.work = ALGRAY_WORK_PACK(0u, 0u);
  r.t_hi = INFINITY;
  r.t_lo = 0;
  r.depth = INFINITY;
  r.normal_x = r.normal_y = r.normal_z = 0;
  return r;
}

/* The size of the isolating interval's coefficients, for the refinement's value stop; over lanes, each lane's. */
static LREAL coefficient_scale(const LREAL* c) {
  LREAL scale = 0;
  for (int k = 0; k <= DEGREE; ++k) scale = fmax(scale, fabs(c[k]));
  return scale;
}

/* The ray parameter of the point y of the isolating interval [lo, hi] (fractions of [t_in, t_out]); of one ray or
 * of lanes. */
#define PLACED_ROOT_T(lo, hi, y, t_in, t_out) ((t_in) + ((lo) + (y) * ((hi) - (lo))) * ((t_out) - (t_in)))

/* How far the root at t may move, read off P's slope on the isolating interval [lo, hi]: for one ray and for lanes
 * alike, so that both take the same operations. */
#define FLAT_ROOT_MARGIN(slope, t, lo, hi, t_in, t_out) \
  (fabs(slope) * ALGRAY_DOUBT_POSITION * fabs(t) / (((hi) - (lo)) * ((t_out) - (t_in))))

/* The roots of the rays' isolations, refined (refine.h): c holds each lane's polynomial on its isolating interval
 * (consumed); t_in, t_out each lane's segment. Lanes that missed the extent (not in `entered`) get no root and no
 * flags; every other lane the isolation's flags with ALGRAY_HIT_IN_EXTENT, and where the isolation found a root (a
 * bracket refined, or one settled at an end: y = 0) its t, with ALGRAY_HIT_FOUND. Adaptive builds doubt a root
 * that lies where P is so flat that the coefficients' noise could move it by more than ALGRAY_DOUBT_POSITION of
 * its t, read off P's slope there: the secant of the isolating interval can be many times steeper than P at the
 * root (a Kummer shell ray: 60 times, with the root 1e-3 off). */
static void refine_rays(LMASK entered, const LaneIsolation* iso, LREAL* c, LREAL t_in, LREAL t_out,
                        __constant const REAL* binomials, LaneRoots* roots, ProbeLog* probe_log) {
  if (LANE_ANY(entered))
    PROBE(ALGRAY_EVENT_ISOLATED, iso->budget, (uint)iso->status, 0u, iso->lo, iso->hi, iso->f_lo, iso->f_hi);
  /* the isolation's flags */
#define FLAG_WHERE(flag, mask) LANE_SEL((LANE_INT_VEC)0, (LANE_INT_VEC)(flag), (mask))
  LANE_INT_VEC flags = FLAG_WHERE(ALGRAY_HIT_IN_EXTENT, entered) | FLAG_WHERE(ALGRAY_HIT_BUDGET, entered && iso->budget) |
                       FLAG_WHERE(ALGRAY_HIT_DOUBT, entered && iso->doubt != 0) |
                       FLAG_WHERE(ALGRAY_HIT_EXACT, entered && iso->status == (REAL)ISOLATION_EXACT) |
                       FLAG_WHERE(ALGRAY_HIT_CLUSTER, entered && iso->status != (REAL)ISOLATION_NONE && iso->cluster);
  const LMASK running = entered && iso->status == (REAL)ISOLATION_BRACKET;
  const LMASK found = entered && iso->status != (REAL)ISOLATION_NONE;
  LREAL y = 0;
  LMASK iterations = 0;
  if (LANE_ANY(running)) {
    /* each refined lane's bracket (zeros elsewhere) */
    const LREAL f0 = LANE_SEL((LREAL)0, iso->f_lo, running), f1 = LANE_SEL((LREAL)0, iso->f_hi, running);
    const LREAL lo = LANE_SEL((LREAL)0, iso->lo, running), hi = LANE_SEL((LREAL)0, iso->hi, running);
    const LREAL tol_y = LANE_SEL((LREAL)0, ISOLATED_TOL_Y(lo, hi, t_in, t_out), running);
    const LREAL scale = coefficient_scale(c), start = isolated_start(c);
    prepare_isolated(c, binomials);
    /* degree 1 in closed form (refine.h, line_root) */
    y = LANE_SEL((LREAL)0,
                 DEGREE == 1 ? line_root(f0, f1)
                             : refine_root(c, f0, f1, tol_y, scale, start, running, &iterations, probe_log),
                 running);
  }
  roots->t = LANE_SEL((LREAL)INFINITY, PLACED_ROOT_T(iso->lo, iso->hi, y, t_in, t_out), found);
  roots->f_before = LANE_SEL((LREAL)0, iso->f_lo, found);
  roots->flags = flags | FLAG_WHERE(ALGRAY_HIT_FOUND, found);
#undef FLAG_WHERE
  roots->steps = LANE_SEL((LANE_INT_VEC)0, LANE_TO_INT(iso->steps), entered);
  roots->iterations = LANE_SEL((LANE_INT_VEC)0, iterations, running);
  /* the flat check, each lane with its operations (taken lane by lane, the coefficients' trip through memory and
   * the scalar slopes were 60% of what adaptive added to the cusp catastrophe's camera pass) */
  if (ALGRAY_ESCALATE && LANE_ANY(running)) {
    LREAL slope;
    (void)isolated_value_slope(c, y, &slope);
    const LREAL margin = FLAT_ROOT_MARGIN(slope, roots->t, iso->lo, iso->hi, t_in, t_out);
    const LMASK flat = running && margin <= iso->noise;
    if (LANE_ANY(flat)) PROBE(ALGRAY_EVENT_DOUBT, 0, ALGRAY_DOUBT_FLAT, 0u, iso->lo, iso->hi, margin, iso->noise);
    roots->flags |= LANE_SEL((LANE_INT_VEC)0, (LANE_INT_VEC)ALGRAY_HIT_DOUBT, flat);
  }
}

/* The coordinates' factors of the ray o + t*d restricted to [t_in, t_out] as s in [0, 1], in the isolation's
 * basis: entry and exit points for the Bernstein form, entry point and chord for the power basis. */
static void segment_factors(REAL3 o, REAL3 d, REAL t_in, REAL t_out, uint even_axes, AxisFactor* fx, AxisFactor* fy,
                            AxisFactor* fz) {
  const REAL3 pa = o + t_in * d, pb = o + t_out * d;
  const REAL3 l1 = ISOLATION_POWER_BASIS ? pb - pa : pb;
  *fx = axis_factor(pa.x, l1.x, even_axes & 1);
  *fy = axis_factor(pa.y, l1.y, even_axes & 2);
  *fz = axis_factor(pa.z, l1.z, even_axes & 4);
}

/* The restriction's result (scaled Bernstein coefficients, or a power basis) as the isolation method takes it. */
static void restricted_to_isolation_basis(REAL* root, REAL* root_lo, __constant const REAL* binomials,
                                          ProbeLog* probe_log) {
  if (!ISOLATION_POWER_BASIS) bernstein_from_scaled(root, root_lo, binomials);
  probe_coefficients(root, root_lo,
                     !ISOLATION_POWER_BASIS              ? ALGRAY_BASIS_BERNSTEIN
                     : RAY_ORIGIN == ALGRAY_ORIGIN_EYE ? ALGRAY_BASIS_POWER_EYE
                                                       : ALGRAY_BASIS_POWER_SEGMENT,
                     probe_log);
}

/* P*(t) on [t_in, t_out] for the ray o + t*d in unit coordinates, in the isolation method's basis: Bernstein
 * coefficients on the segment, or the power basis of the segment (of the whole ray, for RAY_ORIGIN=eye). */
ALGRAY_INLINE void segment_coefficients(REAL3 o, REAL3 d, REAL t_in, REAL t_out, __global const uint* exps,
                                        __global const REAL* coefs, uint count, __constant const REAL* binomials,
                                        uint even_axes, REAL* root,
                                        REAL* root_lo, RayTerms* terms, const REAL* taylor, REAL taylor_t,
                                        ProbeLog* probe_log) {
  if (RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN) {
    /* The same coefficients the extent construction computes from the monomials, from D + 1 numbers instead. */
    restrict_from_taylor(taylor, t_in - taylor_t, t_out - taylor_t, binomials, root);
  } else if (RAY_ORIGIN == ALGRAY_ORIGIN_EYE) {
    /* The paper's construction: P*(t) around the ray origin, then mapped to each subinterval. */
    restrict_to_ray(exps, coefs, count, binomials, axis_factor(o.x, d.x, even_axes & 1),
                    axis_factor(o.y, d.y, even_axes & 2), axis_factor(o.z, d.z, even_axes & 4), root, root_lo);
  } else {
    AxisFactor fx, fy, fz;
    segment_factors(o, d, t_in, t_out, even_axes, &fx, &fy, &fz);
    restrict_to_ray(exps, coefs, count, binomials, fx, fy, fz, root, root_lo);
    if (ALGRAY_ESCALATE) {
      *terms = ray_terms(exps, coefs, count, fx, fy, fz);
      terms->has_ray = 1;
      terms->o = o;
      terms->d = d;
      terms->t_in = t_in;
      terms->t_out = t_out;
    }
  }
  restricted_to_isolation_basis(root, root_lo, binomials, probe_log);
}

/* Isolates the smallest root of P*(t) on [t_in, t_out] for the ray o + t*d in unit coordinates; iso_c gets
 * the polynomial on the isolating interval. The primary and shadow kernels share this: one refines what it
 * returns, the other only asks whether there is anything to refine. */
static Isolation isolate_on_segment(REAL3 o, REAL3 d, REAL t_in, REAL t_out, __global const uint* exps,
                                    __global const REAL* coefs, uint count, __constant const REAL* binomials,
                                    uint even_axes, REAL* iso_c, const REAL* taylor, REAL taylor_t,
                                    ProbeLog* probe_log) {
  REAL root[NCOEF], root_lo[NCOEF];
  RayTerms terms;
  segment_coefficients(o, d, t_in, t_out, exps, coefs, count, binomials, even_axes, root,
                       root_lo, &terms, taylor, taylor_t, probe_log);
  return isolate_method(root, root_lo, t_in, t_out, iso_c, &terms, probe_log);
}

/* Isolates the smallest root on [t_in, t_out] from the coefficients restrict_to_rays made of segment_factors'
 * factors (root, root_lo are consumed), as isolate_on_segment would; iso_c gets the polynomial on the isolating
 * interval. */
static Isolation isolate_restricted(REAL* root, REAL* root_lo, REAL t_in, REAL t_out, __constant const REAL* binomials,
                                    REAL* iso_c, RayTerms* terms, ProbeLog* probe_log) {
  restricted_to_isolation_basis(root, root_lo, binomials, probe_log);
  return isolate_method(root, root_lo, t_in, t_out, iso_c, terms, probe_log);
}

/* The first `count` (<= LANES) of the rays, in unit coordinates (unit) and clipped to the extent and its clip
 * planes (clip_lanes_to_extent): *lane_t_in,
 * *lane_t_out get each lane's segment (0 and 1 where it misses). Returns the lanes that enter the extent (none from
 * `count` on). Unit coordinates keep every point of the extent within |u| <= 1: the conditioning step that makes
 * float usable. */
static LMASK enter_extent(uint count, const LaneRays* rays, REAL3 centre, REAL inv_scale, REAL3 box_half,
                          int extent_kind, __global const REAL4* clip_planes, uint clip_count, LaneRays* unit,
                          LREAL* lane_t_in, LREAL* lane_t_out, ProbeLog* probe_log) {
  unit->ox = (rays->ox - centre.x) * inv_scale;
  unit->oy = (rays->oy - centre.y) * inv_scale;
  unit->oz = (rays->oz - centre.z) * inv_scale;
  unit->dx = rays->dx * inv_scale;
  unit->dy = rays->dy * inv_scale;
  unit->dz = rays->dz * inv_scale;
  LREAL lo, hi;
  const LMASK inside = lanes_of_bits((1u << count) - 1u) &&
                       clip_lanes_to_extent(unit->ox, unit->oy, unit->oz, unit->dx, unit->dy, unit->dz, extent_kind,
                                            box_half, clip_planes, clip_count, &lo, &hi);
  *lane_t_in = LANE_SEL((LREAL)0, lo, inside);
  *lane_t_out = LANE_SEL((LREAL)1, hi, inside);
  if (LANE_ANY(inside)) PROBE(ALGRAY_EVENT_SEGMENT, 0, 0u, 0u, *lane_t_in, *lane_t_out, (REAL)0, (REAL)0);
  return inside;
}

/* The isolations of the rays from their segment_coefficients (root, root_lo are consumed): one ray by its method
 * (isolate_method); lanes together, in the Bernstein search, the one method built for lanes (refine.h). c gets each
 * lane's polynomial on its isolating interval, for refine_rays. Lanes from `count` on, and those whose ray missed the
 * extent (in_extent[j] == 0), are left alone. rays: the lanes' rays in unit coordinates, where adaptive builds'
 * search evaluates P from the monomials (point_values.h, bracket_ends_proven). */
static void isolate_rays(uint count, const int* in_extent, const LaneRays* rays, REAL (*root)[NCOEF],
                         REAL (*root_lo)[NCOEF], const REAL* t_in, const REAL* t_out, LaneIsolation* iso, LREAL* c,
                         RayTerms* terms, ProbeLog* probe_log) {
#if LANES > 1
  isolate_rays_together(count, in_extent, rays, root, root_lo, t_in, t_out, iso, c, terms, probe_log);
#else
  (void)rays;
  (void)count;
  for (int k = 0; k <= DEGREE; ++k) c[k] = 0;
  if (!in_extent[0]) return;
#if ISOLATION == ALGRAY_ISOLATION_BERNSTEIN
  /* straight into the lanes' isolation: isolate_method's round trip through an Isolation measured 2% of the
   * lemniscate's one-ray kernel */
  isolate_bernstein_search(1, root[0], root_lo[0], t_in[0], t_out[0], (const SearchStart*)0, iso, c, &terms[0],
                           probe_log);
#else
  set_lane_isolation(iso, 0, isolate_method(root[0], root_lo[0], t_in[0], t_out[0], c, &terms[0], probe_log));
#endif
#endif
}

/* Adaptive builds: a root doubted as flat (refine_rays) is kept after all where P, evaluated from the
 * monomials (point_values.h, direct_values) at t -+ ALGRAY_DOUBT_POSITION |t| on the ray, has opposite signs beyond
 * that evaluation's rounding: then a root lies within what the flat check allows. The check held the root to the
 * coefficients' noise, which sums the terms over the whole segment, out to the extent's sphere; at a root inside, the
 * terms are far smaller (the Barth decic's flat-doubted roots: 1e-4 to 2e-3 of the segment's), and so is P's rounding
 * there. Measured on the decic at 1024x768: 61% fewer camera rays traced again (bench/RESULTS.md). Where float's
 * rounding is still too large (surfaces whose monomials cancel by orders of magnitude, such as Chebyshev sums),
 * P is evaluated again in float-float, whose rounding is float's squared: over the lanes together, that costs less
 * than the second pass even in double (bench/history/2026-12.md, "Flat roots confirmed in float-float"). */
/* The float-float check of confirm_flat_roots for the lanes in `doubted` (roots at t, rays r from their starts),
 * at t -+ delta with delta shrunk by 2^-10, so that their own rounding keeps the points within
 * ALGRAY_DOUBT_POSITION |t| of t; the lanes it confirms. *v0 ... *rounding1: the values and their bounds. */
static LMASK confirmed_in_float_float(LMASK doubted, const LaneRays* r, LREAL t, __global const uint* exps,
                                      __global const REAL* coefs, uint count, LREAL* v0, LREAL* rounding0, LREAL* v1,
                                      LREAL* rounding1) {
  const LREAL inner = (REAL)ALGRAY_DOUBT_POSITION * (REAL)(1 - 1.0 / 1024) * fabs(t);
  *v0 = direct_value_ff(r, ff_of(t - inner), exps, coefs, count, rounding0);
  *v1 = direct_value_ff(r, ff_of(t + inner), exps, coefs, count, rounding1);
  return doubted && CERTAIN_SIGN_CHANGE(*v0, *rounding0, *v1, *rounding1);
}

/* Adaptive builds: clears the doubt of the found roots (roots, at: each root's point as its ray's origin, in unit
 * coordinates) that P's values confirm, in float lane by lane, and then in float-float for the lanes still in
 * doubt, together (unit: the rays from their starts). The probe sees which arithmetic confirmed it (decision 0 or
 * 1). */
static void confirm_flat_roots(uint count, LaneRoots* roots, const LaneRays* at, const LaneRays* unit,
                               __global const uint* exps, __global const REAL* coefs, uint mono_count,
                               ProbeLog* probe_log) {
  const LMASK found = (roots->flags & (LANE_INT_VEC)ALGRAY_HIT_FOUND) != 0;
  const uint doubted_bits = lane_mask_bits(found && (roots->flags & (LANE_INT_VEC)ALGRAY_HIT_DOUBT) != 0);
  for (uint j = 0; j < min(count, (uint)LANES); ++j) {
    if (!((doubted_bits >> j) & 1u)) continue;
    const REAL delta = (REAL)ALGRAY_DOUBT_POSITION * fabs(lane_get(roots->t, j));
    const REAL3 u = lane_origin(at, j), d = lane_direction(at, j);
    REAL2 rounding;
    const REAL2 v = direct_values(u - delta * d, u + delta * d, exps, coefs, mono_count, &rounding);
    if (!CERTAIN_SIGN_CHANGE(v.s0, rounding.s0, v.s1, rounding.s1)) continue;
    PROBE(ALGRAY_EVENT_CONFIRMED, 0, 0u, 0u, v.s0, rounding.s0, v.s1, rounding.s1);
    ((LANE_INT*)&roots->flags)[j] &= ~ALGRAY_HIT_DOUBT;
  }
  const LMASK still = found && (roots->flags & (LANE_INT_VEC)ALGRAY_HIT_DOUBT) != 0;
  if (!LANE_ANY(still)) return;
  LREAL v0, rounding0, v1, rounding1;
  const LMASK confirmed = confirmed_in_float_float(still, unit, LANE_SEL((LREAL)0, roots->t, still), exps, coefs,
                                                   mono_count, &v0, &rounding0, &v1, &rounding1);
  if (LANE_ANY(confirmed)) PROBE(ALGRAY_EVENT_CONFIRMED, 0, 1u, 0u, v0, rounding0, v1, rounding1);
  roots->flags &= LANE_SEL((LANE_INT_VEC)(-1), (LANE_INT_VEC)(~ALGRAY_HIT_DOUBT), confirmed);
}

/* grad P at (x, y, z), from the monomials, with a table of powers per axis; over lanes, each lane's point. */
static void surface_gradient(LREAL x, LREAL y, LREAL z, __global const uint* exps, __global const REAL* coefs,
                             uint count, LREAL* gx, LREAL* gy, LREAL* gz) {
  LREAL px[NCOEF], py[NCOEF], pz[NCOEF];
  px[0] = py[0] = pz[0] = 1;
  for (int n = 1; n <= DEGREE; ++n) {
    px[n] = px[n - 1] * x;
    py[n] = py[n - 1] * y;
    pz[n] = pz[n - 1] * z;
  }
  LREAL sx = 0, sy = 0, sz = 0;
  for (uint m = 0; m < count; ++m) {
    const uint e = exps[m];
    const int i = (int)(e & 0xffu), j = (int)((e >> 8) & 0xffu), k = (int)((e >> 16) & 0xffu);
    const REAL a = coefs[m];
    if (i > 0) sx += a * (REAL)i * px[i - 1] * py[j] * pz[k];
    if (j > 0) sy += a * (REAL)j * px[i] * py[j - 1] * pz[k];
    if (k > 0) sz += a * (REAL)k * px[i] * py[j] * pz[k - 1];
  }
  *gx = sx;
  *gy = sy;
  *gz = sz;
}

/* The hit records of the first `count` (<= LANES) of the lanes' rays: lane j of roots holds ray j's root, `at` the
 * rays in unit coordinates with each found root's point as the origin, `rays` the rays as traced. Depth, the normal
 * from grad P (taken together in lanes) facing the ray, and the side. */
static void hit_records(uint count, const LaneRays* rays, const LaneRays* at, const LaneRoots* roots,
                        __global const uint* exps, __global const REAL* coefs, uint mono_count, HitRecord* out) {
  const LMASK found = (roots->flags & (LANE_INT_VEC)ALGRAY_HIT_FOUND) != 0;
  const uint found_bits = lane_mask_bits(found);
  REAL depth_of[LANES], nx_of[LANES], ny_of[LANES], nz_of[LANES];
  uint usable_bits = 0, grows_bits = 0;
  if (found_bits) {
    /* lanes without a hit compute on zeros, never on a missed ray's infinities */
    const LREAL x = LANE_SEL((LREAL)0, at->ox, found), y = LANE_SEL((LREAL)0, at->oy, found),
                z = LANE_SEL((LREAL)0, at->oz, found);
    const LREAL dux = at->dx, duy = at->dy, duz = at->dz;
    const LREAL t = LANE_SEL((LREAL)0, roots->t, found);
    LREAL gx, gy, gz;
    surface_gradient(x, y, z, exps, coefs, mono_count, &gx, &gy, &gz);
    LREAL glen, dlen, g_dot_du;
    {
      /* length() and dot() as PoCL computes them: three products, added left to right */
#pragma OPENCL FP_CONTRACT OFF
      glen = sqrt((gx * gx + gy * gy) + gz * gz);
      dlen = sqrt((rays->dx * rays->dx + rays->dy * rays->dy) + rays->dz * rays->dz);
      g_dot_du = (gx * dux + gy * duy) + gz * duz;
    }
    /* Unit coordinates differ from world ones by a translation and a uniform scale: same normal direction. */
    LREAL nx = gx / glen, ny = gy / glen, nz = gz / glen, n_dot_d;
    {
#pragma OPENCL FP_CONTRACT OFF
      n_dot_d = (nx * rays->dx + ny * rays->dy) + nz * rays->dz;
    }
    const LMASK away = n_dot_d > 0;
    LANES_STORE(LANE_SEL(nx, -nx, away), nx_of);
    LANES_STORE(LANE_SEL(ny, -ny, away), ny_of);
    LANES_STORE(LANE_SEL(nz, -nz, away), nz_of);
    LANES_STORE(t * dlen, depth_of);
    usable_bits = lane_mask_bits(glen > 0 && isfinite(glen));
    grows_bits = lane_mask_bits(g_dot_du > 0);
  }
  REAL t_of[LANES], f_before_of[LANES];
  LANE_INT flags_of[LANES], steps_of[LANES], iterations_of[LANES];
  LANES_STORE(roots->t, t_of);
  LANES_STORE(roots->f_before, f_before_of);
  LANES_STORE(roots->flags, flags_of);
  LANES_STORE(roots->steps, steps_of);
  LANES_STORE(roots->iterations, iterations_of);
  /* Front is the side where P > 0; at an exact root use the direction in which P grows instead. */
  for (uint j = 0; j < min(count, (uint)LANES); ++j) {
    HitRecord r = missed_record();
    r.flags = (uint)flags_of[j];
    r.work = ALGRAY_WORK_PACK(min((uint)steps_of[j], ALGRAY_WORK_MAX), min((uint)iterations_of[j], ALGRAY_WORK_MAX));
    if ((found_bits >> j) & 1u) {
      const REAL root_t = t_of[j], f_before = f_before_of[j];
      r.t_hi = (float)root_t;
      r.t_lo = (float)(root_t - (REAL)r.t_hi);
      r.depth = (float)depth_of[j];
      REAL3 n = (REAL3)(nx_of[j], ny_of[j], nz_of[j]);
      if (!((usable_bits >> j) & 1u)) { /* no gradient to speak of: face the ray */
        const REAL3 d = (REAL3)(lane_get(rays->dx, j), lane_get(rays->dy, j), lane_get(rays->dz, j));
        n = -normalize(d);
        if (dot(n, d) > 0) n = -n;
      }
      r.normal_x = (float)n.x;
      r.normal_y = (float)n.y;
      r.normal_z = (float)n.z;
      const int back = f_before != 0 ? f_before < 0 : (grows_bits >> j) & 1u;
      if (back) r.flags |= ALGRAY_HIT_BACK;
    }
    out[j] = r;
  }
}

#if LANES > 1 && RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN
#define SCREEN_LANES 1
/* The screen form's coefficients for a group of lanes at once: screen_ray_taylor, restrict_from_taylor and
 * bernstein_from_scaled over lanes, each lane with the operations that those run one ray at a time (restrict.h:
 * the vector Horner steps), so every lane's coefficients are the one-ray
 * build's bit for bit (tests/test_lanes). One ray's steps are chains of dependent operations; over lanes the D + 1
 * coefficients' chains run side by side (above degree 15 too, where a camera ray restricted one at a time made
 * float 0.63-0.70x double's rate; bench/RESULTS.md, "Float against double, per degree"). row: the image row's
 * polynomials (screen_rows); xi: each lane's column; tau_in, tau_out: each lane's segment about the row's t0. */
ALGRAY_INLINE void screen_coefficients(__global const REAL* row, LREAL xi, LREAL tau_in, LREAL tau_out,
                                       __constant const REAL* binomials, LREAL* out) {
  LREAL taylor[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) taylor[k] = (LREAL)row[DEGREE * NCOEF + k];
  ALGRAY_UNROLL
  for (int j = DEGREE - 1; j >= 0; --j) ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) taylor[k] = taylor[k] * xi + row[j * NCOEF + k];
  const LREAL l0 = tau_in, l1 = RESTRICT_BERNSTEIN ? tau_out : tau_out - tau_in;
  LREAL c[NCOEF];
  c[0] = taylor[DEGREE];
  ALGRAY_UNROLL
  for (int k = 1; k <= DEGREE; ++k) c[k] = 0;
  ALGRAY_UNROLL
  for (int n = DEGREE - 1; n >= 0; --n) {
    /* acc_mul_linear: l0 c + l1 (c shifted up one, a zero below) */
    ALGRAY_UNROLL
    for (int k = DEGREE; k > 0; --k) c[k] = l0 * c[k] + l1 * c[k - 1];
    /* the vector step adds the shifted-in zero (a -0 becomes +0) */
    c[0] = l0 * c[0] + l1 * (LREAL)0;
    /* acc_add_constant */
    if (RESTRICT_BERNSTEIN) {
      ALGRAY_UNROLL
      for (int k = 0; k <= DEGREE; ++k) c[k] += taylor[n] * binomials[(DEGREE - n) * NCOEF + k];
    } else {
      c[0] += taylor[n];
    }
  }
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) out[k] = c[k] / binomials[DEGREE * NCOEF + k]; /* bernstein_from_scaled */
}
#else
#define SCREEN_LANES 0
#endif

/* The hit records of the first `count` (<= LANES) of the rays, or 0 when none enters the extent (records then left
 * alone: each is missed_record()). They are clipped together, each is restricted on its own (the screen form's
 * lanes: together), then all are isolated, refined and their normals taken together, in vector lanes (lanes.h)
 * where LANES > 1, with the one-ray build's records bit for bit (tests/test_lanes). Camera and secondary rays, and
 * the probe, share it. px0, py: the first ray's pixel, and screen_rows .. xi_offset the image rows' polynomials, for
 * the screen form (other builds never read them). */
static int trace_rays(uint count, const LaneRays* rays, REAL3 centre, REAL inv_scale, REAL3 box_half, int extent_kind,
                      __global const REAL4* clip_planes, uint clip_count, __global const uint* exps,
                      __global const REAL* coefs, uint mono_count, __constant const REAL* binomials, uint even_axes,
                      HitRecord* records, uint px0, uint py, __global const REAL* screen_rows, uint screen_row0,
                      REAL screen_t, REAL xi_scale, REAL xi_offset, ProbeLog* probe_log) {
  LaneIsolation iso;
  LaneRoots roots;
  LREAL iso_c[NCOEF], lane_t_in, lane_t_out;
  LaneRays unit;
  const LMASK running =
      enter_extent(count, rays, centre, inv_scale, box_half, extent_kind, clip_planes, clip_count, &unit, &lane_t_in,
                   &lane_t_out, probe_log);
  /* no ray enters the extent (whole groups of most views): the caller writes missed_record() for each */
  if (!LANE_ANY(running)) return 0;
#if SCREEN_LANES
  /* screen_ray_taylor's column and segment_coefficients' segment about t0 */
  const LREAL xi = LANE_SEL((LREAL)0, SCREEN_COLUMN(lane_pixel_centres(px0), xi_scale, xi_offset), running);
  LREAL lane_root[NCOEF];
  screen_coefficients(screen_row(screen_rows, py, screen_row0), xi, LANE_SEL((LREAL)0, lane_t_in - screen_t, running),
                      LANE_SEL((LREAL)1, lane_t_out - screen_t, running), binomials, lane_root);
  /* lanes outside the extent start from zeros, as isolate_rays gives them */
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) lane_root[k] = LANE_SEL((LREAL)0, lane_root[k], running);
  LaneTerms screen_lanes;
  if (ALGRAY_ESCALATE) {
    screen_lanes.value =
        LANE_SEL((LREAL)0,
                 screen_terms(screen_row(screen_rows, py, screen_row0), xi, lane_t_in - screen_t, lane_t_out - screen_t),
                 running);
    screen_lanes.by_part = 0;
    screen_lanes.rays = &unit;
    screen_lanes.exps = exps;
    screen_lanes.coefs = coefs;
    screen_lanes.count = mono_count;
  }
  isolate_bernstein_search(running, lane_root, lane_root, lane_t_in, lane_t_out, (const SearchStart*)0, &iso, iso_c,
                           ALGRAY_ESCALATE ? &screen_lanes : (LaneTerms*)0, probe_log);
#else
  /* one ray at a time: each lane's segment and whether it entered. The loops over lanes run to min(count, LANES),
   * never to count alone: a bound the compiler cannot see is at most 1 kept one-ray builds' arrays in memory (8%
   * of the lemniscate's one-ray kernel). */
  REAL t_in[LANES], t_out[LANES];
  LANES_STORE(lane_t_in, t_in);
  LANES_STORE(lane_t_out, t_out);
  int in_extent[LANES];
  const uint entered_bits = lane_mask_bits(running);
  for (uint j = 0; j < LANES; ++j) in_extent[j] = (entered_bits >> j) & 1u;
  REAL root[LANES][NCOEF], root_lo[LANES][NCOEF];
  RayTerms terms[LANES];
  for (uint j = 0; j < min(count, (uint)LANES); ++j) {
    if (!in_extent[j]) continue;
    REAL taylor[NCOEF], taylor_t = 0;
    if (RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN)
      taylor_t = screen_ray_taylor(px0 + j, py, screen_rows, screen_row0, screen_t, xi_scale, xi_offset, taylor);
    segment_coefficients(lane_origin(&unit, j), lane_direction(&unit, j), t_in[j], t_out[j], exps, coefs, mono_count,
                         binomials, even_axes, root[j], root_lo[j], &terms[j], taylor, taylor_t, probe_log);
    if (RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN && ALGRAY_ESCALATE)
      terms[j] = screen_ray_terms(lane_get(screen_terms(screen_row(screen_rows, py, screen_row0),
                                                        screen_column(px0 + j, xi_scale, xi_offset),
                                                        t_in[j] - taylor_t, t_out[j] - taylor_t),
                                           0),
                                  lane_origin(&unit, j), lane_direction(&unit, j), t_in[j], t_out[j], exps, coefs,
                                  mono_count);
  }
  isolate_rays(count, in_extent, &unit, root, root_lo, t_in, t_out, &iso, iso_c, terms, probe_log);
#endif
  refine_rays(running, &iso, iso_c, lane_t_in, lane_t_out, binomials, &roots, probe_log);
  /* `at` moves each found root's ray to its point */
  const LMASK found = (roots.flags & (LANE_INT_VEC)ALGRAY_HIT_FOUND) != 0;
  LaneRays at = unit;
  if (LANE_ANY(found)) {
    const LREAL t = LANE_SEL((LREAL)0, roots.t, found);
    at.ox = LANE_SEL(unit.ox, unit.ox + t * unit.dx, found);
    at.oy = LANE_SEL(unit.oy, unit.oy + t * unit.dy, found);
    at.oz = LANE_SEL(unit.oz, unit.oz + t * unit.dz, found);
  }
  if (ALGRAY_ESCALATE) confirm_flat_roots(count, &roots, &at, &unit, exps, coefs, mono_count, probe_log);
  hit_records(count, rays, &at, &roots, exps, coefs, mono_count, records);
  return 1;
}

#endif /* ALGRAY_SURFACE_H */
