// Times the lock-step lane prototype (bench/lockstep_lanes.cl) against the repo's scalar refinement and isolation.
//
// Usage: lockstep_lanes [DEGREE...]   (default 3 6 10). For each degree it prints two rows of a markdown table:
// Brent refinement of 2^20 polynomials with one sign change on [0, 1], and Bernstein isolation of 2^20
// polynomials built from random roots, first with unrelated lanes, then with the 8 lanes of a work-item
// perturbing one set of roots by 1e-3 (as neighbouring pixels do). Times are kernel event times, the median of
// 7 interleaved scalar/lane pairs after one warm-up each; the ratio is per pair. Every run checks that the
// lanes return the scalar kernel's results bit for bit and exits 1 when they do not.
#define CL_HPP_TARGET_OPENCL_VERSION 120
#define CL_HPP_MINIMUM_OPENCL_VERSION 120
#define CL_HPP_ENABLE_EXCEPTIONS
#include <CL/opencl.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

constexpr std::size_t kCount = std::size_t{1} << 20;
constexpr int kPairs = 7;

double binomial(int n, int k) {
  double r = 1;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

// Bernstein coefficients on [0, 1] of degree d, with b_0 .. b_j < 0 < b_(j+1) .. b_d: exactly one root.
std::vector<double> one_root_polynomials(int d, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> size(0.01, 1.0);
  std::vector<double> p(kCount * (d + 1));
  for (std::size_t i = 0; i < kCount; ++i) {
    const int j = std::uniform_int_distribution<int>(0, d - 1)(rng);
    for (int k = 0; k <= d; ++k) p[i * (d + 1) + k] = (k <= j ? -1 : 1) * size(rng);
  }
  return p;
}

// Bernstein coefficients on [0, 1] of polynomials with real roots in [-1, 2] and complex pairs within 0.3 of
// the real axis, scaled to max |b_k| = 1. spread < 1: each group of 8 shares roots, moved by up to spread * 0.005.
std::vector<double> random_root_polynomials(int d, double spread, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> p(kCount * (d + 1)), re(d), im(d);
  for (std::size_t i = 0; i < kCount; ++i) {
    if (i % 8 == 0 || spread >= 1)
      for (int j = 0; j < d; ++j) {
        re[j] = -1 + 3 * u(rng);
        im[j] = u(rng) < 0.5 ? 0 : 0.3 * u(rng);
      }
    std::vector<double> a(d + 1, 0);  // power basis
    a[0] = 1;
    int degree = 0;
    for (int j = 0; j < d && degree < d; ++j) {
      const double r = re[j] + (spread >= 1 ? 0 : spread * (u(rng) - 0.5) * 0.01);
      if (im[j] > 0 && degree + 2 <= d) {
        const double q0 = r * r + im[j] * im[j], q1 = -2 * r;
        for (int k = degree + 2; k >= 0; --k) a[k] = (k >= 2 ? a[k - 2] : 0) + (k >= 1 ? q1 * a[k - 1] : 0) + q0 * a[k];
        degree += 2;
      } else {
        for (int k = degree + 1; k >= 0; --k) a[k] = (k >= 1 ? a[k - 1] : 0) - r * a[k];
        degree += 1;
      }
    }
    std::vector<double> b(d + 1, 0);
    double largest = 0;
    for (int k = 0; k <= d; ++k) {
      for (int j = 0; j <= k; ++j) b[k] += binomial(k, j) / binomial(d, j) * a[j];
      largest = std::max(largest, std::fabs(b[k]));
    }
    for (int k = 0; k <= d; ++k) p[i * (d + 1) + k] = b[k] / largest;
  }
  return p;
}

struct Device {
  cl::Context context{CL_DEVICE_TYPE_ALL};
  cl::Device device = context.getInfo<CL_CONTEXT_DEVICES>()[0];
  cl::CommandQueue queue{context, device, CL_QUEUE_PROFILING_ENABLE};
};

cl::Program build(Device& dev, int d) {
  std::ifstream file(ALGRAY_SOURCE_DIR "/bench/lockstep_lanes.cl");
  std::stringstream text;
  text << file.rdbuf();
  cl::Program program(dev.context, text.str());
  const std::string options = "-cl-std=CL1.2 -I " ALGRAY_SOURCE_DIR "/kernels -D DEGREE=" + std::to_string(d) +
                              " -D ALGRAY_DOUBLE=1 -D ALGRAY_COMPENSATED=0 -D ISOLATION=1 -D REFINEMENT=1"
                              " -D TOLERANCE=1e-9 -D MAX_ITERATIONS=100";
  try {
    program.build(options.c_str());
  } catch (const cl::Error&) {
    std::fprintf(stderr, "lockstep_lanes: build failed with %s\n%s\n", options.c_str(),
                 program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(dev.device).c_str());
    std::exit(1);
  }
  return program;
}

// Kernel milliseconds of one launch; the lane kernel runs one work-item per 8 polynomials, in work-groups of 32
// (PoCL's default would put thousands of work-items' private arrays on one thread's stack).
double launch(Device& dev, cl::Kernel& kernel, bool lanes) {
  cl::Event done;
  dev.queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(lanes ? kCount / 8 : kCount),
                                 lanes ? cl::NDRange(32) : cl::NullRange, nullptr, &done);
  done.wait();
  return 1e-6 * static_cast<double>(done.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                                    done.getProfilingInfo<CL_PROFILING_COMMAND_START>());
}

struct Timing {
  double scalar_ms, lanes_ms, ratio, ratio_lo, ratio_hi;
};

Timing time_pairs(Device& dev, cl::Kernel& scalar, cl::Kernel& lanes) {
  launch(dev, scalar, false);
  launch(dev, lanes, true);
  std::vector<double> s, l, r;
  for (int i = 0; i < kPairs; ++i) {
    s.push_back(launch(dev, scalar, false));
    l.push_back(launch(dev, lanes, true));
    r.push_back(s.back() / l.back());
  }
  for (auto* v : {&s, &l, &r}) std::sort(v->begin(), v->end());
  return {s[kPairs / 2], l[kPairs / 2], r[kPairs / 2], r.front(), r.back()};
}

template <typename T>
std::vector<T> read(Device& dev, const cl::Buffer& b) {
  std::vector<T> v(kCount);
  dev.queue.enqueueReadBuffer(b, CL_TRUE, 0, kCount * sizeof(T), v.data());
  return v;
}

template <typename T>
cl::Buffer output(Device& dev) {
  return cl::Buffer(dev.context, CL_MEM_READ_WRITE, kCount * sizeof(T));
}

bool refinement_row(Device& dev, cl::Program& program, int d) {
  const std::uint64_t seed = 42 + d;
  std::vector<double> polys = one_root_polynomials(d, seed);
  std::vector<double> binomials((d + 1) * (d + 1), 0);
  for (int n = 0; n <= d; ++n)
    for (int k = 0; k <= n; ++k) binomials[n * (d + 1) + k] = binomial(n, k);
  cl::Buffer in(dev.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, polys.size() * 8, polys.data());
  cl::Buffer table(dev.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, binomials.size() * 8, binomials.data());
  cl::Buffer roots[2] = {output<double>(dev), output<double>(dev)};
  cl::Buffer iterations[2] = {output<cl_uint>(dev), output<cl_uint>(dev)};
  cl::Kernel kernels[2] = {cl::Kernel(program, "scalar_brent"), cl::Kernel(program, "lockstep_brent")};
  for (int j = 0; j < 2; ++j) {
    kernels[j].setArg(0, in);
    kernels[j].setArg(1, roots[j]);
    kernels[j].setArg(2, iterations[j]);
    kernels[j].setArg(3, 1e-8);
    kernels[j].setArg(4, table);
  }
  const Timing t = time_pairs(dev, kernels[0], kernels[1]);
  const auto r0 = read<double>(dev, roots[0]), r1 = read<double>(dev, roots[1]);
  const auto i0 = read<cl_uint>(dev, iterations[0]), i1 = read<cl_uint>(dev, iterations[1]);
  std::size_t differ = 0;
  double total = 0;
  for (std::size_t i = 0; i < kCount; ++i) {
    if (r0[i] != r1[i] || i0[i] != i1[i]) {
      if (differ == 0) std::fprintf(stderr, "refinement, degree %d, seed %llu: case %zu differs\n", d,
                                    static_cast<unsigned long long>(seed), i);
      ++differ;
    }
    total += i0[i];
  }
  std::printf("| refinement (Brent) | %d | one sign change | %.2f iterations | %.1f | %.1f | %.2fx (%.2f-%.2f) | %zu |\n", d,
              total / kCount, t.scalar_ms, t.lanes_ms, t.ratio, t.ratio_lo, t.ratio_hi, differ);
  return differ == 0;
}

bool isolation_row(Device& dev, cl::Program& program, int d, double spread) {
  const std::uint64_t seed = 7 + d;
  std::vector<double> polys = random_root_polynomials(d, spread, seed);
  cl::Buffer in(dev.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, polys.size() * 8, polys.data());
  cl::Buffer lo[2] = {output<double>(dev), output<double>(dev)}, hi[2] = {output<double>(dev), output<double>(dev)};
  cl::Buffer status[2] = {output<cl_int>(dev), output<cl_int>(dev)};
  cl::Buffer steps[2] = {output<cl_uint>(dev), output<cl_uint>(dev)};
  cl::Kernel kernels[2] = {cl::Kernel(program, "scalar_iso"), cl::Kernel(program, "lockstep_iso")};
  for (int j = 0; j < 2; ++j) {
    kernels[j].setArg(0, in);
    kernels[j].setArg(1, lo[j]);
    kernels[j].setArg(2, hi[j]);
    kernels[j].setArg(3, status[j]);
    kernels[j].setArg(4, steps[j]);
  }
  const Timing t = time_pairs(dev, kernels[0], kernels[1]);
  const auto s0 = read<cl_int>(dev, status[0]), s1 = read<cl_int>(dev, status[1]);
  const auto l0 = read<double>(dev, lo[0]), l1 = read<double>(dev, lo[1]);
  const auto h0 = read<double>(dev, hi[0]), h1 = read<double>(dev, hi[1]);
  const auto p0 = read<cl_uint>(dev, steps[0]), p1 = read<cl_uint>(dev, steps[1]);
  std::size_t differ = 0;
  double total = 0;
  for (std::size_t i = 0; i < kCount; ++i) {
    // The prototype does not reproduce the far end's bookkeeping of a root-free polynomial (lo = hi = 1).
    const bool same = s0[i] == s1[i] && p0[i] == p1[i] && (s0[i] == 0 || (l0[i] == l1[i] && h0[i] == h1[i]));
    if (!same) {
      if (differ == 0) std::fprintf(stderr, "isolation, degree %d, spread %g, seed %llu: case %zu differs\n", d,
                                    spread, static_cast<unsigned long long>(seed), i);
      ++differ;
    }
    total += p0[i];
  }
  std::printf("| isolation (Bernstein) | %d | %s | %.2f intervals | %.1f | %.1f | %.2fx (%.2f-%.2f) | %zu |\n", d,
              spread >= 1 ? "unrelated lanes" : "lanes within 1e-3", total / kCount, t.scalar_ms, t.lanes_ms,
              t.ratio, t.ratio_lo, t.ratio_hi, differ);
  return differ == 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> degrees;
  for (int i = 1; i < argc; ++i) degrees.push_back(std::atoi(argv[i]));
  if (degrees.empty()) degrees = {3, 6, 10};
  Device dev;
  std::printf("Device: %s. %zu polynomials per row, median of %d interleaved pairs.\n\n",
              dev.device.getInfo<CL_DEVICE_NAME>().c_str(), kCount, kPairs);
  std::printf("| stage | degree | inputs | work per polynomial | scalar ms | 8 lanes ms | speed-up (min-max) | "
              "results differing |\n|---|---|---|---|---|---|---|---|\n");
  bool same = true;
  for (int d : degrees) {
    if (d < 2 || d > 32) {
      std::fprintf(stderr, "lockstep_lanes: degree %d is outside 2..32\n", d);
      return 2;
    }
    cl::Program program = build(dev, d);
    same &= refinement_row(dev, program, d);
    same &= isolation_row(dev, program, d, 1.0);
    same &= isolation_row(dev, program, d, 0.1);
  }
  return same ? 0 : 1;
}
