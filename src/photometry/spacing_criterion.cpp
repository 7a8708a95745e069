// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/math/constants.h>
#include <lumx/photometry/spacing_criterion.h>

#include <glm/vec3.hpp>

#include <cmath>

LUMX_NAMESPACE_BEGIN

std::optional<double> spacing_criterion(const IntensityTable& t, double c_deg) {
  const double nadir = t.intensity(glm::dvec3(0, 0, -1));
  if (!(nadir > 0)) return std::nullopt;
  const double c = c_deg * kDegToRad;
  auto excess = [&](double g_deg) {
    const double g = g_deg * kDegToRad, s = std::sin(g), cg = std::cos(g);
    const glm::dvec3 a(s * std::cos(c), s * std::sin(c), -cg), b(-a.x, -a.y, a.z);
    return (t.intensity(a) + t.intensity(b)) * cg * cg * cg - nadir;
  };
  constexpr double kStep = 0.05;  // degrees; the crossing is then refined by bisection
  double lo = 0;
  for (double g = kStep; g <= 85.0 + 1e-9; g += kStep) {
    if (excess(g) <= 0) {
      double hi = g;
      for (int it = 0; it < 50; ++it) {
        const double mid = 0.5 * (lo + hi);
        if (excess(mid) > 0)
          lo = mid;
        else
          hi = mid;
      }
      return 2 * std::tan(0.5 * (lo + hi) * kDegToRad);
    }
    lo = g;
  }
  return std::nullopt;
}

SpacingCriterion spacing_criteria(const IntensityTable& t) {
  return SpacingCriterion{spacing_criterion(t, 0), spacing_criterion(t, 90), spacing_criterion(t, 45)};
}

LUMX_NAMESPACE_END
