// What the algray fuzz targets share: turning a broken property into a crash that libFuzzer saves as a reproducer.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "algray/scene/scene.h"

namespace algray::fuzz {

// An exception escaping a target is already a finding (std::terminate aborts); a wrong result or a malformed
// error is not, unless we check for it.
inline void require(bool ok, const char* property, const std::string& detail = {}) {
  if (ok) return;
  std::fprintf(stderr, "fuzz property violated: %s\n%s\n", property, detail.c_str());
  std::abort();
}

inline bool starts_with(const std::string& s, std::string_view prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

// Every SceneError must say where and what, so that a user can find the mistake (DESIGN.md: typed errors with file,
// line and column).
inline void require_located(const SceneError& e, std::string_view source) {
  require(!e.message.empty(), "SceneError with an empty message", e.what());
  require(starts_with(e.where, source) || starts_with(e.where, "--set "),
          "SceneError not located in the input or an override", e.what());
}

// What the readers promise about any scene they return.
inline void require_valid_scene(const Scene& scene) {
  require(!scene.surfaces.empty() && scene.surfaces.size() <= kMaxSurfaces, "scene surface count out of range");
  for (const SceneSurface& s : scene.surfaces)
    require(s.polynomial.degree() >= 1 && s.polynomial.degree() <= kMaxDegree, "surface degree out of range",
            s.equation);
  require(scene.image.width >= 1 && scene.image.height >= 1, "image size below 1 pixel");
  for (const Light& l : scene.lights)
    require(l.samples >= 1 && l.samples <= kMaxLightSamplesPerSide, "light samples out of range");
}

}  // namespace algray::fuzz
