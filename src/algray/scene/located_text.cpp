// Places in a scene file's text, as messages give them.
#include "algray/scene/located_text.h"

#include <algorithm>
#include <sstream>

#include "algray/scene/scene.h"

namespace algray {

LocatedText::LocatedText(const std::string& text, std::string source) : source_(std::move(source)) {
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) {
    if (!l.empty() && l.back() == '\r') l.pop_back();
    lines_.push_back(l);
  }
}

std::string LocatedText::where(int line, int column) const {
  return source_ + ":" + std::to_string(line) + ":" + std::to_string(column);
}

std::string LocatedText::excerpt(int line, int column) const {
  const std::string text = line >= 1 && static_cast<std::size_t>(line) <= lines_.size()
                               ? lines_[static_cast<std::size_t>(line - 1)]
                               : std::string();
  return text + "\n" + std::string(static_cast<std::size_t>(std::max(column - 1, 0)), ' ') + "^";
}

void LocatedText::fail(int line, int column, const std::string& message) const {
  throw SceneError(where(line, column), message, excerpt(line, column));
}

}  // namespace algray
