// The equation parser: text such as "x^4+y^4+z^4-(x^2+y^2+z^2)" to an exact Polynomial.
#pragma once

#include <cstddef>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>

#include "algray/math/polynomial.h"

namespace algray {

// what() is the bare message; the caller turns `position` into "file:line:col".
struct EquationError : std::runtime_error {
  EquationError(std::size_t position, const std::string& message);
  std::size_t position;  // 0-based offset (in bytes) into the equation text
};

// Parses and expands an equation to an exact Polynomial. `parameters` are named constants from the
// scene file; x, y, z are the variables. Functions apply to constants only (as in jsurf): sqrt (exact
// for squares of rationals), sin, cos, tan, asin, acos, atan, exp, log (natural), abs, sign, floor, ceil;
// parameters may not use those names. Number literals are read exactly as decimal rationals.
//
// Grammar (whitespace anywhere):
//   expr    := term (('+' | '-') term)*
//   term    := unary (('*' | '/') unary)*            divisors must be nonzero constants
//   unary   := ('+' | '-') unary | power
//   power   := primary (('^' | '**') unary)?          right-associative; the exponent must be a
//                                                     constant non-negative integer <= 1000
//   primary := number | x | y | z | parameter | function '(' expr ')' | '(' expr ')'
// Zero polynomials are left to the caller. The degree is bounded while parsing: a power or product whose degree
// would exceed `max_degree` is an error at its exponent or operator before anything is expanded, and so is one
// whose coefficients would grow past kMaxCoefficientBits, so that no input makes the expansion run for minutes.
inline constexpr int kDefaultMaxEquationDegree = 32;  // the kernels' limit; scene.cpp passes kMaxDegree itself
inline constexpr std::size_t kMaxCoefficientBits = std::size_t{1} << 16;
Polynomial parse_equation(std::string_view text, const std::map<std::string, double>& parameters,
                          int max_degree = kDefaultMaxEquationDegree);

// x, y, z and the function names: no parameter may be called so.
bool is_reserved_name(std::string_view name);

}  // namespace algray
