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

/* Extent kinds (kernel argument extent_kind). */
#define ALGRAY_EXTENT_SPHERE 0
#define ALGRAY_EXTENT_BOX 1

/* Compile-time solver choices, passed as -D ISOLATION=... -D REFINEMENT=... */
#define ALGRAY_ISOLATION_BERNSTEIN 1   /* Descartes' rule on Bernstein coefficients over [t_in, t_out], de Casteljau halving */
#define ALGRAY_ISOLATION_POWER 2       /* the paper: power basis mapped to (0, inf), Descartes' rule, left half first */
#define ALGRAY_ISOLATION_STURM 3       /* Sturm sequence of P* in the power basis, bisection by root counts */
#define ALGRAY_ISOLATION_DERIVATIVE_CHAIN 4 /* roots of P*', P*'', ... cut [0, 1] into monotone pieces */
#define ALGRAY_REFINEMENT_BRENT 1      /* Dekker-Brent with the paper's acceptance and stopping rules */
#define ALGRAY_REFINEMENT_BISECTION 2  /* plain bisection of the bracket */
#define ALGRAY_REFINEMENT_REGULA_FALSI 3 /* the paper's plain regula falsi (false position) */
#define ALGRAY_REFINEMENT_ILLINOIS 4   /* regula falsi with the Illinois modification */
#define ALGRAY_REFINEMENT_NEWTON 5     /* Newton's method, safeguarded by the bracket */
#define ALGRAY_ORIGIN_EXTENT 1         /* P*(t) built around the middle of [t_in, t_out] (well conditioned) */
#define ALGRAY_ORIGIN_EYE 2            /* P*(t) built around the ray origin, as the paper does */

/* Per-pixel result of the primary kernel; 32 bytes. */
typedef struct {
  algray_f32 t_hi;      /* ray parameter of the hit along o + t*d (d not normalised); +inf on a miss */
  algray_f32 t_lo;      /* t - t_hi when the kernel ran in double, else 0: t = t_hi + t_lo to ~48 bits */
  algray_f32 depth;     /* distance from the ray origin, t*|d|; +inf on a miss */
  algray_f32 normal_x;  /* unit normal from grad P, world space, facing the viewer; 0 on a miss */
  algray_f32 normal_y;
  algray_f32 normal_z;
  algray_u32 flags;     /* ALGRAY_HIT_* bits */
  algray_u32 work;      /* isolation steps in the low 16 bits, refinement iterations in the high 16 bits */
} HitRecord;

#endif /* ALGRAY_SHARED_H */
