// Solver benchmarks of issue 4: rays/s per degree, accuracy against time, the paper's Fig. 2 and its Barth decic
// experiment. Each writes JSON; bench/solvers.py runs them all, plots them and writes bench/RESULTS.md.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "algray/io/image_io.h"
#include "algray/device/program_cache.h"
#include "algray/render/reference_render.h"
#include "algray/render/renderer.h"
#include "algray/scene/scene.h"
#include "algray/render/shade.h"

using namespace algray;
using json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

struct Method {
  Isolation isolation;
  Refinement refinement;
  std::string name() const { return to_string(isolation) + "/" + to_string(refinement); }
};

// Quick mode and the accuracy sweep vary one choice at a time around the default (Bernstein with Brent):
// every isolation with Brent, every refinement with Bernstein. The full per-degree run takes every pair.
std::vector<Method> one_at_a_time() {
  std::vector<Method> m;
  for (const NamedChoice<Refinement>& r : kRefinements) m.push_back({Isolation::Bernstein, r.value});
  for (const NamedChoice<Isolation>& i : kIsolations)
    if (i.value != Isolation::Bernstein) m.push_back({i.value, Refinement::Brent});
  return m;
}

std::vector<Method> every_pair() {
  std::vector<Method> m;
  for (const NamedChoice<Isolation>& i : kIsolations)
    for (const NamedChoice<Refinement>& r : kRefinements) m.push_back({i.value, r.value});
  return m;
}

std::string quoted(const std::string& s) { return "\"" + s + "\""; }

std::string number(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

std::vector<Override> solver_overrides(const Method& m, Precision p, double tolerance, int max_iterations = 0) {
  std::vector<Override> o = {{"render.isolation", quoted(to_string(m.isolation))},
                             {"render.refinement", quoted(to_string(m.refinement))},
                             {"render.precision", quoted(to_string(p))},
                             {"render.tolerance", number(tolerance)}};
  if (max_iterations > 0) o.push_back({"render.max_iterations", std::to_string(max_iterations)});
  return o;
}

std::vector<Override> joined(std::vector<Override> a, const std::vector<Override>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

double kernel_ms(const RenderResult& r) {
  double ms = 0;
  for (const PassStats& p : r.passes) ms += p.kernel_ms;
  return ms;
}

struct Timed {
  RenderResult result;  // of the last run
  double median_kernel_ms = 0;
};

// One untimed run (builds or loads the program), then `runs` timed ones; device time of the launches.
Timed timed_render(Renderer& renderer, const Scene& scene, int runs) {
  Timed t;
  t.result = renderer.render_with_records(scene);
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    t.result = renderer.render_with_records(scene);
    ms.push_back(kernel_ms(t.result));
  }
  t.median_kernel_ms = median(ms);
  return t;
}

long hit_count(const RenderResult& r) {
  long n = 0;
  for (const HitRecord& h : r.hits.records) n += (h.flags & ALGRAY_HIT_FOUND) != 0;
  return n;
}

json machine(const ClSession& session) {
  return {{"device", session.info.name},
          {"platform", session.info.platform_name + " " + session.info.platform_version},
          {"driver", session.info.driver_version}};
}

void write_json(const fs::path& path, const json& j) {
  fs::create_directories(path.parent_path().empty() ? fs::path(".") : path.parent_path());
  const fs::path tmp = path.string() + ".tmp";
  std::ofstream(tmp) << j.dump(1) << "\n";
  fs::rename(tmp, path);
}

// A seeded random surface of exactly `degree` inside the unit sphere: x^n + y^n + z^n fixes the degree (and,
// for even n, closes the surface off at large radius), then random monomials of every lower degree with
// coefficients in [-1, 1], as many as a hand-made surface of that degree tends to have (about 3n).
std::string random_surface(int degree, unsigned seed, int width, int height) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coefficient(-1, 1);
  std::ostringstream s;
  s.precision(17);
  s << "[surface]\nname = \"random degree " << degree << "\"\nterms = [[" << degree << ", 0, 0, 1], [0, " << degree
    << ", 0, 1], [0, 0, " << degree << ", 1], [0, 0, 0, -0.25]";
  for (int m = 0; m < 3 * degree; ++m) {
    const int total = std::uniform_int_distribution<int>(1, std::max(1, degree - 1))(rng);
    const int i = std::uniform_int_distribution<int>(0, total)(rng);
    const int j = std::uniform_int_distribution<int>(0, total - i)(rng);
    s << ", [" << i << ", " << j << ", " << total - i - j << ", " << coefficient(rng) << "]";
  }
  s << "]\n\n[extent]\ntype = \"sphere\"\ncentre = [0, 0, 0]\nradius = 1\n\n"
    << "[camera]\nprojection = \"perspective\"\neye = [1.2, 0.9, 2.6]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\n"
    << "fov_y = 45\n\n[image]\nwidth = " << width << "\nheight = " << height << "\n";
  return s.str();
}

// --- 1. rays/s per degree -------------------------------------------------------------------------------------

json bench_degrees(ClSession& session, bool quick, const fs::path& cache_dir) {
  const std::vector<int> degrees = quick ? std::vector<int>{2, 4, 8, 15, 32} : [] {
    std::vector<int> all;
    for (int d = 1; d <= kMaxDegree; ++d) all.push_back(d);
    return all;
  }();
  const int side = quick ? 256 : 512, runs = quick ? 3 : 5;
  const std::vector<Method> methods = quick ? one_at_a_time() : every_pair();
  json rows = json::array();
  for (int degree : degrees) {
    const std::string text = random_surface(degree, 1000u + static_cast<unsigned>(degree), side, side);
    for (const NamedChoice<Precision>& choice : kPrecisions) {
      const Precision precision = choice.value;
      if (precision == Precision::Mixed && degree > kMaxMixedDegree) continue;
      for (const Method& m : methods) {
        const Scene scene = load_scene_text(text, "random", solver_overrides(m, precision, 1e-9));
        // Cold: compiled from source (PoCL's own cache is off, see main). Warm: a binary from the disk cache.
        ProgramCache cold_cache(false);
        Renderer cold(session, cold_cache);
        const RenderResult first = cold.render_with_records(scene);
        ProgramCache fill(true, cache_dir);
        Renderer(session, fill).render_with_records(scene);
        ProgramCache warm_cache(true, cache_dir);
        Renderer warm(session, warm_cache);
        const Timed t = timed_render(warm, scene, runs);
        const double rays = static_cast<double>(side) * side;
        json row = {{"degree", degree},
                    {"isolation", to_string(m.isolation)},
                    {"refinement", to_string(m.refinement)},
                    {"precision", to_string(precision)},
                    {"rays", rays},
                    {"hit_share", static_cast<double>(hit_count(t.result)) / rays},
                    {"kernel_ms", t.median_kernel_ms},
                    {"rays_per_s", rays / (t.median_kernel_ms / 1000)},
                    {"build_cold_ms", first.programs.at(0).build_ms}};
        // The warm cache's first render loaded the binary from disk; its record says how long that took.
        ProgramCache probe(true, cache_dir);
        const RenderResult loaded = Renderer(session, probe).render_with_records(scene);
        row["build_warm_ms"] = loaded.programs.at(0).build_ms;
        row["warm_origin"] = loaded.programs.at(0).origin;
        std::fprintf(stderr, "degree %2d %-6s %-28s %10.0f rays/s  build %6.0f / %4.0f ms\n", degree,
                     to_string(precision).c_str(), m.name().c_str(), row["rays_per_s"].get<double>(),
                     row["build_cold_ms"].get<double>(), row["build_warm_ms"].get<double>());
        rows.push_back(row);
      }
    }
  }
  return {{"side", side}, {"runs", runs}, {"rows", rows}};
}

// --- 2. accuracy against time ---------------------------------------------------------------------------------

json bench_accuracy(ClSession& session, bool quick, const fs::path& scenes, const fs::path& cache_dir) {
  const std::vector<std::string> surfaces =
      quick ? std::vector<std::string>{"barth_sextic", "barth_decic", "endrass_octic"}
            : std::vector<std::string>{"barth_sextic", "cusp_catastrophe", "torus",           "tooth",
                                       "lemniscate",   "barth_decic",      "tanglecube",      "kummer",
                                       "cayley_cubic", "endrass_octic",    "chebyshev_nonic", "goursat12"};
  const std::vector<double> tolerances =
      quick ? std::vector<double>{1e-2, 1e-5, 1e-8, 1e-12}
            : std::vector<double>{1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
  // Large enough that kernel time is not launch overhead (160x120 measured 1.5-5 ms, all alike). The full
  // form keeps the quick form's 320x240: at 640x480 it took over an hour on 2 cores, most of it reference
  // renders and kernel runs; the program builds (the tolerance is compiled in) do not shrink with the image.
  const int width = 320, height = 240, runs = 5;
  ProgramCache cache(true, cache_dir);
  json rows = json::array();
  for (const std::string& name : surfaces) {
    const std::string file = (scenes / (name + ".toml")).string();
    // Primary rays only, one per pixel: the pixels are compared one for one with the reference.
    const std::vector<Override> size = {{"image.width", std::to_string(width)},
                                        {"image.height", std::to_string(height)},
                                        {"antialias.samples", "1"},
                                        {"render.preview", "true"}};
    const Scene base = load_scene_file(file, size);
    const ReferenceResult float_rays = render_reference(base, Precision::Float);
    const ReferenceResult double_rays = render_reference(base, Precision::Double);
    for (Precision precision : {Precision::Float, Precision::Mixed, Precision::Double}) {
      if (precision == Precision::Mixed && base.surface().polynomial.degree() > kMaxMixedDegree) continue;
      for (const Method& m : one_at_a_time()) {
        for (double tolerance : tolerances) {
          const Scene scene = load_scene_file(file, joined(size, solver_overrides(m, precision, tolerance)));
          Renderer renderer(session, cache);
          const Timed t = timed_render(renderer, scene, runs);
          const ReferenceComparison c =
              compare_with_reference(t.result.hits, precision == Precision::Double ? double_rays : float_rays);
          rows.push_back({{"surface", name},
                          {"isolation", to_string(m.isolation)},
                          {"refinement", to_string(m.refinement)},
                          {"precision", to_string(precision)},
                          {"tolerance", tolerance},
                          {"kernel_ms", t.median_kernel_ms},
                          {"certified", c.certified},
                          {"ambiguous", c.ambiguous},
                          {"wrong_hit_miss", c.disagreements},
                          {"median_depth_error", c.median_depth},
                          {"max_depth_error", c.worst_depth}});
          std::fprintf(stderr, "%-16s %-6s %-28s tol %-6g %8.1f ms  wrong %4ld  depth median %.2g max %.2g\n",
                       name.c_str(), to_string(precision).c_str(), m.name().c_str(), tolerance, t.median_kernel_ms,
                       c.disagreements, c.median_depth, c.worst_depth);
        }
      }
    }
  }
  return {{"width", width}, {"height", height}, {"runs", runs}, {"rows", rows}};
}

// --- 3. the paper's Fig. 2 ----------------------------------------------------------------------------------

// The paper's solver (power basis around the eye, in double) and ours (Bernstein over the extent), each with
// the three refinements Fig. 2 compares.
struct Setup {
  const char* name;
  Isolation isolation;
  const char* ray_origin;
};
constexpr Setup kSetups[] = {{"paper", Isolation::PowerDescartes, "eye"}, {"ours", Isolation::Bernstein, "extent"}};
constexpr Refinement kFig2Refinements[] = {Refinement::Bisection, Refinement::RegulaFalsi, Refinement::Brent};

json bench_fig2(ClSession& session, bool quick, const fs::path& scenes, const fs::path& cache_dir) {
  // Fig. 2: 1024x768 with antialiasing (2x2 supersampling, the rays of a 2048x1536 image), preview mode.
  const int supersampling = 2, width = 1024, height = 768, runs = quick ? 3 : 5;
  const std::vector<std::pair<std::string, double>> paper_seconds_brent = {
      {"barth_sextic", 457}, {"cusp_catastrophe", 114}, {"torus", 255},
      {"tooth", 114},        {"lemniscate", 245},       {"tanglecube", 239}};
  ProgramCache cache(true, cache_dir);
  Renderer renderer(session, cache);
  json rows = json::array();
  for (const auto& [name, paper_s] : paper_seconds_brent) {
    for (const Setup& setup : kSetups) {
      for (Refinement r : kFig2Refinements) {
        std::vector<Override> o = solver_overrides({setup.isolation, r}, Precision::Double, 1e-6);
        o.push_back({"render.ray_origin", quoted(setup.ray_origin)});
        o.push_back({"image.width", std::to_string(width)});
        o.push_back({"image.height", std::to_string(height)});
        o.push_back({"antialias.samples", std::to_string(supersampling)});
        o.push_back({"render.preview", "true"});
        const Scene scene = load_scene_file((scenes / (name + ".toml")).string(), o);
        const auto start = std::chrono::steady_clock::now();
        const Timed t = timed_render(renderer, scene, runs);
        const double wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        long iterations = 0;
        for (const HitRecord& h : t.result.hits.records) iterations += ALGRAY_WORK_REFINE_ITERATIONS(h.work);
        rows.push_back({{"surface", name},
                        {"setup", setup.name},
                        {"refinement", to_string(r)},
                        {"kernel_ms", t.median_kernel_ms},
                        {"wall_ms_per_run", wall / (runs + 1)},
                        {"refine_iterations", iterations},
                        {"paper_brent_s", paper_s}});
        std::fprintf(stderr, "%-16s %-6s %-12s %8.1f ms  %ld iterations\n", name.c_str(), setup.name,
                     to_string(r).c_str(), t.median_kernel_ms, iterations);
      }
    }
  }
  return {{"width", width}, {"height", height}, {"supersampling", supersampling}, {"runs", runs}, {"rows", rows}};
}

// --- 4. the paper's Barth decic experiment --------------------------------------------------------------------

json bench_decic(ClSession& session, bool quick, const fs::path& scenes, const fs::path& cache_dir,
                 const fs::path& figure) {
  const int width = quick ? 320 : 1024, height = quick ? 240 : 768;
  const double tolerance = 1e-6;  // the paper's accuracy, with its 1000-iteration cap for every method
  const std::string file = (scenes / "barth_decic.toml").string();
  const std::vector<Override> size = {{"image.width", std::to_string(width)},
                                      {"image.height", std::to_string(height)},
                                      {"antialias.samples", "1"},
                                      {"render.preview", "true"}};
  const Scene base = load_scene_file(file, size);
  const ReferenceResult reference = render_reference(base, Precision::Double);
  ProgramCache cache(true, cache_dir);
  Renderer renderer(session, cache);
  json rows = json::array();
  for (const Setup& setup : kSetups) {
    FrameImage strip;
    strip.width = 3 * width;
    strip.height = height;
    strip.rgba.assign(static_cast<std::size_t>(strip.width) * height * 4, 1.0f);
    int panel = 0;
    for (Refinement r : {Refinement::RegulaFalsi, Refinement::Brent, Refinement::Bisection}) {
      std::vector<Override> o =
          joined(size, solver_overrides({setup.isolation, r}, Precision::Double, tolerance, 1000));
      o.push_back({"render.ray_origin", quoted(setup.ray_origin)});
      const Scene scene = load_scene_file(file, o);
      const Timed t = timed_render(renderer, scene, 1);
      const ReferenceComparison c = compare_with_reference(t.result.hits, reference);
      // A defect: a certified pixel where the method disagrees on hit or miss, or misses the requested
      // accuracy (its stopping width, 4 eps max(|t|, 1), with a factor 10 to spare) on a certified root.
      long defects = 0, capped = 0;
      std::vector<bool> defect(t.result.hits.records.size(), false);
      for (std::size_t i = 0; i < defect.size(); ++i) {
        const HitRecord& h = t.result.hits.records[i];
        capped += static_cast<int>(ALGRAY_WORK_REFINE_ITERATIONS(h.work)) >= 1000;
        const auto cls = static_cast<PixelClass>(reference.classes[i]);
        if (cls != PixelClass::Miss && cls != PixelClass::SimpleRoot) continue;
        const bool hit = (h.flags & ALGRAY_HIT_FOUND) != 0;
        bool bad = hit != (cls == PixelClass::SimpleRoot);
        if (hit && !bad) {
          const double t_kernel = static_cast<double>(h.t_hi) + static_cast<double>(h.t_lo);
          bad = std::fabs(t_kernel - reference.t[i]) > 10 * 4 * tolerance * std::max(std::fabs(reference.t[i]), 1.0);
        }
        defect[i] = bad;
        defects += bad;
      }
      const FrameImage shaded = shade_frame(scene, t.result);
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
          const std::size_t from = static_cast<std::size_t>(y) * width + x;
          const std::size_t to = static_cast<std::size_t>(y) * strip.width + panel * width + x;
          for (int ch = 0; ch < 4; ++ch)
            strip.rgba[to * 4 + ch] = defect[from] ? (ch == 0 || ch == 3 ? 1.0f : 0.0f) : shaded.rgba[from * 4 + ch];
        }
      ++panel;
      rows.push_back({{"setup", setup.name},
                      {"refinement", to_string(r)},
                      {"defects", defects},
                      {"wrong_hit_miss", c.disagreements},
                      {"at_iteration_cap", capped},
                      {"max_depth_error", c.worst_depth},
                      {"kernel_ms", t.median_kernel_ms}});
      std::fprintf(stderr, "decic %-6s %-12s %6ld defects (%ld hit/miss), %ld pixels at the cap\n", setup.name,
                   to_string(r).c_str(), defects, c.disagreements, capped);
    }
    fs::path out = figure;
    out.replace_filename(figure.stem().string() + "_" + setup.name + figure.extension().string());
    write_png(out, strip);
  }
  return {{"width", width}, {"height", height}, {"tolerance", tolerance}, {"max_iterations", 1000}, {"rows", rows}};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"algray solver benchmarks (issue 4); bench/solvers.py runs them all and writes RESULTS.md"};
  app.require_subcommand(1);
  std::string device, out, figure = "bench/figures/decic_methods.png";
  std::string scenes = std::string(ALGRAY_SOURCE_DIR) + "/scenes";
  bool quick = false;
  app.add_option("--device", device, "device index or name substring");
  app.add_option("--out", out, "JSON file to write")->required();
  app.add_option("--scenes", scenes, "directory of the scene files");
  app.add_flag("--quick", quick, "fewer degrees, surfaces and tolerances, smaller images");
  CLI::App* degrees = app.add_subcommand("degrees", "rays/s and build times per degree and method");
  CLI::App* accuracy = app.add_subcommand("accuracy", "kernel time and error against solver_ref per tolerance");
  CLI::App* fig2 = app.add_subcommand("fig2", "the paper's Fig. 2: three refinements, six surfaces, 1024x768 AA");
  CLI::App* decic = app.add_subcommand("decic", "the paper's Barth decic experiment, with images");
  decic->add_option("--figure", figure, "PNG of the three methods side by side (one per setup)");
  CLI11_PARSE(app, argc, argv);

  // Cold build times must not come from PoCL's own kernel cache.
  setenv("POCL_KERNEL_CACHE", "0", 1);
  try {
    ClSession session(select_device(device));
    json result = {{"machine", machine(session)}, {"quick", quick}};
    const fs::path cache_dir = fs::temp_directory_path() / ("algray-bench-cache-" + std::to_string(getpid()));
    if (degrees->parsed()) result["degrees"] = bench_degrees(session, quick, cache_dir);
    if (accuracy->parsed()) result["accuracy"] = bench_accuracy(session, quick, scenes, cache_dir);
    if (fig2->parsed()) result["fig2"] = bench_fig2(session, quick, scenes, cache_dir);
    if (decic->parsed()) result["decic"] = bench_decic(session, quick, scenes, cache_dir, figure);
    fs::remove_all(cache_dir);
    write_json(out, result);
  } catch (const std::exception& e) {
    std::cerr << "solver_bench: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
