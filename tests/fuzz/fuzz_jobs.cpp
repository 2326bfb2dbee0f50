// libFuzzer target for load_jobs: the whole input is a batch jobs file; scenes are named, never opened.
//
// Expected: jobs with at least one frame and one output each, or SceneError located in fuzz_jobs.toml. Anything
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
      fuzz::require(!job.outputs.empty(), "a job with no output", job.name);
    }
  } catch (const SceneError& e) {
    fuzz::require(!e.message.empty(), "SceneError with an empty message", e.what());
    fuzz::require(fuzz::starts_with(e.where, "fuzz_jobs.toml"), "SceneError not located in the jobs file", e.what());
  }
  return 0;
}
