// Tests of the reference solver against polynomials whose roots and multiplicities are known exactly.
#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "algray/math/polynomial.h"
#include "solver_ref/solver_ref.h"

using algray::Polynomial;
using algray::ref::Answer;
using algray::ref::Classification;
using algray::ref::ExactRay;
using algray::ref::has_root_in_open;
using algray::ref::restrict_exact;
using algray::ref::smallest_root;
using Poly = std::vector<mpq_class>;

namespace {

mpq_class q(long num, long den = 1) {
  mpq_class r(num, den);
  r.canonicalize();
  return r;
}

mpq_class qs(const char* s) {
  mpq_class r(s);
  r.canonicalize();
  return r;
}

Poly times(const Poly& a, const Poly& b) {
  Poly r(a.size() + b.size() - 1);
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) r[i + j] += a[i] * b[j];
  return r;
}

// prod (t - root)^multiplicity
Poly from_roots(const std::vector<std::pair<mpq_class, int>>& roots) {
  Poly p{1};
  for (const auto& [root, m] : roots)
    for (int k = 0; k < m; ++k) p = times(p, Poly{-root, 1});
  return p;
}

const mpq_class fine = qs("1/1000000000000");  // 1e-12 as a width

bool encloses(const Answer& a, const mpq_class& x) { return a.lo <= x && x <= a.hi; }

Polynomial xyz_poly(const std::vector<std::tuple<int, int, int, mpq_class>>& terms) {
  Polynomial p;
  for (const auto& [i, j, k, c] : terms) p.add_term(i, j, k, c);
  return p;
}

// A random polynomial of degree 1 to 16 with its real roots known (the rest in complex pairs, some barely off the
// axis): simple and multiple, inside [t_in, t_out], at its ends and just outside them.
struct KnownRoots {
  mpq_class t_in, t_out;
  Poly p;
  std::map<mpq_class, int> roots;  // root -> multiplicity
};

KnownRoots random_known_roots(std::mt19937& rng) {
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  KnownRoots c;
  c.t_in = q(uniform(-50, 40), uniform(1, 9));
  c.t_out = c.t_in + q(uniform(1, 60), uniform(1, 9));
  const int degree = uniform(1, 16);
  int used = 0;
  c.p = Poly{uniform(1, 5) * (uniform(0, 1) ? 1 : -1)};
  while (used < degree) {
    const int kind = uniform(0, 9);
    if (kind == 0 && used + 2 <= degree) {
      // A complex pair (t - m)^2 + e, e > 0, sometimes barely off the axis.
      const mpq_class m = q(uniform(-400, 400), uniform(1, 40));
      const mpq_class e = uniform(0, 1) ? q(1, uniform(1, 9)) : q(1, 1000000000) * q(1, 1000000000);
      c.p = times(c.p, Poly{m * m + e, -2 * m, 1});
      used += 2;
      continue;
    }
    mpq_class root;
    if (kind <= 2) {
      // Just outside, or exactly at, an end point.
      const mpq_class eps = q(1, uniform(1, 1000000));
      switch (uniform(0, 3)) {
        case 0:
          root = c.t_in - eps;
          break;
        case 1:
          root = c.t_out + eps;
          break;
        case 2:
          root = c.t_in;
          break;
        default:
          root = c.t_out;
          break;
      }
    } else {
      root = c.t_in + (c.t_out - c.t_in) * q(uniform(-200, 1200), 1000);
    }
    const int m = std::min(degree - used, uniform(0, 3) == 0 ? uniform(2, 4) : 1);
    c.roots[root] += m;
    used += m;
    for (int k = 0; k < m; ++k) c.p = times(c.p, Poly{-root, 1});
  }
  return c;
}

Classification classification_of(int multiplicity) {
  return multiplicity == 1       ? Classification::SimpleRoot
         : multiplicity % 2 == 0 ? Classification::EvenRootNoSignChange
                                 : Classification::MultipleRootOddSignChange;
}

}  // namespace

TEST_CASE("simple rational roots, the interval deciding which is smallest", "[solver_ref]") {
  const Poly p = from_roots({{q(1, 3), 1}, {q(2), 1}, {q(5), 1}});

  const Answer a = smallest_root(p, q(0), q(10), fine);
  CHECK(a.kind == Classification::SimpleRoot);
  CHECK(a.multiplicity == 1);
  CHECK(encloses(a, q(1, 3)));
  CHECK(a.hi - a.lo <= fine);
  CHECK(a.lo < a.hi);  // 1/3 is no dyadic point of [0, 10], so it can only be enclosed
  CHECK(a.t_nearest == Approx(1.0 / 3).epsilon(1e-12));
  CHECK_FALSE(a.root_at_t_in);
  CHECK_FALSE(a.root_at_t_out);

  const Answer b = smallest_root(p, q(1), q(10), fine);
  CHECK(b.kind == Classification::SimpleRoot);
  CHECK(encloses(b, q(2)));

  const Answer c = smallest_root(p, q(2), q(10), fine);
  CHECK(c.kind == Classification::SimpleRoot);
  CHECK(c.root_at_t_in);
  CHECK(c.lo == q(2));
  CHECK(c.hi == q(2));
  CHECK(c.t_nearest == 2.0);

  const Answer d = smallest_root(p, q(3), q(5), fine);
  CHECK(d.kind == Classification::SimpleRoot);
  CHECK(d.root_at_t_out);
  CHECK(d.lo == q(5));

  const Answer e = smallest_root(p, q(6), q(10), fine);
  CHECK(e.kind == Classification::Miss);
  CHECK(e.multiplicity == 0);
  CHECK(std::isinf(e.t_nearest));

  // 2 is the first bisection midpoint of [1, 3]: it is found exactly, though no end point.
  const Answer g = smallest_root(p, q(1), q(3), fine);
  CHECK(g.lo == q(2));
  CHECK(g.hi == q(2));
  CHECK_FALSE(g.root_at_t_in);
  CHECK_FALSE(g.root_at_t_out);

  // A degenerate interval is a single point.
  CHECK(smallest_root(p, q(5), q(5), fine).kind == Classification::SimpleRoot);
  CHECK(smallest_root(p, q(4), q(4), fine).kind == Classification::Miss);
}

TEST_CASE("multiple roots are classified by multiplicity", "[solver_ref]") {
  const Answer dbl = smallest_root(from_roots({{q(1), 2}, {q(3), 1}}), q(0), q(10), fine);
  CHECK(dbl.kind == Classification::EvenRootNoSignChange);
  CHECK(dbl.multiplicity == 2);
  CHECK(encloses(dbl, q(1)));

  const Answer tri = smallest_root(from_roots({{q(7, 5), 3}, {q(3), 1}}), q(0), q(10), fine);
  CHECK(tri.kind == Classification::MultipleRootOddSignChange);
  CHECK(tri.multiplicity == 3);
  CHECK(encloses(tri, q(7, 5)));

  // The simple root comes first; the later quadruple root must not disturb it.
  const Answer before = smallest_root(from_roots({{q(1, 7), 4}, {q(-1, 9), 1}}), q(-1), q(1), fine);
  CHECK(before.kind == Classification::SimpleRoot);
  CHECK(encloses(before, q(-1, 9)));

  const Answer quad = smallest_root(from_roots({{q(1, 7), 4}, {q(-1, 9), 1}}), q(0), q(1), fine);
  CHECK(quad.kind == Classification::EvenRootNoSignChange);
  CHECK(quad.multiplicity == 4);
  CHECK(encloses(quad, q(1, 7)));

  const Answer five_at_end = smallest_root(from_roots({{q(2), 5}}), q(2), q(3), fine);
  CHECK(five_at_end.kind == Classification::MultipleRootOddSignChange);
  CHECK(five_at_end.multiplicity == 5);
  CHECK(five_at_end.root_at_t_in);

  const Answer double_at_out = smallest_root(from_roots({{q(3), 2}, {q(5), 1}}), q(1, 3), q(3), fine);
  CHECK(double_at_out.kind == Classification::EvenRootNoSignChange);
  CHECK(double_at_out.root_at_t_out);
  CHECK(double_at_out.multiplicity == 2);
}

TEST_CASE("complex roots are skipped, even very close to the axis", "[solver_ref]") {
  const Poly pair = times(Poly{1, 0, 1}, from_roots({{q(2), 1}}));
  const Answer a = smallest_root(pair, q(-10), q(10), fine);
  CHECK(a.kind == Classification::SimpleRoot);
  CHECK(encloses(a, q(2)));

  const Poly tiny = times(Poly{qs("1/100000000000000000000"), 0, 1}, from_roots({{q(2), 1}}));  // t^2 + 1e-20
  CHECK(smallest_root(tiny, q(-1), q(3, 2), fine).kind == Classification::Miss);
  const Answer b = smallest_root(tiny, q(-1), q(3), fine);
  CHECK(b.kind == Classification::SimpleRoot);
  CHECK(encloses(b, q(2)));

  // Squared, the near-axis pair must still not pass for a real double root.
  const Poly tiny_squared =
      times(times(Poly{qs("1/100000000000000000000"), 0, 1}, Poly{qs("1/100000000000000000000"), 0, 1}),
            from_roots({{q(2), 1}}));
  CHECK(smallest_root(tiny_squared, q(-1), q(3, 2), fine).kind == Classification::Miss);
}

TEST_CASE("clustered roots are told apart", "[solver_ref]") {
  const mpq_class near_one = 1 + qs("1/1000000000000");
  const Poly p = from_roots({{q(1), 1}, {near_one, 1}, {q(4), 1}});
  const Answer a = smallest_root(p, q(0), q(10), qs("1/100000000000000"));
  CHECK(a.kind == Classification::SimpleRoot);
  CHECK(encloses(a, q(1)));
  CHECK(a.hi < near_one);
  const Answer b = smallest_root(p, q(1001, 1000), q(10), fine);
  CHECK(b.kind == Classification::SimpleRoot);
  CHECK(encloses(b, q(4)));
  CHECK(has_root_in_open(p, q(1), q(2)));
  CHECK_FALSE(has_root_in_open(p, q(1), near_one));
}

TEST_CASE("an irrational root is enclosed to the requested width", "[solver_ref]") {
  const mpq_class width = qs("1/1000000000000000000000000000000");  // 1e-30
  const Answer a = smallest_root(Poly{-2, 0, 1}, q(0), q(2), width);
  CHECK(a.kind == Classification::SimpleRoot);
  CHECK(a.lo * a.lo < 2);
  CHECK(a.hi * a.hi > 2);
  CHECK(a.hi - a.lo <= width);
  CHECK(a.t_nearest == std::sqrt(2.0));
}

TEST_CASE("seeded random polynomials with known roots", "[solver_ref]") {
  const std::uint32_t seed = 20240611;
  std::mt19937 rng(seed);
  INFO("seed " << seed);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };

  for (int index = 0; index < 300; ++index) {
    INFO("case " << index);
    const auto [t_in, t_out, p, roots] = random_known_roots(rng);
    const mpq_class width = q(1, uniform(1, 1000000));
    const Answer a = smallest_root(p, t_in, t_out, width);
    const auto first = roots.lower_bound(t_in);
    if (first == roots.end() || first->first > t_out) {
      CHECK(a.kind == Classification::Miss);
      continue;
    }
    const auto [root, multiplicity] = *first;
    INFO("root " << root << " multiplicity " << multiplicity);
    CHECK(encloses(a, root));
    CHECK(a.hi - a.lo <= width);
    CHECK(a.multiplicity == multiplicity);
    CHECK(a.root_at_t_in == (root == t_in));
    CHECK(a.root_at_t_out == (root == t_out));
    CHECK(a.kind == classification_of(multiplicity));
    // A root strictly inside the interval, seen from the open interval.
    if (root > t_in) CHECK(has_root_in_open(p, t_in, t_out + 1));
  }
}

// The roots a walk should visit: those in [t_in, t_out], in order.
std::vector<std::pair<mpq_class, int>> roots_within(const std::map<mpq_class, int>& roots, const mpq_class& t_in,
                                                    const mpq_class& t_out) {
  std::vector<std::pair<mpq_class, int>> within;
  for (const auto& [root, multiplicity] : roots)
    if (t_in <= root && root <= t_out) within.emplace_back(root, multiplicity);
  return within;
}

// Bisection's enclosure of a root on [t_in, t_out]: the cell of the grid of 2^D equal cells that holds it, D the
// depth whose cells first fit within width (deeper where a root at a cell's right end forced more halvings: `depth`
// at least D), or the root itself where it is a cell's end.
bool is_bisection_cell(const Answer& a, const mpq_class& root, const mpq_class& t_in, const mpq_class& t_out,
                       const mpq_class& width) {
  if (a.lo == a.hi) return a.lo == root;
  const mpq_class length = t_out - t_in;
  mpz_class cells = 1;
  while (length / cells > width) cells *= 2;
  mpz_class deeper = cells;
  while (length / deeper > a.hi - a.lo) deeper *= 2;
  if (length / deeper != a.hi - a.lo) return false;  // not a cell of any depth
  const mpq_class position = (root - t_in) / length * deeper;
  mpz_class k;
  mpz_fdiv_q(k.get_mpz_t(), position.get_num_mpz_t(), position.get_den_mpz_t());
  mpq_class cell_start(k, deeper);
  cell_start.canonicalize();
  return a.lo == t_in + length * cell_start && (deeper == cells || a.hi != t_out);
}

TEST_CASE("for_each_root visits every root in the interval in order, the first as smallest_root gives it",
          "[solver_ref]") {
  const std::uint32_t seed = 20261207;
  std::mt19937 rng(seed);
  INFO("seed " << seed);
  for (int index = 0; index < 300; ++index) {
    INFO("case " << index);
    const auto [t_in, t_out, p, roots] = random_known_roots(rng);
    const mpq_class width = q(1, std::uniform_int_distribution<int>(1, 1000000)(rng));
    std::vector<Answer> visited;
    CHECK(algray::ref::for_each_root(p, t_in, t_out, width, [&](const Answer& a) {
      visited.push_back(a);
      return true;
    }));
    const std::vector<std::pair<mpq_class, int>> expected = roots_within(roots, t_in, t_out);
    REQUIRE(visited.size() == expected.size());
    for (std::size_t i = 0; i < visited.size(); ++i) {
      INFO("root " << i << ": " << expected[i].first << ", multiplicity " << expected[i].second);
      CHECK(encloses(visited[i], expected[i].first));
      CHECK(visited[i].hi - visited[i].lo <= width);
      // refine's guessed start gives bisection's cell
      INFO("enclosure [" << visited[i].lo << ", " << visited[i].hi << "] on [" << t_in << ", " << t_out << "], width "
                         << width);
      CHECK(is_bisection_cell(visited[i], expected[i].first, t_in, t_out, width));
      CHECK(visited[i].multiplicity == expected[i].second);
      CHECK(visited[i].kind == classification_of(expected[i].second));
    }
    if (!visited.empty()) {
      const Answer first = smallest_root(p, t_in, t_out, width);
      CHECK((first.lo == visited[0].lo && first.hi == visited[0].hi && first.t_nearest == visited[0].t_nearest));
      // Asked to stop at the second, it does, and says so.
      std::size_t calls = 0;
      const bool completed =
          algray::ref::for_each_root(p, t_in, t_out, width, [&](const Answer&) { return ++calls < 2; });
      CHECK(completed == (visited.size() < 2));
      CHECK(calls == std::min<std::size_t>(visited.size(), 2));
    }
  }
}

TEST_CASE("for_each_root at the ends and at the dyadic midpoints of its interval", "[solver_ref]") {
  // Roots exactly where the descent splits (1/2, 1/4, 3/4 of [0, 1]) and at both ends; a double one at 1/4.
  const Poly p = from_roots({{q(0), 1}, {q(1, 4), 2}, {q(1, 2), 1}, {q(3, 4), 1}, {q(1), 1}, {q(2), 1}});
  std::vector<Answer> visited;
  algray::ref::for_each_root(p, q(0), q(1), fine, [&](const Answer& a) {
    visited.push_back(a);
    return true;
  });
  REQUIRE(visited.size() == 5);
  const mpq_class at[] = {q(0), q(1, 4), q(1, 2), q(3, 4), q(1)};
  for (std::size_t i = 0; i < 5; ++i) {
    INFO("root " << at[i]);
    CHECK(visited[i].lo == at[i]);
    CHECK(visited[i].hi == at[i]);
    CHECK(visited[i].multiplicity == (i == 1 ? 2 : 1));
  }
  CHECK(visited.front().root_at_t_in);
  CHECK(visited.back().root_at_t_out);
}

TEST_CASE("restriction to a floating-point ray is exact", "[solver_ref]") {
  const Polynomial sphere = xyz_poly({{2, 0, 0, 1}, {0, 2, 0, 1}, {0, 0, 2, 1}, {0, 0, 0, -1}});
  const ExactRay ray{{0.1, -2.7, 1e-3}, {0.3, 1.1, -0.7}};
  mpq_class o[3], d[3];
  for (int a = 0; a < 3; ++a) {
    o[a] = algray::exact_rational(ray.origin[a]);
    d[a] = algray::exact_rational(ray.direction[a]);
  }
  const std::vector<mpq_class> expected{o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - 1,
                                        2 * (o[0] * d[0] + o[1] * d[1] + o[2] * d[2]),
                                        d[0] * d[0] + d[1] * d[1] + d[2] * d[2]};
  CHECK(restrict_exact(sphere, ray) == expected);

  // A mixed, non-dyadic polynomial: 1/3 x y^2 z - 5/7 x + 2, on a ray with a zero and a huge component.
  const Polynomial mixed = xyz_poly({{1, 2, 1, q(1, 3)}, {1, 0, 0, q(-5, 7)}, {0, 0, 0, q(2)}});
  const ExactRay ray2{{0.0, 1e10, -3.5}, {0.25, 0.0, 1e-7}};
  const mpq_class ox = 0, oy = algray::exact_rational(1e10), oz = algray::exact_rational(-3.5);
  const mpq_class dx = algray::exact_rational(0.25), dz = algray::exact_rational(1e-7);
  // x = dx t, y = oy, z = oz + dz t
  const std::vector<mpq_class> expected2{2, q(1, 3) * dx * oy * oy * oz - q(5, 7) * dx, q(1, 3) * dx * oy * oy * dz};
  CHECK(restrict_exact(mixed, ray2) == expected2);

  CHECK(restrict_exact(Polynomial{}, ray).empty());
}

TEST_CASE("the ray overload solves P on the ray", "[solver_ref]") {
  const Polynomial sphere = xyz_poly({{2, 0, 0, 1}, {0, 2, 0, 1}, {0, 0, 2, 1}, {0, 0, 0, -1}});
  const ExactRay through{{-2, 0, 0}, {1, 0, 0}};  // enters at t = 1, leaves at t = 3
  CHECK(encloses(smallest_root(sphere, through, q(0), q(10), fine), q(1)));
  const Answer leaving = smallest_root(sphere, through, q(3, 2), q(10), fine);
  CHECK(encloses(leaving, q(3)));
  CHECK(leaving.kind == Classification::SimpleRoot);

  const ExactRay tangent{{-2, 1, 0}, {1, 0, 0}};  // grazes the sphere at t = 2
  const Answer graze = smallest_root(sphere, tangent, q(0), q(10), fine);
  CHECK(graze.kind == Classification::EvenRootNoSignChange);
  CHECK(encloses(graze, q(2)));

  const ExactRay near_tangent{{-2, 0.99999999999999989, 0}, {1, 0, 0}};  // the double just below 1: two roots
  const Answer near = smallest_root(sphere, near_tangent, q(0), q(10), q(1, 1000000000) * q(1, 1000000000));
  CHECK(near.kind == Classification::SimpleRoot);
  CHECK(near.hi < 2);

  // The kernels' rounded monomials, taken exactly, give back the same polynomial when nothing was rounded.
  CHECK(algray::ref::from_monomials(sphere.monomials()) == sphere);

  // The plane z = 0 contains the ray: every t is a root.
  const Answer plane = smallest_root(xyz_poly({{0, 0, 1, 1}}), ExactRay{{1, 2, 0}, {0.5, -1, 0}}, q(1), q(4), fine);
  CHECK(plane.kind == Classification::IdenticallyZero);
  CHECK(plane.lo == q(1));
  CHECK(plane.root_at_t_in);
}

TEST_CASE("degree 32", "[solver_ref]") {
  // A double root at 1/2 and 30 simple roots -7/3 + (k^2 + 1)/37: the tenth is 44/111, just below 1/2, the
  // eleventh 107/111 just above it.
  std::vector<std::pair<mpq_class, int>> roots{{q(1, 2), 2}};
  for (int k = 0; k < 30; ++k) roots.emplace_back(q(-7, 3) + q(k * k + 1, 37), 1);
  const Poly p = from_roots(roots);
  REQUIRE(p.size() == 33);

  const Answer a = smallest_root(p, q(0), q(40), fine);
  CHECK(a.kind == Classification::SimpleRoot);
  CHECK(encloses(a, q(44, 111)));

  const Answer b = smallest_root(p, q(45, 100), q(40), fine);
  CHECK(b.kind == Classification::EvenRootNoSignChange);
  CHECK(b.multiplicity == 2);
  CHECK(encloses(b, q(1, 2)));

  const Answer c = smallest_root(p, q(-3), q(40), fine);
  CHECK(c.kind == Classification::SimpleRoot);
  CHECK(encloses(c, q(-7, 3) + q(1, 37)));

  const Answer d = smallest_root(p, q(1, 2) + q(1, 1000000), q(40), fine);
  CHECK(d.kind == Classification::SimpleRoot);
  CHECK(encloses(d, q(107, 111)));
}

TEST_CASE("the zero polynomial and has_root_in_open", "[solver_ref]") {
  const Answer z = smallest_root(Poly{0, 0, 0}, q(-1), q(1), fine);
  CHECK(z.kind == Classification::IdenticallyZero);
  CHECK(z.lo == q(-1));
  CHECK(smallest_root(Poly{}, q(0), q(1), fine).kind == Classification::IdenticallyZero);
  CHECK(smallest_root(Poly{q(3, 4)}, q(0), q(1), fine).kind == Classification::Miss);

  const Poly p = from_roots({{q(1), 1}, {q(2), 2}, {q(3), 1}});
  CHECK_FALSE(has_root_in_open(p, q(1), q(2)));  // both ends are roots, the inside is empty of them
  CHECK_FALSE(has_root_in_open(p, q(2), q(3)));
  CHECK(has_root_in_open(p, q(1), q(3)));  // the double root, without a sign change
  CHECK(has_root_in_open(p, q(0), q(3, 2)));
  CHECK_FALSE(has_root_in_open(p, q(7, 2), q(100)));
  CHECK_FALSE(has_root_in_open(p, q(3), q(3)));
  CHECK(has_root_in_open(Poly{-2, 0, 1}, q(1), q(2)));
  CHECK_FALSE(has_root_in_open(Poly{1, 0, 1}, q(-100), q(100)));
  CHECK(has_root_in_open(Poly{}, q(0), q(1)));
}

TEST_CASE("bad arguments are refused", "[solver_ref]") {
  CHECK_THROWS_AS(smallest_root(Poly{-1, 1}, q(2), q(1), fine), std::invalid_argument);
  CHECK_THROWS_AS(smallest_root(Poly{-1, 1}, q(0), q(1), q(0)), std::invalid_argument);
  CHECK_THROWS_AS(restrict_exact(Polynomial::variable(0), ExactRay{{NAN, 0, 0}, {1, 0, 0}}), std::domain_error);
}
