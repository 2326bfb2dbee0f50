// Places in a scene file's text, as messages give them.
#include "algray/scene/located_text.h"

#include <algorithm>
#include <cctype>
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

void TextCursor::advance(std::size_t n) {
  for (std::size_t k = 0; k < n && i < text.size(); ++k, ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
}

int TextCursor::skip_comment() {
  if (at() != '/') return 0;
  if (at(1) == '/') {
    while (!done() && at() != '\n') advance(1);
    return 1;
  }
  if (at(1) != '*') return 0;
  const std::size_t end = text.find("*/", i + 2);
  if (end == std::string::npos) return -1;
  advance(end + 2 - i);
  return 1;
}

std::size_t TextCursor::number_end(bool* real) const {
  auto digit = [&](std::size_t k) { return k < text.size() && std::isdigit(static_cast<unsigned char>(text[k])); };
  std::size_t j = i;
  *real = false;
  while (digit(j)) ++j;
  if (j < text.size() && text[j] == '.') {
    *real = true;
    ++j;
    while (digit(j)) ++j;
  }
  if (j < text.size() && (text[j] == 'e' || text[j] == 'E')) {
    std::size_t k = j + 1;
    if (k < text.size() && (text[k] == '+' || text[k] == '-')) ++k;
    if (digit(k)) {
      *real = true;
      j = k;
      while (digit(j)) ++j;
    }
  }
  return j;
}

}  // namespace algray
