// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/detail/point_kdtree.h — exact nearest neighbour among a few thousand fixed points.
//
// Used to send every ray of a rayset to its nearest APL centre (000 §4.3: "every later particle goes to
// the nearest cluster centre"). A static tree built by median splits on the widest axis; queries
// descend to the query's side first and visit the other side only when the splitting plane is closer
// than the best distance so far, so the answer is exact. Ties go to the lower point index, so the
// result does not depend on the tree's shape.
#pragma once

#include <lumx/version.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <numeric>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace detail {

class PointKdTree {
 public:
  PointKdTree() = default;
  explicit PointKdTree(std::vector<glm::vec3> points) : points_(std::move(points)) {
    order_.resize(points_.size());
    std::iota(order_.begin(), order_.end(), 0u);
    if (!points_.empty()) build(0, order_.size());
  }

  std::size_t size() const { return points_.size(); }

  /// Index of the point nearest to q (Euclidean; lowest index among equals). Requires size() > 0.
  std::uint32_t nearest(const glm::vec3& q) const {
    std::uint32_t best = 0;
    float best_d2 = std::numeric_limits<float>::infinity();
    search(0, order_.size(), q, best, best_d2);
    return best;
  }

 private:
  struct Split {
    int axis;
    float value;
  };

  // Node for range [lo, hi): the median element order_[mid] holds the split; children are [lo, mid)
  // and [mid + 1, hi). Splits are stored by the median's position.
  void build(std::size_t lo, std::size_t hi) {
    if (hi - lo <= 1) return;
    glm::vec3 mn(std::numeric_limits<float>::infinity()), mx(-std::numeric_limits<float>::infinity());
    for (std::size_t i = lo; i < hi; ++i) {
      mn = glm::min(mn, points_[order_[i]]);
      mx = glm::max(mx, points_[order_[i]]);
    }
    const glm::vec3 e = mx - mn;
    const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    const std::size_t mid = lo + (hi - lo) / 2;
    std::nth_element(order_.begin() + std::ptrdiff_t(lo), order_.begin() + std::ptrdiff_t(mid),
                     order_.begin() + std::ptrdiff_t(hi), [&](std::uint32_t a, std::uint32_t b) {
                       return points_[a][axis] < points_[b][axis] || (points_[a][axis] == points_[b][axis] && a < b);
                     });
    if (splits_.size() < order_.size()) splits_.resize(order_.size());
    splits_[mid] = {axis, points_[order_[mid]][axis]};
    build(lo, mid);
    build(mid + 1, hi);
  }

  void consider(std::uint32_t index, const glm::vec3& q, std::uint32_t& best, float& best_d2) const {
    const glm::vec3 d = points_[index] - q;
    const float d2 = glm::dot(d, d);
    if (d2 < best_d2 || (d2 == best_d2 && index < best)) best_d2 = d2, best = index;
  }

  void search(std::size_t lo, std::size_t hi, const glm::vec3& q, std::uint32_t& best, float& best_d2) const {
    if (hi <= lo) return;
    if (hi - lo == 1) return consider(order_[lo], q, best, best_d2);
    const std::size_t mid = lo + (hi - lo) / 2;
    consider(order_[mid], q, best, best_d2);
    const Split s = splits_[mid];
    const float delta = q[s.axis] - s.value;
    const bool left_first = delta <= 0;
    if (left_first) search(lo, mid, q, best, best_d2);
    else search(mid + 1, hi, q, best, best_d2);
    if (delta * delta <= best_d2) {  // the other side may hold a closer (or equally close, lower) point
      if (left_first) search(mid + 1, hi, q, best, best_d2);
      else search(lo, mid, q, best, best_d2);
    }
  }

  std::vector<glm::vec3> points_;
  std::vector<std::uint32_t> order_;
  std::vector<Split> splits_;
};

}  // namespace detail
LUMX_NAMESPACE_END
