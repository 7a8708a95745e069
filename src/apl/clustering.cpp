// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// build_cluster_tree (apl/clustering.h): PLOC over the seeds in Morton order, with eq. 4.1 as the cost.
#include <lumx/apl/clustering.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace {

// A well-mixed 64-bit hash of an unordered pair of node ids (splitmix64 finaliser), for tie-breaking.
std::uint64_t pair_hash(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  std::uint64_t z = (std::uint64_t(a) << 32 | b) + 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// 30-bit Morton code of a point in the unit cube (10 bits per axis).
std::uint32_t morton3(const glm::vec3& unit) {
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

}  // namespace

ClusterTree build_cluster_tree(const std::vector<glm::vec3>& positions, const std::vector<float>& flux,
                               const ClusterOptions& options) {
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
  for (std::size_t i = 0; i < n; ++i) order[i] = {morton3((positions[i] - lo) / extent), std::uint32_t(i)};
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
        const std::uint64_t h = pair_hash(a, b);
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

LUMX_NAMESPACE_END
