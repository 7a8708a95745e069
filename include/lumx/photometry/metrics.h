// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/metrics.h — the figures a datasheet quotes: flux, peak, beam and field angles,
// downward flux fraction, light output ratio.
#pragma once

#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/photometry.h>

#include <glm/vec3.hpp>

#include <cmath>
#include <optional>

LUMX_NAMESPACE_BEGIN

/// Which vertical plane through the photometric axis a spread is measured in.
enum class SpreadPlane {
  c0_c180,   ///< the X-Z plane (for Types A/B: the horizontal spread, V = 0)
  c90_c270,  ///< the Y-Z plane (for Types A/B: the vertical spread, H = 0)
};

/// Beam (50 %) and field (10 %) angles of one plane, degrees (full angles).
struct Spread {
  double beam_deg = 0;
  double field_deg = 0;
  double peak_cd = 0;         ///< largest intensity in that plane
  double peak_angle_deg = 0;  ///< signed angle of the peak from nadir (+ towards C0 or C90)
};

/// Direction in `plane` at signed angle `theta_deg` from nadir (+X or +Y side for theta > 0).
inline glm::dvec3 plane_direction(SpreadPlane plane, double theta_deg) {
  const double t = theta_deg * kDegToRad;
  return plane == SpreadPlane::c0_c180 ? glm::dvec3(std::sin(t), 0, -std::cos(t))
                                       : glm::dvec3(0, std::sin(t), -std::cos(t));
}

/// Beam and field angles: within the plane, from the peak outwards on each side, the angles where the
/// intensity first falls to 50 % (beam) and 10 % (field) of the plane's peak (CIE/NEMA convention),
/// located by linear interpolation between 0.05 degree samples of the interpolant. A side that never
/// falls below the threshold within 180 degrees of nadir contributes up to +-180 (an angle of 360 means
/// "never falls").
inline Spread spread(const IntensityTable& t, SpreadPlane plane) {
  constexpr int kSteps = 7200;  // 0.05 degree over [-180, 180]
  std::vector<double> I(kSteps + 1);
  auto angle = [](int k) { return -180.0 + 360.0 * k / kSteps; };
  int peak = 0;
  for (int k = 0; k <= kSteps; ++k) {
    I[static_cast<std::size_t>(k)] = t.intensity(plane_direction(plane, angle(k)));
    if (I[static_cast<std::size_t>(k)] > I[static_cast<std::size_t>(peak)]) peak = k;
  }
  Spread s;
  s.peak_cd = I[static_cast<std::size_t>(peak)];
  s.peak_angle_deg = angle(peak);
  if (!(s.peak_cd > 0)) return s;
  auto width = [&](double frac) {
    const double thr = frac * s.peak_cd;
    double lo = -180.0, hi = 180.0;
    for (int k = peak; k > 0; --k) {
      const double a = I[static_cast<std::size_t>(k)], b = I[static_cast<std::size_t>(k - 1)];
      if (b < thr) {  // crossing between k-1 and k
        lo = angle(k - 1) + (angle(k) - angle(k - 1)) * (thr - b) / (a - b);
        break;
      }
    }
    for (int k = peak; k < kSteps; ++k) {
      const double a = I[static_cast<std::size_t>(k)], b = I[static_cast<std::size_t>(k + 1)];
      if (b < thr) {
        hi = angle(k) + (angle(k + 1) - angle(k)) * (a - thr) / (a - b);
        break;
      }
    }
    return hi - lo;
  };
  s.beam_deg = width(0.5);
  s.field_deg = width(0.1);
  return s;
}

/// Fraction of the flux emitted downwards (direction z < 0), in [0, 1], exact for the table's bilinear
/// interpolant: for Type C the polar integral split at gamma = 90; for Types A and B, whose polar axis is
/// horizontal, the horizontal angles H in [−90, 90] (z = −cos V cos H).
inline double downward_flux_fraction(const IntensityTable& t) {
  const double total = t.flux_lm();
  if (!(total > 0)) return 0.0;
  if (t.type() == PhotometricType::C) return t.flux_lm(0.0, 90.0) / total;
  return std::clamp(t.flux_lm_horizontal(-90.0, 90.0) / total, 0.0, 1.0);
}

/// Datasheet summary of a Photometry.
struct PhotometricSummary {
  double flux_lm = 0;                 ///< luminaire flux from zonal integration
  double rated_lamp_flux_lm = 0;      ///< sum of lamp sets (0 if absolute)
  double max_cd = 0;
  double max_horizontal_deg = 0, max_vertical_deg = 0;  ///< where the tabulated peak lies
  Spread c0_c180, c90_c270;
  double downward_fraction = 0;       ///< 0..1
  std::optional<double> light_output_ratio;  ///< flux / rated lamp flux; none for absolute photometry
  double efficacy_lm_per_w = 0;       ///< flux / input watts (0 if watts unknown)
};

inline PhotometricSummary summarize(const Photometry& p) {
  const IntensityTable t(p);
  PhotometricSummary s;
  s.flux_lm = t.flux_lm();
  s.rated_lamp_flux_lm = p.rated_lamp_flux_lm();
  for (std::size_t ih = 0; ih < p.num_horizontal(); ++ih)
    for (std::size_t iv = 0; iv < p.num_vertical(); ++iv)
      if (p.at(ih, iv) > s.max_cd) {
        s.max_cd = p.at(ih, iv);
        s.max_horizontal_deg = p.horizontal_deg[ih];
        s.max_vertical_deg = p.vertical_deg[iv];
      }
  s.c0_c180 = spread(t, SpreadPlane::c0_c180);
  s.c90_c270 = spread(t, SpreadPlane::c90_c270);
  s.downward_fraction = downward_flux_fraction(t);
  if (!p.absolute && s.rated_lamp_flux_lm > 0) s.light_output_ratio = s.flux_lm / s.rated_lamp_flux_lm;
  double watts = p.input_watts;
  if (!(watts > 0))
    for (const auto& l : p.lamp_sets) watts += l.watts;
  if (watts > 0) s.efficacy_lm_per_w = s.flux_lm / watts;
  return s;
}

LUMX_NAMESPACE_END
