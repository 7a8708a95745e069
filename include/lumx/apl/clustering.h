// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/apl/clustering.h — the agglomerative cluster tree that APL levels are cut from.
//
// Dissertation 000 §4.3: seed particles (exit points with flux) are merged bottom-up with the cost
//   I(C1, C2) = (Φ_C1 + Φ_C2) · Diag(C1 ∪ C2)^4                                       (eq. 4.1)
// (Diag = diagonal of the union's bounding box) into one binary tree; levels of 1, 8, 64, ... APLs are
// cuts of that tree taken with a max-priority queue on the merge cost.
//
// The tree is built by PLOC, "parallel locally-ordered clustering" (Meister & Bittner, TVCG 2018), the
// parallel form of Walter et al.'s locally-ordered merging (RT 2008): clusters are kept sorted along a
// Morton curve; each pass finds every cluster's cheapest partner within `window` positions on either
// side and merges the pairs that chose each other. A pair that is the cheapest in both its endpoints'
// windows is merged in the same order greedy merging would take it; the window only limits which
// partners are considered, which on a Morton order costs little tree quality (Meister & Bittner report
// ~1–3 % higher SAH cost at r = 16 than full greedy), while the work is O(n · window) per pass instead
// of a dynamic KD-tree. Ties (equal costs: coincident seeds, a far-field rayset where every ray starts at
// one point) are broken by a hash of the pair's node ids, so a constant fraction of clusters still pairs
// up every pass and the result never depends on thread count or timing.
#pragma once

#include <lumx/version.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <queue>
#include <stdexcept>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// A binary cluster tree over n seeds: nodes 0..n−1 are the seeds, n..2n−2 the merges; `root` is the last.
struct ClusterTree {
  std::vector<int> left, right, parent;  ///< −1 where absent
  std::vector<double> cost;              ///< eq. 4.1 cost of the merge that made the node (0 for seeds)
  std::vector<double> flux;              ///< Σ seed flux below the node
  std::vector<glm::vec3> lo, hi;         ///< bounding box of the seeds below the node, m
  std::vector<std::uint32_t> seeds;      ///< number of seeds below the node
  int root = -1;
  std::size_t seed_count = 0;

  std::size_t size() const { return left.size(); }
  bool is_seed(int node) const { return std::size_t(node) < seed_count; }
  glm::vec3 center(int node) const { return 0.5f * (lo[std::size_t(node)] + hi[std::size_t(node)]); }
};

struct ClusterOptions {
  int window = 16;  ///< PLOC search radius r (clusters on each side in Morton order)
};

namespace detail {

/// Eq. 4.1 for the union of two boxes and their fluxes.
inline double merge_cost(const glm::vec3& lo1, const glm::vec3& hi1, double f1, const glm::vec3& lo2,
                         const glm::vec3& hi2, double f2) {
  const glm::dvec3 d = glm::dvec3(glm::max(hi1, hi2)) - glm::dvec3(glm::min(lo1, lo2));
  const double diag2 = glm::dot(d, d);
  return (f1 + f2) * diag2 * diag2;
}

/// A well-mixed 64-bit hash of an unordered pair of node ids (splitmix64 finaliser), for tie-breaking.
inline std::uint64_t pair_hash(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  std::uint64_t z = (std::uint64_t(a) << 32 | b) + 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// 30-bit Morton code of a point in the unit cube (10 bits per axis).
inline std::uint32_t morton3(const glm::vec3& unit) {
  auto spread = [](std::uint32_t v) {
    v = (v * 0x00010001u) & 0xFF0000FFu;
    v = (v * 0x00000101u) & 0x0F00F00Fu;
    v = (v * 0x00000011u) & 0xC30C30C3u;
    v = (v * 0x00000005u) & 0x49249249u;
    return v;
  };
  auto q = [](float t) { return std::uint32_t(std::clamp(t, 0.0f, 1.0f) * 1023.0f + 0.5f); };
  return spread(q(unit.x)) << 2 | spread(q(unit.y)) << 1 | spread(q(unit.z));
}

}  // namespace detail

/// Builds the tree over seeds at `positions` (m) with `flux` (≥ 0, finite). Deterministic: the result
/// depends only on the inputs. Throws std::invalid_argument for empty or mismatched inputs, non-finite
/// values or more than 2^31 seeds.
inline ClusterTree build_cluster_tree(const std::vector<glm::vec3>& positions, const std::vector<float>& flux,
                                      const ClusterOptions& options = {}) {
  const std::size_t n = positions.size();
  if (n == 0 || flux.size() != n) throw std::invalid_argument("build_cluster_tree: need as many fluxes as positions (≥ 1)");
  if (n > (std::size_t(1) << 31)) throw std::invalid_argument("build_cluster_tree: more than 2^31 seeds");
  const int r = std::max(1, options.window);
  ClusterTree t;
  t.seed_count = n;
  const std::size_t total = 2 * n - 1;
  t.left.assign(total, -1);
  t.right.assign(total, -1);
  t.parent.assign(total, -1);
  t.cost.assign(total, 0.0);
  t.flux.assign(total, 0.0);
  t.lo.resize(total);
  t.hi.resize(total);
  t.seeds.assign(total, 0);
  glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3& p = positions[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(flux[i]) || flux[i] < 0)
      throw std::invalid_argument("build_cluster_tree: seed " + std::to_string(i) + " has a non-finite position or bad flux");
    t.lo[i] = t.hi[i] = p;
    t.flux[i] = flux[i];
    t.seeds[i] = 1;
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  // Seeds in Morton order of their position in the seeds' bounding box (ties by index: stable).
  const glm::vec3 extent = glm::max(hi - lo, glm::vec3(1e-30f));
  std::vector<std::pair<std::uint32_t, std::uint32_t>> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = {detail::morton3((positions[i] - lo) / extent), std::uint32_t(i)};
  std::sort(order.begin(), order.end());
  std::vector<std::uint32_t> active(n);
  for (std::size_t i = 0; i < n; ++i) active[i] = order[i].second;

  std::size_t next = n;
  std::vector<std::int32_t> best(n);
  while (active.size() > 1) {
    const std::size_t m = active.size();
    best.resize(m);
    // Each cluster's cheapest partner within the window: key (cost, pair hash), smallest wins.
    for (std::size_t i = 0; i < m; ++i) {
      const std::uint32_t a = active[i];
      double best_cost = std::numeric_limits<double>::infinity();
      std::uint64_t best_hash = ~std::uint64_t(0);
      std::int32_t best_j = -1;
      const std::size_t j0 = i >= std::size_t(r) ? i - std::size_t(r) : 0, j1 = std::min(m - 1, i + std::size_t(r));
      for (std::size_t j = j0; j <= j1; ++j) {
        if (j == i) continue;
        const std::uint32_t b = active[j];
        const double c = detail::merge_cost(t.lo[a], t.hi[a], t.flux[a], t.lo[b], t.hi[b], t.flux[b]);
        if (c > best_cost) continue;
        const std::uint64_t h = detail::pair_hash(a, b);
        if (c < best_cost || h < best_hash) best_cost = c, best_hash = h, best_j = std::int32_t(j);
      }
      best[i] = best_j;
    }
    // Merge mutual pairs (the left partner takes the new node's place: Morton order is kept).
    std::vector<std::uint32_t> survivors;
    survivors.reserve(m);
    for (std::size_t i = 0; i < m; ++i) {
      const std::int32_t j = best[i];
      const bool mutual = j >= 0 && best[std::size_t(j)] == std::int32_t(i);
      if (!mutual) {
        survivors.push_back(active[i]);
        continue;
      }
      if (std::size_t(j) < i) continue;  // merged when its partner came by
      const std::uint32_t a = active[i], b = active[std::size_t(j)];
      const std::size_t c = next++;
      t.left[c] = int(a);
      t.right[c] = int(b);
      t.parent[a] = t.parent[b] = int(c);
      t.lo[c] = glm::min(t.lo[a], t.lo[b]);
      t.hi[c] = glm::max(t.hi[a], t.hi[b]);
      t.flux[c] = t.flux[a] + t.flux[b];
      t.seeds[c] = t.seeds[a] + t.seeds[b];
      t.cost[c] = detail::merge_cost(t.lo[a], t.hi[a], t.flux[a], t.lo[b], t.hi[b], t.flux[b]);
      survivors.push_back(std::uint32_t(c));
    }
    active.swap(survivors);
  }
  t.root = int(active.front());
  return t;
}

/// Cuts of the tree with `counts[k]` clusters each (increasing), taken with a max-priority queue on
/// merge cost: starting from the root, the costliest node is replaced by its two children until the cut
/// has the requested size (000 §4.3). Each cut refines the previous one, so every node of cut k+1 lies
/// below exactly one node of cut k. A cut stops early when only seeds are left (fewer seeds than
/// requested clusters). Ties in cost go to the lower node id. Nodes within a cut are sorted by id.
inline std::vector<std::vector<int>> cut_cluster_tree(const ClusterTree& t, const std::vector<std::size_t>& counts) {
  struct Item {
    double cost;
    int node;
    bool operator<(const Item& o) const { return cost < o.cost || (cost == o.cost && node > o.node); }
  };
  std::priority_queue<Item> queue;
  std::vector<int> finished;  // seeds: cannot be split further
  auto push = [&](int node) {
    if (t.is_seed(node)) finished.push_back(node);
    else queue.push({t.cost[std::size_t(node)], node});
  };
  push(t.root);
  std::vector<std::vector<int>> cuts;
  for (std::size_t want : counts) {
    while (queue.size() + finished.size() < want && !queue.empty()) {
      const Item top = queue.top();
      queue.pop();
      push(t.left[std::size_t(top.node)]);
      push(t.right[std::size_t(top.node)]);
    }
    std::vector<int> cut = finished;
    auto copy = queue;
    while (!copy.empty()) cut.push_back(copy.top().node), copy.pop();
    std::sort(cut.begin(), cut.end());
    cuts.push_back(std::move(cut));
  }
  return cuts;
}

LUMX_NAMESPACE_END
