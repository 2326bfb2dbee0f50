/* The secondary-ray kernel: given rays (reflection, transmission) against the surface, one work-item per ray. */
#include "algray_shared.h"
#include "isolate.h"
#include "ray.h"
#include "real.h"
#include "restrict.h"
#include "surface.h"

#if RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN
#error "the screen form is for camera rays; the host builds this kernel with RAY_ORIGIN=extent"
#endif

/* Ray i is origins[i].xyz + t * directions[i].xyz, t >= 0, in world coordinates; its hit goes to out[i] as the
 * primary kernel writes it (t, depth, normal facing the ray, side, work). */
__kernel void trace(__global const REAL4* origins, __global const REAL4* directions, uint count,
                    REAL4 extent_centre, REAL extent_inv_scale, REAL4 extent_box_half, int extent_kind,
                    __global const uint* mono_exps, __global const REAL* mono_coefs, uint mono_count,
                    __constant const REAL* binomials, uint even_axes, __global HitRecord* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  Ray ray;
  ray.o = origins[i].xyz;
  ray.d = directions[i].xyz;
  const SurfaceHit hit = trace_surface(ray, extent_centre.xyz, extent_inv_scale, extent_box_half.xyz, extent_kind,
                                       mono_exps, mono_coefs, mono_count, binomials, even_axes);
  out[i] = hit_record(ray, hit, mono_exps, mono_coefs, mono_count);
}
