// libFuzzer target for parse_equation: leading "#name=value" lines are parameters, the rest is the equation.
//
// Expected: a Polynomial of degree <= kDefaultMaxEquationDegree, or EquationError at a position inside the text.
// Anything else escaping (std::bad_alloc, std::domain_error, ...), a sanitizer report, a leak or a 60-s input is a
// finding.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <string>
#include <string_view>

#include "algray/scene/expression.h"
#include "fuzz_checks.h"
#include "algray/scene/toml_reader.h"

using namespace algray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  std::map<std::string, double> parameters;
  while (!text.empty() && text.front() == '#') {
    const std::size_t eol = text.find('\n');
    const std::string_view line = text.substr(1, eol == std::string_view::npos ? std::string_view::npos : eol - 1);
    text = eol == std::string_view::npos ? std::string_view{} : text.substr(eol + 1);
    const std::size_t eq = line.find('=');
    if (eq == std::string_view::npos) continue;
    const std::string name(line.substr(0, eq));
    const std::string value(line.substr(eq + 1));
    // The scene reader hands over only identifiers that are not reserved, with finite values: the parser may rely
    // on that, so the fuzzer keeps to it.
    if (!is_identifier(name) || is_reserved_name(name)) continue;
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (end == value.c_str() || !std::isfinite(v)) continue;
    parameters[name] = v;
  }
  try {
    // `text` views the fuzzer's own buffer, so a read one byte past the equation is an ASan report.
    const Polynomial p = parse_equation(text, parameters);
    fuzz::require(p.degree() <= kDefaultMaxEquationDegree, "parse_equation returned a degree above its limit",
                  std::to_string(p.degree()));
  } catch (const EquationError& e) {
    fuzz::require(e.position <= text.size(), "EquationError position past the end of the text",
                  std::to_string(e.position) + " > " + std::to_string(text.size()));
  }
  return 0;
}
