// The heat map of solver work per pixel, with a colour bar and a caption naming its scale.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "algray/io/image_io.h"

namespace algray {

// How work_heatmap maps work to colour: over in-extent pixels only, logarithmic (in 1 + work) when
// (1 + max) / (1 + min) > 50, since a few pathological pixels would otherwise flatten everything else to
// the bottom colour.
struct HeatmapScale {
  bool logarithmic = false;
  double min = 0, max = 0;  // 0, 0 when no pixel is in the extent
  std::size_t pixels = 0;   // in-extent pixels
};
HeatmapScale heatmap_scale(const std::vector<std::uint32_t>& work, const std::vector<std::uint8_t>& in_extent);

// work: one value per pixel (row-major, top row first); in_extent: 0 where the pixel's ray missed the extent
// (drawn as neutral dark grey) — may be empty meaning all in extent. The result holds the map at 1:1 in its
// top-left width x height pixels, a colour bar with labelled ticks to its right and the caption (with the
// scale used) below; higher work is brighter. Throws OutputError when the sizes disagree.
FrameImage work_heatmap(int width, int height, const std::vector<std::uint32_t>& work,
                        const std::vector<std::uint8_t>& in_extent, const std::string& caption);

}  // namespace algray
