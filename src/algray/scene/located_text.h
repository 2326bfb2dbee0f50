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

}  // namespace algray
