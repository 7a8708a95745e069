// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/apl/lod.h — which level of an APL set a shading point should use.
//
// Two rules:
//  1. The dissertation's distance heuristic (000 §6.1): f(d) = 630.31 · exp(−0.333 d) APLs at relative
//     distance d (eq. 6.1, fitted for 4 % error on the Artichoke luminaire), or its (2,3) rational
//     minimax approximation (eq. 6.2), 1 APL beyond d = 20. A point then picks one of the two levels whose
//     counts bracket f(d) at random, with the probability that makes the expected APL count f(d) — the
//     stochastic analogue of blending two MIP levels.
//  2. An error target: given per-level error-against-distance tables stored with the set (ErrorTable),
//     the smallest level whose interpolated error at d is at most the caller's target.
// Both ignore occlusion: penumbrae from partly blocked luminaires may need more APLs (000 §6.1).
#pragma once

#include <lumx/apl/apl_set.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// Eq. 6.1: APLs needed at relative distance d for ≈4 % error.
inline double lod_apl_count_exact(double d) { return 630.31 * std::exp(-0.333 * std::max(0.0, d)); }

/// Eq. 6.2: the rational approximation of eq. 6.1 (within 6.9 % of it on [0, 20], 2.8 % for d ≥ 0.5);
/// exactly 1 beyond d = 20.
inline double lod_apl_count(double d) {
  d = std::max(0.0, d);
  if (d > 20.0) return 1.0;
  return (104741.36 + d * (-8309.86309 + 172.5216419 * d)) / (155.5587609 + d * (55.55720 + d * (0.20698246 + d)));
}

/// Level to use for a desired APL count, chosen at random between the two levels whose counts bracket
/// `desired` so that the expected count equals it (clamped to the first/last level). `u` ∈ [0,1).
/// Levels must be ordered by increasing count, as in AplSet.
inline std::size_t choose_level_stochastic(const AplSet& set, double desired, double u) {
  const std::size_t n = set.levels.size();
  if (n == 0) return 0;
  if (!(desired > double(set.levels.front().size()))) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    const double lo = double(set.levels[k - 1].size()), hi = double(set.levels[k].size());
    if (desired <= hi) return u < (desired - lo) / (hi - lo) ? k : k - 1;
  }
  return n - 1;
}

/// Eq. 6.2 plus the stochastic choice, for a point at x.
inline std::size_t choose_level_by_distance(const AplSet& set, const glm::dvec3& x, double u) {
  return choose_level_stochastic(set, lod_apl_count(set.relative_distance(x)), u);
}

/// A level's tabulated error at relative distance d: linear in log d between table entries, held
/// constant beyond either end. Returns +inf for an empty table (unknown error).
inline double interpolated_error(const ErrorTable& table, double d) {
  const auto& ds = table.relative_distance;
  const auto& es = table.relative_rmse;
  if (ds.empty() || es.size() != ds.size()) return INFINITY;
  if (!(d > ds.front())) return es.front();  // also NaN: never index past the table
  if (d >= ds.back()) return es.back();
  const std::size_t j = std::size_t(std::upper_bound(ds.begin(), ds.end(), d) - ds.begin());
  const double t = (std::log(d) - std::log(ds[j - 1])) / (std::log(ds[j]) - std::log(ds[j - 1]));
  return es[j - 1] + t * (es[j] - es[j - 1]);
}

/// The smallest level whose stored error at relative distance d is ≤ target; the finest level if none
/// is (the caller then knows the target cannot be met: compare interpolated_error yourself).
inline std::size_t choose_level_for_error(const AplSet& set, double d, double target) {
  for (std::size_t k = 0; k < set.levels.size(); ++k)
    if (interpolated_error(set.levels[k].error, d) <= target) return k;
  return set.levels.empty() ? 0 : set.levels.size() - 1;
}

LUMX_NAMESPACE_END
