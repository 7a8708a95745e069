// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/math/constants.h>
#include <lumx/photometry/zonal_flux.h>

#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

LUMX_NAMESPACE_BEGIN

double zone_flux_lm(const IntensityTable& t, double gamma_min_deg, double gamma_max_deg, double c_min_deg,
                    double c_max_deg) {
  const double g0 = std::clamp(gamma_min_deg, 0.0, 180.0), g1 = std::clamp(gamma_max_deg, 0.0, 180.0);
  if (!(g1 > g0) || !(c_max_deg > c_min_deg)) return 0.0;
  const double span_c = std::min(360.0, c_max_deg - c_min_deg);
  if (t.type() == PhotometricType::C && span_c >= 360.0) return t.flux_lm(g0, g1);
  const int ng = std::max(1, static_cast<int>(std::ceil((g1 - g0) / 0.25 - 1e-9)));
  const int nc = std::max(1, static_cast<int>(std::ceil(span_c / 0.5 - 1e-9)));
  const double dg = (g1 - g0) / ng, dc = span_c / nc;
  double sum = 0;
  for (int ig = 0; ig < ng; ++ig) {
    const double g = (g0 + (ig + 0.5) * dg) * kDegToRad;
    const double sg = std::sin(g), cg = std::cos(g);
    double ring = 0;
    for (int ic = 0; ic < nc; ++ic) {
      const double c = (c_min_deg + (ic + 0.5) * dc) * kDegToRad;
      ring += t.intensity(glm::dvec3(sg * std::cos(c), sg * std::sin(c), -cg));
    }
    sum += ring * sg;
  }
  return sum * dg * kDegToRad * dc * kDegToRad;
}

ZonalLumenSummary zonal_lumen_summary(const Photometry& p) {
  const IntensityTable t(p);
  ZonalLumenSummary s;
  s.luminaire_lm = zone_flux_lm(t, 0, 180);
  const double lamp = p.rated_lamp_flux_lm();
  if (!p.absolute && lamp > 0) s.lamp_lm = lamp;
  auto zone = [&](double a, double b) {
    Zone z;
    z.gamma_min_deg = a;
    z.gamma_max_deg = b;
    z.lm = zone_flux_lm(t, a, b);
    if (s.lamp_lm) z.percent_lamp = 100 * z.lm / *s.lamp_lm;
    z.percent_luminaire = s.luminaire_lm > 0 ? 100 * z.lm / s.luminaire_lm : 0.0;
    return z;
  };
  for (auto [a, b] : {std::pair{0, 30}, {0, 40}, {0, 60}, {0, 90}, {90, 120}, {90, 130}, {90, 150}, {90, 180}, {0, 180}})
    s.summary.push_back(zone(a, b));
  for (int k = 0; k < 18; ++k) s.ten_degree.push_back(zone(10.0 * k, 10.0 * (k + 1)));
  return s;
}

std::string CieFluxCode::str() const {
  char buf[96];
  if (n5)
    std::snprintf(buf, sizeof buf, "%.0f %.0f %.0f %.0f %.0f", n1, n2, n3, n4, *n5);
  else
    std::snprintf(buf, sizeof buf, "%.0f %.0f %.0f %.0f -", n1, n2, n3, n4);
  return buf;
}

CieFluxCode cie_flux_code(const Photometry& p) {
  const IntensityTable t(p);
  CieFluxCode c;
  const double all = zone_flux_lm(t, 0, 180), down = zone_flux_lm(t, 0, 90);
  // Cones of pi/2, pi and 3 pi/2 sr around nadir: cos gamma = 3/4, 1/2, 1/4.
  if (down > 0) {
    c.n1 = 100 * zone_flux_lm(t, 0, std::acos(0.75) * kRadToDeg) / down;
    c.n2 = 100 * zone_flux_lm(t, 0, 60) / down;
    c.n3 = 100 * zone_flux_lm(t, 0, std::acos(0.25) * kRadToDeg) / down;
  }
  if (all > 0) c.n4 = 100 * down / all;
  const double lamp = p.rated_lamp_flux_lm();
  if (!p.absolute && lamp > 0) c.n5 = 100 * all / lamp;
  return c;
}

LUMX_NAMESPACE_END
