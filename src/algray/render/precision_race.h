// Which of double and adaptive precision a stream of preview frames renders in: the one measured faster here.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "algray/scene/scene.h"
#include "algray/scene/solver_options.h"

namespace algray {

// Issue 44, goal 3. Where fp64 is fast (CPUs, datacenter GPUs) `auto` renders in double, which agrees with the
// certified reference exactly; adaptive precision promises the same hits with depth within 1e-4 relative, and is
// faster on some surfaces and slower on others (bench/RESULTS.md, "Float first": 0.74x to 1.25x of double's
// kernel time in preview on one CPU). A preview frame has no use for double's last digits, so a renderer that
// draws frame after frame (the view, Python) races the two: the frames of one race key alternate double,
// adaptive, double, ... until each has run kRounds times, and from then on the key renders in the one whose
// fastest frame took less device time, adaptive on a tie. A decision is not for ever: the camera or the size of
// the surface on screen can move the balance, so when kRounds frames in a row in the chosen precision each take
// more than kReopen times the other's fastest, the key races again. Every frame of the race is a correct render
// in its precision; a single render (the command line) only ever runs the first, double: today's `auto`.
class PrecisionRace {
 public:
  static constexpr int kRounds = 2;
  // How much slower than the other precision's fastest frame a frame in the chosen one may be before it counts
  // against the decision: frames of one view vary by some 10% from one to the next.
  static constexpr double kReopen = 1.25;
  // Keys kept at most: a long session over many surfaces forgets the oldest decisions and races them again.
  static constexpr std::size_t kKeys = 64;

  // The precision the next frame of `key` renders in.
  Precision next(const std::string& key) const;
  // The device time of a frame of `key` that rendered in `precision` (double or adaptive).
  void record(const std::string& key, Precision precision, double kernel_ms);
  // What the key's frames render in and why, for --stats: "racing (double 14.8 ms, adaptive 11.7 ms so far)" or
  // "adaptive: its fastest frame 11.7 ms of device time, double's 14.8".
  std::string reason(const std::string& key) const;

  // The key of a scene's frames: what their relative cost depends on, apart from the camera and the
  // coefficients (a slider moving a parameter keeps its race): each surface's monomials, the isolation method,
  // the image size and the samples per pixel.
  static std::string key_of(const Scene& scene);

 private:
  struct Entry {
    std::vector<double> double_ms, adaptive_ms;
    std::optional<Precision> chosen;
    int slow_in_a_row = 0;  // frames in the chosen precision past kReopen times the other's fastest
    std::size_t last_used = 0;
  };
  std::map<std::string, Entry> entries_;
  std::size_t clock_ = 0;
};

}  // namespace algray
