/* The probe kernel: one ray through the render's own solver code, with every solver step recorded. */
#define ALGRAY_PROBE 1
#include "algray_shared.h"
#include "isolate.h"
#include "probe_log.h"
#include "ray.h"
#include "real.h"
#include "restrict.h"
#include "surface.h"

/* A single work-item. The ray is pixel (px, py) of the camera, built by camera_rays() exactly as the primary
 * kernel builds it, or, with use_given_ray, given_o + t * given_d (world coordinates, as the trace kernel takes
 * rays). out gets the hit record the render would write; ray_out the ray (origin, direction) that was traced;
 * events and values the log (see ALGRAY_EVENT_* in algray_shared.h); event_count[0] how many events were
 * offered, which may exceed capacity. screen_rows .. xi_offset: the rows of the primary kernel's screen form
 * (surface.h), of which the host passes py's alone; other builds never read them. The arguments are
 * ALGRAY_PROBE_ARG_NAMES (algray_shared.h), by which the host sets them. */
__kernel void probe(REAL4 ray_o00, REAL4 ray_ou, REAL4 ray_ov, REAL4 ray_d00, REAL4 ray_du, REAL4 ray_dv, uint px,
                    uint py, int use_given_ray, REAL4 given_o, REAL4 given_d, REAL4 extent_centre,
                    REAL extent_inv_scale, REAL4 extent_box_half, int extent_kind, __global const REAL4* clip_planes,
                    uint clip_count, __global const uint* mono_exps,
                    __global const REAL* mono_coefs, uint mono_count, __constant const REAL* binomials, uint even_axes,
                    __global const REAL* screen_rows, uint screen_row0, REAL screen_t, REAL xi_scale, REAL xi_offset,
                    __global HitRecord* out, __global REAL4* ray_out, __global ProbeEvent* events,
                    __global REAL* values, uint capacity, __global uint* event_count) {
  if (get_global_id(0) != 0) return;
  const LaneRays ray = use_given_ray ? one_lane_rays(given_o.xyz, given_d.xyz)
                                     : camera_rays(px, py, ray_o00, ray_ou, ray_ov, ray_d00, ray_du, ray_dv);
  ProbeLog log;
  log.events = events;
  log.values = values;
  log.capacity = capacity;
  log.count = 0;
  /* Camera rays only: the host probes a given ray with the trace kernel's construction (RAY_ORIGIN=extent). */
  HitRecord record;
  const int entered = trace_rays(1, &ray, extent_centre.xyz, extent_inv_scale, extent_box_half.xyz, extent_kind,
                                 clip_planes, clip_count, mono_exps, mono_coefs, mono_count, binomials, even_axes, &record, px, py, screen_rows,
                                 screen_row0, screen_t, xi_scale, xi_offset, &log);
  out[0] = entered ? record : missed_record();
  ray_out[0] = (REAL4)(ray.ox, ray.oy, ray.oz, 0);
  ray_out[1] = (REAL4)(ray.dx, ray.dy, ray.dz, 0);
  event_count[0] = log.count;
}
