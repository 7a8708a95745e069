// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/math/constants.h>
#include <lumx/photometry/cone_diagram.h>

#include <glm/vec3.hpp>

#include <cmath>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN

ConeDiagram cone_diagram(const IntensityTable& t, const std::vector<double>& distances_m) {
  ConeDiagram cd;
  cd.c0_c180 = spread(t, SpreadPlane::c0_c180);
  cd.c90_c270 = spread(t, SpreadPlane::c90_c270);
  const double a = 0.5 * cd.c0_c180.beam_deg, b = 0.5 * cd.c90_c270.beam_deg;  // half-angles
  if (!(a > 0 && a <= 85 && b > 0 && b <= 85))
    throw std::invalid_argument("cone diagram: the beam must be between 0 and 170 degrees wide in both planes");
  const double ta = std::tan(a * kDegToRad), tb = std::tan(b * kDegToRad);
  // Flux inside the elliptic cone tan² g (cos² C / ta² + sin² C / tb²) <= 1, midpoint rule 0.1° × 1°.
  constexpr int nc = 360;
  const int ng = 900;
  const double gmax = std::max(a, b) * kDegToRad, dg = gmax / ng, dc = 2 * kPi / nc;
  double flux = 0;
  for (int ig = 0; ig < ng; ++ig) {
    const double g = (ig + 0.5) * dg, tg = std::tan(g), sg = std::sin(g), cg = std::cos(g);
    for (int ic = 0; ic < nc; ++ic) {
      const double c = (ic + 0.5) * dc, cc = std::cos(c), sc = std::sin(c);
      if (tg * tg * (cc * cc / (ta * ta) + sc * sc / (tb * tb)) > 1) continue;
      flux += t.intensity(glm::dvec3(sg * cc, sg * sc, -cg)) * sg * dg * dc;
    }
  }
  cd.beam_flux_lm = flux;
  const double axis_cd = t.intensity(glm::dvec3(0, 0, -1));
  auto diameter = [](double d, double full_deg) { return 2 * d * std::tan(0.5 * std::min(full_deg, 170.0) * kDegToRad); };
  for (double d : distances_m) {
    if (!(d > 0) || !std::isfinite(d)) throw std::invalid_argument("cone diagram: distances must be > 0");
    ConeRow r;
    r.distance_m = d;
    r.beam_diameter_m[0] = diameter(d, cd.c0_c180.beam_deg);
    r.beam_diameter_m[1] = diameter(d, cd.c90_c270.beam_deg);
    r.field_diameter_m[0] = diameter(d, cd.c0_c180.field_deg);
    r.field_diameter_m[1] = diameter(d, cd.c90_c270.field_deg);
    r.center_lux = axis_cd / (d * d);
    r.mean_beam_lux = flux / (kPi * d * d * ta * tb);
    cd.rows.push_back(r);
  }
  return cd;
}

LUMX_NAMESPACE_END
