// The progress line a command keeps rewriting on a terminal's standard error.
#pragma once

#include <string>

namespace algray::cli {

// Draws "\r<text>" over the previous line; ends it with a newline before any other message and at the end.
class ProgressLine {
 public:
  explicit ProgressLine(bool enabled) : enabled_(enabled) {}
  ~ProgressLine() { finish(); }
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;
  bool enabled() const { return enabled_; }
  void show(const std::string& text);
  // Ends the line, if one is shown, so that what follows starts on a line of its own.
  void finish();

 private:
  bool enabled_;
  bool shown_ = false;
};

// "1.23 s" under ten seconds, "42 s" above.
std::string seconds_text(double ms);

}  // namespace algray::cli
