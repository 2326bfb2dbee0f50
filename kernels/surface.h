/* One ray against one surface: clip, restrict, isolate the smallest root, refine it; then its normal and side. */
#ifndef ALGRAY_SURFACE_H
#define ALGRAY_SURFACE_H

#include "algray_shared.h"
#include "float_float.h"
#include "lanes.h"
#include "ray.h"
#include "real.h"

#if RAY_ORIGIN == ALGRAY_ORIGIN_EYE && ISOLATION == ALGRAY_ISOLATION_BERNSTEIN
#error "RAY_ORIGIN=eye needs a power-basis isolation method"
#endif
#if ALGRAY_ESCALATE && ISOLATION != ALGRAY_ISOLATION_BERNSTEIN
#error "adaptive precision doubts rays in the Bernstein isolation only"
#endif
#if RAY_ORIGIN != ALGRAY_ORIGIN_EXTENT && ALGRAY_ESCALATE
#error "adaptive precision builds P*(t) on the segment (RAY_ORIGIN=extent), whose terms it measures its noise by"
#endif
#if RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN && ALGRAY_COMPENSATED
#error "RAY_ORIGIN=screen is built in plain float or double"
#endif

/* The screen form hands each camera ray's Taylor coefficients, about t = taylor_t, to the solver (taylor and
 * taylor_t, which other builds pass as 0 and never read). Its kernels take the image rows' polynomials:
 * screen_rows[(py - screen_row0) * NCOEF * NCOEF + j * NCOEF + k] is the xi^j coefficient of row py's taylor[k],
 * expanded about t = screen_t; a pixel's xi = (px + 1/2) * xi_scale + xi_offset. */
#if RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN

/* The xi of a pixel column whose centre is `centre` ((REAL)px + 0.5, as camera_ray's), where its row's polynomials
 * are evaluated; of one column or of lanes (lane_pixel_centres). */
#define SCREEN_COLUMN(centre, xi_scale, xi_offset) ((centre) * (xi_scale) + (xi_offset))

ALGRAY_INLINE REAL screen_column(uint px, REAL xi_scale, REAL xi_offset) {
  return SCREEN_COLUMN((REAL)px + (REAL)0.5, xi_scale, xi_offset);
}

/* Image row py's polynomials in xi (screen_taylor's row). */
ALGRAY_INLINE __global const REAL* screen_row(__global const REAL* rows, uint py, uint row0) {
  return rows + (size_t)(py - row0) * (NCOEF * NCOEF);
}

/* Pixel (px, py)'s Taylor coefficients; returns the t they are expanded about. */
REAL screen_ray_taylor(uint px, uint py, __global const REAL* rows, uint row0, REAL t0, REAL xi_scale, REAL xi_offset,
                       REAL* taylor) {
  screen_taylor(screen_row(rows, py, row0), screen_column(px, xi_scale, xi_offset), taylor);
  return t0;
}
#endif

/* The outcome of isolating and refining the smallest root of P*(t) on [t_in, t_out]. */
typedef struct {
  REAL t;          /* the root; meaningful with ALGRAY_HIT_FOUND */
  REAL f_before;   /* P at the left end of the isolating interval */
  uint flags;      /* ALGRAY_HIT_FOUND, ALGRAY_HIT_BUDGET */
  uint steps;      /* isolation intervals examined */
  uint iterations; /* refinement iterations */
} SegmentRoot;

/* SegmentRoot for LANES rays side by side (trace_lanes), lane j ray j's; with LANES = 1, one ray's (hit_record). */
typedef struct {
  LREAL t, f_before;
  LANE_INT_VEC flags, steps, iterations;
} LaneRoots;

typedef struct {
  SegmentRoot root; /* root.t: the ray parameter of the hit; root.flags also carries ALGRAY_HIT_IN_EXTENT */
  REAL3 u;          /* hit point in unit coordinates */
  REAL3 d_unit;     /* ray direction in unit coordinates */
} SurfaceHit;

/* The probe records the coefficients the isolation starts from, in its basis; a render build has no such call. */
#if ALGRAY_PROBE
void probe_coefficients(const REAL* c, const REAL* c_lo, uint basis, ProbeLog* probe_log) {
  for (int k = 0; k <= DEGREE; ++k)
    PROBE(ALGRAY_EVENT_COEFFICIENT, k, basis, 0u, c[k], ALGRAY_COMPENSATED ? c_lo[k] : (REAL)0, (REAL)0, (REAL)0);
}
#else
#define probe_coefficients(c, c_lo, basis, probe_log) ((void)0)
#endif

/* The refinement's stopping width in y on the isolating interval [lo, hi] of the segment [t_in, t_out] (lo and hi
 * fractions of it): the stopping width at the interval's left end over the interval's width in t. Of one ray or
 * of lanes. */
#define ISOLATED_TOL_Y(lo, hi, t_in, t_out) \
  (STOP_WIDTH((t_in) + (lo) * ((t_out) - (t_in))) / (((hi) - (lo)) * ((t_out) - (t_in))))

/* The record of a ray that misses the extent, as enter_surface starts it. */
ALGRAY_INLINE SegmentRoot missed_root(void) {
  SegmentRoot r;
  r.t = INFINITY;
  r.f_before = 0;
  r.flags = 0;
  r.steps = 0;
  r.iterations = 0;
  return r;
}

/* The hit record of a ray that misses the extent: hit_records_lanes starts every record from it. */
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

/* The record of what the isolation found, before refinement; a bracket (ISOLATION_BRACKET) is refined next. */
SegmentRoot isolated_root(Isolation iso, ProbeLog* probe_log) {
  SegmentRoot r = missed_root();
  r.flags = iso.budget ? ALGRAY_HIT_BUDGET : 0u;
  r.steps = iso.steps;
  PROBE(ALGRAY_EVENT_ISOLATED, iso.budget, (uint)iso.status, 0u, iso.lo, iso.hi, iso.f_lo, iso.f_hi);
  if (iso.doubt) r.flags |= ALGRAY_HIT_DOUBT;
  if (iso.status == ISOLATION_EXACT) r.flags |= ALGRAY_HIT_EXACT;
  if (iso.status != ISOLATION_NONE && iso.cluster) r.flags |= ALGRAY_HIT_CLUSTER;
  return r;
}

/* The size of the isolating interval's coefficients, for the refinement's value stop; over lanes, each lane's. */
LREAL coefficient_scale(const LREAL* c) {
  LREAL scale = 0;
  for (int k = 0; k <= DEGREE; ++k) scale = fmax(scale, fabs(c[k]));
  return scale;
}

/* The ray parameter of the point y of the isolating interval [lo, hi] (fractions of [t_in, t_out]); of one ray or
 * of lanes. */
#define PLACED_ROOT_T(lo, hi, y, t_in, t_out) ((t_in) + ((lo) + (y) * ((hi) - (lo))) * ((t_out) - (t_in)))

/* The root at y of the isolating interval (0 when the isolation settled it at the interval's left end). */
void place_root(SegmentRoot* r, Isolation iso, REAL y, REAL t_in, REAL t_out) {
  r->t = PLACED_ROOT_T(iso.lo, iso.hi, y, t_in, t_out);
  r->f_before = iso.f_lo;
  r->flags |= ALGRAY_HIT_FOUND;
}

/* Adaptive builds: whether the root at y of the isolating interval (prepared coefficients c) could move by more
 * than ALGRAY_DOUBT_POSITION of its t under the coefficients' noise, read off P's slope there: the secant of the
 * isolating interval can be many times steeper than P at the root (a Kummer shell ray: 60 times, with the root
 * 1e-3 off). Then r is marked doubted. */
/* How far the root at t may move, read off P's slope on the isolating interval [lo, hi]: for one ray and for lanes
 * alike, so that both take the same operations. */
#define FLAT_ROOT_MARGIN(slope, t, lo, hi, t_in, t_out) \
  (fabs(slope) * ALGRAY_DOUBT_POSITION * fabs(t) / (((hi) - (lo)) * ((t_out) - (t_in))))
void doubt_flat_root(SegmentRoot* r, Isolation iso, const REAL* c, REAL y, REAL t_in, REAL t_out, ProbeLog* probe_log) {
#if ALGRAY_ESCALATE
  REAL slope;
  (void)isolated_value_slope(c, y, &slope);
  const REAL margin = FLAT_ROOT_MARGIN(slope, r->t, iso.lo, iso.hi, t_in, t_out);
  if (!(margin <= iso.noise)) return;
  PROBE(ALGRAY_EVENT_DOUBT, 0, ALGRAY_DOUBT_FLAT, 0u, iso.lo, iso.hi, margin, iso.noise);
  r->flags |= ALGRAY_HIT_DOUBT;
#else
  (void)r;
  (void)iso;
  (void)c;
  (void)y;
  (void)t_in;
  (void)t_out;
#endif
}

#if LANES == 1
/* Refines what the isolation found; iso_c holds the polynomial on the isolating interval (consumed). */
SegmentRoot refine_isolated(Isolation iso, REAL* iso_c, REAL t_in, REAL t_out,
                            __constant const REAL* binomials, ProbeLog* probe_log) {
  SegmentRoot r = isolated_root(iso, probe_log);
  if (iso.status == ISOLATION_NONE) return r;
  REAL y = 0;
  const int refine = iso.status == ISOLATION_BRACKET;
  if (refine) {
    const REAL tol_y = ISOLATED_TOL_Y(iso.lo, iso.hi, t_in, t_out);
    const REAL scale = coefficient_scale(iso_c), start = isolated_start(iso_c);
    prepare_isolated(iso_c, binomials);
#if REFINE_IN_CLOSED_FORM
    (void)scale;
    (void)start;
    y = line_root(iso.f_lo, iso.f_hi);
#else
    y = refine_root(iso_c, iso.f_lo, iso.f_hi, tol_y, scale, start, &r.iterations, probe_log);
#endif
  }
  place_root(&r, iso, y, t_in, t_out);
  if (refine) doubt_flat_root(&r, iso, iso_c, y, t_in, t_out, probe_log);
  return r;
}
#else
/* The roots of LANES rays' isolations, refined together in lanes (lanes.h), in vectors throughout: c holds each
 * lane's polynomial on its isolating interval (consumed); t_in, t_out each lane's segment. Lanes that missed the
 * extent (not in `entered`) get missed_root()'s fields; every other lane isolated_root's, then place_root's where
 * a root was found, with ALGRAY_HIT_IN_EXTENT. */
void refine_lanes(LMASK entered, const LaneIsolation* iso, LREAL* c, LREAL t_in, LREAL t_out,
                  __constant const REAL* binomials, LaneRoots* roots) {
  /* isolated_root's flags */
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
#if REFINE_IN_CLOSED_FORM
    (void)scale;
    (void)tol_y;
    (void)start;
    y = LANE_SEL((LREAL)0, line_root(f0, f1), running);
#else
    y = LANE_SEL((LREAL)0, refine_root_lanes(c, f0, f1, tol_y, scale, start, running, &iterations, NO_PROBE), running);
#endif
  }
  /* place_root, where the isolation found a root (a bracket refined, or one settled at an end: y = 0) */
  roots->t = LANE_SEL((LREAL)INFINITY, PLACED_ROOT_T(iso->lo, iso->hi, y, t_in, t_out), found);
  roots->f_before = LANE_SEL((LREAL)0, iso->f_lo, found);
  roots->flags = flags | FLAG_WHERE(ALGRAY_HIT_FOUND, found);
#undef FLAG_WHERE
  roots->steps = LANE_SEL((LANE_INT_VEC)0, LANE_TO_INT(iso->steps), entered);
  roots->iterations = LANE_SEL((LANE_INT_VEC)0, iterations, running);
#if ALGRAY_ESCALATE
  /* doubt_flat_root over lanes, each lane with its operations (taken lane by lane, the coefficients' trip through
   * memory and the scalar slopes were 60% of what adaptive added to the cusp catastrophe's camera pass) */
  if (LANE_ANY(running)) {
    LREAL slope;
    (void)isolated_value_slope_lanes(c, y, &slope);
    const LREAL margin = FLAT_ROOT_MARGIN(slope, roots->t, iso->lo, iso->hi, t_in, t_out);
    roots->flags |= LANE_SEL((LANE_INT_VEC)0, (LANE_INT_VEC)ALGRAY_HIT_DOUBT, running && margin <= iso->noise);
  }
#endif
}
#endif

#if RAY_ORIGIN == ALGRAY_ORIGIN_EXTENT || RAY_ORIGIN == ALGRAY_ORIGIN_POINT
/* The coordinates' factors of the ray o + t*d restricted to [t_in, t_out] as s in [0, 1], in the isolation's
 * basis: entry and exit points for the Bernstein form, entry point and chord for the power basis. */
void segment_factors(REAL3 o, REAL3 d, REAL t_in, REAL t_out, uint even_axes, AxisFactor* fx, AxisFactor* fy,
                     AxisFactor* fz) {
  const REAL3 pa = o + t_in * d, pb = o + t_out * d;
#if ISOLATION == ALGRAY_ISOLATION_BERNSTEIN
  const REAL3 l1 = pb;
#else
  const REAL3 l1 = pb - pa;
#endif
  *fx = axis_factor(pa.x, l1.x, even_axes & 1);
  *fy = axis_factor(pa.y, l1.y, even_axes & 2);
  *fz = axis_factor(pa.z, l1.z, even_axes & 4);
}

#endif

/* The restriction's result (scaled Bernstein coefficients, or a power basis) as the isolation method takes it. */
void restricted_to_isolation_basis(REAL* root, REAL* root_lo, __constant const REAL* binomials, ProbeLog* probe_log) {
#if ISOLATION == ALGRAY_ISOLATION_BERNSTEIN
  bernstein_from_scaled(root, root_lo, binomials);
  probe_coefficients(root, root_lo, ALGRAY_BASIS_BERNSTEIN, probe_log);
#elif RAY_ORIGIN == ALGRAY_ORIGIN_EYE
  (void)binomials;
  probe_coefficients(root, root_lo, ALGRAY_BASIS_POWER_EYE, probe_log);
#else
  (void)binomials;
  probe_coefficients(root, root_lo, ALGRAY_BASIS_POWER_SEGMENT, probe_log);
#endif
}

/* P*(t) on [t_in, t_out] for the ray o + t*d in unit coordinates, in the isolation method's basis: Bernstein
 * coefficients on the segment, or the power basis of the segment (of the whole ray, for RAY_ORIGIN=eye). */
ALGRAY_INLINE void segment_coefficients(REAL3 o, REAL3 d, REAL t_in, REAL t_out, __global const uint* exps,
                                        __global const REAL* coefs, uint count, __constant const REAL* binomials,
                                        uint even_axes, REAL* root,
                                        REAL* root_lo, RayTerms* terms, const REAL* taylor, REAL taylor_t,
                                        ProbeLog* probe_log) {
#if RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN
  /* The same coefficients the extent construction computes from the monomials, from D + 1 numbers instead. */
  (void)o;
  (void)d;
  (void)exps;
  (void)coefs;
  (void)count;
  (void)even_axes;
  restrict_from_taylor(taylor, t_in - taylor_t, t_out - taylor_t, binomials, root);
#elif RAY_ORIGIN == ALGRAY_ORIGIN_EYE
  /* The paper's construction: P*(t) around the ray origin, then mapped to each subinterval. */
  (void)t_in;
  (void)t_out;
  restrict_to_ray(exps, coefs, count, binomials, axis_factor(o.x, d.x, even_axes & 1),
                  axis_factor(o.y, d.y, even_axes & 2), axis_factor(o.z, d.z, even_axes & 4), root, root_lo);
#else
  AxisFactor fx, fy, fz;
  segment_factors(o, d, t_in, t_out, even_axes, &fx, &fy, &fz);
  restrict_to_ray(exps, coefs, count, binomials, fx, fy, fz, root, root_lo);
#if ALGRAY_ESCALATE
  *terms = ray_terms(exps, coefs, count, fx, fy, fz);
  terms->has_ray = 1;
  terms->o = o;
  terms->d = d;
  terms->t_in = t_in;
  terms->t_out = t_out;
#endif
#endif
  restricted_to_isolation_basis(root, root_lo, binomials, probe_log);
}

/* Isolates the smallest root of P*(t) on [t_in, t_out] for the ray o + t*d in unit coordinates; iso_c gets
 * the polynomial on the isolating interval. The primary and shadow kernels share this: one refines what it
 * returns, the other only asks whether there is anything to refine. */
Isolation isolate_on_segment(REAL3 o, REAL3 d, REAL t_in, REAL t_out, __global const uint* exps,
                             __global const REAL* coefs, uint count, __constant const REAL* binomials, uint even_axes,
                             REAL* iso_c, const REAL* taylor, REAL taylor_t, ProbeLog* probe_log) {
  REAL root[NCOEF], root_lo[NCOEF];
  RayTerms terms;
  segment_coefficients(o, d, t_in, t_out, exps, coefs, count, binomials, even_axes, root,
                       root_lo, &terms, taylor, taylor_t, probe_log);
  return isolate_method(root, root_lo, t_in, t_out, iso_c, &terms, probe_log);
}

#if RAY_ORIGIN == ALGRAY_ORIGIN_EXTENT
/* Isolates the smallest root on [t_in, t_out] from the coefficients restrict_to_rays made of segment_factors'
 * factors (root, root_lo are consumed), as isolate_on_segment would; iso_c gets the polynomial on the isolating
 * interval. */
Isolation isolate_restricted(REAL* root, REAL* root_lo, REAL t_in, REAL t_out, __constant const REAL* binomials,
                             REAL* iso_c, RayTerms* terms, ProbeLog* probe_log) {
  restricted_to_isolation_basis(root, root_lo, binomials, probe_log);
  return isolate_method(root, root_lo, t_in, t_out, iso_c, terms, probe_log);
}
#endif

/* The start of trace_surface: the ray in unit coordinates (h->u, h->d_unit), clipped to the extent. Returns 0
 * when the ray misses the extent; *h is then the whole answer. */
int enter_surface(Ray ray, REAL3 centre, REAL inv_scale, REAL3 box_half, int extent_kind, SurfaceHit* h, REAL* t_in,
                  REAL* t_out, ProbeLog* probe_log) {
  h->root = missed_root();
  /* Unit coordinates keep every point of the extent within |u| <= 1: the conditioning step that makes float usable. */
  h->u = (ray.o - centre) * inv_scale;
  h->d_unit = ray.d * inv_scale;
  if (!clip_to_extent(h->u, h->d_unit, extent_kind, box_half, t_in, t_out)) return 0;
  PROBE(ALGRAY_EVENT_SEGMENT, 0, 0u, 0u, *t_in, *t_out, (REAL)0, (REAL)0);
  h->root.flags = ALGRAY_HIT_IN_EXTENT;
  return 1;
}

#if LANES > 1
/* enter_surface for LANES rays at once: unit gets each lane's ray in unit coordinates (as enter_surface's h->u and
 * h->d_unit, bit for bit), and *lane_t_in, *lane_t_out each lane's segment (0 and 1 where it misses). Returns the
 * lanes that enter the extent (none from `count` on). */
LMASK enter_lanes(uint count, const LaneRays* rays, REAL3 centre, REAL inv_scale, REAL3 box_half, int extent_kind,
                  LaneRays* unit, LREAL* lane_t_in, LREAL* lane_t_out) {
  unit->ox = (rays->ox - centre.x) * inv_scale;
  unit->oy = (rays->oy - centre.y) * inv_scale;
  unit->oz = (rays->oz - centre.z) * inv_scale;
  unit->dx = rays->dx * inv_scale;
  unit->dy = rays->dy * inv_scale;
  unit->dz = rays->dz * inv_scale;
  LREAL lo, hi;
  const LMASK inside = lanes_of_bits((1u << count) - 1u) &&
                       clip_lanes_to_extent(unit->ox, unit->oy, unit->oz, unit->dx, unit->dy, unit->dz, extent_kind,
                                            box_half, &lo, &hi);
  *lane_t_in = LANE_SEL((LREAL)0, lo, inside);
  *lane_t_out = LANE_SEL((LREAL)1, hi, inside);
  return inside;
}

/* Lane j of rays as one ray (REAL3 origin and direction). */
ALGRAY_INLINE REAL3 lane_origin(const LaneRays* rays, uint j) {
  return (REAL3)(lane_get(rays->ox, j), lane_get(rays->oy, j), lane_get(rays->oz, j));
}
ALGRAY_INLINE REAL3 lane_direction(const LaneRays* rays, uint j) {
  return (REAL3)(lane_get(rays->dx, j), lane_get(rays->dy, j), lane_get(rays->dz, j));
}
#endif

/* The part of trace_surface before the refinement: enter_surface, then the isolation of P*(t)'s smallest root
 * on the segment (iso_c: the polynomial on the isolating interval). Returns 0 when the ray misses the extent. */
int isolate_surface(Ray ray, REAL3 centre, REAL inv_scale, REAL3 box_half, int extent_kind, __global const uint* exps,
                    __global const REAL* coefs, uint count, __constant const REAL* binomials, uint even_axes,
                    SurfaceHit* h, Isolation* iso, REAL* t_in, REAL* t_out, REAL* iso_c, const REAL* taylor,
                    REAL taylor_t, ProbeLog* probe_log) {
  if (!enter_surface(ray, centre, inv_scale, box_half, extent_kind, h, t_in, t_out, probe_log)) return 0;
  *iso = isolate_on_segment(h->u, h->d_unit, *t_in, *t_out, exps, coefs, count, binomials, even_axes,
                            iso_c, taylor, taylor_t, probe_log);
  return 1;
}

#if LANES > 1
#if ALGRAY_ESCALATE && !ALGRAY_COMPENSATED
/* terms_sum over lanes (restrict.h): every lane's ray terms summed at once, each the value ray_terms_exact would
 * give it. Summed one lane at a time, they were a tenth of the Endrass octic's adaptive camera pass. */
DEFINE_TERMS_SUM(terms_sum_lanes, LREAL)
#endif

/* The isolations of LANES rays from their segment_coefficients (root, root_lo are consumed): together in lanes
 * (isolate_bernstein_lanes), or one lane at a time in mixed precision. c gets each lane's polynomial on its
 * isolating interval, for refine_lanes. Lanes from `count` on, and those whose ray missed the extent
 * (in_extent[j] == 0), are left alone. rays: the lanes' rays in unit coordinates, where adaptive builds' search
 * evaluates P in float-float (bracket_ends_in_float_float). */
void isolate_lanes(uint count, const int* in_extent, const LaneRays* rays, REAL (*root)[NCOEF], REAL (*root_lo)[NCOEF],
                   const REAL* t_in, const REAL* t_out, LaneIsolation* iso, LREAL* c, RayTerms* terms) {
  (void)rays; /* adaptive builds' search checks its accept doubts on them */
  for (int k = 0; k <= DEGREE; ++k) c[k] = 0;
#if ALGRAY_COMPENSATED
  for (uint j = 0; j < LANES; ++j) set_lane_isolation(iso, j, isolation_none());
  for (uint j = 0; j < count; ++j) {
    if (!in_extent[j]) continue;
    REAL iso_c[NCOEF];
    set_lane_isolation(iso, j,
                       isolate_method(root[j], root_lo[j], t_in[j], t_out[j], iso_c, &terms[j], NO_PROBE));
    for (int k = 0; k <= DEGREE; ++k) lane_set(&c[k], j, iso_c[k]);
  }
#else
  (void)root_lo;
  LREAL lane_root[NCOEF], lane_t_in = 0, lane_t_out = 1, lane_terms = 0;
  for (int k = 0; k <= DEGREE; ++k) lane_root[k] = 0;
  LMASK running = 0;
#if ALGRAY_ESCALATE
  LREAL x = 0, y = 0, z = 0; /* each ray's largest coordinates, where its terms are summed */
  uint first = LANES; /* the first ray in the extent: its terms name the monomials */
#endif
  for (uint j = 0; j < count; ++j) {
    if (!in_extent[j]) continue;
    lane_set_mask(&running, j, 1);
    for (int k = 0; k <= DEGREE; ++k) lane_set(&lane_root[k], j, root[j][k]);
    lane_set(&lane_t_in, j, t_in[j]);
    lane_set(&lane_t_out, j, t_out[j]);
#if ALGRAY_ESCALATE
    if (first == LANES) first = j;
    lane_set(&x, j, terms[j].x);
    lane_set(&y, j, terms[j].y);
    lane_set(&z, j, terms[j].z);
#endif
  }
#if ALGRAY_ESCALATE
  if (LANE_ANY(running)) {
    lane_terms = terms_sum_lanes(terms[first].exps, terms[first].coefs, terms[first].count, x, y, z);
    REAL terms_of[LANES];
    LANES_STORE(lane_terms, terms_of);
    for (uint j = 0; j < count; ++j) {
      if (!in_extent[j]) continue;
      terms[j].value = terms_of[j];
      terms[j].exact = 1;
    }
  }
#endif
  (void)lane_terms;
  if (LANE_ANY(running)) {
    LaneTerms search_terms;
#if ALGRAY_ESCALATE
    search_terms.value = lane_terms;
    search_terms.rays = rays;
    search_terms.exps = terms[first].exps;
    search_terms.coefs = terms[first].coefs;
    search_terms.count = terms[first].count;
#endif
    isolate_bernstein_lanes(running, lane_root, lane_t_in, lane_t_out, iso, c, &search_terms);
  }
#endif
}
#endif

/* The hit of a ray that entered the extent, from its refined root. */
void finish_surface(SurfaceHit* h, SegmentRoot root) {
  h->root = root;
  h->root.flags |= ALGRAY_HIT_IN_EXTENT;
  if (h->root.flags & ALGRAY_HIT_FOUND) h->u = h->u + h->root.t * h->d_unit;
}

/* Adaptive builds: a root doubted as flat (doubt_flat_root) is kept after all where P, evaluated from the
 * monomials at t -+ ALGRAY_DOUBT_POSITION |t| on the ray, has opposite signs beyond that evaluation's rounding:
 * then a root lies within what the flat check allows. The check held the root to the coefficients' noise, which
 * sums the terms over the whole segment, out to the extent's sphere; at a root inside, the terms are far smaller
 * (the Barth decic's flat-doubted roots: 1e-4 to 2e-3 of the segment's), and so is P's rounding there.
 * Measured on the decic at 1024x768: 61% fewer camera rays traced again (bench/RESULTS.md). Where float's
 * rounding is still too large (surfaces whose monomials cancel by orders of magnitude, such as Chebyshev sums),
 * P is evaluated again in float-float, whose rounding is float's squared: over the lanes together, that costs less
 * than the second pass even in double (bench/history/2026-12.md, "Flat roots confirmed in float-float"). */
#if ALGRAY_ESCALATE
/* P at q from the monomials (the power tables of axis_powers, restrict.h), and a bound on its rounding: the
 * products, the sum, and the rounding of q's coordinates and of the coefficients, each of at most REAL_EPS / 2
 * per operation to first order, with room. */
REAL direct_value(REAL3 q, __global const uint* exps, __global const REAL* coefs, uint count, REAL* rounding) {
  REAL px[NCOEF], py[NCOEF], pz[NCOEF];
  axis_powers(q, px, py, pz);
  REAL value = 0, size = 0;
  for (uint m = 0; m < count; ++m) {
    const uint e = exps[m];
    const REAL term = coefs[m] * px[e & 0xffu] * py[(e >> 8) & 0xffu] * pz[(e >> 16) & 0xffu];
    value += term;
    size += fabs(term);
  }
  *rounding = size * (REAL)(2 * DEGREE + 4 + (int)count) * REAL_EPS;
  return value;
}

/* Whether values v0 and v1 stand beyond their roundings with opposite signs (of one ray or of lanes): then P
 * changes sign between them. */
#define CERTAIN_SIGN_CHANGE(v0, rounding0, v1, rounding1) \
  (fabs(v0) > (rounding0) && fabs(v1) > (rounding1) && ((v0) > 0) != ((v1) > 0))

/* The float-float check of confirm_flat_root for the lanes in `doubted` (roots at t, rays r from their starts),
 * at t -+ delta with delta shrunk by 2^-10, so that their own rounding keeps the points within
 * ALGRAY_DOUBT_POSITION |t| of t; the lanes it confirms. *v0 ... *rounding1: the values and their bounds. */
LMASK confirmed_in_float_float(LMASK doubted, const LaneRays* r, LREAL t, __global const uint* exps,
                               __global const REAL* coefs, uint count, LREAL* v0, LREAL* rounding0, LREAL* v1,
                               LREAL* rounding1) {
  const LREAL inner = (REAL)ALGRAY_DOUBT_POSITION * (REAL)(1 - 1.0 / 1024) * fabs(t);
  *v0 = direct_value_ff(r, ff_of(t - inner), exps, coefs, count, rounding0);
  *v1 = direct_value_ff(r, ff_of(t + inner), exps, coefs, count, rounding1);
  return doubted && CERTAIN_SIGN_CHANGE(*v0, *rounding0, *v1, *rounding1);
}

/* h: a found root (h->u its point), u the ray's start; clears the doubt when P's values confirm it, in float or
 * else in float-float (the probe's event says which: decision 0 or 1). */
void confirm_flat_root(SurfaceHit* h, REAL3 u, __global const uint* exps, __global const REAL* coefs,
                       uint count, ProbeLog* probe_log) {
  if ((h->root.flags & (ALGRAY_HIT_FOUND | ALGRAY_HIT_DOUBT)) != (ALGRAY_HIT_FOUND | ALGRAY_HIT_DOUBT)) return;
  const REAL delta = (REAL)ALGRAY_DOUBT_POSITION * fabs(h->root.t);
  REAL rounding0, rounding1;
  REAL v0 = direct_value(h->u - delta * h->d_unit, exps, coefs, count, &rounding0);
  REAL v1 = direct_value(h->u + delta * h->d_unit, exps, coefs, count, &rounding1);
  uint arithmetic = 0;
  if (!CERTAIN_SIGN_CHANGE(v0, rounding0, v1, rounding1)) {
#if LANES == 1
    const LaneRays r = one_lane_rays(u, h->d_unit);
    if (!confirmed_in_float_float(1, &r, h->root.t, exps, coefs, count, &v0, &rounding0, &v1, &rounding1)) return;
    arithmetic = 1;
#else
    (void)u; /* the lanes' caller checks its lanes in float-float together */
    return;
#endif
  }
  PROBE(ALGRAY_EVENT_CONFIRMED, 0, arithmetic, 0u, v0, rounding0, v1, rounding1);
  h->root.flags &= ~ALGRAY_HIT_DOUBT;
}
#else
#define confirm_flat_root(h, u, exps, coefs, count, probe_log) ((void)(u))
#endif

#if LANES == 1
SurfaceHit trace_surface(Ray ray, REAL3 centre, REAL inv_scale, REAL3 box_half, int extent_kind,
                         __global const uint* exps, __global const REAL* coefs, uint count,
                         __constant const REAL* binomials, uint even_axes, const REAL* taylor, REAL taylor_t,
                         ProbeLog* probe_log) {
  SurfaceHit h;
  Isolation iso;
  REAL t_in, t_out, iso_c[NCOEF];
  if (isolate_surface(ray, centre, inv_scale, box_half, extent_kind, exps, coefs, count, binomials, even_axes, &h, &iso,
                      &t_in, &t_out, iso_c, taylor, taylor_t, probe_log)) {
    const REAL3 start = h.u; /* finish_surface moves h.u to the root */
    finish_surface(&h, refine_isolated(iso, iso_c, t_in, t_out, binomials, probe_log));
    confirm_flat_root(&h, start, exps, coefs, count, probe_log);
  }
  return h;
}
#endif

/* grad P at (x, y, z), from the monomials, with a table of powers per axis; over lanes, each lane's point. */
void surface_gradient_lanes(LREAL x, LREAL y, LREAL z, __global const uint* exps, __global const REAL* coefs,
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
 * from grad P (taken together in lanes) facing the ray, and the side. With LANES = 1, one ray's record
 * (hit_record). */
void hit_records_lanes(uint count, const LaneRays* rays, const LaneRays* at, const LaneRoots* roots,
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
    surface_gradient_lanes(x, y, z, exps, coefs, mono_count, &gx, &gy, &gz);
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
  for (uint j = 0; j < count; ++j) {
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

#if LANES == 1
HitRecord hit_record(Ray ray, SurfaceHit h, __global const uint* exps, __global const REAL* coefs, uint count) {
  /* the ray as traced, and in unit coordinates from its hit point (as trace_lanes' `at`) */
  const LaneRays r = one_lane_rays(ray.o, ray.d), at = one_lane_rays(h.u, h.d_unit);
  LaneRoots root;
  root.t = h.root.t;
  root.f_before = h.root.f_before;
  root.flags = (LANE_INT_VEC)h.root.flags;
  root.steps = (LANE_INT_VEC)h.root.steps;
  root.iterations = (LANE_INT_VEC)h.root.iterations;
  HitRecord record;
  hit_records_lanes(1, &r, &at, &root, exps, coefs, count, &record);
  return record;
}
#endif

#if LANES > 1 && RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN && DEGREE <= 15
#define SCREEN_LANES 1
/* The screen form's coefficients for a group of lanes at once: screen_ray_taylor, restrict_from_taylor and
 * bernstein_from_scaled over lanes, each lane with the operations of the vector Horner steps that those run one
 * ray at a time (restrict.h), so every lane's coefficients are the one-ray kernel's bit for bit (tests/test_lanes).
 * One ray's steps are chains of dependent vector operations; over lanes the D + 1 coefficients' chains run side
 * by side. row: the image row's polynomials (screen_rows); xi: each lane's column; tau_in, tau_out: each lane's
 * segment about the row's t0. */
ALGRAY_INLINE void screen_coefficients_lanes(__global const REAL* row, LREAL xi, LREAL tau_in, LREAL tau_out,
                               __constant const REAL* binomials, LREAL* out) {
  LREAL taylor[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) taylor[k] = (LREAL)row[DEGREE * NCOEF + k];
  ALGRAY_UNROLL
  for (int j = DEGREE - 1; j >= 0; --j) ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) taylor[k] = taylor[k] * xi + row[j * NCOEF + k];
#if RESTRICT_BERNSTEIN
  const LREAL l0 = tau_in, l1 = tau_out;
#else
  const LREAL l0 = tau_in, l1 = tau_out - tau_in;
#endif
  LREAL c[NCOEF];
  c[0] = taylor[DEGREE];
  ALGRAY_UNROLL
  for (int k = 1; k <= DEGREE; ++k) c[k] = 0;
  ALGRAY_UNROLL
  for (int n = DEGREE - 1; n >= 0; --n) {
    /* acc_mul_linear: l0 c + l1 (c shifted up one, a zero below) */
    ALGRAY_UNROLL
    for (int k = DEGREE; k > 0; --k) c[k] = l0 * c[k] + l1 * c[k - 1];
    c[0] = l0 * c[0] + l1 * (LREAL)0;
    /* acc_add_constant */
#if RESTRICT_BERNSTEIN
    ALGRAY_UNROLL
    for (int k = 0; k <= DEGREE; ++k) c[k] += taylor[n] * binomials[(DEGREE - n) * NCOEF + k];
#else
    c[0] += taylor[n];
#endif
  }
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) out[k] = c[k] / binomials[DEGREE * NCOEF + k]; /* bernstein_from_scaled */
}
#else
#define SCREEN_LANES 0
#endif

#if LANES > 1
/* trace_surface and hit_record for the first `count` (<= LANES) of the lanes' rays, or 0 when none enters the
 * extent (records then left alone: each is missed_record()). They are clipped together, each
 * is restricted on its own (the screen form: together), then all are isolated, refined and their normals taken
 * together in vector lanes (lanes.h), with the one-ray kernel's records bit for bit (tests/test_lanes). Camera
 * and secondary rays share it. */
int trace_lanes(uint count, const LaneRays* rays, REAL3 centre, REAL inv_scale, REAL3 box_half, int extent_kind,
                 __global const uint* exps, __global const REAL* coefs, uint mono_count,
                 __constant const REAL* binomials, uint even_axes, HitRecord* records, uint px0, uint py,
                 __global const REAL* screen_rows, uint screen_row0, REAL screen_t, REAL xi_scale, REAL xi_offset) {
  LaneIsolation iso;
  LaneRoots roots;
  LREAL iso_c[NCOEF], lane_t_in, lane_t_out;
  LaneRays unit;
  const LMASK running =
      enter_lanes(count, rays, centre, inv_scale, box_half, extent_kind, &unit, &lane_t_in, &lane_t_out);
  /* no ray enters the extent (whole groups of most views): the caller writes missed_record() for each */
  if (!LANE_ANY(running)) return 0;
#if SCREEN_LANES
  /* screen_ray_taylor's column and segment_coefficients' segment about t0 */
  const LREAL xi = LANE_SEL((LREAL)0, SCREEN_COLUMN(lane_pixel_centres(px0), xi_scale, xi_offset), running);
  LREAL lane_root[NCOEF];
  screen_coefficients_lanes(screen_row(screen_rows, py, screen_row0), xi,
                            LANE_SEL((LREAL)0, lane_t_in - screen_t, running),
                            LANE_SEL((LREAL)1, lane_t_out - screen_t, running), binomials, lane_root);
  /* lanes outside the extent start from zeros, as isolate_lanes gives them */
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) lane_root[k] = LANE_SEL((LREAL)0, lane_root[k], running);
  isolate_bernstein_lanes(running, lane_root, lane_t_in, lane_t_out, &iso, iso_c, (const LaneTerms*)0);
#else
  /* one ray at a time: each lane's segment and whether it entered */
  REAL t_in[LANES], t_out[LANES];
  LANES_STORE(lane_t_in, t_in);
  LANES_STORE(lane_t_out, t_out);
  int in_extent[LANES];
  const uint entered_bits = lane_mask_bits(running);
  for (uint j = 0; j < LANES; ++j) in_extent[j] = (entered_bits >> j) & 1u;
  REAL root[LANES][NCOEF], root_lo[LANES][NCOEF];
  RayTerms terms[LANES];
  for (uint j = 0; j < count; ++j) {
    if (!in_extent[j]) continue;
    REAL taylor[NCOEF], taylor_t = 0;
#if RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN
    taylor_t = screen_ray_taylor(px0 + j, py, screen_rows, screen_row0, screen_t, xi_scale, xi_offset, taylor);
#endif
    segment_coefficients(lane_origin(&unit, j), lane_direction(&unit, j), t_in[j], t_out[j], exps, coefs, mono_count,
                         binomials, even_axes, root[j], root_lo[j], &terms[j], taylor, taylor_t, NO_PROBE);
  }
  isolate_lanes(count, in_extent, &unit, root, root_lo, t_in, t_out, &iso, iso_c, terms);
#endif
  refine_lanes(running, &iso, iso_c, lane_t_in, lane_t_out, binomials, &roots);
  /* finish_surface over lanes: `at` moves each found root's ray to its point */
  const LMASK found = (roots.flags & (LANE_INT_VEC)ALGRAY_HIT_FOUND) != 0;
  LaneRays at = unit;
  if (LANE_ANY(found)) {
    const LREAL t = LANE_SEL((LREAL)0, roots.t, found);
    at.ox = LANE_SEL(unit.ox, unit.ox + t * unit.dx, found);
    at.oy = LANE_SEL(unit.oy, unit.oy + t * unit.dy, found);
    at.oz = LANE_SEL(unit.oz, unit.oz + t * unit.dz, found);
  }
#if ALGRAY_ESCALATE
  /* confirm_flat_root lane by lane in float, then in float-float for the lanes still doubted, together */
  const uint doubted_bits = lane_mask_bits(found && (roots.flags & (LANE_INT_VEC)ALGRAY_HIT_DOUBT) != 0);
  for (uint j = 0; j < count; ++j) {
    if (!((doubted_bits >> j) & 1u)) continue;
    SurfaceHit h;
    h.root.t = lane_get(roots.t, j);
    h.root.flags = (uint)((LANE_INT*)&roots.flags)[j];
    h.u = lane_origin(&at, j);
    h.d_unit = lane_direction(&at, j);
    confirm_flat_root(&h, lane_origin(&unit, j), exps, coefs, mono_count, NO_PROBE);
    ((LANE_INT*)&roots.flags)[j] = (LANE_INT)h.root.flags;
  }
  const LMASK still = found && (roots.flags & (LANE_INT_VEC)ALGRAY_HIT_DOUBT) != 0;
  if (LANE_ANY(still)) {
    LREAL v0, rounding0, v1, rounding1;
    const LMASK confirmed = confirmed_in_float_float(still, &unit, LANE_SEL((LREAL)0, roots.t, still), exps, coefs,
                                                     mono_count, &v0, &rounding0, &v1, &rounding1);
    roots.flags &= LANE_SEL((LANE_INT_VEC)(-1), (LANE_INT_VEC)(~ALGRAY_HIT_DOUBT), confirmed);
  }
#endif
  hit_records_lanes(count, rays, &at, &roots, exps, coefs, mono_count, records);
  return 1;
}
#endif

#endif /* ALGRAY_SURFACE_H */
