// Double-coefficient polynomial arithmetic for the surf and POV-Ray readers.
#include "algray/scene/sparse_poly.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace algray {

int SparsePoly::degree() const {
  int d = -1;
  for (const auto& [e, c] : terms) d = std::max(d, e[0] + e[1] + e[2]);
  return d;
}

void SparsePoly::add(const Exponents& e, double c) {
  const double sum = (terms[e] += c);
  if (sum == 0) terms.erase(e);
}

SparsePoly SparsePoly::constant(double c) {
  SparsePoly p;
  if (c != 0) p.terms[{0, 0, 0}] = c;
  return p;
}

SparsePoly SparsePoly::variable(int axis) {
  SparsePoly p;
  Exponents e{0, 0, 0};
  e[static_cast<std::size_t>(axis)] = 1;
  p.terms[e] = 1;
  return p;
}

namespace {

[[noreturn]] void throw_over_budget(const PolyBudget& budget) {
  throw PolyTooLarge("the polynomial arithmetic is too large to expand here (more than " +
                     std::to_string(static_cast<long long>(budget.limit)) + " coefficient products)");
}

}  // namespace

SparsePoly multiply(const SparsePoly& a, const SparsePoly& b, PolyBudget& budget) {
  if (a.terms.empty() || b.terms.empty()) return {};
  if (a.degree() + b.degree() > budget.max_degree)
    throw PolyTooLarge("this product has degree " + std::to_string(a.degree() + b.degree()) +
                       "; algray draws degrees up to " + std::to_string(budget.max_degree));
  budget.work += static_cast<double>(a.terms.size()) * static_cast<double>(b.terms.size());
  if (budget.work > budget.limit) throw_over_budget(budget);
  // Products are summed in a dense table of the result's degree, far cheaper per product than map inserts.
  const int d = a.degree() + b.degree(), side = d + 1;
  thread_local std::vector<double> table;
  table.assign(static_cast<std::size_t>(side * side * side), 0.0);
  auto at = [side](int i, int j, int k) { return static_cast<std::size_t>((i * side + j) * side + k); };
  std::vector<std::pair<SparsePoly::Exponents, double>> bs(b.terms.begin(), b.terms.end());
  for (const auto& [ea, ca] : a.terms)
    for (const auto& [eb, cb] : bs) table[at(ea[0] + eb[0], ea[1] + eb[1], ea[2] + eb[2])] += ca * cb;
  SparsePoly out;
  for (int i = 0; i <= d; ++i)
    for (int j = 0; i + j <= d; ++j)
      for (int k = 0; i + j + k <= d; ++k)
        if (const double c = table[at(i, j, k)]; c != 0)
          out.terms.emplace_hint(out.terms.end(), SparsePoly::Exponents{i, j, k}, c);
  return out;
}

SparsePoly power(const SparsePoly& p, long e, PolyBudget& budget) {
  if (p.terms.empty()) return e == 0 ? SparsePoly::constant(1) : SparsePoly{};
  if (p.degree() == 0) {  // a constant: one pow, not e products
    const double c = std::pow(p.terms.begin()->second, static_cast<double>(e));
    if (!std::isfinite(c)) throw PolyTooLarge("this power of a constant overflows");
    return SparsePoly::constant(c);
  }
  if (static_cast<long>(p.degree()) * e > budget.max_degree)
    throw PolyTooLarge("this power has degree " + std::to_string(static_cast<long>(p.degree()) * e) +
                       "; algray draws degrees up to " + std::to_string(budget.max_degree));
  SparsePoly out = SparsePoly::constant(1);
  for (long k = 0; k < e; ++k) out = multiply(out, p, budget);
  return out;
}

namespace {

long long binomial(int n, int k) {
  long long b = 1;
  for (int i = 1; i <= k; ++i) b = b * (n - k + i) / i;
  return b;
}

// Which of x, y, z and the constant an affine form uses.
struct FormSupport {
  std::array<bool, 3> variables{};
  bool constant = false;
  int entries() const { return variables[0] + variables[1] + variables[2] + constant; }
};

// Terms of the power e of a form with k entries: one per way to share e among them, all nonzero.
double power_terms(const FormSupport& f, int e) { return static_cast<double>(binomial(e + f.entries() - 1, f.entries() - 1)); }

// At most how many terms the product of powers a and b of two forms has: the monomials in their variables whose
// degree the products can reach (exact for forms in general position, an upper bound otherwise).
double product_terms(const FormSupport& f, int a, const FormSupport& g, int b) {
  const int variables = (f.variables[0] || g.variables[0]) + (f.variables[1] || g.variables[1]) +
                        (f.variables[2] || g.variables[2]);
  const int high = a + b, low = (f.constant ? 0 : a) + (g.constant ? 0 : b);
  // Monomials of degree low..high in `variables` variables: those of degree <= high less those of degree < low.
  const long long count = binomial(high + variables, variables) - (low > 0 ? binomial(low - 1 + variables, variables) : 0);
  return std::min(static_cast<double>(count), power_terms(f, a) * power_terms(g, b));
}

// The coefficient products `substitute` will count, found from the term counts alone, so that a substitution past
// the budget is refused before any of its work is done rather than when the work reaches the limit.
double substitution_products(const SparsePoly& p, const std::array<FormSupport, 3>& forms) {
  double products = 0;
  std::array<int, 3> highest{};
  std::map<std::pair<int, int>, double> xy_terms;
  for (const auto& [e, c] : p.terms) {
    for (std::size_t axis = 0; axis < 3; ++axis) highest[axis] = std::max(highest[axis], e[axis]);
    auto [it, inserted] = xy_terms.emplace(std::make_pair(e[0], e[1]), 0.0);
    if (inserted) {
      products += power_terms(forms[0], e[0]) * power_terms(forms[1], e[1]);
      it->second = product_terms(forms[0], e[0], forms[1], e[1]);
    }
    products += it->second * power_terms(forms[2], e[2]);
  }
  for (std::size_t axis = 0; axis < 3; ++axis)
    for (int e = 1; e <= highest[axis]; ++e) products += power_terms(forms[axis], e - 1) * forms[axis].entries();
  return products;
}

}  // namespace

SparsePoly substitute(const SparsePoly& p, const std::array<std::array<double, 4>, 3>& m, PolyBudget& budget) {
  std::array<FormSupport, 3> supports;
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t c = 0; c < 3; ++c) supports[r].variables[c] = m[r][c] != 0;
    supports[r].constant = m[r][3] != 0;
  }
  if (budget.work + substitution_products(p, supports) > budget.limit) throw_over_budget(budget);
  std::array<SparsePoly, 3> forms;
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t c = 0; c < 3; ++c)
      if (m[r][c] != 0) {
        SparsePoly::Exponents e{0, 0, 0};
        e[c] = 1;
        forms[r].add(e, m[r][c]);
      }
    if (m[r][3] != 0) forms[r].add({0, 0, 0}, m[r][3]);
  }
  // Powers of each form, and products of x's and y's, made once and reused by every term.
  std::array<std::vector<SparsePoly>, 3> powers;
  auto pow_of = [&](std::size_t axis, int e) -> const SparsePoly& {
    auto& list = powers[axis];
    if (list.empty()) list.push_back(SparsePoly::constant(1));
    while (static_cast<int>(list.size()) <= e) list.push_back(multiply(list.back(), forms[axis], budget));
    return list[static_cast<std::size_t>(e)];
  };
  std::map<std::pair<int, int>, SparsePoly> xy;
  SparsePoly out;
  for (const auto& [e, c] : p.terms) {
    auto it = xy.find({e[0], e[1]});
    if (it == xy.end())
      it = xy.emplace(std::make_pair(e[0], e[1]), multiply(pow_of(0, e[0]), pow_of(1, e[1]), budget)).first;
    const SparsePoly term = multiply(it->second, pow_of(2, e[2]), budget);
    for (const auto& [f, d] : term.terms) out.add(f, c * d);
  }
  return out;
}

}  // namespace algray
