// Resolves the kernels' quoted #include lines against the embedded files (or a directory, for kernel work).
#include "algray/device/kernel_sources.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <regex>
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

// Every #include is expanded where it stands, even when the file came in before: an earlier copy may sit in a
// branch of #if that the preprocessor drops, so only the headers' own include guards may skip it. The assembled
// text is thus megabytes (primary.cl's 2.2 MB), assembled once per process and entry file: lines are scanned in
// place rather than copied through a stream.
void append_with_includes(const std::string& name, std::vector<std::string>& stack, std::string& out) {
  if (std::find(stack.begin(), stack.end(), name) != stack.end())
    throw std::runtime_error("kernel file '" + name + "' includes itself");
  stack.push_back(name);
  std::string storage;
  const std::string_view text = kernel_file_text(name, storage);
  int number = 0;
  out += "#line 1 \"" + name + "\"\n";
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::string_view line = text.substr(at, end - at);
    at = end + 1;
    ++number;
    const auto first = line.find_first_not_of(" \t");
    if (first != std::string_view::npos && line.compare(first, 9, "#include ") == 0) {
      const auto open = line.find('"', first), close = line.rfind('"');
      if (open != std::string_view::npos && close > open) {
        append_with_includes(std::string(line.substr(open + 1, close - open - 1)), stack, out);
        out += "#line " + std::to_string(number + 1) + " \"" + name + "\"\n";
        continue;
      }
    }
    out += line;
    out += '\n';
  }
  stack.pop_back();
}

}  // namespace

std::string assemble_kernel_source(const std::string& main_file) {
  std::vector<std::string> stack;
  std::string out;
  append_with_includes(main_file, stack, out);
  return out;
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
