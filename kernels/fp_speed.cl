// Dependent multiply-adds in float or double (ALGRAY_FP_DOUBLE), to time a device's double arithmetic against
// its float arithmetic once (device/fp64_speed.h).
#ifdef ALGRAY_FP_DOUBLE
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double fp_t;
#else
typedef float fp_t;
#endif

// Four independent chains per work-item, so that a pipelined unit is busy; `rounds` multiply-adds each.
__kernel void fp_speed(__global fp_t* out, const uint rounds) {
  const fp_t x = (fp_t)get_global_id(0) * (fp_t)1e-6;
  fp_t a = x, b = x + (fp_t)0.25, c = x + (fp_t)0.5, d = x + (fp_t)0.75;
  for (uint i = 0; i < rounds; ++i) {
    a = a * (fp_t)0.9999 + (fp_t)0.0001;
    b = b * (fp_t)0.9998 + (fp_t)0.0002;
    c = c * (fp_t)0.9997 + (fp_t)0.0003;
    d = d * (fp_t)0.9996 + (fp_t)0.0004;
  }
  out[get_global_id(0)] = a + b + c + d;
}
