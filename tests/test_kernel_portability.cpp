// Every kernel configuration the host can build, compiled as strict OpenCL C 1.2 by clang: what PoCL's lenient
// front end lets through and stricter vendors' compilers refuse (NVIDIA's: variadic macros) fails here first.
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "algray/device/fp64_speed.h"
#include "algray/device/kernel_config.h"
#include "algray/device/kernel_sources.h"
#include "algray/render/render_plan.h"
#include "sweep.h"

using namespace algray;

namespace {

struct Compile {
  std::string kind;     // kernel file and precision: each must compile in some configuration
  std::string what;     // the config's key, for the failure message
  std::string file;     // kernel file to assemble
  std::string options;  // the host's build options
};

// The host's options without -w (which would hide the pedantic diagnostics), with the language fixed at 1.2.
std::string strict_options(const std::string& host_options) {
  std::istringstream in(host_options);
  std::string word, out = "-cl-std=CL1.2";
  while (in >> word)
    if (word != "-w" && word.rfind("-cl-std=", 0) != 0) out += " " + word;
  return out;
}

// Which ray origins each kernel file is built with (the others stop at an #error by design).
std::vector<RayOrigin> origins_of(const std::string& entry, Precision precision, int degree) {
  if (entry == "univariate") return {RayOrigin::Extent};
  std::vector<RayOrigin> origins{RayOrigin::Extent, RayOrigin::Eye};
  if (entry == "primary" || entry == "probe") origins.push_back(RayOrigin::Screen);
  if (entry == "shadow" || entry == "shadow_serial") {
    KernelConfig point;
    point.entry = entry;
    point.precision = precision;
    point.degree = degree;
    if (point_form_applies(point)) origins.push_back(RayOrigin::Point);
  }
  return origins;
}

// Float, mixed and adaptive builds are what devices without fp64 run: they compile with cl_khr_fp64 switched
// off, so that no double type creeps into them (double constants cast to float stay allowed, as OpenCL C 1.2
// lets such devices do).
std::string device_options(const KernelConfig& config) {
  return strict_options(config.build_options()) +
         (config.precision == Precision::Double ? "" : " -Xclang -cl-ext=-cl_khr_fp64");
}

void add(std::vector<Compile>& jobs, KernelConfig config) {
  const std::string kind = config.entry + " " + to_string(config.precision);
  jobs.push_back({kind, config.key(), config.source_file(), device_options(config)});
  config.lanes = 8;
  if (lanes_apply(config)) jobs.push_back({kind, config.key(), config.source_file(), device_options(config)});
  // Adaptive kernels as the plan builds them where the second pass runs in float-float (settle_doubts): shadow
  // kernels sample doubted rays' signs, the others settle discard doubts in float-float.
  if (config.precision != Precision::Adaptive || config.entry == "univariate") return;
  config.settle_doubts = true;
  for (int lanes : {1, 8}) {
    config.lanes = lanes;
    if (lanes == 1 || lanes_apply(config))
      jobs.push_back({kind + " settling", config.key(), config.source_file(), device_options(config)});
  }
}

// Every entry in every precision and ray origin, at the degrees where the kernels switch code paths, with the
// default solver: their #if lines part the degrees into 1, 2-7, 8-15, 16-31 and 32, so 1, 7, 16 and 32 every run
// and one of 8 and 15 drawn (a degree costs some 120 clang runs of 0.14 s CPU each). Then the isolation and
// refinement methods at one degree. All degrees, and the methods' product of entry, precision and method, under
// the `exhaustive` label; otherwise each (entry, precision) pair takes a seeded third of the methods, in a
// pattern that still gives every method with every entry and with every precision each run.
std::vector<Compile> every_configuration() {
  std::vector<Compile> jobs;
  const char* const entries[] = {"primary", "trace", "shadow", "shadow_serial", "probe", "univariate"};
  const unsigned offset = testing::sample_seed() % 3;
  if (testing::exhaustive_run())
    std::printf("test_kernel_portability: every method with every entry and precision (ALGRAY_EXHAUSTIVE=1)\n");
  else
    std::printf("test_kernel_portability: a third of the methods per entry and precision, pattern %u "
                "(ALGRAY_SAMPLE_SEED=%u repeats it, ALGRAY_EXHAUSTIVE=1 takes all)\n",
                offset, testing::sample_seed());
  const std::vector<int> degrees =
      testing::sampled("test_kernel_portability degrees", {1, 7, 8, 15, 16, kMaxDegree}, {1, 7, 16, kMaxDegree}, 1);
  unsigned pair = 0;
  for (const char* entry : entries)
    for (const auto& precision : kPrecisions) {
      if (precision.value == Precision::Mixed && std::string(entry) == "univariate") continue;
      ++pair;
      for (int degree : degrees) {
        if (precision.value == Precision::Mixed && degree > kMaxMixedDegree) continue;
        for (RayOrigin origin : origins_of(entry, precision.value, degree)) {
          KernelConfig c;
          c.entry = entry;
          c.precision = precision.value;
          c.degree = degree;
          c.ray_origin = origin;
          add(jobs, c);
        }
      }
      unsigned method = 0;
      for (const auto& isolation : kIsolations)
        for (const auto& refinement : kRefinements) {
          if (!testing::exhaustive_run() && (pair + offset + method++) % 3 != 0) continue;
          KernelConfig c;
          c.entry = entry;
          c.precision = precision.value;
          c.degree = 6;
          c.isolation = isolation.value;
          c.refinement = refinement.value;
          if (c.isolation != Isolation::Bernstein || c.refinement != Refinement::Brent) add(jobs, c);
        }
    }
  // The shading kernel, which the solver's choices do not touch: in float and double, one pixel and lanes of them.
  for (Precision precision : {Precision::Float, Precision::Double})
    for (int lanes : {1, 8, 16}) {
      KernelConfig c;
      c.entry = "shade";
      c.precision = precision;
      c.lanes = lanes;
      jobs.push_back({"shade " + to_string(precision), c.key(), c.source_file(), device_options(c)});
    }
  // The test-only restriction kernel, one ray at a time and in a vector's lanes, on each side of degree 15.
  for (Precision precision : {Precision::Float, Precision::Double})
    for (int degree : {7, kMaxDegree})
      for (int batch : {0, 8}) {
        KernelConfig c;
        c.entry = "restrict_check";
        c.precision = precision;
        c.degree = degree;
        c.shadow_batch = batch;
        jobs.push_back({"restrict_check " + to_string(precision), c.key(), c.source_file(), device_options(c)});
      }
  for (bool in_double : {false, true})
    jobs.push_back(
        {std::string("fp_speed ") + (in_double ? "double" : "float"), "fp_speed", "fp_speed.cl",
         strict_options(fp_speed_build_options(in_double)) + (in_double ? "" : " -Xclang -cl-ext=-cl_khr_fp64")});
  return jobs;
}

// What clang made of one configuration.
struct Outcome {
  enum Kind { Compiled, RefusedByDesign, Failed } kind = Compiled;
  std::string report;  // the command and its diagnostics, when it failed
};

// Whether an #error directive fired: a combination the kernels refuse by design (the eye origin with Bernstein
// isolation, say), which the host never builds; the errors after it follow from the code it left out. Any other
// failure is a portability bug.
bool directive_fired(const std::string& log) {
  std::istringstream lines(log);
  std::string line;
  bool after_error = false;
  while (std::getline(lines, line)) {
    const auto first = line.find_first_not_of(' ');
    if (after_error && first != std::string::npos && line.compare(first, 6, "#error") == 0) return true;
    after_error = line.find(": error: ") != std::string::npos;
  }
  return false;
}

Outcome compile(const Compile& job, const std::filesystem::path& dir, std::size_t index) {
  const auto source = dir / ("k" + std::to_string(index) + ".cl");
  const auto log = dir / ("k" + std::to_string(index) + ".log");
  std::ofstream(source) << assemble_kernel_source(job.file);
  const std::string command = std::string(ALGRAY_OPENCL_CLANG) +
                              " -x cl -Xclang -finclude-default-header -fsyntax-only -pedantic-errors " + job.options +
                              " " + source.string() + " > " + log.string() + " 2>&1";
  if (std::system(command.c_str()) == 0) return {};
  std::ifstream in(log);
  std::ostringstream text;
  text << in.rdbuf();
  if (directive_fired(text.str())) return {Outcome::RefusedByDesign, ""};
  return {Outcome::Failed, command + "\n" + text.str()};
}

}  // namespace

TEST_CASE("every kernel configuration compiles as strict OpenCL C 1.2") {
  REQUIRE_FALSE(std::string(ALGRAY_OPENCL_CLANG).empty());  // CMake found no clang: install clang-15
  const auto dir = std::filesystem::temp_directory_path() / ("algray-portability-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::vector<Compile> jobs = every_configuration();
  // Several compilers at once: each is one process, mostly waiting on its own parse.
  const std::size_t width = std::max(2u, std::thread::hardware_concurrency());
  std::vector<Outcome> outcomes(jobs.size());
  for (std::size_t start = 0; start < jobs.size(); start += width) {
    std::vector<std::future<Outcome>> running;
    for (std::size_t i = start; i < std::min(jobs.size(), start + width); ++i)
      running.push_back(std::async(std::launch::async, compile, std::cref(jobs[i]), std::cref(dir), i));
    for (std::size_t i = 0; i < running.size(); ++i) outcomes[start + i] = running[i].get();
  }
  std::filesystem::remove_all(dir);
  int failed = 0, compiled = 0;
  std::set<std::string> kinds, compiled_kinds;
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    kinds.insert(jobs[i].kind);
    if (outcomes[i].kind == Outcome::Failed && ++failed <= 3) UNSCOPED_INFO(jobs[i].what << "\n" << outcomes[i].report);
    if (outcomes[i].kind == Outcome::Compiled) {
      ++compiled;
      compiled_kinds.insert(jobs[i].kind);
    }
  }
  INFO(failed << " of " << jobs.size() << " configurations failed (the first three above), " << compiled
              << " compiled, the rest refused by an #error by design");
  CHECK(failed == 0);
  // Refusals by design must not swallow the matrix: every kernel file compiles in each precision it takes.
  CHECK(compiled_kinds == kinds);
}

TEST_CASE("a build log's locations in the assembled program point back into the kernel files") {
  const std::string source = assemble_kernel_source("primary.cl");
  // The line of the assembled text that holds isolation.h's ISOLATION_NONE, and that line in the file.
  const std::string marker = "#define ISOLATION_NONE ALGRAY_ISOLATED_NONE";
  const auto at = source.find(marker);
  REQUIRE(at != std::string::npos);
  const long assembled_line = std::count(source.begin(), source.begin() + static_cast<long>(at), '\n') + 1;
  std::ifstream file(std::string(ALGRAY_SOURCE_DIR) + "/kernels/isolation.h");
  std::string line;
  int file_line = 0;
  for (int n = 1; std::getline(file, line); ++n)
    if (line == marker) file_line = n;
  REQUIRE(file_line > 0);

  // NVIDIA's form, then PoCL's (already a kernel file: unchanged), then a location past the program's end.
  const std::string log = "<kernel>:" + std::to_string(assembled_line) + ":17: error: variadic macros\n" +
                          "isolation.h:12:3: note: kept\n<kernel>:99999999:1: error: beyond\n";
  const std::string mapped = locate_in_kernel_files(log, source);
  INFO(mapped);
  CHECK(mapped == "isolation.h:" + std::to_string(file_line) + ":17: error: variadic macros\n" +
                      "isolation.h:12:3: note: kept\n<kernel>:99999999:1: error: beyond\n");
}
