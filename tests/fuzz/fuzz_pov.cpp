// libFuzzer target for load_povray_text: the whole input is a POV-Ray scene (.pov).
//
// Expected: a valid Scene, or SceneError located in fuzz.pov itself or in one of POV-Ray's include files it names
// (fuzz.pov has no directory, so #include looks only there and in ALGRAY_POV_INCLUDE), never in the TOML it is
// translated to. Anything
// else escaping, a sanitizer report, a leak or a 60-s input (an expansion the budget missed) is a
// finding.
#include <cstdint>
#include <string>

#include "fuzz_checks.h"
#include "algray/scene/scene.h"

using namespace algray;

namespace {
constexpr const char* kPovInclude = "/usr/share/povray-3.7/include/";
// Where a message may point: the input, or an include file from POV-Ray's include directory.
bool located_here(const std::string& where) {
  return fuzz::starts_with(where, "fuzz.pov:") || fuzz::starts_with(where, kPovInclude);
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const Scene scene = load_povray_text(text, "fuzz.pov", {});
    fuzz::require_valid_scene(scene);
    for (const std::string& w : scene.warnings)
      fuzz::require(located_here(w), "a POV-Ray warning that does not say where", w);
  } catch (const SceneError& e) {
    fuzz::require_located(e, fuzz::starts_with(e.where, kPovInclude) ? kPovInclude : "fuzz.pov:");
    fuzz::require(e.where.find("(translated to TOML)") == std::string::npos,
                  "a POV-Ray error points into the translated TOML", e.what());
  }
  return 0;
}
