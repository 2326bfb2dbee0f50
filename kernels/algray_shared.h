/* Struct layouts and constants shared by the C++ host and the OpenCL kernels: the one place they are defined. */
#ifndef ALGRAY_SHARED_H
#define ALGRAY_SHARED_H

/* Only 32-bit members, so the layout is identical on every device and needs no padding rules. */
#if defined(__OPENCL_VERSION__) || defined(__OPENCL_C_VERSION__)
typedef float algray_f32;
typedef uint algray_u32;
typedef int algray_i32;
#else
#include <CL/cl_platform.h>
typedef cl_float algray_f32;
typedef cl_uint algray_u32;
typedef cl_int algray_i32;
#endif

/* HitRecord.flags */
#define ALGRAY_HIT_FOUND 1u        /* a root of P*(t) was accepted in [t_in, t_out] */
#define ALGRAY_HIT_BACK 2u         /* the ray arrived from the side where P < 0 (the back/inside colour) */
#define ALGRAY_HIT_TANGENT 4u      /* reference images only: the smallest root has even multiplicity */
#define ALGRAY_HIT_BUDGET 8u       /* isolation stopped at its depth limit with the question still open */
#define ALGRAY_HIT_IN_EXTENT 16u   /* the ray met the extent at all */
#define ALGRAY_HIT_EXACT 32u       /* the root is where P* came out exactly 0, or changed sign between two intervals */
#define ALGRAY_HIT_CLUSTER 64u     /* the root is a sign change across an interval that still held several roots */
#define ALGRAY_HIT_DOUBT 128u      /* adaptive precision: the float kernel could not decide this ray (ALGRAY_DOUBT_*) and
                                      left it for the float-float pass; its other fields mean nothing */
#define ALGRAY_HIT_ESCALATED 256u  /* adaptive precision: this record is the float-float answer to a doubted ray */

/* Extent kinds (kernel argument extent_kind). */
#define ALGRAY_EXTENT_SPHERE 0
#define ALGRAY_EXTENT_BOX 1
/* A cylinder about axis a (0 x, 1 y, 2 z) is kind ALGRAY_EXTENT_CYLINDER + a: the axis is chosen with the kind, not
 * an argument of its own, and extent_box_half is the box around it (its radius across, half-height along a). */
#define ALGRAY_EXTENT_CYLINDER 2
/* Added to a kind: the shape is a ray gate (the scene's extent.gate), not a cut. A ray that does not meet it misses;
 * a ray that does is traced along the unit sphere (the gate's far sphere), the shape then being given by
 * extent_box_half, a sphere's radius in its x (kernels/ray.h, clip_lanes_to_extent). */
#define ALGRAY_EXTENT_GATE 8

/* Compile-time solver choices, passed as -D ISOLATION=... -D REFINEMENT=... */
#define ALGRAY_ISOLATION_BERNSTEIN 1   /* Descartes' rule on Bernstein coefficients over [t_in, t_out], de Casteljau halving */
#define ALGRAY_ISOLATION_POWER 2       /* the paper: power basis mapped to (0, inf), Descartes' rule, left half first */
#define ALGRAY_ISOLATION_STURM 3       /* Sturm sequence of P* in the power basis, bisection by root counts */
#define ALGRAY_ISOLATION_DERIVATIVE_CHAIN 4 /* roots of P*', P*'', ... cut [0, 1] into monotone pieces */
#define ALGRAY_ISOLATION_LAST 4        /* the largest id: a new method's id goes above, and here */
#define ALGRAY_REFINEMENT_BRENT 1      /* Dekker-Brent with the paper's acceptance and stopping rules */
#define ALGRAY_REFINEMENT_BISECTION 2  /* plain bisection of the bracket */
#define ALGRAY_REFINEMENT_REGULA_FALSI 3 /* the paper's plain regula falsi (false position) */
#define ALGRAY_REFINEMENT_ILLINOIS 4   /* regula falsi with the Illinois modification */
#define ALGRAY_REFINEMENT_NEWTON 5     /* Newton's method, safeguarded by the bracket */
#define ALGRAY_ORIGIN_EXTENT 1         /* P*(t) built around the middle of [t_in, t_out] (well conditioned) */
#define ALGRAY_ORIGIN_EYE 2            /* P*(t) built around the ray origin, as the paper does */
#define ALGRAY_ORIGIN_SCREEN 3         /* camera rays: P*(t) from its Taylor coefficients where the ray crosses the
                                          extent's middle, given per image row as polynomials in the column */
#define ALGRAY_ORIGIN_POINT 4          /* shadow rays: P expanded once about their shared origin (point_form.h);
                                          other rays as ALGRAY_ORIGIN_EXTENT */

/* Each kernel's arguments by name, in the order it declares them. The host sets them by these names
 * (render/kernel_binder.h), never by position, and test_kernel_args reads every kernel's names back from the driver
 * to hold each list to its kernel. REAL-typed arguments follow the build's precision; arguments a build does not
 * use (the screen form's rows elsewhere, `undecided` outside adaptive builds) are still passed, and never read. */
#define ALGRAY_EXTENT_ARG_NAMES(X) \
  X(extent_centre) X(extent_inv_scale) X(extent_box_half) X(extent_kind) X(clip_planes) X(clip_count)
#define ALGRAY_SURFACE_ARG_NAMES(X) X(mono_exps) X(mono_coefs) X(mono_count) X(binomials) X(even_axes)
#define ALGRAY_CAMERA_ARG_NAMES(X) X(ray_o00) X(ray_ou) X(ray_ov) X(ray_d00) X(ray_du) X(ray_dv)
#define ALGRAY_SCREEN_ARG_NAMES(X) X(screen_rows) X(screen_row0) X(screen_t) X(xi_scale) X(xi_offset)
#define ALGRAY_PRIMARY_ARG_NAMES(X)                                                                    \
  ALGRAY_CAMERA_ARG_NAMES(X) ALGRAY_EXTENT_ARG_NAMES(X) ALGRAY_SURFACE_ARG_NAMES(X) ALGRAY_SCREEN_ARG_NAMES(X) X(tile_x0) \
  X(tile_y0) X(tile_w) X(tile_h) X(out)
#define ALGRAY_TRACE_ARG_NAMES(X) X(origins) X(directions) X(count) ALGRAY_EXTENT_ARG_NAMES(X) ALGRAY_SURFACE_ARG_NAMES(X) X(out)
#define ALGRAY_SHADOW_ARG_NAMES(X)                                                                                   \
  X(points) X(normals) X(point_count) X(light_points) X(light_count) X(offset) ALGRAY_EXTENT_ARG_NAMES(X)          \
  ALGRAY_SURFACE_ARG_NAMES(X) X(occluded) X(rays_traced) X(undecided)
#define ALGRAY_PROBE_ARG_NAMES(X)                                                                                  \
  ALGRAY_CAMERA_ARG_NAMES(X) X(px) X(py) X(use_given_ray) X(given_o) X(given_d) ALGRAY_EXTENT_ARG_NAMES(X)            \
  ALGRAY_SURFACE_ARG_NAMES(X) ALGRAY_SCREEN_ARG_NAMES(X) X(out) X(ray_out) X(events) X(values) X(capacity) X(event_count)
#define ALGRAY_UNIVARIATE_ARG_NAMES(X) X(polys) X(count) X(binomials) X(out)
#define ALGRAY_RESTRICT_CHECK_ARG_NAMES(X) \
  X(segments) X(count) X(mono_exps) X(mono_coefs) X(mono_count) X(binomials) X(even_axes) X(out)
#define ALGRAY_SHADE_ARG_NAMES(X)                                                                                  \
  ALGRAY_CAMERA_ARG_NAMES(X) X(rays_in_float) X(samples) X(tile_x0) X(tile_y0) X(tile_w) X(tile_h) X(hits)         \
  X(hit_surface) X(several_surfaces) X(materials) X(light_colours) X(light_first) X(light_occlusion) X(light_count)  \
  X(headlight_ambient) X(light_points) X(point_of_hit) X(occlusion_masks) X(occlusion_stride) X(section_planes) X(section_looks)        \
  X(section_surfaces) X(section_count) X(secondary) X(has_secondary) X(background) X(film_rgba) X(film_depth)       \
  X(film_normal) X(film_depth_and_normal) X(film_width) X(film_y0) X(kept_first) X(kept_end) X(summary)

/* Per-pixel result of the primary kernel; 32 bytes. */
typedef struct {
  algray_f32 t_hi;      /* ray parameter of the hit along o + t*d (d not normalised); +inf on a miss */
  algray_f32 t_lo;      /* t - t_hi when the kernel ran in double, else 0: t = t_hi + t_lo to ~48 bits */
  algray_f32 depth;     /* distance from the ray origin, t*|d|; +inf on a miss */
  algray_f32 normal_x;  /* unit normal from grad P, world space, facing the viewer; 0 on a miss */
  algray_f32 normal_y;
  algray_f32 normal_z;
  algray_u32 flags;     /* ALGRAY_HIT_* bits */
  algray_u32 work;      /* isolation steps and refinement iterations: ALGRAY_WORK_PACK */
} HitRecord;

/* HitRecord.work: isolation steps in the low 16 bits, refinement iterations in the high 16. The kernels pack it
 * and the host reads it only through these, so the layout is written down here alone. A count saturates at
 * ALGRAY_WORK_MAX rather than spill into the other. */
#define ALGRAY_WORK_MAX 0xffffu
#define ALGRAY_WORK_PACK(steps, iterations) ((steps) | ((iterations) << 16)) /* each at most ALGRAY_WORK_MAX */
#define ALGRAY_WORK_ISOLATION_STEPS(work) ((work) & ALGRAY_WORK_MAX)
#define ALGRAY_WORK_REFINE_ITERATIONS(work) ((work) >> 16)

/* Shading (kernels/shade.cl). A material is ALGRAY_MATERIAL_VALUES numbers of the kernel's REAL, in this order: its
 * colour, the Phong weights and exponent, the share of its own colour (1 - transparency where light passes through)
 * and the highlight cutoff (r.v below it adds under 1/4096 of full strength). */
#define ALGRAY_MATERIAL_RED 0
#define ALGRAY_MATERIAL_GREEN 1
#define ALGRAY_MATERIAL_BLUE 2
#define ALGRAY_MATERIAL_AMBIENT 3
#define ALGRAY_MATERIAL_DIFFUSE 4
#define ALGRAY_MATERIAL_SPECULAR 5
#define ALGRAY_MATERIAL_EXPONENT 6
#define ALGRAY_MATERIAL_OWN 7
#define ALGRAY_MATERIAL_CUTOFF 8
#define ALGRAY_MATERIAL_VALUES 9
/* The shading kernel's work-groups are this many pixels on a side; each writes its camera rays' totals, in this
 * order, to its ALGRAY_SUMMARY_VALUES numbers of `summary` (the host's PrimarySummary). */
#define ALGRAY_SHADE_GROUP_SIDE 8
#define ALGRAY_SUMMARY_RAYS 0
#define ALGRAY_SUMMARY_HITS 1
#define ALGRAY_SUMMARY_DEPTH_LIMITED 2
#define ALGRAY_SUMMARY_ISOLATION_STEPS 3
#define ALGRAY_SUMMARY_REFINE_ITERATIONS 4
#define ALGRAY_SUMMARY_PIXELS 5
#define ALGRAY_SUMMARY_PIXELS_HIT 6
#define ALGRAY_SUMMARY_VALUES 7

/* The probe: kernels/probe.cl records what the solver did on one ray as a list of events, each with four REAL
 * values in a separate buffer (values[4 i .. 4 i + 3] belong to event i). */
#define ALGRAY_EVENT_SEGMENT 1      /* values: t_in, t_out of the ray in the extent */
#define ALGRAY_EVENT_COEFFICIENT 2  /* count: k; decision: ALGRAY_BASIS_*; values: c_k and its low part (mixed) */
#define ALGRAY_EVENT_STEP 3         /* an isolation step. count: sign variations (Sturm: distinct roots), -1 if not
                                       counted; decision: ALGRAY_STEP_*; level: halving level; values: the
                                       interval's ends lo, hi as fractions of [t_in, t_out], and P there */
#define ALGRAY_EVENT_CHAIN_ITERATE 4 /* derivative chain: one Newton/bisection step on the derivative of order
                                       `level`; values: x, its value there, then the bracket lo, hi (fractions) */
#define ALGRAY_EVENT_ISOLATED 5     /* the isolation's result. decision: ALGRAY_ISOLATED_*; count: 1 at the
                                       halving limit; values: lo, hi, P(lo), P(hi) */
#define ALGRAY_EVENT_ITERATE 6      /* a refinement iterate. count: its number; values: y, P(y), and the bracket
                                       (y in [0, 1] across the isolating interval) */
#define ALGRAY_EVENT_DOUBT 7        /* adaptive precision: a decision within the coefficients' rounding noise, which
                                       ends the float search. decision: ALGRAY_DOUBT_*; level: halving level;
                                       values: the interval's lo, hi, the value in question, the noise bound */
/* ALGRAY_EVENT_CONFIRMED, adaptive precision: a doubt settled after all. Decision 0: a flat-doubted root kept
 * (confirm_flat_roots), P from the monomials in float, values P and its rounding bound at t - delta, then at
 * t + delta; decision 1: the same in float-float. Decision 2: an accept-doubted bracket kept (methods/bernstein.h,
 * settle_brackets), values P and its bound at the bracket's ends, level 1 where float-float evaluated them, 0 where
 * float did. Decision 3: a discard-doubted interval settled (methods/bernstein.h, discards_settled), values P and its
 * bound at the interval's ends. */
#define ALGRAY_EVENT_CONFIRMED 8

/* What an isolation found (kernels/isolation.h's Isolation.status) */
#define ALGRAY_ISOLATED_NONE 0    /* certified: no root in [t_in, t_out] (up to the tolerance) */
#define ALGRAY_ISOLATED_BRACKET 1 /* one root (or an odd cluster) bracketed by a sign change on [lo, hi] */
#define ALGRAY_ISOLATED_EXACT 2   /* the polynomial is exactly zero at lo */

#define ALGRAY_BASIS_BERNSTEIN 1     /* Bernstein basis of s in [0, 1] over [t_in, t_out] */
#define ALGRAY_BASIS_POWER_SEGMENT 2 /* power basis of s in [0, 1] over [t_in, t_out] */
#define ALGRAY_BASIS_POWER_EYE 3     /* power basis of t itself, around the ray origin (the paper's RAY_ORIGIN=eye) */

/* Why an adaptive float kernel doubted a ray (ALGRAY_EVENT_DOUBT; the host's names in render/escalation.h) */
#define ALGRAY_DOUBT_DISCARD 1 /* an interval looked root-free, but one of its coefficients was within noise of 0 */
#define ALGRAY_DOUBT_ACCEPT 2  /* a root looked isolated or crossed, but P at an end was within noise of 0 */
#define ALGRAY_DOUBT_CLUSTER 3 /* the search reached the stopping width or the halving limit with several roots */
#define ALGRAY_DOUBT_FLAT 4    /* the refined root lies where P is so flat that the noise could move it by more
                                  than ALGRAY_DOUBT_POSITION of its t (rays that need the position) */

/* Rays that need their root's position doubt a refined root whose position the noise could move by more than
 * this fraction of its t: the noise over P's slope there (surface.h, flat_root). Measured: an Endrass octic ray
 * whose interval's ends stood just clear of the noise had its root 1.2e-3 off. Kept as digits, so that the kernels
 * read a float literal (devices without fp64 need not accept double constants) and the host's messages the same
 * number as text (ALGRAY_DOUBT_POSITION_TEXT). */
#define ALGRAY_DOUBT_POSITION_DIGITS 1e-4
#define ALGRAY_PASTE_(a, b) a##b
#define ALGRAY_PASTE(a, b) ALGRAY_PASTE_(a, b)
#define ALGRAY_TEXT_(x) #x
#define ALGRAY_TEXT(x) ALGRAY_TEXT_(x)
#define ALGRAY_DOUBT_POSITION ALGRAY_PASTE(ALGRAY_DOUBT_POSITION_DIGITS, f)
#define ALGRAY_DOUBT_POSITION_TEXT ALGRAY_TEXT(ALGRAY_DOUBT_POSITION_DIGITS)

/* ALGRAY_EVENT_STEP decisions */
#define ALGRAY_STEP_EXACT_ZERO 1   /* P is exactly 0 at the interval's left end: the root is there */
#define ALGRAY_STEP_CROSSED 2      /* P changed sign at the left end, between two intervals: the root is there */
#define ALGRAY_STEP_ISOLATED 3     /* exactly one root: the isolating interval */
#define ALGRAY_STEP_SPLIT 4        /* possibly several roots: halve */
#define ALGRAY_STEP_NO_ROOT 5      /* no root: go on to the next interval */
#define ALGRAY_STEP_CLUSTER_ROOT 6 /* down to the stopping width (or the halving limit) and P changes sign: root */
#define ALGRAY_STEP_CLUSTER_SKIP 7 /* down to the stopping width without a sign change: an even cluster, skipped */
#define ALGRAY_STEP_END_ZERO 8     /* nothing before the far end, where P is 0 */
#define ALGRAY_STEP_END_NONE 9     /* nothing in the whole segment */
#define ALGRAY_STEP_PIECE 10       /* derivative chain: a monotone piece of P without a sign change */

typedef struct {
  algray_u32 kind;     /* ALGRAY_EVENT_* */
  algray_i32 count;    /* see the event kinds */
  algray_u32 decision; /* ALGRAY_STEP_* or ALGRAY_BASIS_* */
  algray_u32 level;
} ProbeEvent;

#endif /* ALGRAY_SHARED_H */
