// Compares two algray EXR files pixel by pixel: hit/miss disagreements, relative depth differences, colour
// differences in 8-bit steps, identical bits.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "algray/io/image_io.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: exr_compare TEST.exr REFERENCE.exr\n");
    return 2;
  }
  try {
    const algray::FrameImage test = algray::read_exr(argv[1]), ref = algray::read_exr(argv[2]);
    if (test.depth.size() != ref.depth.size() || test.depth.empty()) {
      std::fprintf(stderr, "exr_compare: the images differ in size or have no Z channel\n");
      return 2;
    }
    long hit_miss = 0, both = 0, off_1e3 = 0, off_1e6 = 0;
    double worst = 0;
    std::string where;  // the first few hit/miss disagreements, as x,y: which pixels to probe
    for (std::size_t i = 0; i < ref.depth.size(); ++i) {
      const bool ht = std::isfinite(test.depth[i]), hr = std::isfinite(ref.depth[i]);
      if (ht != hr) {
        if (++hit_miss <= 8) {
          char pixel[64];
          const auto width = static_cast<std::size_t>(ref.width);
          std::snprintf(pixel, sizeof pixel, " %zu,%zu (test %s)", i % width, i / width, ht ? "hits" : "misses");
          where += pixel;
        }
      } else if (hr) {
        ++both;
        const double rel = std::fabs(double(test.depth[i]) - ref.depth[i]) / std::fabs(double(ref.depth[i]));
        worst = std::max(worst, rel);
        off_1e3 += rel > 1e-3;
        off_1e6 += rel > 1e-6;
      }
    }
    std::printf(
        "pixels %zu, hit/miss disagreements %ld (%.3f%%), both hit %ld, depth off by >1e-6 %ld, >1e-3 %ld "
        "(%.2f%% of common hits), worst relative depth difference %.2g\n",
        ref.depth.size(), hit_miss, 100.0 * static_cast<double>(hit_miss) / static_cast<double>(ref.depth.size()), both,
        off_1e6, off_1e3, 100.0 * static_cast<double>(off_1e3) / static_cast<double>(std::max(both, 1L)), worst);
    if (!where.empty()) std::printf("hit/miss disagreements at%s%s\n", where.c_str(), hit_miss > 8 ? " ..." : "");
    // Colour in 8-bit steps of the linear values (what a change to shading or shadows moves): pixels whose largest
    // channel difference exceeds 1 and 16 steps, and the largest.
    long colour_off_1 = 0, colour_off_16 = 0;
    double colour_worst = 0;
    for (std::size_t i = 0; i + 3 < ref.rgba.size() && i + 3 < test.rgba.size(); i += 4) {
      double d = 0;
      for (std::size_t c = 0; c < 4; ++c) d = std::max(d, std::fabs(double(test.rgba[i + c]) - ref.rgba[i + c]) * 255);
      colour_off_1 += d > 1;
      colour_off_16 += d > 16;
      colour_worst = std::max(colour_worst, d);
    }
    std::printf("colour off by >1/255 %ld pixels, >16/255 %ld, largest %.1f/255\n", colour_off_1, colour_off_16,
                colour_worst);
    // Whether a change kept every stored value (colour, depth, normal, solver channels) bit for bit: the check
    // for work that must not move an image. NaNs compare by their bits too.
    const auto same_bits = [](const auto& a, const auto& b) {
      return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
    };
    std::vector<std::string> differing;
    if (!same_bits(test.rgba, ref.rgba)) differing.push_back("RGBA");
    if (!same_bits(test.depth, ref.depth)) differing.push_back("Z");
    if (!same_bits(test.normal, ref.normal)) differing.push_back("N");
    const bool same_layout = test.uint_channels.size() == ref.uint_channels.size() &&
                             test.float_channels.size() == ref.float_channels.size();
    if (!same_layout) differing.push_back("(channel lists)");
    for (std::size_t c = 0; same_layout && c < ref.uint_channels.size(); ++c)
      if (test.uint_channels[c].name != ref.uint_channels[c].name ||
          !same_bits(test.uint_channels[c].values, ref.uint_channels[c].values))
        differing.push_back(ref.uint_channels[c].name);
    for (std::size_t c = 0; same_layout && c < ref.float_channels.size(); ++c)
      if (test.float_channels[c].name != ref.float_channels[c].name ||
          !same_bits(test.float_channels[c].values, ref.float_channels[c].values))
        differing.push_back(ref.float_channels[c].name);
    std::string list;
    for (const std::string& name : differing) list += " " + name;
    std::printf("channels bit-identical: %s\n", differing.empty() ? "all" : ("no, differing:" + list).c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "exr_compare: %s\n", e.what());
    return 1;
  }
  return 0;
}
