// Resolves the kernels' quoted #include lines against the embedded files (or a directory, for kernel work).
#include "algray/device/kernel_sources.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace algray {
namespace {

// A kernel file's text: the embedded file itself (no copy), or, with ALGRAY_KERNEL_DIR, the file read into storage.
std::string_view kernel_file_text(const std::string& name, std::string& storage) {
  if (const char* dir = std::getenv("ALGRAY_KERNEL_DIR"); dir && *dir) {
    std::ifstream in(std::string(dir) + "/" + name, std::ios::binary);
    if (!in)
      throw std::runtime_error("ALGRAY_KERNEL_DIR is set but " + std::string(dir) + "/" + name + " cannot be read");
    std::ostringstream text;
    text << in.rdbuf();
    storage = text.str();
    return storage;
  }
  for (const EmbeddedFile& f : embedded_kernel_files())
    if (name == f.name) return f.text;
  throw std::runtime_error("kernel file '" + name + "' is not embedded in this build");
}

// Where the assembly stands in the program text it writes: which files it has written and which of them the
// preprocessor is sure to have read, whatever the build's switches.
struct Assembly {
  std::vector<std::string> stack;      // the files being written, outermost first (an include cycle is an error)
  std::set<std::string> written;       // files written at least once
  std::set<std::string> surely_read;   // files written outside every #if: their include guards are set after
  std::vector<bool> condition_counts;  // the open #if directives: whether each may drop what it holds
  std::string out;
};

// The words of a preprocessor line: `# ifndef X` gives "ifndef" (word 0) and "X" (word 1); empty past its end or
// for a line that is no directive.
std::string_view directive_word(std::string_view line, int index) {
  const auto hash = line.find_first_not_of(" \t");
  if (hash == std::string_view::npos || line[hash] != '#') return {};
  std::size_t at = hash + 1;
  for (int i = 0;; ++i) {
    const auto word = line.find_first_not_of(" \t", at);
    if (word == std::string_view::npos) return {};
    const auto end = std::min(line.find_first_of(" \t(", word), line.size());
    if (i == index) return line.substr(word, end - word);
    at = end;
  }
}

// Writes `name` with its #include "..." lines resolved. A file is written again where it is included again,
// unless an earlier copy stands outside every #if: an earlier copy in a branch the preprocessor drops (isolate.h
// includes one isolation method per branch) must not hide the file from a later include. A file's own include
// guard, the first time it is written, drops nothing and does not count as an #if; a later copy's guard does (the
// preprocessor may have read the file already). So each header is written about once instead of at every include
// (primary.cl's program was 2.2 MB, shadow.cl's 3.4 MB: assembled by every process, and lexed by every compile).
void append_with_includes(const std::string& name, Assembly& a) {
  if (std::find(a.stack.begin(), a.stack.end(), name) != a.stack.end())
    throw std::runtime_error("kernel file '" + name + "' includes itself");
  a.stack.push_back(name);
  const bool first_copy = a.written.insert(name).second;
  std::string storage;
  const std::string_view text = kernel_file_text(name, storage);
  int number = 0, directives = 0;
  std::string_view guard;  // the first copy's include guard, while it is still to be seen
  a.out += "#line 1 \"" + name + "\"\n";
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::string_view line = text.substr(at, end - at);
    at = end + 1;
    ++number;
    const std::string_view directive = directive_word(line, 0);
    if (directive.empty()) {
      a.out += line;
      a.out += '\n';
      continue;
    }
    ++directives;
    if (directives == 2 && !guard.empty() && !(directive == "define" && directive_word(line, 1) == guard)) {
      a.condition_counts.back() = true;  // not an include guard after all: the #ifndef may drop what it holds
    }
    if (directive == "if" || directive == "ifdef" || directive == "ifndef") {
      // `#ifndef X` then `#define X` as a first copy's first directives: its include guard
      const bool is_guard = first_copy && directives == 1 && directive == "ifndef";
      if (is_guard) guard = directive_word(line, 1);
      a.condition_counts.push_back(!is_guard);
    } else if (directive == "endif" && !a.condition_counts.empty()) {
      a.condition_counts.pop_back();
    } else if (directive == "include") {
      const auto open = line.find('"'), close = line.rfind('"');
      if (open != std::string_view::npos && close > open) {
        const std::string included(line.substr(open + 1, close - open - 1));
        if (a.surely_read.count(included)) {
          a.out += '\n';  // its guard is set: the line stays, empty, so that the lines after keep their numbers
          continue;
        }
        const bool outside_every_if =
            std::find(a.condition_counts.begin(), a.condition_counts.end(), true) == a.condition_counts.end();
        if (outside_every_if) a.surely_read.insert(included);
        append_with_includes(included, a);
        a.out += "#line " + std::to_string(number + 1) + " \"" + name + "\"\n";
        continue;
      }
    }
    a.out += line;
    a.out += '\n';
  }
  a.stack.pop_back();
}

}  // namespace

std::string assemble_kernel_source(const std::string& main_file) {
  Assembly a;
  append_with_includes(main_file, a);
  return std::move(a.out);
}

namespace {

struct SourceLine {
  std::string file;
  int line = 0;
};

// Where each line of an assembled program came from, by its #line directives (index 0 is the text's line 1).
std::vector<SourceLine> line_origins(const std::string& source) {
  std::vector<SourceLine> origins;
  std::istringstream lines(source);
  std::string line, file = "?";
  int next = 1;
  while (std::getline(lines, line)) {
    origins.push_back({file, next});
    std::istringstream directive(line);
    std::string word, name;
    int number = 0;
    if (directive >> word && word == "#line" && directive >> number >> name && name.size() >= 2) {
      file = name.substr(1, name.size() - 2);
      next = number;
    } else {
      ++next;
    }
  }
  return origins;
}

bool is_kernel_file(const std::string& name) {
  for (const EmbeddedFile& f : embedded_kernel_files())
    if (name == f.name) return true;
  return false;
}

}  // namespace

std::string locate_in_kernel_files(const std::string& log, const std::string& source) {
  const std::vector<SourceLine> origins = line_origins(source);
  static const std::regex location(R"(([^\s:]+):(\d+):(\d+):)");
  std::string out;
  auto rest = log.cbegin();
  for (std::sregex_iterator it(log.begin(), log.end(), location), end; it != end; ++it) {
    const std::smatch& m = *it;
    const long line = std::stol(m[2].str());
    out.append(rest, m[0].first);
    if (!is_kernel_file(m[1].str()) && line >= 1 && line <= static_cast<long>(origins.size())) {
      const SourceLine& from = origins[static_cast<std::size_t>(line - 1)];
      out += from.file + ":" + std::to_string(from.line) + ":" + m[3].str() + ":";
    } else {
      out += m[0].str();
    }
    rest = m[0].second;
  }
  out.append(rest, log.cend());
  return out;
}

}  // namespace algray
