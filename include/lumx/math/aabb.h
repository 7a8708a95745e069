// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/aabb.h — an axis-aligned box [lo, hi] (closed on every face) and the slab ray clip.
//
// The default box is empty (lo = +inf, hi = -inf), so expand() from it gives the bounds of the points
// added. A box with lo == hi on an axis is flat but valid: points on that plane are inside it.
//
// clip() is the slab method (Kay & Kajiya 1986; pbrt-v4 Bounds3::IntersectP): for each axis with a
// non-zero direction component the ray is inside the slab for t between (lo - o)/d and (hi - o)/d, and
// the clipped interval is the intersection of the three slab intervals with [t_min, t_max]. An axis with
// d == 0 constrains nothing if the origin lies in that slab and empties the interval otherwise, so the
// 0 * inf = NaN of the reciprocal formulation cannot arise.
#pragma once

#include <lumx/version.h>

#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

LUMX_NAMESPACE_BEGIN

/// A parameter range [t0, t1] along a ray; empty when t0 > t1 (or either is NaN).
struct RayInterval {
  double t0 = 0.0;
  double t1 = -1.0;
  bool empty() const { return !(t0 <= t1); }
  double length() const { return empty() ? 0.0 : t1 - t0; }
};

struct Aabb {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()};
  glm::dvec3 hi{-std::numeric_limits<double>::infinity()};

  /// Finite corners with lo <= hi on every axis (flat and single-point boxes are valid).
  bool valid() const {
    for (int a = 0; a < 3; ++a)
      if (!(std::isfinite(lo[a]) && std::isfinite(hi[a]) && lo[a] <= hi[a])) return false;
    return true;
  }
  /// hi - lo (negative components for the default empty box).
  glm::dvec3 extent() const { return hi - lo; }
  glm::dvec3 center() const { return 0.5 * (lo + hi); }
  /// Closed test: points on a face are inside.
  bool contains(const glm::dvec3& p) const {
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
  }
  /// Grow to include p.
  void expand(const glm::dvec3& p) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  }

  /// The part of {origin + t * direction : t in [t_min, t_max]} inside the closed box. `direction` need
  /// not be normalised (t is in units of its length). A ray grazing an edge or face gives t0 == t1 or a
  /// non-empty interval along the face; a miss, or any NaN input, gives an empty interval.
  RayInterval clip(const glm::dvec3& origin, const glm::dvec3& direction, double t_min, double t_max) const {
    RayInterval r{t_min, t_max};
    for (int a = 0; a < 3; ++a) {
      const double d = direction[a];
      if (d == 0.0) {
        if (!(origin[a] >= lo[a] && origin[a] <= hi[a])) return RayInterval{};
        continue;
      }
      double t_near = (lo[a] - origin[a]) / d;  // division, not * (1/d): a subnormal d cannot give 0 * inf
      double t_far = (hi[a] - origin[a]) / d;
      if (t_near > t_far) std::swap(t_near, t_far);
      if (!(t_near <= t_far)) return RayInterval{};  // NaN
      r.t0 = std::max(r.t0, t_near);
      r.t1 = std::min(r.t1, t_far);
    }
    if (r.empty()) return RayInterval{};
    return r;
  }
};

LUMX_NAMESPACE_END
