// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/direction_mask.h — the set of directions light leaves one point in, with borders as geometry.
//
// A point source behind apertures (a box with holes, an LED behind a shutter) lights a set of directions
// with perfectly sharp borders. A texel map reads such a border through interpolated texels and is wrong
// in a band a texel or so wide at every resolution a bundle can afford (docs/apl_sets.md, "What maps can
// do on the box at all"). The rays themselves locate the border far more finely: n rays spread over an
// aperture find its edge to about its length / n.
//
// A DirectionMask stores that set as a union of caps: the directions are split into connected groups
// (directions closer than `link_angle` are linked), and each group becomes the convex hull of its
// directions in the gnomonic chart about the group's mean direction. The gnomonic projection maps great
// circles to straight lines, so each hull is a geodesically convex spherical polygon, whose solid angle
// is a sum of spherical triangles. A hull of points drawn inside a convex region lies inside it, and its
// missing area shrinks like (2k/3)·ln n / n of the area for a k-gon (Rényi & Sulanke 1963): about 0.05 %
// of a rectangular hole's solid angle from n = 56 000 rays (one source of the box with holes in
// docs/apl_sets.md), missed at the border.
//
// Within the mask a texel map still carries the intensity. coverage() is the lit fraction of every texel
// of a map; a texel value is flux over the whole texel, so intensity inside the mask is the bilinear value
// over the bilinear coverage (a normalised convolution, Knutsson & Westin 1993): a beam of constant
// intensity reads back up to its border, however coarse the map, to within the sampling of the coverage
// (sub × sub directions a texel: up to 1/(2·sub) of a border texel's lit fraction) and, in texels lit
// below min_coverage, that clamp.
//
// Limits: a group must fit within `max_half_angle` of its mean direction (a gnomonic chart ends at 90°),
// and a non-convex group is covered by its hull (an L-shaped aperture lights its notch). from_directions
// says why it refuses.
#pragma once

#include <lumx/math/constants.h>
#include <lumx/math/sphere_map.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

struct DirectionMaskOptions {
  /// rad: directions closer than this are linked into one group (up to about 3.5× further may be: the
  /// link is between neighbouring cells of this size). Larger than the rays' spacing inside a beam,
  /// smaller than the gaps between beams.
  double link_angle = 0.03;
  /// Groups of fewer directions are stray rays, not a beam: dropped (their light is outside the mask).
  std::size_t min_group = 64;
  /// rad: the widest a group may reach from its mean direction (the gnomonic chart ends at π/2).
  double max_half_angle = 1.2;
};

/// A union of geodesically convex spherical polygons ("caps"), each the hull of one group of directions.
class DirectionMask {
 public:
  struct Cap {
    glm::dvec3 axis{0, 0, 1}, e1{1, 0, 0}, e2{0, 1, 0};  ///< the chart: centre and tangent basis
    std::vector<glm::dvec2> hull;  ///< counter-clockwise vertices in the chart (w·e1, w·e2) / (w·axis)
    double min_cos = 1;            ///< the least w·axis of the hull's vertices: a quick reject
    double reach = 0;              ///< rad, acos(min_cos): the hull lies within it of the axis
  };

  /// The mask of `directions` (unit vectors, any order). Returns nothing, with the reason in `why`, when
  /// no group has min_group directions, a group is wider than max_half_angle, or a group's directions
  /// cancel (no mean direction). Throws std::invalid_argument naming the index of a direction that is not
  /// finite and of unit length (±1e-3), or for link_angle outside [0.001, 1) or max_half_angle outside
  /// (0, 1.5) rad.
  /// Deterministic: the same directions in the same order give the same mask (the groups do not depend
  /// on the order; a cap's chart axis, a sum, does to rounding).
  static std::optional<DirectionMask> from_directions(const std::vector<glm::dvec3>& directions,
                                                      const DirectionMaskOptions& options = {},
                                                      std::string* why = nullptr);

  /// A mask from stored caps (a bundle's): each needs an orthonormal chart (axis, e1, e2 unit and
  /// perpendicular to 1e-5, e2 = axis × e1), at least 3 and at most kMaxHullVertices finite hull vertices,
  /// counter-clockwise and convex, within max_half_angle of the axis; min_cos and reach are recomputed.
  /// Throws std::invalid_argument naming the cap and what is wrong.
  static constexpr std::size_t kMaxHullVertices = 1u << 16;
  static DirectionMask from_caps(std::vector<Cap> caps, const DirectionMaskOptions& options = {}) {
    if (caps.empty()) throw std::invalid_argument("no cap");
    const double min_cos = std::cos(options.max_half_angle);
    for (std::size_t i = 0; i < caps.size(); ++i) {
      Cap& c = caps[i];
      const std::string at = "cap " + std::to_string(i) + ": ";
      const auto finite = [](const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
      if (!finite(c.axis) || !finite(c.e1) || !finite(c.e2) || std::abs(glm::length(c.axis) - 1) > 1e-5 ||
          std::abs(glm::length(c.e1) - 1) > 1e-5 || std::abs(glm::dot(c.axis, c.e1)) > 1e-5 ||
          glm::length(c.e2 - glm::cross(c.axis, c.e1)) > 1e-5)
        throw std::invalid_argument(at + "axis, e1 and e2 are not a right-handed orthonormal basis");
      if (c.hull.size() < 3 || c.hull.size() > kMaxHullVertices)
        throw std::invalid_argument(at + std::to_string(c.hull.size()) + " hull vertices (3 to " +
                                    std::to_string(kMaxHullVertices) + ")");
      c.min_cos = 1;
      for (std::size_t v = 0; v < c.hull.size(); ++v) {
        const glm::dvec2& p = c.hull[v];
        if (!std::isfinite(p.x) || !std::isfinite(p.y)) throw std::invalid_argument(at + "vertex " + std::to_string(v) + " is not finite");
        c.min_cos = std::min(c.min_cos, 1 / std::sqrt(1 + glm::dot(p, p)));
        const std::size_t n = c.hull.size();
        if (cross2(c.hull[v], c.hull[(v + 1) % n], c.hull[(v + 2) % n]) <= 0)
          throw std::invalid_argument(at + "vertices " + std::to_string(v) + " to " + std::to_string((v + 2) % n) +
                                      " do not turn counter-clockwise: not a convex hull");
      }
      // Every turn left and the edges' directions once around (their turning angles add up to 2π, not
      // 2πk): a convex polygon. (Winding once about one point is not enough: a curve with a loop can.)
      double turn = 0;
      const std::size_t n = c.hull.size();
      for (std::size_t v = 0; v < n; ++v) {
        const glm::dvec2 a = c.hull[(v + 1) % n] - c.hull[v], b = c.hull[(v + 2) % n] - c.hull[(v + 1) % n];
        turn += std::atan2(a.x * b.y - a.y * b.x, glm::dot(a, b));
      }
      if (!(std::abs(turn - 2 * kPi) < 1e-6))
        throw std::invalid_argument(at + "its edges turn " + std::to_string(turn / (2 * kPi)) + " times around: not convex");
      if (c.min_cos < min_cos) throw std::invalid_argument(at + "reaches beyond " + std::to_string(options.max_half_angle) + " rad of its axis");
      c.reach = std::acos(std::clamp(c.min_cos, -1.0, 1.0));
    }
    DirectionMask m;
    m.caps_ = std::move(caps);
    return m;
  }

  const std::vector<Cap>& caps() const { return caps_; }

  /// The containment tests coverage(R, …, sub) may make at most: every sub-direction of every texel
  /// against every cap, each in 1 + log2(vertices) steps. What a reader bounds before it computes one.
  double coverage_tests(int resolution, int sub) const {
    double tests = 0;
    for (const Cap& c : caps_)
      tests += 2.0 * double(resolution) * double(resolution) * double(sub) * double(sub) *
               (1.0 + std::log2(double(std::max<std::size_t>(1, c.hull.size()))));
    return tests;
  }

  /// Whether unit direction w lies in some cap (on a border counts as inside).
  bool contains(const glm::dvec3& w) const {
    for (const Cap& c : caps_) {
      const double z = glm::dot(w, c.axis);
      if (z < c.min_cos - 1e-12 || z <= 0) continue;
      if (inside_hull(c.hull, {glm::dot(w, c.e1) / z, glm::dot(w, c.e2) / z})) return true;
    }
    return false;
  }

  /// sr: the sum of the caps' solid angles. Hulls of separate groups can
  /// overlap (one group in another's notch); an overlap is then counted twice.
  double solid_angle() const {
    double total = 0;
    for (const Cap& c : caps_) total += cap_solid_angle(c);
    return total;
  }

  /// The lit fraction of every texel of a map of square resolution R whose directions turn into the
  /// mask's frame by `map_to_mask` (a rotation), from sub × sub equal-area sub-directions per texel.
  SphereMap coverage(int resolution, const glm::mat3& map_to_mask, int sub = 4) const {
    if (sub < 1 || sub > 256) throw std::invalid_argument("DirectionMask::coverage: sub " + std::to_string(sub) + " outside [1, 256]");
    SphereMap out(resolution, 1);
    const float inv = 1.0f / float(sub * sub);
    for (int y = 0; y < resolution; ++y)
      for (int x = 0; x < 2 * resolution; ++x) {
        // Texels whose centre is far from every cap cannot hold a lit sub-direction: skip them. No point
        // of a texel is more than 2.63 / R rad from its centre (measured for R = 1 … 4096; the largest are
        // next to the poles, along the squares' diagonals), so 4 / R keeps a margin of 1.5.
        const glm::vec2 centre((float(x) + 0.5f) / float(2 * resolution), (float(y) + 0.5f) / float(resolution));
        const glm::dvec3 wc = glm::normalize(glm::dvec3(map_to_mask * sphere_map::uv_to_direction(centre)));
        if (!near_a_cap(wc, 4.0 / double(resolution))) continue;
        int lit = 0;
        for (int j = 0; j < sub; ++j)
          for (int i = 0; i < sub; ++i) {
            const glm::vec2 uv((float(x) + (float(i) + 0.5f) / float(sub)) / float(2 * resolution),
                               (float(y) + (float(j) + 0.5f) / float(sub)) / float(resolution));
            lit += contains(glm::normalize(glm::dvec3(map_to_mask * sphere_map::uv_to_direction(uv))));
          }
        out.at(x, y, 0) = float(lit) * inv;
      }
    return out;
  }

  /// Intensity inside the mask from a map of the whole texels' flux and the mask's coverage of the same
  /// resolution, both read bilinearly in map direction m; w is the same direction in the mask's frame.
  /// Outside the mask: 0. Coverage below `min_coverage` is raised to it (a sliver of a texel that the
  /// bilinear weights barely reach would otherwise divide noise by almost nothing).
  /// Throws std::invalid_argument when the coverage's resolution is not the map's.
  glm::vec3 normalised_lookup(const SphereMap& map, const SphereMap& coverage, const glm::vec3& m, const glm::dvec3& w,
                              float min_coverage = 1.0f / 16) const {
    if (coverage.resolution() != map.resolution() || coverage.empty())
      throw std::invalid_argument("DirectionMask::normalised_lookup: coverage of resolution " +
                                  std::to_string(coverage.resolution()) + " for a map of " + std::to_string(map.resolution()));
    if (!contains(w)) return glm::vec3(0.0f);
    return map.lookup(m) / std::max(min_coverage, coverage.lookup(m).x);
  }

 private:
  static double cross2(const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
  }
  /// Whether q lies in the convex counter-clockwise polygon h (its border included), in O(log n): the
  /// fan wedge from h[0] that holds q by bisection, then that wedge's outer edge.
  static bool inside_hull(const std::vector<glm::dvec2>& h, const glm::dvec2& q) {
    const std::size_t n = h.size();
    // The two edges at h[0] with the same arithmetic as a test of every edge (h[i] → h[i+1]).
    if (n < 3 || cross2(h[0], h[1], q) < 0 || cross2(h[n - 1], h[0], q) < 0) return false;
    std::size_t lo = 1, hi = n - 1;  // cross2(h0, h[lo], q) ≥ 0 > cross2(h0, h[hi], q), or hi = n − 1
    while (hi - lo > 1) {
      const std::size_t mid = (lo + hi) / 2;
      (cross2(h[0], h[mid], q) >= 0 ? lo : hi) = mid;
    }
    return cross2(h[lo], h[lo + 1], q) >= 0;
  }
  /// Whether w is within `reach` rad of some cap's hull (a conservative test on the cap's circumcone).
  bool near_a_cap(const glm::dvec3& w, double reach) const {
    for (const Cap& c : caps_)
      if (std::acos(std::clamp(glm::dot(w, c.axis), -1.0, 1.0)) <= c.reach + reach) return true;
    return false;
  }
  static double cap_solid_angle(const Cap& c) {
    // A fan of spherical triangles (v0, vi, vi+1) over the hull's directions, each by Van Oosterom &
    // Strackee (1983): tan(Ω/2) = a·(b×c) / (1 + a·b + b·c + c·a). Unlike a sum of interior angles, a
    // degenerate triangle (two vertices that round to one direction) adds 0.
    const std::size_t k = c.hull.size();
    if (k < 3) return 0;
    std::vector<glm::dvec3> v(k);
    for (std::size_t i = 0; i < k; ++i) v[i] = glm::normalize(c.axis + c.hull[i].x * c.e1 + c.hull[i].y * c.e2);
    double total = 0;
    for (std::size_t i = 1; i + 1 < k; ++i) {
      const glm::dvec3 &a = v[0], &b = v[i], &d = v[i + 1];
      total += 2 * std::atan2(glm::dot(a, glm::cross(b, d)), 1 + glm::dot(a, b) + glm::dot(b, d) + glm::dot(d, a));
    }
    return total;
  }

  std::vector<Cap> caps_;
};

LUMX_NAMESPACE_END
