// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/math/constants.h>
#include <lumx/photometry/bug_rating.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/zonal_flux.h>

#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <initializer_list>

LUMX_NAMESPACE_BEGIN
namespace {

// TM-15-11 Addendum A limits, lumens, for ratings 0 … 4 (above the last: 5).
constexpr double kBacklightBL[5] = {110, 500, 1000, 2500, 5000};
constexpr double kBacklightBM[5] = {220, 1000, 2500, 5000, 8500};
constexpr double kBacklightBH[5] = {110, 500, 1000, 2500, 5000};
constexpr double kUplightUL[5] = {0, 10, 50, 500, 1000};
constexpr double kUplightUH[5] = {0, 10, 50, 500, 1000};
constexpr double kGlareFVH[5] = {10, 100, 225, 500, 750};  // also BVH
constexpr double kGlareFH[5] = {660, 1800, 5000, 7500, 12000};
constexpr double kGlareBH[5] = {110, 500, 1000, 2500, 5000};  // asymmetric types; Type V uses kGlareFH

// The lowest rating whose limits all hold.
int rating(std::initializer_list<std::pair<double, const double*>> zones) {
  for (int r = 0; r < 5; ++r) {
    bool ok = true;
    for (const auto& [lm, limits] : zones) ok = ok && lm <= limits[r] + 1e-9;
    if (ok) return r;
  }
  return 5;
}

bool looks_quadrilateral_symmetric(const Photometry& p, const IntensityTable& t) {
  if (p.type == PhotometricType::C && p.symmetry == Symmetry::rotational) return true;
  const double peak = t.max_cd();
  if (!(peak > 0)) return true;
  for (double g = 0; g <= 180; g += 2.5)
    for (double c = 0; c < 360; c += 5) {
      auto dir = [&](double cc) {
        const double gr = g * kDegToRad, cr = cc * kDegToRad;
        return glm::dvec3(std::sin(gr) * std::cos(cr), std::sin(gr) * std::sin(cr), -std::cos(gr));
      };
      if (std::abs(t.intensity(dir(c)) - t.intensity(dir(c + 90))) > 0.02 * peak) return false;
    }
  return true;
}

}  // namespace

std::string BugRating::str() const {
  return "B" + std::to_string(b) + " U" + std::to_string(u) + " G" + std::to_string(g);
}

BugRating bug_rating(const BugZones& z, bool quadrilateral_symmetric) {
  BugRating r;
  r.zones = z;
  r.quadrilateral_symmetric = quadrilateral_symmetric;
  r.b = rating({{z.bl, kBacklightBL}, {z.bm, kBacklightBM}, {z.bh, kBacklightBH}});
  r.u = rating({{z.ul, kUplightUL}, {z.uh, kUplightUH}});
  r.g = rating({{z.fvh, kGlareFVH},
                {z.bvh, kGlareFVH},
                {z.fh, kGlareFH},
                {z.bh, quadrilateral_symmetric ? kGlareFH : kGlareBH}});
  return r;
}

BugRating bug_rating(const Photometry& p, const BugOptions& o) {
  const IntensityTable t(p);
  const double f0 = o.forward_c_deg - 90, b0 = o.forward_c_deg + 90;  // front: C in [f0, f0 + 180]
  BugZones z;
  z.fl = zone_flux_lm(t, 0, 30, f0, f0 + 180);
  z.fm = zone_flux_lm(t, 30, 60, f0, f0 + 180);
  z.fh = zone_flux_lm(t, 60, 80, f0, f0 + 180);
  z.fvh = zone_flux_lm(t, 80, 90, f0, f0 + 180);
  z.bl = zone_flux_lm(t, 0, 30, b0, b0 + 180);
  z.bm = zone_flux_lm(t, 30, 60, b0, b0 + 180);
  z.bh = zone_flux_lm(t, 60, 80, b0, b0 + 180);
  z.bvh = zone_flux_lm(t, 80, 90, b0, b0 + 180);
  z.ul = zone_flux_lm(t, 90, 100);
  z.uh = zone_flux_lm(t, 100, 180);
  const bool quad = o.quadrilateral_symmetric ? *o.quadrilateral_symmetric : looks_quadrilateral_symmetric(p, t);
  return bug_rating(z, quad);
}

LUMX_NAMESPACE_END
