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
#include <cstddef>
#include <cstdint>
#include <queue>
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

}  // namespace detail

/// Builds the tree over seeds at `positions` (m) with `flux` (≥ 0, finite). Deterministic: the result
/// depends only on the inputs. Throws std::invalid_argument for empty or mismatched inputs, non-finite
/// values or more than 2^31 seeds.
ClusterTree build_cluster_tree(const std::vector<glm::vec3>& positions, const std::vector<float>& flux,
                               const ClusterOptions& options = {});

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
