// The shadow kernel against shadow_serial, the plain one-segment-at-a-time construction: whatever shortcuts
// shadow.cl takes, the occlusion masks must be identical on seeded random surfaces, points and lights; and its
// batch of restrictions in a vector's lanes against one ray at a time, coefficient for coefficient.
#include <algorithm>
#include <bit>
#include <catch2/catch.hpp>
#include <cstdio>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "algray/device/kernel_binder.h"
#include "algray/device/program_cache.h"
#include "algray/render/device_surface.h"
#include "algray/render/render_plan.h"
#include "algray/render/shadow_tracer.h"
#include "algray/scene/scene.h"
#include "sweep.h"
#include "test_support.h"

using namespace algray;

namespace {

constexpr unsigned kSeed = 20261202;

// A random surface of degree `degree` inside the unit sphere: a dozen random monomials, one of full degree, with
// coefficients in [-1, 1]; with `even`, every exponent even, as the Barth surfaces have (the restriction then
// steps by squares).
Scene random_scene(std::mt19937& rng, int degree, bool even, Precision precision, Isolation isolation) {
  std::uniform_real_distribution<double> coef(-1, 1);
  std::ostringstream eq;
  eq.precision(17);
  const int step = even ? 2 : 1;
  for (int m = 0; m < 12; ++m) {
    const int total = m == 0 ? degree : std::uniform_int_distribution<int>(0, degree / step)(rng) * step;
    const int i = std::uniform_int_distribution<int>(0, total / step)(rng) * step;
    const int j = std::uniform_int_distribution<int>(0, (total - i) / step)(rng) * step;
    const int k = total - i - j;
    eq << (m ? " + " : "") << "(" << coef(rng) << ")*x^" << i << "*y^" << j << "*z^" << k;
  }
  std::ostringstream toml;
  toml << "[surface]\nequation = \"" << eq.str() << "\"\n"
       << "[extent]\nradius = 1\n"
       << "[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\n"
       << "[render]\nprecision = \"" << to_string(precision) << "\"\nisolation = \"" << to_string(isolation) << "\"\n";
  return load_scene_text(toml.str(), "random.toml");
}

struct Counts {
  long hidden = 0, visible = 0, traced = 0;
  long doubted = 0;  // adaptive builds' undecided samples
};

// The config both kernels are built with; entry names the kernel. The point form's shadow kernel runs the lanes
// the plan gives it on this device (testing::plan_shadow_lanes), and shadow_serial the same code in one; the extent
// form's restricts the batch the plan gives it (testing::plan_shadow_batch: a vector register's rays in its lanes
// here), shadow_serial one ray at a time.
KernelConfig shadow_config(const Scene& scene, Precision precision, Isolation isolation, const std::string& entry,
                           RayOrigin origin, bool settle_doubts) {
  KernelConfig config = primary_config(scene, precision);
  config.ray_origin = origin;
  config.lanes = origin == RayOrigin::Point && entry == "shadow" ? testing::plan_shadow_lanes(precision) : 1;
  config.isolation = isolation;
  config.refinement = Refinement::Brent;
  config.max_iterations = default_max_iterations(Refinement::Brent);
  config.entry = entry;
  config.settle_doubts = settle_doubts;
  config.shadow_batch = origin == RayOrigin::Extent && entry == "shadow" ? testing::plan_shadow_batch(precision) : 0;
  return config;
}

// The shadow kernel and shadow_serial for one scene, with the renderer's shadow offset.
struct TracerPair {
  TracerPair(const Scene& scene, Precision precision, Isolation isolation, RayOrigin origin = RayOrigin::Extent,
             bool settle_doubts = false)
      : surface(testing::device_session().context, scene, precision),
        offset(shadow_offset_unit(precision) * scene.extent.unit_scale()),
        batched(testing::device_session(), testing::program_cache(),
                shadow_config(scene, precision, isolation, "shadow", origin, settle_doubts), surface, offset),
        serial(testing::device_session(), testing::program_cache(),
               shadow_config(scene, precision, isolation, "shadow_serial", origin, settle_doubts), surface, offset) {}
  DeviceSurface surface;
  double offset;
  ShadowTracer batched, serial;
};

// Traces `points` random surface points towards up to 64 random light points with both kernels and requires the
// same masks and the same count of traced rays. Some bits start set, as when another surface hid the sample.
Counts check_same_masks(const Scene& scene, Precision precision, Isolation isolation, std::mt19937& rng,
                        const std::string& what, RayOrigin origin = RayOrigin::Extent, bool settle_doubts = false) {
  TracerPair tracers(scene, precision, isolation, origin, settle_doubts);
  ShadowTracer& batched = tracers.batched;
  ShadowTracer& serial = tracers.serial;

  const glm::dvec3 centre = scene.extent.unit_centre();
  const double radius = scene.extent.unit_scale();
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> g;
  auto in_ball = [&](double r) {
    for (;;) {
      const glm::dvec3 v(u(rng), u(rng), u(rng));
      if (glm::dot(v, v) <= 1) return centre + r * radius * v;
    }
  };
  Counts counts;
  for (int round = 0; round < 4; ++round) {
    const int point_count = 500;
    std::vector<glm::dvec3> points;
    std::vector<glm::vec3> normals;
    std::vector<std::uint64_t> hidden;
    for (int i = 0; i < point_count; ++i) {
      points.push_back(in_ball(1.1));  // a few outside the extent too
      normals.push_back(glm::vec3(glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)))));
      hidden.push_back(std::uniform_int_distribution<int>(0, 3)(rng) == 0 ? rng() : 0u);
    }
    const int light_count = std::uniform_int_distribution<int>(1, 64)(rng);
    std::vector<glm::dvec3> lights;
    for (int s = 0; s < light_count; ++s)
      lights.push_back(in_ball(std::uniform_real_distribution<double>(0.3, 4)(rng)));
    const ShadowAnswer a = batched.trace(points, normals, lights, hidden);
    const ShadowAnswer b = serial.trace(points, normals, lights, hidden);
    REQUIRE(a.masks.size() == b.masks.size());
    int mismatches = 0;
    for (std::size_t i = 0; i < a.masks.size(); ++i) {
      if (a.masks[i] == b.masks[i]) continue;
      if (mismatches++ == 0)
        UNSCOPED_INFO(what << ", round " << round << ", point " << i << " of " << point_count << " (" << points[i].x
                           << ", " << points[i].y << ", " << points[i].z << "), " << light_count
                           << " lights: batched mask " << std::hex << a.masks[i] << ", serial " << b.masks[i]
                           << std::dec);
    }
    INFO(what << ", round " << round << ": " << mismatches << " masks differ");
    CHECK(mismatches == 0);
    CHECK(a.rays_traced == b.rays_traced);
    // Adaptive builds also name the samples they doubted, alike.
    CHECK(a.undecided.size() == (precision == Precision::Adaptive ? a.masks.size() : 0u));
    CHECK(a.undecided == b.undecided);
    counts.traced += a.rays_traced;
    for (std::uint64_t bits : a.undecided) counts.doubted += std::popcount(bits);
    const std::uint64_t all = light_count == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << light_count) - 1;
    for (std::size_t i = 0; i < a.masks.size(); ++i)
      for (int s = 0; s < light_count; ++s) {
        if (hidden[i] & all & (std::uint64_t{1} << s)) continue;
        ((a.masks[i] >> s) & 1 ? counts.hidden : counts.visible)++;
      }
  }
  return counts;
}

}  // namespace

TEST_CASE("batched shadow rays answer as the serial ones, bit for bit, at every vector width and precision",
          "[shadows]") {
  // Degrees on each side of the restriction's representations: 8 lanes (up to 7), 16 lanes (up to 15), arrays.
  struct Case {
    int degree;
    bool even;
  };
  const Case cases[] = {{1, false}, {2, true},   {5, false},  {6, true},  {7, false},
                        {10, true}, {13, false}, {15, false}, {18, true}, {21, false}};
  for (Precision precision : {Precision::Double, Precision::Float, Precision::Mixed, Precision::Adaptive}) {
    // Each precision's cases: its degree ends on every run (and adaptive's two settling degrees, 6 and 10), a
    // seeded sample of the others; each case draws from a stream of its own, so that any sample repeats it.
    const bool compensated = precision == Precision::Mixed || precision == Precision::Adaptive;
    std::vector<int> indices, always = {0, 1, compensated ? 7 : 9};
    for (std::size_t c = 0; c < std::size(cases); ++c)
      if (!compensated || cases[c].degree <= kMaxMixedDegree) indices.push_back(static_cast<int>(c));
    if (precision == Precision::Adaptive) always.insert(always.end(), {3, 5});
    // One drawn case beyond those a precision (each case is two programs to compile, seconds each on PoCL).
    for (int index : testing::sampled("test_shadows_batched " + to_string(precision) + " cases", indices, always, 1)) {
      const std::size_t c = static_cast<std::size_t>(index);
      const Case& k = cases[c];
      const unsigned seed = kSeed + 100 * static_cast<unsigned>(precision) + static_cast<unsigned>(c);
      std::mt19937 rng(seed);
      const Scene scene = random_scene(rng, k.degree, k.even, precision, Isolation::Bernstein);
      std::ostringstream what;
      what << to_string(precision) << " case " << c << " (degree " << k.degree << (k.even ? ", even" : "") << ", seed "
           << seed << ")";
      const Counts n = check_same_masks(scene, precision, Isolation::Bernstein, rng, what.str());
      INFO(what.str() << ": " << n.traced << " rays traced, " << n.hidden << " samples hidden, " << n.visible
                      << " visible");
      // Both answers, and rays for the isolation to decide, so the comparison means something.
      CHECK(n.traced >= 1000);
      CHECK(n.hidden >= 100);
      CHECK(n.visible >= 100);
      // Adaptive's shadow kernel as the plan builds it where the second pass is float-float: doubted rays a
      // certain sign change settles (shadow.h), alike in both kernels.
      // (On two degrees only: each case builds two more programs, seconds each on PoCL.)
      if (precision == Precision::Adaptive && (k.degree == 6 || k.degree == 10)) {
        std::mt19937 own(kSeed + 10 +
                         static_cast<unsigned>(c));  // its own stream: the cases after it stay as they were
        check_same_masks(scene, precision, Isolation::Bernstein, own,
                         what.str() + ", settled by signs (seed " + std::to_string(kSeed + 10 + c) + ")",
                         RayOrigin::Extent, true);
      }
    }
  }
}

namespace {

// The coefficients restrict_check (kernels/restrict_check.cl) gives `segments` (two 4-vectors a segment: o and t_in,
// d and t_out), restricted `batch` at a time (0: one ray at a time), as the bits of each: doubles, or floats widened.
std::vector<std::uint64_t> restricted_bits(const Scene& scene, Precision precision, int batch,
                                           const std::vector<double>& segments) {
  const DeviceSurface surface(testing::device_session().context, scene, precision);
  KernelConfig config = primary_config(scene, precision);
  config.entry = "restrict_check";
  config.ray_origin = RayOrigin::Extent;
  config.lanes = 1;
  config.shadow_batch = batch;
  ClSession& session = testing::device_session();
  cl::Kernel kernel = testing::program_cache().kernel(session, config);
  const std::size_t count = segments.size() / 8, ncoef = static_cast<std::size_t>(config.degree) + 1;
  const bool is_double = precision == Precision::Double;
  const std::size_t real_bytes = is_double ? sizeof(double) : sizeof(float);
  const cl::Buffer in = real_buffer(session.context, segments, precision);
  cl::Buffer out(session.context, CL_MEM_WRITE_ONLY, count * ncoef * real_bytes);
  KernelBinder args(kernel, "restrict_check", precision);
  args.plain("segments", in);
  args.plain("count", static_cast<cl_uint>(count));
  surface.set_surface_args(args);
  args.plain("out", out);
  const std::size_t per_item = static_cast<std::size_t>(std::max(batch, 1));
  session.queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(count / per_item));
  std::vector<std::uint64_t> bits(count * ncoef);
  if (is_double) {
    session.queue.enqueueReadBuffer(out, CL_TRUE, 0, bits.size() * sizeof(double), bits.data());
  } else {
    std::vector<std::uint32_t> words(bits.size());
    session.queue.enqueueReadBuffer(out, CL_TRUE, 0, words.size() * sizeof(float), words.data());
    std::copy(words.begin(), words.end(), bits.begin());
  }
  return bits;
}

}  // namespace

TEST_CASE("the extent form's shadow batch restricts every segment as one ray at a time, coefficient for coefficient",
          "[shadows]") {
  // Occlusion masks (above) hide a difference in the last bits of a few coefficients: a batch whose steps the
  // compiler fused otherwise than the one-ray vector step's passed them (bench/history/2026-12.md, "Shadow rays
  // restricted side by side in lanes"). Degrees on each side of the accumulators' layouts: one vector (up to 15),
  // 16-wide vectors and a tail (16 to 32); even exponents step by squares.
  for (Precision precision : {Precision::Float, Precision::Double}) {
    const int batch = testing::plan_shadow_batch(precision);
    if (batch == 0) {
      // The plan batches only where the device fuses multiply-adds in vector registers of several rays; elsewhere
      // every kernel restricts one ray at a time, and there is no second layout to hold to it.
      std::printf("test_shadows_batched: no %s shadow batch on this device\n", to_string(precision).c_str());
      continue;
    }
    for (int degree : testing::sampled("test_shadows_batched restriction degrees " + to_string(precision),
                                       {1, 2, 3, 5, 6, 7, 8, 10, 12, 15, 16, 17, 20, 24, 31, 32}, {7, 16, 24}, 1)) {
      // Every exponent even (the steps by squares) where the degree is, and any exponents (the linear steps).
      for (const bool even : {false, true}) {
        if (even && degree % 2 != 0) continue;
        const unsigned seed = kSeed + 20 + 1000 * static_cast<unsigned>(degree) + 10 * static_cast<unsigned>(even) +
                              static_cast<unsigned>(precision);
        std::mt19937 rng(seed);
        const Scene scene = random_scene(rng, degree, even, precision, Isolation::Bernstein);
        // 2048 segments from points in the unit ball (some outside it), of lengths 0.3 to 2.5 units.
        std::uniform_real_distribution<double> u(-1, 1), length(0.3, 2.5), start(0, 0.3), end(0.6, 1);
        std::vector<double> segments;
        for (int s = 0; s < 2048; ++s) {
          const glm::dvec3 o(1.1 * u(rng), 1.1 * u(rng), 1.1 * u(rng));
          const glm::dvec3 d = length(rng) * glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)) + glm::dvec3(1e-3));
          segments.insert(segments.end(), {o.x, o.y, o.z, start(rng), d.x, d.y, d.z, end(rng)});
        }
        const std::vector<std::uint64_t> lanes = restricted_bits(scene, precision, batch, segments);
        const std::vector<std::uint64_t> one = restricted_bits(scene, precision, 0, segments);
        REQUIRE(lanes.size() == one.size());
        const std::size_t ncoef = static_cast<std::size_t>(degree) + 1;
        const std::uint64_t sign_bit = precision == Precision::Double ? std::uint64_t{1} << 63 : std::uint64_t{1} << 31;
        std::size_t differing = 0, nonzero = 0;
        for (std::size_t i = 0; i < one.size(); ++i) {
          if ((one[i] & ~sign_bit) != 0) ++nonzero;
          if (lanes[i] == one[i]) continue;
          if (differing++ == 0)
            UNSCOPED_INFO(to_string(precision)
                          << " degree " << degree << (even ? " (even)" : "") << ", seed " << seed << ": segment "
                          << i / ncoef << ", coefficient " << i % ncoef << ": batch bits " << std::hex << lanes[i]
                          << ", one ray " << one[i] << std::dec);
        }
        INFO(to_string(precision) << " degree " << degree << ", batch " << batch << ", seed " << seed << ": "
                                  << differing << " of " << one.size() << " coefficients differ");
        CHECK(differing == 0);
        CHECK(nonzero > one.size() / 2);  // coefficients, not a buffer left empty
      }
    }
  }
}

TEST_CASE("the point form's shadow rays in lanes answer as one at a time, bit for bit, at every degree it takes",
          "[shadows]") {
  // Random points (some outside the extent) and up to 64 lights: blocks of 8 lanes that end mid-way, rays the
  // signs settle, rays a sampled sign change settles, and rays only the search in lanes settles.
  for (int degree : testing::sampled_degrees("test_shadows_batched point form degrees", kMaxPointFormDegree, 2)) {
    const unsigned seed = kSeed + 3 + 1000 * static_cast<unsigned>(degree);  // a stream of its own, as above
    std::mt19937 rng(seed);
    const bool even = degree % 2 == 0 && degree % 4 != 0;
    const Scene scene = random_scene(rng, degree, even, Precision::Double, Isolation::Bernstein);
    std::ostringstream what;
    what << "point form (seed " << seed << "), degree " << degree << (even ? ", even" : "");
    const Counts n =
        check_same_masks(scene, Precision::Double, Isolation::Bernstein, rng, what.str(), RayOrigin::Point);
    INFO(what.str() << ": " << n.traced << " rays traced, " << n.hidden << " samples hidden, " << n.visible
                    << " visible");
    CHECK(n.traced >= 1000);
    CHECK(n.hidden >= 100);
    CHECK(n.visible >= 100);
  }
  const Scene barth = load_scene_file(ALGRAY_SOURCE_DIR "/scenes/barth_sextic.toml");
  std::mt19937 rng(kSeed + 3);
  check_same_masks(barth, Precision::Double, Isolation::Bernstein, rng,
                   "point form (seed " + std::to_string(kSeed + 3) + "), Barth sextic", RayOrigin::Point);
  // Adaptive's point form: its noise checks, doubts and (where it settles doubts) its doubted rays searched again by
  // the noise of each part (kernels/shadow.h, point_part_polys) decide alike in 16 lanes and in one, undecided
  // samples included (check_same_masks compares them), on two surfaces whose shadow rays it doubts often.
  for (const auto& [file, settle_doubts] :
       {std::pair{"barth_decic.toml", false}, std::pair{"endrass_octic.toml", true}}) {
    const unsigned seed = kSeed + 5;
    std::mt19937 own(seed);
    const Scene scene =
        load_scene_file(std::string(ALGRAY_SOURCE_DIR "/scenes/") + file, {{"render.precision", "\"adaptive\""}});
    std::ostringstream what;
    what << "adaptive point form (seed " << seed << "), " << file << (settle_doubts ? ", settling doubts" : "");
    const Counts n = check_same_masks(scene, Precision::Adaptive, Isolation::Bernstein, own, what.str(),
                                      RayOrigin::Point, settle_doubts);
    INFO(what.str() << ": " << n.traced << " rays traced, " << n.hidden << " samples hidden, " << n.visible
                    << " visible, " << n.doubted << " doubted");
    CHECK(n.traced >= 1000);
    CHECK(n.hidden >= 100);
    CHECK(n.visible >= 100);
    CHECK(n.doubted >= 10);  // doubts too, so that their answers are compared
  }
}

TEST_CASE("batched shadow rays answer as the serial ones with a power-basis isolation and on the Barth sextic",
          "[shadows]") {
  std::mt19937 rng(kSeed + 1);
  for (Precision precision : {Precision::Double, Precision::Float}) {
    const Scene random = random_scene(rng, 6, false, precision, Isolation::PowerDescartes);
    const std::string stream = " (seed " + std::to_string(kSeed + 1) + ")";
    check_same_masks(random, precision, Isolation::PowerDescartes, rng, to_string(precision) + " power basis" + stream);
    const Scene barth = load_scene_file(ALGRAY_SOURCE_DIR "/scenes/barth_sextic.toml");
    check_same_masks(barth, precision, Isolation::Bernstein, rng, to_string(precision) + " Barth sextic" + stream);
  }
}

TEST_CASE("adaptive shadow rays that start exactly on the surface are doubted alike by both kernels", "[shadows]") {
  // Points on the plane z = 0 with normals in the plane: the offset start stays on it, so P there is exactly 0.
  // The search doubts such a start (a root within the noise), so the sign shortcut must not settle it.
  const Scene scene = load_scene_text(
      "[surface]\nequation = \"z\"\n[extent]\nradius = 1\n"
      "[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\n[render]\nprecision = \"adaptive\"\n",
      "plane.toml");
  TracerPair tracers(scene, Precision::Adaptive, Isolation::Bernstein);
  std::mt19937 rng(kSeed + 2);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::vector<glm::dvec3> points, lights;
  std::vector<glm::vec3> normals;
  for (int i = 0; i < 200; ++i) {
    points.emplace_back(u(rng), u(rng), 0.0);
    normals.emplace_back(i % 2 ? 1.0f : 0.0f, i % 2 ? 0.0f : 1.0f, 0.0f);
  }
  for (int s = 0; s < 16; ++s) lights.emplace_back(u(rng), u(rng), s % 2 ? 2.0 : -2.0);
  const ShadowAnswer a = tracers.batched.trace(points, normals, lights, {});
  const ShadowAnswer b = tracers.serial.trace(points, normals, lights, {});
  CHECK(a.masks == b.masks);
  CHECK(a.undecided == b.undecided);
  long undecided = 0;
  for (std::uint64_t m : a.undecided) undecided += __builtin_popcountll(m);
  INFO("seed " << kSeed + 2 << ": " << undecided << " of " << points.size() * lights.size() << " samples undecided");
  CHECK(undecided > 0);
}

TEST_CASE("a launch of many rows of work-items answers each ray as launches of one row do", "[shadows]") {
  // ray_launch's shape: fixed groups, rows under PoCL's 65,536 work-items a dimension, every ray covered.
  for (std::size_t largest : {std::size_t{256}, std::size_t{32}, std::size_t{1}})
    for (std::size_t count : {std::size_t{1}, std::size_t{63}, std::size_t{64}, std::size_t{65}, std::size_t{16383},
                              std::size_t{16384}, std::size_t{16385}, std::size_t{40000}, std::size_t{1} << 24}) {
      const RayLaunch launch = ray_launch(count, largest);
      INFO("count " << count << ", largest group " << largest << ": global " << launch.global[0] << " x "
                    << launch.global[1] << ", local " << launch.local[0] << " x " << launch.local[1]);
      REQUIRE(launch.global.dimensions() == 2);
      CHECK(launch.local[0] == std::min<std::size_t>(largest, 64));
      CHECK(launch.local[1] == 1);
      CHECK(launch.global[0] % launch.local[0] == 0);
      CHECK(launch.global[0] < 65536);
      CHECK(launch.global[1] < 65536);
      CHECK(launch.global[0] * launch.global[1] >= count);
      CHECK(launch.global[0] * launch.global[1] - count < launch.global[0]);  // at most the last row part empty
    }

  // On the device: 40,000 points in one launch (three rows of 16,384) and in launches of 5,000 (one row each).
  // A ball of radius 0.5 under lights above it: the points beneath or inside it are hidden, the others not.
  const unsigned seed = kSeed + 7;
  std::mt19937 rng(seed);
  const Scene scene = load_scene_text(
      "[surface]\nequation = \"x^2 + y^2 + z^2 - 0.25\"\n[extent]\nradius = 1\n"
      "[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\n[render]\nprecision = \"double\"\n",
      "ball.toml");
  // The batched kernel alone: the serial one is not needed here (each program is seconds to compile on PoCL).
  const DeviceSurface surface(testing::device_session().context, scene, Precision::Double);
  ShadowTracer batched(
      testing::device_session(), testing::program_cache(),
      shadow_config(scene, Precision::Double, Isolation::Bernstein, "shadow", RayOrigin::Extent, false), surface,
      shadow_offset_unit(Precision::Double) * scene.extent.unit_scale());
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<glm::dvec3> points, lights;
  std::vector<glm::vec3> normals;
  for (int i = 0; i < 40000; ++i) {
    points.emplace_back(u(rng), u(rng), u(rng));
    normals.emplace_back(glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0, 0, 2)));
  }
  for (int s = 0; s < 8; ++s) lights.emplace_back(0.2 * u(rng), 0.2 * u(rng), 3.0);
  const ShadowAnswer whole = batched.trace(points, normals, lights, {});
  std::vector<std::uint64_t> masks;
  std::uint64_t traced = 0;
  for (std::size_t first = 0; first < points.size(); first += 5000) {
    const auto part = [&](const auto& v) { return std::vector(v.begin() + first, v.begin() + first + 5000); };
    const ShadowAnswer a = batched.trace(part(points), part(normals), lights, {});
    masks.insert(masks.end(), a.masks.begin(), a.masks.end());
    traced += a.rays_traced;
  }
  long hidden = 0;
  for (std::uint64_t m : whole.masks) hidden += std::popcount(m);
  INFO("seed " << seed << ": " << whole.rays_traced << " rays traced, " << hidden << " of "
               << points.size() * lights.size() << " samples hidden");
  CHECK(whole.masks == masks);
  CHECK(whole.rays_traced == traced);
  CHECK(hidden > 1000);
  CHECK(hidden < static_cast<long>(points.size() * lights.size()) - 1000);
}
