// A scene file's text as its readers' messages locate things in it: "file:line:column" and the line with a caret.
#pragma once

#include <string>
#include <vector>

namespace algray {

class LocatedText {
 public:
  LocatedText(const std::string& text, std::string source);
  const std::string& source() const { return source_; }
  std::string where(int line, int column) const;    // source:line:column
  std::string excerpt(int line, int column) const;  // the line, and a caret under the column
  // A SceneError at the place, with its excerpt.
  [[noreturn]] void fail(int line, int column, const std::string& message) const;

 private:
  std::string source_;
  std::vector<std::string> lines_;  // without their line ends ("\n" or "\r\n")
};

// A walk through a scene file's text one token at a time, counting lines and columns as messages give them.
struct TextCursor {
  explicit TextCursor(const std::string& t) : text(t) {}
  const std::string& text;
  std::size_t i = 0;  // the next character
  int line = 1, column = 1;

  bool done() const { return i >= text.size(); }
  // The character `ahead` places on, or 0 past the end.
  char at(std::size_t ahead = 0) const { return i + ahead < text.size() ? text[i + ahead] : '\0'; }
  void advance(std::size_t n);
  // At "//" or "/*": moves past the comment and returns 1, or returns -1 for a "/*" that never ends (the cursor
  // stays on it); elsewhere returns 0.
  int skip_comment();
  // The end of the decimal number starting here (digits, a fraction, an exponent); *real says whether it had a
  // fraction or an exponent.
  std::size_t number_end(bool* real) const;
};

}  // namespace algray
