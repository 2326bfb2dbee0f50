// The real roots of a polynomial along a ray, found on the host: for readers that must choose an extent from
// what a camera sees of surfaces that come without one (a POV-Ray poly with no clipped_by, say).
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "algray/scene/sparse_poly.h"

namespace algray {

// The coefficients of P(o + t d) in t, lowest first.
std::vector<double> restrict_to_ray(const SparsePoly& p, const glm::dvec3& o, const glm::dvec3& d);

// The roots of P(o + t d) for t in [t_min, t_max] (0 < t_min < t_max), in increasing order: sign changes on a
// geometric grid of `steps` points, each narrowed by bisection. A root where P touches zero without changing
// sign, or two roots within one step (about 14 / steps of t in relative terms for the default range), may be
// missed: this chooses extents, it certifies nothing.
std::vector<double> ray_roots(const SparsePoly& p, const glm::dvec3& o, const glm::dvec3& d, double t_min, double t_max,
                              int steps = 3000);

}  // namespace algray
