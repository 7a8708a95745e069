// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// check_apl_set (apl/apl_set.h): the set's consistency rules, one message per violation.
#include <lumx/apl/apl_set.h>

#include <lumx/core/units.h>

#include <glm/glm.hpp>

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

std::vector<std::string> check_apl_set(const AplSet& set, double flux_tolerance) {
  std::vector<std::string> out;
  const int nc = channel_count(set.channels);
  if (set.levels.empty()) out.push_back("levels: the set has no level");
  if (!(set.bounds.radius >= 0) || !std::isfinite(set.bounds.radius))
    out.push_back("bounding_sphere.radius: not a finite non-negative number");
  if (!std::isfinite(set.bounds.center.x) || !std::isfinite(set.bounds.center.y) || !std::isfinite(set.bounds.center.z))
    out.push_back("bounding_sphere.center: not finite");
  for (std::size_t k = 0; k < set.levels.size(); ++k) {
    const AplLevel& level = set.levels[k];
    const std::string where = "levels[" + std::to_string(k) + "]";
    if (level.apls.empty()) out.push_back(where + ": no APL");
    if (k > 0 && level.apls.size() <= set.levels[k - 1].apls.size())
      out.push_back(where + ": APL count " + std::to_string(level.apls.size()) +
                    " does not exceed the previous level's");
    const auto [frame_off, frame_det] = level.frame.deviation();
    if (!(frame_off <= 1e-4f) || !(std::abs(frame_det - 1.0f) <= 1e-4f))
      out.push_back(where + ".frame: not a rotation (|RᵀR − I| " + std::to_string(frame_off) + ", determinant " +
                    std::to_string(frame_det) + ")");
    const ErrorTable& e = level.error;
    bool table_ok = e.relative_rmse.size() == e.relative_distance.size() && e.relative_distance.size() <= 4096;
    for (std::size_t j = 0; table_ok && j < e.relative_distance.size(); ++j)
      table_ok = e.relative_distance[j] > 0 && std::isfinite(e.relative_distance[j]) &&
                 (j == 0 || e.relative_distance[j] > e.relative_distance[j - 1]) && e.relative_rmse[j] >= 0 &&
                 std::isfinite(e.relative_rmse[j]);
    if (!table_ok)
      out.push_back(where + ".error: distances must be positive, finite and increasing, errors finite and ≥ 0, "
                            "one error per distance (at most 4096)");
    const double level_flux = luminance_of(set.channels, level.flux());
    const double floor_tol = 1e-6 * std::abs(level_flux);
    auto tol = [&](const glm::dvec3& f) { return flux_tolerance * std::abs(luminance_of(set.channels, f)) + floor_tol; };
    for (std::size_t i = 0; i < level.apls.size(); ++i) {
      const Apl& a = level.apls[i];
      const std::string at = where + ".apls[" + std::to_string(i) + "]";
      if (!std::isfinite(a.position.x) || !std::isfinite(a.position.y) || !std::isfinite(a.position.z))
        out.push_back(at + ".position: not finite");
      for (int c = 0; c < nc; ++c)
        if (!(a.flux[c] >= 0) || !std::isfinite(a.flux[c])) {
          out.push_back(at + ".flux: channel " + std::to_string(c) + " is negative or not finite");
          break;
        }
      if (a.map.resolution() != level.map_resolution || a.map.channels() != nc) {
        out.push_back(at + ".map: resolution " + std::to_string(a.map.resolution()) + " × " +
                      std::to_string(a.map.channels()) + " channels, expected " +
                      std::to_string(level.map_resolution) + " × " + std::to_string(nc));
        continue;
      }
      if (a.mask && (a.coverage.resolution() != a.map.resolution() || a.coverage.channels() != 1))
        out.push_back(at + ".coverage: resolution " + std::to_string(a.coverage.resolution()) +
                      " for a masked map of " + std::to_string(a.map.resolution()));
      int bx = 0, by = 0, bc = 0;
      if (!a.map.all_finite_nonnegative(&bx, &by, &bc))
        out.push_back(at + ".map: texel (" + std::to_string(bx) + ", " + std::to_string(by) + ") channel " +
                      std::to_string(bc) + " is negative or not finite");
      else if (!(std::abs(luminance_of(set.channels, a.map.integral() - a.flux)) <= tol(a.flux)))
        out.push_back(at + ".flux: differs from the integral of its map");
      if (k == 0 ? a.parent != -1 : (a.parent < 0 || std::size_t(a.parent) >= set.levels[k - 1].apls.size()))
        out.push_back(at + ".parent: " + std::to_string(a.parent) + " is not a valid index");
    }
    if (k == 0) continue;
    std::vector<glm::dvec3> child_sum(set.levels[k - 1].apls.size(), glm::dvec3(0.0));
    for (const Apl& a : level.apls)
      if (a.parent >= 0 && std::size_t(a.parent) < child_sum.size()) child_sum[a.parent] += a.flux;
    for (std::size_t p = 0; p < child_sum.size(); ++p)
      if (!(std::abs(luminance_of(set.channels, child_sum[p] - set.levels[k - 1].apls[p].flux)) <=
            tol(set.levels[k - 1].apls[p].flux)))
        out.push_back(where + ": children of levels[" + std::to_string(k - 1) + "].apls[" + std::to_string(p) +
                      "] do not sum to its flux");
  }
  return out;
}

LUMX_NAMESPACE_END
