// libFuzzer target for load_scene_text: leading "--set key=value" lines are overrides, the rest is the TOML scene.
//
// Expected: a valid Scene, or SceneError located in fuzz.toml or naming the override. Anything else escaping, a
// sanitizer report, a leak or a 60-s input is a finding.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_checks.h"
#include "algray/scene/scene.h"

using namespace algray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  std::vector<Override> overrides;
  constexpr std::string_view kSet = "--set ";
  while (rest.substr(0, kSet.size()) == kSet) {
    const std::size_t eol = rest.find('\n');
    const std::string_view arg =
        rest.substr(kSet.size(), eol == std::string_view::npos ? std::string_view::npos : eol - kSet.size());
    rest = eol == std::string_view::npos ? std::string_view{} : rest.substr(eol + 1);
    // The command line refuses a --set without '=' before the scene reader sees it.
    const std::size_t eq = arg.find('=');
    if (eq != std::string_view::npos) overrides.push_back({std::string(arg.substr(0, eq)), std::string(arg.substr(eq + 1))});
  }
  try {
    fuzz::require_valid_scene(load_scene_text(std::string(rest), "fuzz.toml", overrides));
  } catch (const SceneError& e) {
    fuzz::require_located(e, "fuzz.toml");
  }
  return 0;
}
