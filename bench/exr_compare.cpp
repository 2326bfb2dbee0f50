// Compares two algray EXR files pixel by pixel: hit/miss disagreements and relative depth differences.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>

#include "image_io.h"

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
    for (std::size_t i = 0; i < ref.depth.size(); ++i) {
      const bool ht = std::isfinite(test.depth[i]), hr = std::isfinite(ref.depth[i]);
      if (ht != hr) {
        ++hit_miss;
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
  } catch (const std::exception& e) {
    std::fprintf(stderr, "exr_compare: %s\n", e.what());
    return 1;
  }
  return 0;
}
