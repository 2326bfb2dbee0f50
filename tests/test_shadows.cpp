// The shadow kernel against the certified reference: no self-shadowing, and the same answer wherever the
// reference can certify whether the shadow ray meets the surface.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "algray/device/program_cache.h"
#include "algray/render/reference_render.h"
#include "algray/render/render_plan.h"
#include "algray/render/renderer.h"
#include "algray/render/shadow_tracer.h"
#include "algray/scene/scene.h"
#include "solver_ref/solver_ref.h"
#include "test_support.h"

using namespace algray;

namespace {

constexpr unsigned kSeed = 20261129;
const char* const kScenes[] = {"barth_sextic.toml", "torus.toml", "tanglecube.toml", "cusp_catastrophe.toml",
                               "kummer.toml"};

// A surface point seen by a camera ray: the shadow pass's input.
struct SurfacePoint {
  glm::dvec3 point;
  glm::vec3 normal;
};

// Every hit of a small primary render of `scene`.
std::vector<SurfacePoint> surface_points(Renderer& renderer, const Scene& scene) {
  const RenderResult r = renderer.render_with_records(scene);
  const bool single = r.config.precision != Precision::Double;
  std::vector<SurfacePoint> points;
  for (int y = 0; y < r.hits.height; ++y)
    for (int x = 0; x < r.hits.width; ++x) {
      const HitRecord& h = r.hits.at(x, y);
      if (h.flags & ALGRAY_HIT_FOUND)
        points.push_back({hit_point(pixel_ray(r.basis, single, x, y), h), {h.normal_x, h.normal_y, h.normal_z}});
    }
  return points;
}

enum class Verdict { Visible, Hidden, Ambiguous, OriginOnSurface };

// What the reference certifies for the shadow ray the kernel builds from `sp` towards `light`: the origin moved
// by the offset along the normal, in the kernel's precision, then the segment to the light inside the extent.
Verdict reference_verdict(const Scene& scene, Precision precision, const SurfacePoint& sp, const glm::dvec3& light,
                          PixelRay& ray) {
  const double offset = shadow_offset_unit(precision) * scene.extent.unit_scale();
  const bool single = precision != Precision::Double;
  if (single) {
    const glm::vec3 p(sp.point), q(light);
    const glm::vec3 o = p + static_cast<float>(offset) * sp.normal;
    ray = {glm::dvec3(o), glm::dvec3(q - o)};
  } else {
    const glm::dvec3 o = sp.point + offset * glm::dvec3(sp.normal);
    ray = {o, light - o};
  }
  const long double eps = single ? 0x1p-23L : 0x1p-52L;
  long double t_in = 0, t_out = 0;
  if (!extent_interval(scene.extent, ray, t_in, t_out)) return Verdict::Visible;
  t_in = std::max<long double>(t_in, 0);
  t_out = std::min<long double>(t_out, 1);
  if (!(t_out > t_in)) return Verdict::Visible;
  const long double margin = kReferenceEndMargin * eps;
  const ref::ExactRay exact{{ray.origin.x, ray.origin.y, ray.origin.z},
                            {ray.direction.x, ray.direction.y, ray.direction.z}};
  const std::vector<mpq_class> restricted = ref::restrict_exact(scene.surface().polynomial, exact);
  // Solved from a little before the origin: a root that close to it means the origin is still on the surface.
  const mpq_class lo = exact_rational(static_cast<double>(t_in - margin));
  const mpq_class hi = exact_rational(static_cast<double>(t_out + margin));
  const mpq_class width = exact_rational(1e-13);
  const ref::Answer a = ref::smallest_root(restricted, lo, hi, width);
  if (a.kind == ref::Classification::Miss)
    return flips_under_ray_rounding(restricted, scene.surface().polynomial.monomials(), ray, lo, hi, eps)
               ? Verdict::Ambiguous
               : Verdict::Visible;
  const long double t = a.t_nearest;
  if (std::fabs(t) <= margin) return Verdict::OriginOnSurface;
  if (t < t_in + margin || t > t_out - margin) return Verdict::Ambiguous;
  const bool crosses =
      a.kind == ref::Classification::SimpleRoot || a.kind == ref::Classification::MultipleRootOddSignChange;
  return crosses ? Verdict::Hidden : Verdict::Ambiguous;
}

const char* name(Verdict v) {
  switch (v) {
    case Verdict::Visible:
      return "visible";
    case Verdict::Hidden:
      return "hidden";
    case Verdict::Ambiguous:
      return "ambiguous";
    case Verdict::OriginOnSurface:
      return "origin on the surface";
  }
  return "?";
}

// A light point for a shadow ray from `sp`: `elevation` radians above the tangent plane, on the normal's side,
// at `distance`.
glm::dvec3 light_at(std::mt19937& rng, const SurfacePoint& sp, double elevation, double distance) {
  const glm::dvec3 n = glm::normalize(glm::dvec3(sp.normal));
  const glm::dvec3 a = std::fabs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 e1 = glm::normalize(glm::cross(n, a)), e2 = glm::cross(n, e1);
  const double phi = std::uniform_real_distribution<double>(0, 6.283185307179586)(rng);
  const glm::dvec3 tangent = std::cos(phi) * e1 + std::sin(phi) * e2;
  return sp.point + distance * (std::cos(elevation) * tangent + std::sin(elevation) * n);
}

// The shadow kernels the render plan builds: double around each segment or from the point form, float around
// each segment.
// Adaptive's point form answers what it decides in float; the rays it doubts (about 0.1 to 16% of them, by the
// surface) go again in double, where the reference's answers hold them to double's kernels.
const std::pair<Precision, RayOrigin> kConstructions[] = {{Precision::Double, RayOrigin::Extent},
                                                          {Precision::Double, RayOrigin::Point},
                                                          {Precision::Float, RayOrigin::Extent},
                                                          {Precision::Adaptive, RayOrigin::Point}};

struct Tally {
  int certified = 0, ambiguous = 0, failures = 0;
  int doubted = 0;  // adaptive: rays the float kernel left to the second pass (no answer of its own to check)
};

// Traces each (surface point, light point) pair with the shadow kernel and checks it against the reference.
// `make_light` picks the light point of ray `index`; `extra` overrides every scene (clipping planes); `scenes`
// are the files of scenes/, kScenes unless given.
template <typename MakeLight>
Tally check_shadow_rays(Precision precision, RayOrigin origin, int rays_per_scene, MakeLight make_light,
                        const std::vector<Override>& extra = {},
                        const std::vector<const char*>& scenes = {std::begin(kScenes), std::end(kScenes)}) {
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  Tally tally;
  // Built piecewise: GCC 12 warns falsely (-Wrestrict) about "\"" + std::string + "\"".
  std::string precision_value = "\"";
  precision_value += to_string(precision);
  precision_value += '"';
  for (const char* file : scenes) {
    std::string path = ALGRAY_SOURCE_DIR "/scenes/";  // appended, not added: the same false warning otherwise
    path += file;
    std::vector<Override> overrides = {{"image.width", "48"},
                                       {"image.height", "36"},
                                       {"antialias.samples", "1"},
                                       {"render.preview", "true"},
                                       {"render.precision", precision_value}};
    overrides.insert(overrides.end(), extra.begin(), extra.end());
    const Scene scene = load_scene_file(path, overrides);
    const std::vector<SurfacePoint> points = surface_points(renderer, scene);
    REQUIRE(points.size() > 100);
    const RenderPlan plan = make_render_plan(scene, precision);
    KernelConfig config = primary_config(scene, precision);
    config.entry = "shadow";
    // The render plan's two constructions of shadow rays: around each segment, or from P expanded about their
    // origin (in lanes, as on a CPU).
    config.ray_origin = origin;
    if (origin == RayOrigin::Point) config.lanes = testing::plan_shadow_lanes(precision);
    config.refinement = Refinement::Brent;
    config.max_iterations = default_max_iterations(Refinement::Brent);
    const DeviceSurface surface(session.context, scene, precision);
    ShadowTracer tracer(session, cache, config, surface, shadow_offset_unit(precision) * scene.extent.unit_scale());
    std::mt19937 rng(kSeed);
    for (int index = 0; index < rays_per_scene; ++index) {
      const SurfacePoint& sp = points[std::uniform_int_distribution<std::size_t>(0, points.size() - 1)(rng)];
      const glm::dvec3 light = make_light(rng, scene, sp);
      PixelRay ray;
      const Verdict verdict = reference_verdict(scene, precision, sp, light, ray);
      const ShadowAnswer answer = tracer.trace({sp.point}, {sp.normal}, {light});
      const bool hidden = answer.masks[0] & 1u;
      if (precision == Precision::Adaptive && (answer.undecided.at(0) & 1u)) {
        ++tally.doubted;
        continue;
      }
      INFO(file << " " << to_string(precision) << " " << to_string(origin) << " seed " << kSeed << " ray " << index
                << ": from " << sp.point.x << "," << sp.point.y << "," << sp.point.z << " to " << light.x << ","
                << light.y << "," << light.z << "; reference " << name(verdict) << ", kernel "
                << (hidden ? "hidden" : "visible"));
      CHECK(verdict != Verdict::OriginOnSurface);  // the offset must take the origin clearly off the surface
      if (verdict == Verdict::Ambiguous || verdict == Verdict::OriginOnSurface) {
        ++tally.ambiguous;
        continue;
      }
      ++tally.certified;
      const bool agree = hidden == (verdict == Verdict::Hidden);
      tally.failures += !agree;
      CHECK(agree);
    }
  }
  return tally;
}

}  // namespace

TEST_CASE("shadow rays never hit the surface they leave, at any angle, in double and float", "[shadows]") {
  // 1000 rays per construction (200 per surface): a fifth of them grazing, 0.5 to 5 degrees above the tangent
  // plane, the rest up to the normal; lights 1% to 2.5 extent radii away, so that short rays are tried too.
  for (const auto& [precision, origin] : kConstructions) {
    const Tally t =
        check_shadow_rays(precision, origin, 200, [](std::mt19937& rng, const Scene& scene, const SurfacePoint& sp) {
          const bool grazing = std::uniform_int_distribution<int>(0, 4)(rng) == 0;
          const double degrees = grazing ? std::uniform_real_distribution<double>(0.5, 5)(rng)
                                         : std::uniform_real_distribution<double>(5, 90)(rng);
          const double distance = std::uniform_real_distribution<double>(0.01, 2.5)(rng) * scene.extent.unit_scale();
          return light_at(rng, sp, degrees * 3.141592653589793 / 180, distance);
        });
    INFO(to_string(precision) << " " << to_string(origin) << ": " << t.certified << " certified, " << t.ambiguous
                              << " ambiguous, " << t.doubted << " doubted");
    CHECK(t.failures == 0);
    CHECK(t.certified >= 900);  // the reference certifies almost all of them, so the check means something
  }
}

TEST_CASE("shadow answers agree with the reference towards the lights of a scene", "[shadows]") {
  // Light points where a scene puts its lights: on a sphere of 3 extent radii around the extent, on the side
  // of the surface point's normal (behind the tangent plane the kernel answers "hidden" without tracing).
  for (const auto& [precision, origin] : kConstructions) {
    const Tally t =
        check_shadow_rays(precision, origin, 200, [](std::mt19937& rng, const Scene& scene, const SurfacePoint& sp) {
          std::normal_distribution<double> g;
          for (;;) {
            const glm::dvec3 dir = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
            const glm::dvec3 light = scene.extent.unit_centre() + 3 * scene.extent.unit_scale() * dir;
            if (glm::dot(light - sp.point, glm::dvec3(sp.normal)) > 0) return light;
          }
        });
    INFO(to_string(precision) << " " << to_string(origin) << ": " << t.certified << " certified, " << t.ambiguous
                              << " ambiguous, " << t.doubted << " doubted");
    CHECK(t.failures == 0);
    CHECK(t.certified >= 900);
  }
}

TEST_CASE("shadow rays are cut by clipping planes as the reference cuts them: what is cut away casts no shadow",
          "[shadows][clip]") {
  // Two planes across every scene (each centred on the origin): x <= 0.5 and y >= -1. The surface points are the
  // cut surface's, from a render at 96x72 (the cut leaves a half to a third of the points of 48x36), and the
  // lights where a scene puts its lights, so that many shadow rays pass where the cut took surface away.
  const std::vector<Override> planes = {
      {"clip", "[{plane = [1, 0, 0, -0.5]}, {plane = [0, -1, 0, -1]}]"}, {"image.width", "96"}, {"image.height", "72"}};
  for (const auto& [precision, origin] : kConstructions) {
    const Tally t = check_shadow_rays(
        precision, origin, 200,
        [](std::mt19937& rng, const Scene& scene, const SurfacePoint& sp) {
          REQUIRE(scene.extent.clips.size() == 2);
          std::normal_distribution<double> g;
          for (;;) {
            const glm::dvec3 dir = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
            const glm::dvec3 light = scene.extent.unit_centre() + 3 * scene.extent.unit_scale() * dir;
            if (glm::dot(light - sp.point, glm::dvec3(sp.normal)) > 0) return light;
          }
        },
        planes);
    INFO(to_string(precision) << " " << to_string(origin) << ": " << t.certified << " certified, " << t.ambiguous
                              << " ambiguous, " << t.doubted << " doubted");
    CHECK(t.failures == 0);
    CHECK(t.certified >= 900);
  }
}

TEST_CASE("a gate's shadow rays see the surface beyond it, and those that miss it see none, as the reference does",
          "[shadows][gate]") {
  // Two quartics (the same kernels), each gated by a sphere smaller than the surface: surface points beyond the
  // gate (seen through it) cast and catch shadows, and shadow rays that miss the gate pass. Lights where a scene
  // puts its lights, 3 of the gate's radii from its centre.
  const std::vector<Override> gate = {{"extent.radius", "2.2"}, {"extent.gate", "true"}};
  for (const auto& [precision, origin] : kConstructions) {
    const Tally t = check_shadow_rays(precision, origin, 150,
                                      [](std::mt19937& rng, const Scene& scene, const SurfacePoint& sp) {
                                        REQUIRE(scene.extent.gate);
                                        std::normal_distribution<double> g;
                                        for (;;) {
                                          const glm::dvec3 dir = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
                                          const glm::dvec3 light =
                                              scene.extent.unit_centre() + 3 * scene.extent.shape_scale() * dir;
                                          if (glm::dot(light - sp.point, glm::dvec3(sp.normal)) > 0) return light;
                                        }
                                      },
                                      gate, {"torus.toml", "kummer.toml"});
    INFO(to_string(precision) << " " << to_string(origin) << ": " << t.certified << " certified, " << t.ambiguous
                              << " ambiguous, " << t.doubted << " doubted");
    CHECK(t.failures == 0);
    CHECK(t.certified >= 270);
  }
}

namespace {

// Surface points from a small render of a scene file in adaptive precision, and 64 light points on a sphere of 3
// extent radii around it: every pair is one shadow ray.
struct PairedRays {
  Scene scene;
  std::vector<SurfacePoint> sps;
  std::vector<glm::dvec3> points, lights;
  std::vector<glm::vec3> normals;
};

PairedRays paired_rays(Renderer& renderer, const char* file, unsigned seed) {
  std::string path = ALGRAY_SOURCE_DIR "/scenes/";
  path += file;
  PairedRays r{load_scene_file(path, {{"image.width", "64"},
                                      {"image.height", "48"},
                                      {"antialias.samples", "1"},
                                      {"render.preview", "true"},
                                      {"render.precision", "\"adaptive\""}}),
               {},
               {},
               {},
               {}};
  r.sps = surface_points(renderer, r.scene);
  for (const SurfacePoint& sp : r.sps) {
    r.points.push_back(sp.point);
    r.normals.push_back(sp.normal);
  }
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  for (int s = 0; s < 64; ++s)
    r.lights.push_back(r.scene.extent.unit_centre() +
                       3 * r.scene.extent.unit_scale() * glm::normalize(glm::dvec3(g(rng), g(rng), g(rng))));
  return r;
}

// The shadow kernel of `precision` for the scene, in the extent form, one ray per work-item;
// settle_doubts is set in adaptive precision, as the plan sets it where the second pass runs in float-float.
KernelConfig extent_shadow_config(const Scene& scene, Precision precision) {
  KernelConfig config = primary_config(scene, precision);
  config.entry = "shadow";
  config.ray_origin = RayOrigin::Extent;
  config.lanes = 1;
  config.settle_doubts = precision == Precision::Adaptive;
  return config;
}

}  // namespace

TEST_CASE("adaptive shadow rays that settle_doubts settles are only doubted ones, and agree with the reference",
          "[shadows]") {
  // The float shadow kernel as the plan builds it where the second pass runs in float-float or float (settle_doubts:
  // in the extent form the noise of each interval and a certain sign change at 16 points, in the point form its
  // doubted rays searched again by the noise of each part) against the same kernel without it, on the scenes whose
  // shadow rays it doubts most.
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  int certified_total = 0;
  for (RayOrigin origin : {RayOrigin::Extent, RayOrigin::Point})
    for (const char* file : {"barth_decic.toml", "endrass_octic.toml"}) {
      const PairedRays r = paired_rays(renderer, file, kSeed + 7);
      REQUIRE(r.sps.size() > 100);
      KernelConfig config = extent_shadow_config(r.scene, Precision::Adaptive);
      if (origin == RayOrigin::Point) {
        config.ray_origin = RayOrigin::Point;
        config.lanes = testing::plan_shadow_lanes(Precision::Adaptive);
      }
      const DeviceSurface surface(session.context, r.scene, Precision::Adaptive);
      const double offset = shadow_offset_unit(Precision::Adaptive) * r.scene.extent.unit_scale();
      config.settle_doubts = false;
      ShadowTracer plain(session, cache, config, surface, offset);
      config.settle_doubts = true;
      ShadowTracer settling(session, cache, config, surface, offset);
      const ShadowAnswer a = plain.trace(r.points, r.normals, r.lights);
      const ShadowAnswer b = settling.trace(r.points, r.normals, r.lights);
      REQUIRE(a.undecided.size() == r.points.size());
      REQUIRE(b.undecided.size() == r.points.size());
      int doubted = 0, settled = 0, hidden = 0, certified = 0;
      for (std::size_t i = 0; i < r.points.size(); ++i) {
        INFO(file << ", " << to_string(origin) << " form, seed " << kSeed + 7 << ", point " << i);
        CHECK((b.undecided[i] & ~a.undecided[i]) == 0);             // it doubts no ray the plain one did not
        CHECK(((a.masks[i] ^ b.masks[i]) & ~a.undecided[i]) == 0);  // nor changes a decided answer
        doubted += __builtin_popcountll(a.undecided[i]);
        for (std::uint64_t cleared = a.undecided[i] & ~b.undecided[i]; cleared; cleared &= cleared - 1) {
          const int s = __builtin_ctzll(cleared);
          ++settled;
          const bool is_hidden = (b.masks[i] >> s) & 1;
          hidden += is_hidden;
          PixelRay ray;
          const Verdict v = reference_verdict(r.scene, Precision::Adaptive, r.sps[i], r.lights[s], ray);
          if (v != Verdict::Visible && v != Verdict::Hidden) continue;
          ++certified;
          INFO("light " << s << ": settled " << (is_hidden ? "hidden" : "visible") << ", the reference says "
                        << name(v));
          CHECK(is_hidden == (v == Verdict::Hidden));
        }
      }
      std::printf("%s, %s form: %d doubted shadow rays, %d of them settled (%d hidden), %d of those certified\n", file,
                  to_string(origin).c_str(), doubted, settled, hidden, certified);
      INFO(file << ", " << to_string(origin) << " form");
      // The noise of each interval settles most of them; the point form's search again, on segments that reach
      // further from their start and from a point's third doubted ray on, more than a third (Endrass octic: 39% of
      // these, 61% in a 1024x768 render).
      CHECK(settled * (origin == RayOrigin::Extent ? 2 : 3) > doubted);
      CHECK(hidden > 0);
      CHECK(hidden < settled);
      certified_total += certified;
    }
  CHECK(certified_total >= 200);  // enough certified rays for the reference's answers to mean something
}

TEST_CASE(
    "adaptive shadow rays the float kernel decides agree with the reference wherever the second pass answers "
    "otherwise",
    "[shadows]") {
  // The decided rays are adaptive's answers as they stand; a doubt withdrawn by the noise local to an interval
  // (kernels/isolation.h, within_noise_at) must not turn one the wrong way. The second pass traces the same float
  // rays (double's start closer to the surface); where it answers otherwise, the reference decides. The plan's
  // pairings: the extent form against mixed precision's, and the point form (kernels/shadow.h, PointTerms) as the
  // plan builds it where the second pass is double (against double's point form), and where it is float-float or
  // plain float's (searching its doubted rays again by the noise of each part, against mixed precision's and
  // float's extent forms).
  struct Pairing {
    const char* file;
    RayOrigin origin;
    bool settle_doubts;
    Precision second;
  };
  const Pairing pairings[] = {{"barth_decic.toml", RayOrigin::Extent, true, Precision::Mixed},
                              {"endrass_octic.toml", RayOrigin::Extent, true, Precision::Mixed},
                              {"barth_decic.toml", RayOrigin::Point, false, Precision::Double},
                              {"endrass_octic.toml", RayOrigin::Point, true, Precision::Mixed},
                              {"barth_decic.toml", RayOrigin::Point, true, Precision::Float}};
  ClSession& session = testing::device_session();
  ProgramCache& cache = testing::program_cache();
  Renderer renderer(session, cache);
  for (const Pairing& p : pairings) {
    const PairedRays r = paired_rays(renderer, p.file, kSeed + 11);
    REQUIRE(r.sps.size() > 100);
    const DeviceSurface float_surface(session.context, r.scene, Precision::Adaptive);
    const DeviceSurface second_surface(session.context, r.scene, p.second);
    const double offset = shadow_offset_unit(Precision::Adaptive) * r.scene.extent.unit_scale();
    KernelConfig first_config = extent_shadow_config(r.scene, Precision::Adaptive);
    first_config.settle_doubts = p.settle_doubts;
    KernelConfig second_config = extent_shadow_config(r.scene, p.second);
    if (p.origin == RayOrigin::Point) {
      first_config.ray_origin = RayOrigin::Point;
      first_config.lanes = testing::plan_shadow_lanes(Precision::Adaptive);
      if (p.second == Precision::Double) {
        second_config.ray_origin = RayOrigin::Point;
        second_config.lanes = testing::plan_shadow_lanes(Precision::Double);
      }
    }
    ShadowTracer adaptive(session, cache, first_config, float_surface, offset);
    ShadowTracer second(session, cache, second_config, second_surface, offset);
    const ShadowAnswer a = adaptive.trace(r.points, r.normals, r.lights);
    const ShadowAnswer d = second.trace(r.points, r.normals, r.lights);
    long decided = 0, differing = 0, certified = 0;
    for (std::size_t i = 0; i < r.points.size(); ++i) {
      const std::uint64_t all = r.lights.size() == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << r.lights.size()) - 1;
      decided += __builtin_popcountll(all & ~a.undecided[i]);
      for (std::uint64_t diff = (a.masks[i] ^ d.masks[i]) & ~a.undecided[i] & all; diff; diff &= diff - 1) {
        const int s = __builtin_ctzll(diff);
        ++differing;
        PixelRay ray;
        const Verdict v = reference_verdict(r.scene, Precision::Adaptive, r.sps[i], r.lights[s], ray);
        if (v != Verdict::Visible && v != Verdict::Hidden) continue;
        ++certified;
        const bool hidden = (a.masks[i] >> s) & 1;
        INFO(p.file << " " << to_string(p.origin) << (p.settle_doubts ? " settling doubts" : "") << ", seed "
                    << kSeed + 11 << ", point " << i << ", light " << s << ": adaptive "
                    << (hidden ? "hidden" : "visible") << ", reference " << name(v));
        CHECK(hidden == (v == Verdict::Hidden));
      }
    }
    std::printf(
        "%s, %s form%s: %ld shadow rays decided in float, %ld of them answered otherwise in %s, %ld of those "
        "certified\n",
        p.file, to_string(p.origin).c_str(), p.settle_doubts ? " settling doubts" : "", decided, differing,
        to_string(p.second).c_str(), certified);
    CHECK(decided > 20000);
  }
}
