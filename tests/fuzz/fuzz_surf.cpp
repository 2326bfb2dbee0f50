// libFuzzer target for load_surf_script_text: the whole input is a surf script (.pic).
//
// Expected: a valid Scene, or SceneError located in fuzz.pic itself, never in the TOML it is translated to. Anything
// else escaping, a sanitizer report, a leak or a 60-s input (a goto loop or an expansion the budgets missed) is a
// finding.
#include <cstdint>
#include <string>

#include "fuzz_checks.h"
#include "algray/scene/scene.h"

using namespace algray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const Scene scene = load_surf_script_text(text, "fuzz.pic", {});
    fuzz::require_valid_scene(scene);
    for (const std::string& w : scene.warnings)
      fuzz::require(fuzz::starts_with(w, "fuzz.pic:"), "a surf warning that does not say where", w);
  } catch (const SceneError& e) {
    fuzz::require_located(e, "fuzz.pic:");
    fuzz::require(e.where.find("(translated to TOML)") == std::string::npos,
                  "a surf script error points into the translated TOML", e.what());
  }
  return 0;
}
