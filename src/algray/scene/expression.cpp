// Recursive-descent parser that expands an equation into an exact Polynomial.
#include "algray/scene/expression.h"

#include <algorithm>
#include <cfloat>
#include <climits>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <vector>

namespace algray {

EquationError::EquationError(std::size_t pos, const std::string& message)
    : std::runtime_error(message), position(pos) {}

namespace {

// Functions of constants besides sqrt, which has its own exact case.
constexpr const char* kConstantFunctions[] = {"sin", "cos", "tan", "asin", "acos",  "atan",
                                              "exp", "log", "abs", "sign", "floor", "ceil"};

bool is_constant_function(std::string_view name) {
  for (const char* f : kConstantFunctions)
    if (name == f) return true;
  return false;
}

constexpr unsigned max_exponent = 1000;
// Keeps hostile input such as 100000 nested parentheses from overflowing the stack.
constexpr int max_nesting = 500;

enum class Tok { Number, Ident, Plus, Minus, Star, Slash, Caret, LParen, RParen, End };

struct Token {
  Tok kind;
  std::size_t pos;
  std::string_view text;
};

bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_ident_start(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool is_ident_char(char c) { return is_ident_start(c) || is_digit(c); }
bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

std::string describe_char(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u >= 0x21 && u < 0x7f) return std::string("'") + c + "'";
  static const char hex[] = "0123456789abcdef";
  return std::string("byte 0x") + hex[u >> 4] + hex[u & 15];
}

std::vector<Token> tokenize(std::string_view s) {
  std::vector<Token> out;
  std::size_t i = 0;
  while (i < s.size()) {
    const char c = s[i];
    if (is_space(c)) {
      ++i;
      continue;
    }
    const std::size_t start = i;
    if (is_digit(c) || (c == '.' && i + 1 < s.size() && is_digit(s[i + 1]))) {
      while (i < s.size() && is_digit(s[i])) ++i;
      if (i < s.size() && s[i] == '.') {
        ++i;
        while (i < s.size() && is_digit(s[i])) ++i;
      }
      if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
        std::size_t j = i + 1;
        if (j < s.size() && (s[j] == '+' || s[j] == '-')) ++j;
        if (j >= s.size() || !is_digit(s[j]))
          throw EquationError(i, "malformed number: '" + std::string(s.substr(i, 1)) +
                                     "' must be followed by the digits of an exponent");
        i = j;
        while (i < s.size() && is_digit(s[i])) ++i;
      }
      out.push_back({Tok::Number, start, s.substr(start, i - start)});
      continue;
    }
    if (is_ident_start(c)) {
      while (i < s.size() && is_ident_char(s[i])) ++i;
      out.push_back({Tok::Ident, start, s.substr(start, i - start)});
      continue;
    }
    Tok kind;
    std::size_t len = 1;
    switch (c) {
      case '+':
        kind = Tok::Plus;
        break;
      case '-':
        kind = Tok::Minus;
        break;
      case '*':
        if (i + 1 < s.size() && s[i + 1] == '*') {
          kind = Tok::Caret;
          len = 2;
        } else {
          kind = Tok::Star;
        }
        break;
      case '/':
        kind = Tok::Slash;
        break;
      case '^':
        kind = Tok::Caret;
        break;
      case '(':
        kind = Tok::LParen;
        break;
      case ')':
        kind = Tok::RParen;
        break;
      default:
        throw EquationError(i, "unexpected character " + describe_char(c));
    }
    out.push_back({kind, start, s.substr(start, len)});
    i += len;
  }
  out.push_back({Tok::End, s.size(), {}});
  return out;
}

// Literals are read as the exact decimal the user wrote, so that e.g. "x^2-0.81" and "0.81-x^2"
// cancel exactly; a double detour would not guarantee that across different spellings.
mpq_class parse_number(const Token& tok) {
  const std::string_view s = tok.text;
  std::string digits;
  std::size_t i = 0;
  long long frac_digits = 0;
  while (i < s.size() && is_digit(s[i])) digits += s[i++];
  if (i < s.size() && s[i] == '.') {
    ++i;
    while (i < s.size() && is_digit(s[i])) {
      digits += s[i++];
      ++frac_digits;
    }
  }
  long long exp10 = 0;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    bool negative = false;
    if (s[i] == '+' || s[i] == '-') negative = s[i++] == '-';
    for (; i < s.size(); ++i) exp10 = std::min(exp10 * 10 + (s[i] - '0'), 1'000'000'000LL);  // saturate: huge is huge
    if (negative) exp10 = -exp10;
  }

  const std::size_t first_nonzero = digits.find_first_not_of('0');
  if (first_nonzero == std::string::npos) return mpq_class(0);
  digits.erase(0, first_nonzero);

  const std::string out_of_range = "number literal " + std::string(s) + " is outside the range of double";
  // The value lies in [10^(order-1), 10^order); reject hopeless magnitudes before computing powers of 10.
  const long long order = static_cast<long long>(digits.size()) + exp10 - frac_digits;
  if (order > DBL_MAX_10_EXP + 1 || order < DBL_MIN_10_EXP - 20) throw EquationError(tok.pos, out_of_range);

  mpz_class mantissa(digits, 10);
  const long long shift = exp10 - frac_digits;
  mpz_class ten_pow;
  mpz_ui_pow_ui(ten_pow.get_mpz_t(), 10, static_cast<unsigned long>(shift >= 0 ? shift : -shift));
  mpq_class value;
  if (shift >= 0) {
    value = mpq_class(mantissa * ten_pow);
  } else {
    value = mpq_class(mantissa, ten_pow);
    value.canonicalize();
  }
  if (value > exact_rational(DBL_MAX) || nearest_double(value) == 0.0) throw EquationError(tok.pos, out_of_range);
  return value;
}

mpq_class exact_rational_long(long double v) {
  if (v < 0) return -exact_rational_long(-v);  // the significand below is taken unsigned
  int e = 0;
  const long double m = std::frexp(v, &e);  // v = m * 2^e, 0.5 <= m < 1
  constexpr int digits = std::numeric_limits<long double>::digits;
  static_assert(sizeof(unsigned long) * CHAR_BIT >= digits, "the significand must fit an unsigned long");
  const auto significand = static_cast<unsigned long>(std::ldexp(m, digits));
  mpq_class r{mpz_class(significand)};
  const int shift = e - digits;
  if (shift >= 0)
    mpq_mul_2exp(r.get_mpq_t(), r.get_mpq_t(), static_cast<mp_bitcnt_t>(shift));
  else
    mpq_div_2exp(r.get_mpq_t(), r.get_mpq_t(), static_cast<mp_bitcnt_t>(-shift));
  return r;
}

// The largest coefficient's size in bits, numerator and denominator together: what an expansion's cost grows with.
std::size_t coefficient_bits(const Polynomial& p) {
  std::size_t bits = 0;
  for (const auto& [exponents, c] : p.terms())
    bits = std::max(bits, mpz_sizeinbase(c.get_num_mpz_t(), 2) + mpz_sizeinbase(c.get_den_mpz_t(), 2));
  return bits;
}

class Parser {
 public:
  Parser(std::string_view text, const std::map<std::string, double>& parameters, int max_degree)
      : params_(parameters), tokens_(tokenize(text)), max_degree_(max_degree) {}

  Polynomial parse() {
    if (peek().kind == Tok::End) throw EquationError(0, "empty equation");
    Polynomial p = expr();
    const Token& t = peek();
    if (t.kind == Tok::RParen) throw EquationError(t.pos, "unmatched ')'");
    if (t.kind != Tok::End) throw missing_operator_or(t, "unexpected " + quote(t) + " after the end of the expression");
    return p;
  }

 private:
  const std::map<std::string, double>& params_;
  std::vector<Token> tokens_;
  int max_degree_;
  double spent_work_ = 0;  // the expansion work admitted so far, against kMaxExpansionWork
  std::size_t next_ = 0;
  int depth_ = 0;

  // Checked before a product or power is expanded: its degree, the size its coefficients would reach (a
  // product's coefficients are sums of products, hence the log2 of the number of terms), and the work of the
  // expansion, terms x terms x (kTermOverhead + bits), which bounds its time: measured in a Release build on
  // this project's 2-core machines, 1.2 to 2.4 ns per unit ((x+y+z+1)^32: 1.9e8 units, 0.46 s; with a 9-digit
  // constant: 1.9e9, 2.3 s).
  void check_growth(std::size_t pos, const char* what, long long degree, double bits, double work) {
    if (degree > max_degree_)
      throw EquationError(pos, std::string("this ") + what + " would have degree " + std::to_string(degree) +
                                   "; algray renders degrees up to " + std::to_string(max_degree_));
    if (bits > static_cast<double>(kMaxCoefficientBits))
      throw EquationError(pos, std::string("the coefficients of this ") + what + " would have about " +
                                   std::to_string(static_cast<long long>(bits * 0.30103)) + " digits; at most " +
                                   std::to_string(static_cast<long long>(kMaxCoefficientBits * 0.30103)) +
                                   " are allowed");
    // The budget is the whole equation's: 40 admissible powers in a sum must not cost 40 times one.
    spent_work_ += work;
    if (work > kMaxExpansionWork || spent_work_ > kMaxExpansionWork) {
      char text[256];
      std::snprintf(text, sizeof text, "expanding this %s would take too long (about %.1e coefficient bit operations "
                                       "for the equation so far, at most %.0e); simplify it or use fewer digits",
                    what, spent_work_, kMaxExpansionWork);
      throw EquationError(pos, text);
    }
  }
  static constexpr double kMaxExpansionWork = 4e9;
  static constexpr double kTermOverhead = 64;  // a product of small coefficients still costs a map insertion
  static double terms(const Polynomial& p) { return static_cast<double>(p.terms().size()); }
  // At most how many terms p^k has: no more than the monomials of its degree in x, y, z, nor than the multisets of
  // k of p's terms.
  static double power_terms_bound(const Polynomial& p, unsigned k) {
    const double d = std::max(p.degree(), 0) * static_cast<double>(k);
    const double dense = (d + 1) * (d + 2) * (d + 3) / 6;
    double multisets = 1;  // C(n + k - 1, k), stopped once it passes the dense bound
    for (unsigned i = 1; i <= k && multisets < dense; ++i) multisets = multisets * (terms(p) + i - 1) / i;
    return std::min(dense, multisets);
  }
  static double log2_terms(const Polynomial& p) { return std::log2(static_cast<double>(p.terms().size()) + 1); }

  struct DepthGuard {
    int& depth;
    DepthGuard(int& d, std::size_t pos) : depth(d) {
      if (++depth > max_nesting) throw EquationError(pos, "expression is nested too deeply");
    }
    ~DepthGuard() { --depth; }
    DepthGuard(const DepthGuard&) = delete;
    DepthGuard& operator=(const DepthGuard&) = delete;
  };

  const Token& peek() const { return tokens_[next_]; }
  const Token& take() { return tokens_[next_++]; }
  bool accept(Tok k) {
    if (peek().kind != k) return false;
    ++next_;
    return true;
  }

  static std::string quote(const Token& t) {
    return t.kind == Tok::End ? std::string("end of equation") : "'" + std::string(t.text) + "'";
  }

  // Two operands in a row almost always mean a forgotten '*', so say that rather than something vague.
  static EquationError missing_operator_or(const Token& t, const std::string& otherwise) {
    if (t.kind == Tok::Number || t.kind == Tok::Ident || t.kind == Tok::LParen)
      return EquationError(t.pos, "missing operator before " + quote(t) + " (use '*' to multiply)");
    return EquationError(t.pos, otherwise);
  }

  void expect_close(const char* what) {
    const Token& t = peek();
    if (t.kind == Tok::RParen) {
      ++next_;
      return;
    }
    if (t.kind == Tok::End) throw EquationError(t.pos, std::string("missing ')' ") + what);
    throw missing_operator_or(t, "expected ')' " + std::string(what) + " but found " + quote(t));
  }

  Polynomial expr() {
    Polynomial lhs = term();
    for (;;) {
      if (accept(Tok::Plus))
        lhs = lhs + term();
      else if (accept(Tok::Minus))
        lhs = lhs - term();
      else
        return lhs;
    }
  }

  Polynomial term() {
    Polynomial lhs = unary();
    for (;;) {
      if (peek().kind == Tok::Star) {
        const std::size_t pos = take().pos;
        const Polynomial rhs = unary();
        const double bits = static_cast<double>(coefficient_bits(lhs) + coefficient_bits(rhs));
        check_growth(pos, "product", static_cast<long long>(lhs.degree()) + rhs.degree(),
                     bits + std::min(log2_terms(lhs), log2_terms(rhs)),
                     terms(lhs) * terms(rhs) * (kTermOverhead + bits));
        lhs = lhs * rhs;
      } else if (accept(Tok::Slash)) {
        const std::size_t pos = peek().pos;
        const std::optional<mpq_class> divisor = unary().constant_value();
        if (!divisor) throw EquationError(pos, "division by a variable: only constants may divide");
        if (sgn(*divisor) == 0) throw EquationError(pos, "division by zero");
        lhs = lhs * Polynomial::constant(1 / *divisor);
      } else {
        return lhs;
      }
    }
  }

  // Every nesting construct (parentheses, sqrt, unary signs, exponents) passes through here.
  Polynomial unary() {
    const DepthGuard guard(depth_, peek().pos);
    if (accept(Tok::Plus)) return unary();
    if (accept(Tok::Minus)) return -unary();
    return power();
  }

  Polynomial power() {
    Polynomial base = primary();
    if (!accept(Tok::Caret)) return base;
    const std::size_t pos = peek().pos;
    const unsigned e = exponent(unary(), pos);
    // Repeated squaring: the last product, of two halves, dominates the work.
    const double bits = static_cast<double>(e) * (static_cast<double>(coefficient_bits(base)) + log2_terms(base));
    const double half = power_terms_bound(base, e / 2);
    check_growth(pos, "power", static_cast<long long>(base.degree()) * e, bits,
                 e < 2 ? 0 : half * half * (kTermOverhead + bits));
    return base.pow(e);
  }

  static unsigned exponent(const Polynomial& p, std::size_t pos) {
    const std::optional<mpq_class> v = p.constant_value();
    if (!v) throw EquationError(pos, "exponent is not constant: it may not contain x, y or z");
    if (sgn(*v) < 0) throw EquationError(pos, "negative exponent: only non-negative integer powers are allowed");
    if (v->get_den() != 1)
      throw EquationError(pos, "fractional exponent: only non-negative integer powers are allowed");
    if (v->get_num() > max_exponent) {
      const std::string shown =
          mpz_sizeinbase(v->get_num().get_mpz_t(), 10) <= 20 ? " " + v->get_num().get_str() : std::string();
      throw EquationError(pos, "exponent" + shown + " is too large (at most " + std::to_string(max_exponent) + ")");
    }
    return static_cast<unsigned>(v->get_num().get_ui());
  }

  Polynomial primary() {
    const Token& t = take();
    switch (t.kind) {
      case Tok::Number:
        return Polynomial::constant(parse_number(t));
      case Tok::Ident:
        return identifier(t);
      case Tok::LParen: {
        Polynomial inner = expr();
        expect_close("to close the '('");
        return inner;
      }
      case Tok::End:
        throw EquationError(t.pos, "unexpected end of equation: expected a number, a variable or '('");
      case Tok::RParen:
        throw EquationError(t.pos, "unexpected ')': expected a number, a variable or '('");
      default:
        throw EquationError(t.pos, "unexpected " + quote(t) + ": expected a number, a variable or '('");
    }
  }

  Polynomial identifier(const Token& t) {
    if (t.text == "x") return Polynomial::variable(0);
    if (t.text == "y") return Polynomial::variable(1);
    if (t.text == "z") return Polynomial::variable(2);
    if (t.text == "sqrt") return square_root();
    if (is_constant_function(t.text)) return constant_function(std::string(t.text));
    const auto it = params_.find(std::string(t.text));
    if (it == params_.end())
      throw EquationError(t.pos, "unknown identifier '" + std::string(t.text) +
                                     "': parameters must be declared in the scene before use");
    if (!std::isfinite(it->second))
      throw EquationError(t.pos, "parameter '" + it->first + "' is not finite (nan or inf)");
    return Polynomial::constant(exact_rational(it->second));
  }

  // Functions of constants only, as jsurf allows them: evaluated in long double, then taken exactly.
  Polynomial constant_function(const std::string& name) {
    if (!accept(Tok::LParen)) throw EquationError(peek().pos, "expected '(' after " + name);
    const std::size_t pos = peek().pos;
    const std::optional<mpq_class> v = expr().constant_value();
    expect_close(("to close " + name + "(").c_str());
    if (!v) throw EquationError(pos, name + " of a non-constant expression: its argument may not contain x, y or z");
    if (name == "abs") return Polynomial::constant(abs(*v));
    if (name == "sign") return Polynomial::constant(mpq_class(sgn(*v)));
    if (name == "floor") return Polynomial::constant(mpq_class(floor_of(*v)));
    if (name == "ceil") return Polynomial::constant(mpq_class(-floor_of(-*v)));
    const long double a = nearest_long_double(*v);
    long double r = 0;
    if (name == "sin")
      r = std::sin(a);
    else if (name == "cos")
      r = std::cos(a);
    else if (name == "tan")
      r = std::tan(a);
    else if (name == "asin")
      r = std::asin(a);
    else if (name == "acos")
      r = std::acos(a);
    else if (name == "atan")
      r = std::atan(a);
    else if (name == "exp")
      r = std::exp(a);
    else if (name == "log")
      r = std::log(a);
    if (!std::isfinite(r)) throw EquationError(pos, name + " is not finite (or not defined) at this argument");
    return Polynomial::constant(exact_rational_long(r));
  }

  static mpz_class floor_of(const mpq_class& q) {
    mpz_class f;
    mpz_fdiv_q(f.get_mpz_t(), q.get_num_mpz_t(), q.get_den_mpz_t());
    return f;
  }

  Polynomial square_root() {
    if (!accept(Tok::LParen)) throw EquationError(peek().pos, "expected '(' after sqrt");
    const std::size_t pos = peek().pos;
    const std::optional<mpq_class> v = expr().constant_value();
    expect_close("to close sqrt(");
    if (!v) throw EquationError(pos, "sqrt of a non-constant expression: its argument may not contain x, y or z");
    if (sgn(*v) < 0) throw EquationError(pos, "sqrt of a negative number");
    const mpz_class& num = v->get_num();
    const mpz_class& den = v->get_den();
    if (mpz_perfect_square_p(num.get_mpz_t()) && mpz_perfect_square_p(den.get_mpz_t())) {
      mpq_class root{mpz_class(sqrt(num)), mpz_class(sqrt(den))};
      root.canonicalize();
      return Polynomial::constant(root);
    }
    const long double r = std::sqrt(nearest_long_double(*v));
    if (!std::isfinite(r)) throw EquationError(pos, "sqrt argument is too large");
    return Polynomial::constant(exact_rational_long(r));
  }
};

}  // namespace

bool is_reserved_name(std::string_view name) {
  return name == "x" || name == "y" || name == "z" || name == "sqrt" || is_constant_function(name);
}

Polynomial parse_equation(std::string_view text, const std::map<std::string, double>& parameters, int max_degree) {
  for (const auto& [name, value] : parameters)
    if (is_reserved_name(name))
      throw EquationError(0, "a parameter may not be named '" + name + "': the name is reserved");
  return Parser(text, parameters, max_degree).parse();
}

}  // namespace algray
