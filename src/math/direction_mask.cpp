// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// DirectionMask::from_directions (math/direction_mask.h): directions linked through a cell grid into
// groups (union–find), each group's hull in the gnomonic chart about its mean direction.
#include <lumx/math/direction_mask.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

LUMX_NAMESPACE_BEGIN

std::optional<DirectionMask> DirectionMask::from_directions(const std::vector<glm::dvec3>& directions,
                                                            const DirectionMaskOptions& options, std::string* why) {
  auto refuse = [&](const std::string& reason) -> std::optional<DirectionMask> {
    if (why) *why = reason;
    return std::nullopt;
  };
  if (!(options.link_angle >= 1e-3 && options.link_angle < 1))
    throw std::invalid_argument("DirectionMask: link_angle " + std::to_string(options.link_angle) + " outside [0.001, 1) rad");
  if (!(options.max_half_angle > 0 && options.max_half_angle < 1.5))
    throw std::invalid_argument("DirectionMask: max_half_angle " + std::to_string(options.max_half_angle) +
                                " outside (0, 1.5) rad");
  const std::size_t n = directions.size();
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec3& w = directions[i];
    const double len2 = glm::dot(w, w);
    if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z) || std::abs(len2 - 1) > 2e-3)
      throw std::invalid_argument("DirectionMask: direction " + std::to_string(i) + " is not a finite unit vector");
  }
  // Groups: directions in one cell of a cubic grid of side link_angle, or in neighbouring cells, are
  // linked (union–find). Cells are keyed by their integer coordinates, which fit in 11 bits each for
  // link_angle ≥ 1/1000 (|v / cell| ≤ 1001); the key packs them.
  const double cell = options.link_angle;
  auto coord = [&](double v) { return std::int64_t(std::floor(v / cell)) + 1024; };
  auto key = [](std::int64_t a, std::int64_t b, std::int64_t c) { return (a << 22) | (b << 11) | c; };
  std::unordered_map<std::int64_t, std::size_t> first_in_cell;  // cell → the smallest index in it
  std::vector<std::size_t> parent(n);
  std::iota(parent.begin(), parent.end(), std::size_t(0));
  auto find = [&](std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  auto unite = [&](std::size_t a, std::size_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);  // the root is the group's smallest index
  };
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t k = key(coord(directions[i].x), coord(directions[i].y), coord(directions[i].z));
    auto [it, added] = first_in_cell.emplace(k, i);
    if (!added) unite(i, it->second);
  }
  for (const auto& [k, i] : first_in_cell) {
    const std::int64_t a = k >> 22, b = (k >> 11) & 2047, c = k & 2047;
    for (std::int64_t da = -1; da <= 1; ++da)
      for (std::int64_t db = -1; db <= 1; ++db)
        for (std::int64_t dc = -1; dc <= 1; ++dc) {
          const auto it = first_in_cell.find(key(a + da, b + db, c + dc));
          if (it != first_in_cell.end()) unite(i, it->second);
        }
  }
  // Groups in order of their smallest index, whatever order the cells were visited in.
  std::vector<std::size_t> root(n), group_of_root(n, std::size_t(-1));
  std::vector<std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < n; ++i) {
    root[i] = find(i);
    if (group_of_root[root[i]] == std::size_t(-1)) group_of_root[root[i]] = groups.size(), groups.emplace_back();
    groups[group_of_root[root[i]]].push_back(i);
  }
  DirectionMask mask;
  const double min_cos = std::cos(options.max_half_angle);
  for (const std::vector<std::size_t>& g : groups) {
    if (g.size() < options.min_group) continue;
    glm::dvec3 sum(0.0);
    for (std::size_t i : g) sum += directions[i];
    if (glm::length(sum) <= 0.5 * double(g.size()) * 1e-9) return refuse("a group of directions has no mean direction");
    Cap cap;
    cap.axis = glm::normalize(sum);
    cap.e1 = glm::normalize(glm::cross(std::abs(cap.axis.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0), cap.axis));
    cap.e2 = glm::cross(cap.axis, cap.e1);
    std::vector<glm::dvec2> pts;
    pts.reserve(g.size());
    for (std::size_t i : g) {
      // The chart's coordinates (d·e1, d·e2) / (d·axis) do not depend on |d|; the angle test does.
      const glm::dvec3& d = directions[i];
      const double along = glm::dot(d, cap.axis), z = along / glm::length(d);
      if (z < min_cos)
        return refuse("a group of " + std::to_string(g.size()) + " directions reaches " +
                      std::to_string(std::acos(std::clamp(z, -1.0, 1.0))) + " rad from its mean direction (at most " +
                      std::to_string(options.max_half_angle) + ")");
      pts.push_back({glm::dot(d, cap.e1) / along, glm::dot(d, cap.e2) / along});
    }
    // Andrew's monotone chain: counter-clockwise, collinear points dropped.
    std::sort(pts.begin(), pts.end(), [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    if (pts.size() < 3) continue;
    std::vector<glm::dvec2> h(2 * pts.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      while (k >= 2 && cross2(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
      h[k++] = pts[i];
    }
    for (std::size_t i = pts.size() - 1, lower = k + 1; i > 0; --i) {
      while (k >= lower && cross2(h[k - 2], h[k - 1], pts[i - 1]) <= 0) --k;
      h[k++] = pts[i - 1];
    }
    h.resize(k - 1);
    if (h.size() < 3) continue;  // all on one great circle: no area
    cap.hull = std::move(h);
    for (const glm::dvec2& p : cap.hull) cap.min_cos = std::min(cap.min_cos, 1 / std::sqrt(1 + glm::dot(p, p)));
    cap.reach = std::acos(std::clamp(cap.min_cos, -1.0, 1.0));
    mask.caps_.push_back(std::move(cap));
  }
  if (mask.caps_.empty()) return refuse("no group of at least " + std::to_string(options.min_group) + " directions");
  return mask;
}

LUMX_NAMESPACE_END
