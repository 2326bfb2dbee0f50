// The progress line a command keeps rewriting on a terminal's standard error.
#include "progress_line.h"

#include <cstdio>

namespace algray::cli {

void ProgressLine::show(const std::string& text) {
  if (!enabled_) return;
  std::fprintf(stderr, "\r%s", text.c_str());
  std::fflush(stderr);
  shown_ = true;
}

void ProgressLine::finish() {
  if (!shown_) return;
  std::fprintf(stderr, "\n");
  std::fflush(stderr);
  shown_ = false;
}

std::string seconds_text(double ms) {
  char buf[32];
  std::snprintf(buf, sizeof buf, ms < 10000 ? "%.2f s" : "%.0f s", ms / 1000);
  return buf;
}

}  // namespace algray::cli
