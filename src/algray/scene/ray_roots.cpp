#include "algray/scene/ray_roots.h"

#include <cmath>

namespace algray {

std::vector<double> restrict_to_ray(const SparsePoly& p, const glm::dvec3& o, const glm::dvec3& d) {
  const int n = std::max(p.degree(), 0);
  // powers[a][k]: the coefficients of (o[a] + t d[a])^k.
  std::vector<std::vector<double>> powers[3];
  for (int a = 0; a < 3; ++a) {
    powers[a].push_back({1.0});
    for (int k = 1; k <= n; ++k) {
      const std::vector<double>& last = powers[a].back();
      std::vector<double> next(last.size() + 1, 0.0);
      for (std::size_t i = 0; i < last.size(); ++i) {
        next[i] += last[i] * o[a];
        next[i + 1] += last[i] * d[a];
      }
      powers[a].push_back(std::move(next));
    }
  }
  std::vector<double> out(static_cast<std::size_t>(n) + 1, 0.0), xy;
  for (const auto& [e, c] : p.terms) {
    const std::vector<double>& px = powers[0][static_cast<std::size_t>(e[0])];
    const std::vector<double>& py = powers[1][static_cast<std::size_t>(e[1])];
    const std::vector<double>& pz = powers[2][static_cast<std::size_t>(e[2])];
    xy.assign(px.size() + py.size() - 1, 0.0);
    for (std::size_t i = 0; i < px.size(); ++i)
      for (std::size_t j = 0; j < py.size(); ++j) xy[i + j] += px[i] * py[j];
    for (std::size_t i = 0; i < xy.size(); ++i)
      for (std::size_t k = 0; k < pz.size(); ++k) out[i + k] += c * xy[i] * pz[k];
  }
  return out;
}

std::vector<double> ray_roots(const SparsePoly& p, const glm::dvec3& o, const glm::dvec3& d, double t_min, double t_max,
                              int steps) {
  const std::vector<double> q = restrict_to_ray(p, o, d);
  auto at = [&](double t) {
    double v = 0;
    for (std::size_t i = q.size(); i-- > 0;) v = v * t + q[i];
    return v;
  };
  std::vector<double> roots;
  const double ratio = std::pow(t_max / t_min, 1.0 / std::max(steps - 1, 1));
  double a = t_min, fa = at(a);
  if (fa == 0) roots.push_back(a);
  for (int i = 1; i < steps; ++i) {
    const double b = i == steps - 1 ? t_max : a * ratio, fb = at(b);
    if (fb == 0) {
      roots.push_back(b);
    } else if (fa != 0 && (fa < 0) != (fb < 0)) {
      double lo = a, hi = b, flo = fa;
      for (int k = 0; k < 60 && hi - lo > 1e-12 * hi; ++k) {
        const double mid = 0.5 * (lo + hi), fm = at(mid);
        if (fm == 0)
          lo = hi = mid;
        else if ((fm < 0) == (flo < 0))
          lo = mid, flo = fm;
        else
          hi = mid;
      }
      roots.push_back(0.5 * (lo + hi));
    }
    a = b;
    fa = fb;
  }
  return roots;
}

}  // namespace algray
