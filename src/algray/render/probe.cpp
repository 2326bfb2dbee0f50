// Host side of the probe kernel: one work-item, its event log read back and decoded.
#include "algray/render/probe.h"

#include <cstring>

#include "algray/render/device_surface.h"

namespace algray {
namespace {

std::vector<double> read_reals(ClSession& session, const cl::Buffer& buffer, std::size_t count, Precision precision) {
  std::vector<double> out(count);
  if (count == 0) return out;
  if (precision == Precision::Double) {
    session.queue.enqueueReadBuffer(buffer, CL_TRUE, 0, count * sizeof(double), out.data());
  } else {
    std::vector<float> f(count);
    session.queue.enqueueReadBuffer(buffer, CL_TRUE, 0, count * sizeof(float), f.data());
    out.assign(f.begin(), f.end());
  }
  return out;
}

// The recorded events into the trace's fields; values holds 4 per event.
void decode_events(const std::vector<ProbeEvent>& events, const std::vector<double>& values, SolverTrace& trace) {
  for (std::size_t i = 0; i < events.size(); ++i) {
    const ProbeEvent& e = events[i];
    const double* v = &values[4 * i];
    switch (e.kind) {
      case ALGRAY_EVENT_SEGMENT:
        trace.in_extent = true;
        trace.t_in = v[0];
        trace.t_out = v[1];
        break;
      case ALGRAY_EVENT_COEFFICIENT:
        trace.basis = static_cast<int>(e.decision);
        trace.coefficients.push_back(v[0]);
        trace.coefficients_lo.push_back(v[1]);
        break;
      case ALGRAY_EVENT_STEP:
        trace.steps.push_back(
            {static_cast<int>(e.decision), e.count, static_cast<int>(e.level), v[0], v[1], v[2], v[3]});
        break;
      case ALGRAY_EVENT_CHAIN_ITERATE:
        trace.chain_iterates.push_back({e.count, static_cast<int>(e.level), v[0], v[1], v[2], v[3], trace.t_at(v[0])});
        break;
      case ALGRAY_EVENT_ISOLATED:
        trace.isolation_status = static_cast<int>(e.decision);
        trace.halving_limit = e.count != 0;
        trace.iso_lo = v[0];
        trace.iso_hi = v[1];
        trace.iso_f_lo = v[2];
        trace.iso_f_hi = v[3];
        break;
      case ALGRAY_EVENT_ITERATE: {
        // Iterates are fractions y of the isolating interval, which the ISOLATED event before them gave.
        const double fraction = trace.iso_lo + v[0] * (trace.iso_hi - trace.iso_lo);
        trace.iterates.push_back({e.count, 0, v[0], v[1], v[2], v[3], trace.t_at(fraction)});
        break;
      }
      case ALGRAY_EVENT_DOUBT:
        trace.doubt = ProbeDoubt{static_cast<int>(e.decision), static_cast<int>(e.level), v[0], v[1], v[2], v[3]};
        trace.confirmed.reset();  // a settled bracket's root may be doubted again, as flat
        break;
      case ALGRAY_EVENT_CONFIRMED:
        trace.confirmed = ProbeConfirmed{v[0],
                                         v[1],
                                         v[2],
                                         v[3],
                                         e.decision == 1 || e.decision == 3 || (e.decision == 2 && e.level != 0),
                                         e.decision == 2,
                                         e.decision == 3};
        if (trace.confirmed->discard && trace.doubt) trace.settled_discards.emplace_back(*trace.doubt, *trace.confirmed);
        break;
      default:
        break;
    }
  }
}

}  // namespace

std::vector<double> bernstein_to_power(const std::vector<double>& b, const std::vector<double>& b_lo) {
  const int n = static_cast<int>(b.size()) - 1;
  if (n < 0) return {};
  // sum_k b_k C(n,k) s^k (1-s)^(n-k): the coefficient of s^j is sum_{k<=j} b_k C(n,k) C(n-k, j-k) (-1)^(j-k).
  std::vector<long double> binom(static_cast<std::size_t>((n + 1) * (n + 1)), 0);
  auto C = [&](int a, int k) -> long double& { return binom[static_cast<std::size_t>(a * (n + 1) + k)]; };
  for (int a = 0; a <= n; ++a) {
    C(a, 0) = 1;
    for (int k = 1; k <= a; ++k) C(a, k) = C(a - 1, k - 1) + (k < a ? C(a - 1, k) : 0);
  }
  std::vector<double> power(static_cast<std::size_t>(n + 1));
  for (int j = 0; j <= n; ++j) {
    long double sum = 0;
    for (int k = 0; k <= j; ++k) {
      const long double bk = static_cast<long double>(b[k]) + (b_lo.empty() ? 0.0L : b_lo[k]);
      sum += ((j - k) % 2 ? -1.0L : 1.0L) * bk * C(n, k) * C(n - k, j - k);
    }
    power[static_cast<std::size_t>(j)] = static_cast<double>(sum);
  }
  return power;
}

SolverTrace trace_probe(ClSession& session, ProgramCache& cache, const Scene& scene, std::size_t surface_index,
                        KernelConfig config, const ProbeTarget& target, std::uint32_t capacity) {
  const cl_uint log_capacity = std::max<std::uint32_t>(capacity, 1);
  config.entry = "probe";
  // One ray: the lanes' arithmetic is the scalar build's lane for lane (kernels/lanes.h), so one lane is the
  // render's own code.
  config.lanes = 1;
  // A given ray is traced as the trace kernel traces it: the screen form is the camera rays' alone.
  if (target.given_ray && config.ray_origin == RayOrigin::Screen) config.ray_origin = RayOrigin::Extent;
  SolverTrace trace;
  trace.config = config;
  ProgramRecord record;
  cl::Kernel kernel = cache.kernel(session, config, &record);
  trace.program_origin = record.origin;
  const DeviceSurface surface(session.context, scene, config.precision, surface_index);
  const cl::Context& ctx = session.context;
  cl::Buffer out(ctx, CL_MEM_WRITE_ONLY, sizeof(HitRecord));
  const std::size_t real_size = config.precision == Precision::Double ? sizeof(double) : sizeof(float);
  cl::Buffer ray_out(ctx, CL_MEM_WRITE_ONLY, 8 * real_size);
  cl::Buffer events(ctx, CL_MEM_WRITE_ONLY, log_capacity * sizeof(ProbeEvent));
  cl::Buffer values(ctx, CL_MEM_WRITE_ONLY, 4 * log_capacity * real_size);
  cl::Buffer count(ctx, CL_MEM_WRITE_ONLY, sizeof(cl_uint));

  // The same basis the primary pass builds for a render at the scene's size without antialiasing.
  const RayBasis b = make_ray_basis(scene.camera, scene.image.width, scene.image.height);
  KernelBinder args(kernel, "probe", config.precision);
  args.ray_basis(b);
  args.plain("px", static_cast<cl_uint>(target.px));
  args.plain("py", static_cast<cl_uint>(target.py));
  args.plain("use_given_ray", static_cast<cl_int>(target.given_ray ? 1 : 0));
  args.real_vec("given_o", target.origin);
  args.real_vec("given_d", target.direction);
  surface.set_extent_args(args);
  surface.set_surface_args(args);
  // The render computes every row; the probe only its own, with the same arithmetic.
  const cl::Buffer screen_rows = surface.set_screen_args(args, ctx, config, b, scene.image.width, scene.image.height,
                                                         static_cast<int>(target.py), 1);
  args.plain("out", out);
  args.plain("ray_out", ray_out);
  args.plain("events", events);
  args.plain("values", values);
  args.plain("capacity", log_capacity);
  args.plain("event_count", count);
  session.queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(1), cl::NullRange);
  session.queue.finish();

  session.queue.enqueueReadBuffer(out, CL_TRUE, 0, sizeof(HitRecord), &trace.hit);
  const std::vector<double> ray = read_reals(session, ray_out, 8, config.precision);
  trace.ray.origin = {ray[0], ray[1], ray[2]};
  trace.ray.direction = {ray[4], ray[5], ray[6]};
  session.queue.enqueueReadBuffer(count, CL_TRUE, 0, sizeof(cl_uint), &trace.events_offered);
  trace.events_recorded = std::min<std::uint32_t>(trace.events_offered, log_capacity);
  std::vector<ProbeEvent> log(trace.events_recorded);
  if (!log.empty()) session.queue.enqueueReadBuffer(events, CL_TRUE, 0, log.size() * sizeof(ProbeEvent), log.data());
  decode_events(log, read_reals(session, values, 4 * log.size(), config.precision), trace);

  if (trace.found()) trace.t = static_cast<double>(trace.hit.t_hi) + static_cast<double>(trace.hit.t_lo);
  trace.power = trace.basis == ALGRAY_BASIS_BERNSTEIN ? bernstein_to_power(trace.coefficients, trace.coefficients_lo)
                                                      : trace.coefficients;
  return trace;
}

const char* step_decision_name(int decision) {
  switch (decision) {
    case ALGRAY_STEP_EXACT_ZERO:
      return "exact zero at lo: root";
    case ALGRAY_STEP_CROSSED:
      return "sign changed at lo: root";
    case ALGRAY_STEP_ISOLATED:
      return "one root: isolated";
    case ALGRAY_STEP_SPLIT:
      return "several possible: split";
    case ALGRAY_STEP_NO_ROOT:
      return "no root: next";
    case ALGRAY_STEP_CLUSTER_ROOT:
      return "cluster at stopping width, sign change: root";
    case ALGRAY_STEP_CLUSTER_SKIP:
      return "cluster at stopping width, no sign change: skipped";
    case ALGRAY_STEP_END_ZERO:
      return "far end is a zero: root";
    case ALGRAY_STEP_END_NONE:
      return "searched to the far end: no root";
    case ALGRAY_STEP_PIECE:
      return "monotone piece, no sign change: next";
    default:
      return "?";
  }
}

const char* basis_name(int basis) {
  switch (basis) {
    case ALGRAY_BASIS_BERNSTEIN:
      return "Bernstein basis of s in [0, 1], t = t_in + s (t_out - t_in)";
    case ALGRAY_BASIS_POWER_SEGMENT:
      return "power basis of s in [0, 1], t = t_in + s (t_out - t_in)";
    case ALGRAY_BASIS_POWER_EYE:
      return "power basis of t (around the ray origin)";
    default:
      return "none (the ray misses the extent)";
  }
}

}  // namespace algray
