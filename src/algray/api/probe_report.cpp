// Probe reports: the probe kernel run per solver and surface, the ray certified, and the report as text, JSON or plot.
#include "algray/api/probe_report.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <sstream>

#include "algray/api/render_job.h"
#include "algray/io/image_io.h"
#include "algray/io/probe_plot.h"
#include "algray/render/escalation.h"
#include "algray/render/render_plan.h"
#include "algray/render/renderer.h"
#include "algray/util/json_text.h"
#include "algray/util/version.h"
#include "solver_ref/solver_ref.h"

namespace algray {
namespace {

std::string num(double v, int digits = 17) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

// Built by appending: GCC 12 warns falsely (-Wrestrict) about a chain of operator+ starting from a literal.
std::string joined(const char* open, std::initializer_list<double> values, const char* close) {
  std::string s = open;
  for (double v : values) {
    if (s.size() > 1) s += ", ";
    s += num(v);
  }
  return s += close;
}

std::string vec(const glm::dvec3& v) { return joined("(", {v.x, v.y, v.z}, ")"); }

std::string solver_name(const KernelConfig& c) { return to_string(c.isolation) + "+" + to_string(c.refinement); }

double evaluate(const std::vector<mpq_class>& poly, double t) {
  const mpq_class x = exact_rational(t);
  mpq_class v = 0;
  for (auto it = poly.rbegin(); it != poly.rend(); ++it) v = v * x + *it;
  return v.get_d();
}

const char* status_name(int status) {
  return status == ALGRAY_ISOLATED_BRACKET ? "bracket"
         : status == ALGRAY_ISOLATED_EXACT ? "exact (root at the interval's left end)"
                                           : "none";
}

// The render's own kernel for the surface first (`own`, from its plan), then, when asked, every other valid
// isolation x refinement in its place.
std::vector<KernelConfig> solver_configs(const Scene& scene, const KernelConfig& own, bool all) {
  std::vector<KernelConfig> configs{own};
  if (!all) return configs;
  for (const NamedChoice<Isolation>& isolation : kIsolations) {
    const Isolation i = isolation.value;
    if (own.ray_origin == RayOrigin::Eye && !isolates_in_power_basis(i)) continue;  // none but these around the eye
    for (const NamedChoice<Refinement>& refinement : kRefinements) {
      const Refinement r = refinement.value;
      if (i == own.isolation && r == own.refinement) continue;
      KernelConfig c = own;
      c.isolation = i;
      c.refinement = r;
      c.max_iterations = scene.render.max_iterations > 0 ? scene.render.max_iterations : default_max_iterations(r);
      configs.push_back(c);
    }
  }
  return configs;
}

std::string reference_summary(const ProbeReference& ref) {
  const RayCertificate& c = ref.certificate;
  if (c.cls == PixelClass::OutsideExtent) return "the ray misses the extent";
  std::string s = to_string(c.answer.kind);
  if (c.answer.kind != ref::Classification::Miss && c.answer.kind != ref::Classification::IdenticallyZero)
    s += " at t = " + num(c.answer.t_nearest) + " (multiplicity " + std::to_string(c.answer.multiplicity) + ")";
  const bool certified = c.cls == PixelClass::Miss || c.cls == PixelClass::SimpleRoot;
  s += certified ? ", certified" : std::string(", ambiguous: ") + pixel_class_name(c.cls);
  return s;
}

void print_trace_heading(std::ostream& out, const SolverTrace& tr) {
  const KernelConfig& c = tr.config;
  out << "\n== " << solver_name(c) << ", " << to_string(c.precision) << ", tolerance " << num(c.tolerance, 3)
      << ", max " << c.max_iterations << " iterations, ray origin " << to_string(c.ray_origin) << " (program "
      << tr.program_origin << ") ==\n";
}

void print_polynomial(std::ostream& out, const SolverTrace& tr) {
  out << "P* in the solver's basis: " << basis_name(tr.basis) << "\n";
  for (std::size_t k = 0; k < tr.coefficients.size(); ++k) {
    out << "  c" << k << " = " << num(tr.coefficients[k]);
    if (tr.coefficients_lo[k] != 0) out << " + " << num(tr.coefficients_lo[k]);
    out << "\n";
  }
  if (tr.basis == ALGRAY_BASIS_BERNSTEIN) {
    out << "P* in the power basis of s (converted on the host in long double):\n";
    for (std::size_t k = 0; k < tr.power.size(); ++k) out << "  a" << k << " = " << num(tr.power[k]) << "\n";
  }
}

// The steps as a table, the derivative chain's solves, and the interval isolation settled on.
void print_isolation(std::ostream& out, const SolverTrace& tr) {
  out << "isolation, " << tr.steps.size() << " steps (intervals in t; P* at its ends in the solver's scaling):\n";
  char line[256];
  std::snprintf(line, sizeof line, "  %4s %5s  %-45s %12s %12s %5s  %s\n", "step", "level", "interval [lo, hi]",
                "P*(lo)", "P*(hi)", "count", "decision");
  out << line;
  for (std::size_t i = 0; i < tr.steps.size(); ++i) {
    const ProbeStep& s = tr.steps[i];
    const std::string interval = joined("[", {tr.t_at(s.lo), tr.t_at(s.hi)}, "]");
    std::snprintf(line, sizeof line, "  %4zu %5d  %-45s %12.4e %12.4e %5s  %s\n", i + 1, s.level, interval.c_str(),
                  s.f_lo, s.f_hi, s.count < 0 ? "-" : std::to_string(s.count).c_str(), step_decision_name(s.decision));
    out << line;
  }
  if (!tr.chain_iterates.empty()) {
    out << "derivative chain solves (Newton or bisection on derivatives of P*):\n";
    for (const ProbeIterate& it : tr.chain_iterates)
      out << "  order " << it.order << " #" << it.number << ": t = " << num(it.t) << ", value " << num(it.value, 6)
          << "\n";
  }
  out << "isolation result: " << status_name(tr.isolation_status);
  if (tr.isolation_status != ALGRAY_ISOLATED_NONE)
    out << " on [" << num(tr.t_at(tr.iso_lo)) << ", " << num(tr.t_at(tr.iso_hi)) << "]";
  if (tr.halving_limit) out << " (an interval reached the halving limit)";
  out << "\n";
}

void print_refinement(std::ostream& out, const SolverTrace& tr) {
  if (tr.iterates.empty()) return;
  out << "refinement (" << to_string(tr.config.refinement) << "), " << tr.iterates.size() << " iterates:\n";
  char line[256];
  for (const ProbeIterate& it : tr.iterates) {
    std::snprintf(line, sizeof line, "  %4d  t = %-24s P*(y) = %12.4e  y = %.17g  bracket y in [%.17g, %.17g]\n",
                  it.number + 1, num(it.t).c_str(), it.value, it.y, it.lo, it.hi);
    out << line;
  }
}

bool doubted(const SolverTrace& tr) { return (tr.hit.flags & ALGRAY_HIT_DOUBT) != 0; }

void print_result(std::ostream& out, const SolverTrace& tr) {
  out << "result: ";
  if (doubted(tr)) {
    out << "undecided, left to the second pass";
  } else if (tr.found()) {
    out << "root t = " << num(tr.t) << " (" << ((tr.hit.flags & ALGRAY_HIT_BACK) ? "back" : "front") << " side";
    if (tr.hit.flags & ALGRAY_HIT_EXACT) out << ", exact zero";
    if (tr.hit.flags & ALGRAY_HIT_CLUSTER) out << ", cluster";
    out << ")";
  } else {
    out << "no root";
  }
  out << "; " << tr.isolation_steps() << " isolation steps, " << tr.refine_iterations() << " refinement iterations";
  if (tr.hit.flags & ALGRAY_HIT_BUDGET) out << "; halving limit reached";
  out << "\n";
}

void print_reference_comparison(std::ostream& out, const SolverTrace& tr, const RayCertificate& cert) {
  if (tr.found() && cert.answer.kind != ref::Classification::Miss && cert.cls != PixelClass::OutsideExtent) {
    const double error = std::fabs(tr.t - cert.answer.t_nearest);
    out << "vs solver_ref: |t - t_ref| = " << num(error, 3);
    if (cert.answer.t_nearest != 0) out << " (relative " << num(error / std::fabs(cert.answer.t_nearest), 3) << ")";
    out << "\n";
  } else if (!tr.found() && cert.answer.kind == ref::Classification::Miss) {
    out << "vs solver_ref: agrees, no root\n";
  } else if (tr.found() != (cert.answer.kind != ref::Classification::Miss)) {
    out << "vs solver_ref: DISAGREES (" << (tr.found() ? "kernel hit, reference miss" : "kernel miss, reference root")
        << ")\n";
  }
}

void print_settled_discards(std::ostream& out, const SolverTrace& tr) {
  // The last settled discard is the doubt line below when nothing was doubted after it.
  const std::size_t shown_below = tr.confirmed && tr.confirmed->discard ? 1 : 0;
  for (std::size_t i = 0; i + shown_below < tr.settled_discards.size(); ++i) {
    const auto& [doubt, ends] = tr.settled_discards[i];
    out << "settled on the way: a discard doubt on [" << num(tr.t_at(doubt.lo)) << ", " << num(tr.t_at(doubt.hi))
        << "], P at its ends " << num(ends.before, 4) << " (bound " << num(ends.before_rounding, 3) << ") and "
        << num(ends.after, 4) << " (bound " << num(ends.after_rounding, 3) << ")\n";
  }
}

// How the doubt ended: settled or confirmed by P from the monomials (the render keeps the answer), else the next trace.
void print_doubt_outcome(std::ostream& out, const std::optional<ProbeConfirmed>& confirmed) {
  if (confirmed && confirmed->bracket)
    out << "; settled: P from the monomials" << (confirmed->float_float ? " in float-float" : "") << " is "
        << num(confirmed->before, 4) << " (rounding " << num(confirmed->before_rounding, 3)
        << ") at the interval's start and " << num(confirmed->after, 4) << " (rounding "
        << num(confirmed->after_rounding, 3) << ") at its end, the signs float gave: the render keeps this bracket\n";
  else if (confirmed && confirmed->discard)
    out << "; settled: P at the interval's ends is " << num(confirmed->before, 4) << " (bound "
        << num(confirmed->before_rounding, 3) << ") and " << num(confirmed->after, 4) << " (bound "
        << num(confirmed->after_rounding, 3)
        << "), in float-float where float's value was within the noise, of its coefficients' sign: the search "
           "went on\n";
  else if (confirmed)
    out << "; confirmed: P from the monomials" << (confirmed->float_float ? " in float-float" : "") << " is "
        << num(confirmed->before, 4) << " (rounding " << num(confirmed->before_rounding, 3) << ") before the root and "
        << num(confirmed->after, 4) << " (rounding " << num(confirmed->after_rounding, 3)
        << ") after it, within " ALGRAY_DOUBT_POSITION_TEXT " of its t: the render keeps this root\n";
  else
    out << "; the render traces the ray again in the next trace's precision, whose answer it keeps\n";
}

void print_doubt(std::ostream& out, const SolverTrace& tr, const ProbeDoubt& doubt) {
  const DoubtReason* why = doubt_reason(static_cast<unsigned>(doubt.reason));
  out << "doubted (" << (why ? why->name : "?") << ": " << (why ? why->meaning : "unknown reason")
      << "): " << num(doubt.value, 4) << " within the noise " << num(doubt.noise, 4) << " on ["
      << num(tr.t_at(doubt.lo)) << ", " << num(tr.t_at(doubt.hi)) << "]";
  print_doubt_outcome(out, tr.confirmed);
}

void print_trace(std::ostream& out, const SolverTrace& tr, const ProbeReference& ref) {
  print_trace_heading(out, tr);
  if (!tr.in_extent) {
    out << "the ray misses the extent: nothing to solve\n";
    return;
  }
  print_polynomial(out, tr);
  print_isolation(out, tr);
  print_refinement(out, tr);
  print_result(out, tr);
  // A doubted trace has no answer to compare: the next trace's is the one the render keeps.
  if (!doubted(tr)) print_reference_comparison(out, tr, ref.certificate);
  print_settled_discards(out, tr);
  if (tr.doubt) print_doubt(out, tr, *tr.doubt);
  if (tr.events_offered > tr.events_recorded)
    out << "note: the log kept the first " << tr.events_recorded << " of " << tr.events_offered << " events\n";
}

std::string target_text(const ProbeTarget& t) {
  if (t.given_ray) return "ray o = " + vec(t.origin) + ", d = " + vec(t.direction);
  return "pixel (" + std::to_string(t.px) + ", " + std::to_string(t.py) + ")";
}

nlohmann::json step_json(const SolverTrace& tr, const ProbeStep& s) {
  return {{"decision", step_decision_name(s.decision)},
          {"decision_code", s.decision},
          {"count", s.count},
          {"level", s.level},
          {"t_lo", tr.t_at(s.lo)},
          {"t_hi", tr.t_at(s.hi)},
          {"s_lo", s.lo},
          {"s_hi", s.hi},
          {"f_lo", s.f_lo},
          {"f_hi", s.f_hi}};
}

nlohmann::json iterates_json(const std::vector<ProbeIterate>& list) {
  nlohmann::json a = nlohmann::json::array();
  for (const ProbeIterate& it : list)
    a.push_back({{"number", it.number},
                 {"order", it.order},
                 {"t", it.t},
                 {"y", it.y},
                 {"value", it.value},
                 {"bracket", {it.lo, it.hi}}});
  return a;
}

// What was traced, and how: the solver's configuration and the ray.
nlohmann::json traced_json(const SolverTrace& tr) {
  return {{"solver", solver_name(tr.config)},
          {"isolation", to_string(tr.config.isolation)},
          {"refinement", to_string(tr.config.refinement)},
          {"precision", to_string(tr.config.precision)},
          {"tolerance", tr.config.tolerance},
          {"max_iterations", tr.config.max_iterations},
          {"ray_origin", to_string(tr.config.ray_origin)},
          {"program", tr.program_origin},
          {"ray",
           {{"origin", {tr.ray.origin.x, tr.ray.origin.y, tr.ray.origin.z}},
            {"direction", {tr.ray.direction.x, tr.ray.direction.y, tr.ray.direction.z}}}},
          {"in_extent", tr.in_extent}};
}

// P at a settled interval's ends, or around a confirmed root, and the rounding bound of each.
nlohmann::json ends_json(const ProbeConfirmed& ends) {
  return {{"before", ends.before},
          {"before_rounding", ends.before_rounding},
          {"after", ends.after},
          {"after_rounding", ends.after_rounding}};
}

nlohmann::json settled_discards_json(const SolverTrace& tr) {
  nlohmann::json settled = nlohmann::json::array();
  for (const auto& [doubt, ends] : tr.settled_discards) {
    nlohmann::json s = ends_json(ends);
    s["t_lo"] = tr.t_at(doubt.lo);
    s["t_hi"] = tr.t_at(doubt.hi);
    settled.push_back(s);
  }
  return settled;
}

nlohmann::json doubt_json(const SolverTrace& tr, const ProbeDoubt& doubt) {
  const DoubtReason* why = doubt_reason(static_cast<unsigned>(doubt.reason));
  nlohmann::json j = {{"reason", why ? why->name : "?"}, {"level", doubt.level}, {"t_lo", tr.t_at(doubt.lo)},
                      {"t_hi", tr.t_at(doubt.hi)},       {"value", doubt.value}, {"noise", doubt.noise}};
  if (tr.confirmed) {
    j["confirmed"] = ends_json(*tr.confirmed);
    j["confirmed"]["float_float"] = tr.confirmed->float_float;
    j["confirmed"]["bracket"] = tr.confirmed->bracket;
    j["confirmed"]["discard"] = tr.confirmed->discard;
  }
  return j;
}

nlohmann::json trace_json(const SolverTrace& tr) {
  nlohmann::json j = traced_json(tr);
  if (!tr.in_extent) return j;
  j["t_in"] = tr.t_in;
  j["t_out"] = tr.t_out;
  j["basis"] = basis_name(tr.basis);
  j["coefficients"] = tr.coefficients;
  if (tr.config.precision == Precision::Mixed) j["coefficients_lo"] = tr.coefficients_lo;
  j["power_coefficients"] = tr.power;
  j["steps"] = nlohmann::json::array();
  for (const ProbeStep& s : tr.steps) j["steps"].push_back(step_json(tr, s));
  if (!tr.chain_iterates.empty()) j["chain_iterates"] = iterates_json(tr.chain_iterates);
  j["isolation"] = {{"status", status_name(tr.isolation_status)},
                    {"t_lo", tr.t_at(tr.iso_lo)},
                    {"t_hi", tr.t_at(tr.iso_hi)},
                    {"f_lo", tr.iso_f_lo},
                    {"f_hi", tr.iso_f_hi},
                    {"halving_limit", tr.halving_limit}};
  j["iterates"] = iterates_json(tr.iterates);
  if (!tr.settled_discards.empty()) j["settled_discards"] = settled_discards_json(tr);
  if (tr.doubt) j["doubt"] = doubt_json(tr, *tr.doubt);
  j["found"] = tr.found();
  if (tr.found()) j["t"] = tr.t;
  j["back_side"] = (tr.hit.flags & ALGRAY_HIT_BACK) != 0;
  j["flags"] = tr.hit.flags;
  j["isolation_steps"] = tr.isolation_steps();
  j["refine_iterations"] = tr.refine_iterations();
  j["events"] = {{"offered", tr.events_offered}, {"recorded", tr.events_recorded}};
  return j;
}

nlohmann::json reference_json(const ProbeReference& ref) {
  const RayCertificate& c = ref.certificate;
  nlohmann::json j = {{"class", pixel_class_name(c.cls)},
                      {"certified", c.cls == PixelClass::Miss || c.cls == PixelClass::SimpleRoot}};
  if (c.cls == PixelClass::OutsideExtent) return j;
  j["t_in"] = static_cast<double>(c.t_in);
  j["t_out"] = static_cast<double>(c.t_out);
  j["smallest"] = {{"kind", to_string(c.answer.kind)}, {"multiplicity", c.answer.multiplicity}};
  if (c.answer.kind != ref::Classification::Miss) {
    j["smallest"]["t"] = c.answer.t_nearest;
    j["smallest"]["enclosure"] = {c.answer.lo.get_d(), c.answer.hi.get_d()};
  }
  nlohmann::json roots = nlohmann::json::array();
  for (const ProbeReference::Root& r : ref.roots)
    roots.push_back({{"t", r.t}, {"multiplicity", r.multiplicity}, {"kind", r.kind}});
  j["roots"] = roots;
  std::vector<double> power;
  for (const mpq_class& q : c.restricted) power.push_back(q.get_d());
  j["power_coefficients_t"] = power;
  return j;
}

}  // namespace

// P*(t) from solver_ref's exact restriction, sampled evenly and at the isolating intervals' ends. Not at the
// roots: a sample there is 0 to rounding, and the plot's log floor would follow it down to 1e-12 of the
// largest value, spending most of the height on decades that only the roots' neighbourhoods reach.
ProbePlot make_plot(const Scene& scene, const ProbeTarget& target, const SurfaceProbe& probe, const PlotRange& range) {
  const SolverTrace& first = probe.traces.front();
  ProbePlot plot;
  plot.t_in = first.t_in;
  plot.t_out = first.t_out;
  std::string shown = "[t_in, t_out]";
  if (range.kind == PlotRange::Kind::Given) {
    plot.t_in = range.from;
    plot.t_out = range.to;
    shown = "[" + num(range.from, 10) + ", " + num(range.to, 10) + "]";
  } else if (range.kind == PlotRange::Kind::Isolating && first.isolation_status != ALGRAY_ISOLATED_NONE) {
    const double lo = first.t_at(first.iso_lo), hi = first.t_at(first.iso_hi);
    const double margin = hi > lo ? (hi - lo) / 10 : 1e-6 * std::max(1.0, std::fabs(lo));
    plot.t_in = std::max(first.t_in, lo - margin);
    plot.t_out = std::min(first.t_out, hi + margin);
    shown = "the isolating interval";
  }
  plot.title = scene.name + ", " + target_text(target) + ": P*(t) on " + shown;
  std::vector<double> ts;
  const int samples = 1500;
  for (int i = 0; i <= samples; ++i) ts.push_back(plot.t_in + (plot.t_out - plot.t_in) * i / samples);
  const bool several = probe.traces.size() > 1;
  for (const SolverTrace& tr : probe.traces) {
    const std::string who = several ? " (" + solver_name(tr.config) + ")" : "";
    if (tr.isolation_status != ALGRAY_ISOLATED_NONE) {
      const double lo = tr.t_at(tr.iso_lo), hi = tr.t_at(tr.iso_hi);
      plot.intervals.push_back({lo, hi});
      plot.markers.push_back({PlotMarker::Kind::IsolationEnd, lo, "isolating lo" + who});
      if (hi != lo) plot.markers.push_back({PlotMarker::Kind::IsolationEnd, hi, "isolating hi" + who});
      ts.push_back(lo);
      ts.push_back(hi);
    }
    if (tr.found()) plot.markers.push_back({PlotMarker::Kind::Root, tr.t, "root " + num(tr.t, 10) + who});
    if (!several) break;
  }
  for (const ProbeReference::Root& r : probe.reference.roots) {
    plot.markers.push_back({PlotMarker::Kind::ReferenceRoot, r.t, "solver_ref " + r.kind + " " + num(r.t, 10)});
  }
  std::sort(ts.begin(), ts.end());
  ts.erase(std::unique(ts.begin(), ts.end()), ts.end());
  for (double t : ts) {
    if (t < plot.t_in || t > plot.t_out) continue;
    plot.t.push_back(t);
    plot.value.push_back(evaluate(probe.reference.certificate.restricted, t));
  }
  return plot;
}

ProbeReference probe_reference(const Scene& scene, std::size_t surface, const PixelRay& ray, Precision precision) {
  ProbeReference out;
  const SceneSurface& s = scene.surfaces.at(surface);
  out.certificate = certify_ray(s.polynomial, s.polynomial.monomials(), scene.extent, ray, precision);
  const RayCertificate& c = out.certificate;
  if (c.cls == PixelClass::OutsideExtent || c.answer.kind == ref::Classification::IdenticallyZero) return out;
  // Every root on the segment, left to right: each search starts past the previous root's enclosure.
  mpq_class from = c.lo;
  for (std::size_t guard = 0; guard <= c.restricted.size() && from <= c.hi; ++guard) {
    const ref::Answer a = ref::smallest_root(c.restricted, from, c.hi, c.width);
    if (a.kind == ref::Classification::Miss || a.kind == ref::Classification::IdenticallyZero) break;
    out.roots.push_back({a.t_nearest, a.multiplicity, ref::to_string(a.kind)});
    from = a.hi + c.width;
  }
  return out;
}

void print_probe(std::ostream& out, const Scene& scene, const ProbeTarget& target,
                 const std::vector<SurfaceProbe>& probes) {
  out << "algray probe: " << scene.source << ", " << target_text(target) << "\n";
  for (const SurfaceProbe& p : probes) {
    const SolverTrace& first = p.traces.front();
    out << "\n# surface " << p.surface << " \"" << scene.surfaces[p.surface].name
        << "\": " << scene.surfaces[p.surface].equation << "\n";
    out << "ray as traced (" << to_string(first.config.precision) << "): o = " << vec(first.ray.origin)
        << ", d = " << vec(first.ray.direction) << "\n";
    if (first.in_extent) out << "[t_in, t_out] = [" << num(first.t_in) << ", " << num(first.t_out) << "]\n";
    out << "solver_ref: " << reference_summary(p.reference) << "\n";
    if (!p.reference.roots.empty()) {
      out << "solver_ref roots on the segment:";
      for (const ProbeReference::Root& r : p.reference.roots)
        out << " " << num(r.t) << " (" << r.kind << ", multiplicity " << r.multiplicity << ")";
      out << "\n";
    }
    for (const SolverTrace& tr : p.traces) print_trace(out, tr, p.reference);
    if (p.traces.size() > 1) {
      out << "\nside by side (surface " << p.surface << "):\n";
      char line[200];
      std::snprintf(line, sizeof line, "  %-32s %-24s %10s %6s %6s\n", "solver", "root t", "|error|", "steps", "iters");
      out << line;
      const bool ref_root = p.reference.certificate.answer.kind != ref::Classification::Miss &&
                            p.reference.certificate.cls != PixelClass::OutsideExtent;
      for (const SolverTrace& tr : p.traces) {
        const std::string error = tr.found() && ref_root
                                      ? num(std::fabs(tr.t - p.reference.certificate.answer.t_nearest), 3)
                                  : tr.found() != ref_root ? "DISAGREES"
                                                           : "-";
        std::snprintf(line, sizeof line, "  %-32s %-24s %10s %6u %6u\n", solver_name(tr.config).c_str(),
                      tr.found() ? num(tr.t).c_str() : "no root", error.c_str(), tr.isolation_steps(),
                      tr.refine_iterations());
        out << line;
      }
    }
  }
}

nlohmann::json probe_json(const Scene& scene, const ProbeTarget& target, const std::vector<SurfaceProbe>& probes) {
  nlohmann::json j = {{"version", version_string()}, {"name", utf8_for_json(scene.name)}};
  put_path(j, "scene", scene.source);
  if (target.given_ray)
    j["ray"] = {{"origin", {target.origin.x, target.origin.y, target.origin.z}},
                {"direction", {target.direction.x, target.direction.y, target.direction.z}}};
  else
    j["pixel"] = {target.px, target.py};
  nlohmann::json surfaces = nlohmann::json::array();
  for (const SurfaceProbe& p : probes) {
    nlohmann::json solvers = nlohmann::json::array();
    for (const SolverTrace& tr : p.traces) solvers.push_back(trace_json(tr));
    surfaces.push_back({{"surface", p.surface},
                        {"name", utf8_for_json(scene.surfaces[p.surface].name)},
                        {"equation", utf8_for_json(scene.surfaces[p.surface].equation)},
                        {"reference", reference_json(p.reference)},
                        {"solvers", solvers}});
  }
  j["surfaces"] = surfaces;
  return j;
}

void check_probe_target(const Scene& scene, const ProbeTarget& target) {
  if (!target.given_ray &&
      (target.px < 0 || target.py < 0 || target.px >= scene.image.width || target.py >= scene.image.height))
    throw SceneError("--pixel", "pixel (" + std::to_string(target.px) + ", " + std::to_string(target.py) +
                                    ") is outside the " + std::to_string(scene.image.width) + "x" +
                                    std::to_string(scene.image.height) + " image");
  const glm::dvec3& d = target.direction;
  if (target.given_ray && !(std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)}) > 0))
    throw SceneError("--ray", "the direction must be nonzero");
}

std::vector<SurfaceProbe> probe_scene(const Scene& scene, const ProbeTarget& target, bool all_solvers,
                                      RenderContext& context) {
  ClSession& session = context.session();
  const Precision precision = resolve_precision(scene, session.info, context.cache());
  // The render's plan on this device decides the probe's kernels as it decides the render's: the solver, the ray
  // origin, whether the float kernels settle their doubts, and the second pass's precision.
  const RenderPlan plan = make_render_plan(
      scene, precision,
      {PlanDevice{session.info, precision == Precision::Adaptive ? escalation_precision(session.info, context.cache())
                                                                 : Precision::Mixed}});
  const PlannedPass& primary = *plan.find(PassKind::Primary);
  std::vector<SurfaceProbe> probes;
  for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
    SurfaceProbe p;
    p.surface = s;
    for (const KernelConfig& c : solver_configs(scene, primary.kernels.at(s), all_solvers)) {
      p.traces.push_back(trace_probe(session, context.cache(), scene, s, c, target));
      // A ray adaptive precision doubts is traced again as the render does, the float ray as it was traced, in
      // the precision of the second pass (the plan's escalation kernel): that trace follows it.
      if (p.traces.back().hit.flags & ALGRAY_HIT_DOUBT) {
        KernelConfig again = c;
        again.precision = primary.escalation.at(s).precision;
        again.settle_doubts = primary.escalation.at(s).settle_doubts;
        ProbeTarget same_ray;
        same_ray.given_ray = true;
        same_ray.origin = p.traces.back().ray.origin;
        same_ray.direction = p.traces.back().ray.direction;
        p.traces.push_back(trace_probe(session, context.cache(), scene, s, again, same_ray));
      }
    }
    p.reference = probe_reference(scene, s, p.traces.front().ray, precision);
    probes.push_back(std::move(p));
  }
  return probes;
}

}  // namespace algray
