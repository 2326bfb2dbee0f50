/* The secondary-ray kernel: given rays (reflection, transmission) against the surface, LANES rays per work-item. */
#include "algray_shared.h"
#include "isolate.h"
#include "lanes.h"
#include "ray.h"
#include "real.h"
#include "restrict.h"
#include "surface.h"

#if RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN
#error "the screen form is for camera rays; the host builds this kernel with RAY_ORIGIN=extent"
#endif

/* Ray i is origins[i].xyz + t * directions[i].xyz, t >= 0, in world coordinates; its hit goes to out[i] as the
 * primary kernel writes it (t, depth, normal facing the ray, side, work). Global size ceil(count / LANES), LANES
 * consecutive rays per work-item (trace_rays). */
__kernel void trace(__global const REAL4* origins, __global const REAL4* directions, uint count, REAL4 extent_centre,
                    REAL extent_inv_scale, REAL4 extent_box_half, int extent_kind, __global const REAL4* clip_planes,
                    uint clip_count, __global const uint* mono_exps,
                    __global const REAL* mono_coefs, uint mono_count, __constant const REAL* binomials, uint even_axes,
                    __global HitRecord* out) {
  const uint first = launch_item_index() * LANES;
  if (first >= count) return;
  const uint group = min((uint)LANES, count - first);
  /* lanes from `group` on repeat the last ray; trace_rays leaves them alone */
#define RAY_AXIS(array, axis, j) array[first + min((uint)(j), group - 1)].axis
#define ORIGIN_X(j) RAY_AXIS(origins, x, j)
#define ORIGIN_Y(j) RAY_AXIS(origins, y, j)
#define ORIGIN_Z(j) RAY_AXIS(origins, z, j)
#define DIRECTION_X(j) RAY_AXIS(directions, x, j)
#define DIRECTION_Y(j) RAY_AXIS(directions, y, j)
#define DIRECTION_Z(j) RAY_AXIS(directions, z, j)
  LaneRays rays;
  rays.ox = LANES_OF(LREAL, ORIGIN_X);
  rays.oy = LANES_OF(LREAL, ORIGIN_Y);
  rays.oz = LANES_OF(LREAL, ORIGIN_Z);
  rays.dx = LANES_OF(LREAL, DIRECTION_X);
  rays.dy = LANES_OF(LREAL, DIRECTION_Y);
  rays.dz = LANES_OF(LREAL, DIRECTION_Z);
#undef RAY_AXIS
#undef ORIGIN_X
#undef ORIGIN_Y
#undef ORIGIN_Z
#undef DIRECTION_X
#undef DIRECTION_Y
#undef DIRECTION_Z
  HitRecord records[LANES];
  const int entered = trace_rays(group, &rays, extent_centre.xyz, extent_inv_scale, extent_box_half.xyz, extent_kind,
                                 clip_planes, clip_count, mono_exps, mono_coefs, mono_count, binomials, even_axes, records, 0, 0, 0, 0, 0, 0, 0,
                                 NO_PROBE);
  for (uint j = 0; j < group; ++j) out[first + j] = entered ? records[j] : missed_record();
}
