// libFuzzer target for load_jsurf_text: the whole input is a .jsurf (Java properties) file.
//
// Expected: a valid Scene, or SceneError located in fuzz.jsurf itself, never in the TOML it is translated to (the
// user never saw that). Anything else escaping, a sanitizer report, a leak or a 60-s input is a finding.
#include <cstdint>
#include <string>

#include "fuzz_checks.h"
#include "algray/scene/scene.h"

using namespace algray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    fuzz::require_valid_scene(load_jsurf_text(text, "fuzz.jsurf", {}));
  } catch (const SceneError& e) {
    fuzz::require_located(e, "fuzz.jsurf");
    fuzz::require(e.where.find("(translated to TOML)") == std::string::npos,
                  "a .jsurf error points into the translated TOML", e.what());
  }
  return 0;
}
