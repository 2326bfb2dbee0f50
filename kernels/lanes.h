/* Lanes: LANES rays side by side in one work-item's vector registers (-D LANES=n), and the scalar case n = 1. */
#ifndef ALGRAY_LANES_H
#define ALGRAY_LANES_H

#include "real.h"

/* PoCL runs a CPU work-group's work-items one after another, and the solver's loops keep its vectoriser from
 * merging them, so each ray's divisions and Horner chains wait on one another. Code written over LREAL runs
 * LANES rays at once instead: every lane takes the same steps, a lane that has finished keeps its state
 * through LANE_SEL, and a loop ends when every lane has. Each lane's arithmetic is the scalar code's,
 * operation for operation, so a lane's result is the scalar build's bit for bit (bench/lockstep_lanes checks
 * this on 2^20 polynomials per degree). With LANES = 1 the same code is the scalar build: GPUs, the probe,
 * and the other kernels.
 *
 * LMASK is what a comparison of LREALs gives: 0 or 1 for scalars, 0 or -1 (all bits) per lane for vectors. So
 * masks combine with !, && and ||, never ~, and count with LANE_SEL((LMASK)0, (LMASK)1, m). */
#ifndef LANES
#define LANES 1
#endif

#if LANES == 1
typedef REAL LREAL;
typedef int LMASK;
#define LANE_SEL(a, b, m) ((m) ? (b) : (a))
#define LANE_ANY(m) (m)
#define LANE_ALL(m) (m)
#elif LANES == 2 || LANES == 4 || LANES == 8 || LANES == 16
#define LANE_CAT(a, b) a##b
#define LANE_VEC(type, n) LANE_CAT(type, n)
typedef LANE_VEC(REAL, LANES) LREAL; /* REAL8 for LANES = 8 (real.h) */
#if ALGRAY_DOUBLE
typedef long LANE_INT; /* one lane of a mask: as wide as a REAL */
typedef LANE_VEC(long, LANES) LMASK;
#else
typedef int LANE_INT;
typedef LANE_VEC(int, LANES) LMASK;
#endif
#define LANE_SEL(a, b, m) select((a), (b), (m))
#define LANE_ANY(m) any(m)
#define LANE_ALL(m) all(m)
#else
#error "LANES must be 1, 2, 4, 8 or 16"
#endif

/* Lane j of a vector (j < LANES), read and written through its private storage. */
ALGRAY_INLINE REAL lane_get(LREAL v, uint j) { return ((REAL*)&v)[j]; }
ALGRAY_INLINE void lane_set(LREAL* v, uint j, REAL x) { ((REAL*)v)[j] = x; }
ALGRAY_INLINE long lane_get_mask(LMASK m, uint j) {
#if LANES == 1
  (void)j;
  return m;
#else
  return ((LANE_INT*)&m)[j];
#endif
}
ALGRAY_INLINE void lane_set_mask(LMASK* m, uint j, int on) {
#if LANES == 1
  (void)j;
  *m = on != 0;
#else
  ((LANE_INT*)m)[j] = on ? -1 : 0;
#endif
}

#endif /* ALGRAY_LANES_H */
