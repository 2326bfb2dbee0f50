// libFuzzer target for load_jobs: the whole input is a batch jobs file; scenes are named, never opened.
//
// Expected: jobs with at least one frame each and a positive frame rate, located (their outputs may be none: the
// frames then go into a --video, which plan_batch requires), or SceneError located in fuzz_jobs.toml. Anything
// else escaping, a sanitizer report, a leak or a 60-s input is a finding.
#include <cstdint>
#include <string>

#include "algray/api/batch.h"
#include "fuzz_checks.h"

using namespace algray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    for (const BatchJob& job : load_jobs(text, "fuzz_jobs.toml", "/tmp")) {
      fuzz::require(job.frames >= 1, "a job with no frames", job.name);
      fuzz::require(job.fps > 0 && job.fps <= 1000, "a job's frame rate out of range", job.name);
      fuzz::require(fuzz::starts_with(job.origin, "fuzz_jobs.toml:"), "a job not located", job.origin);
    }
  } catch (const SceneError& e) {
    fuzz::require(!e.message.empty(), "SceneError with an empty message", e.what());
    fuzz::require(fuzz::starts_with(e.where, "fuzz_jobs.toml"), "SceneError not located in the jobs file", e.what());
  }
  return 0;
}
