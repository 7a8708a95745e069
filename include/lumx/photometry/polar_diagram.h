// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/polar_diagram.h — the data behind a datasheet polar intensity diagram ("polar LDC"). No I/O, no
// drawing: converters/polar_plot.cpp renders what make_polar_diagram() computes.
//
// The diagram shows two vertical planes through the photometric axis, each as one closed curve of
// intensity against the signed angle theta from nadir:
//   - the C0-C180 plane (the X-Z plane of the photometric frame): theta > 0 is the C0 half (+X), drawn on
//     the right; theta < 0 is the C180 half (-X), mirrored onto the left;
//   - the C90-C270 plane (the Y-Z plane): theta > 0 is the C90 half (+Y), theta < 0 the C270 half (-Y).
// theta = 0 is nadir (drawn at the bottom), theta = +-180 is the zenith (top), |theta| = 90 the horizon.
// Each curve is sampled every `step_deg` (0.5 degree by default) over [-180, 180], both ends included, by
// evaluating IntensityTable::intensity() towards plane_direction(plane, theta) (lumx/photometry/metrics.h).
// Because sampling goes through directions, Types A and B need no special case: the X-Z plane is their
// V = 0 (Type B) or H = 0 (Type A) plane and the Y-Z plane the other one; only the names differ.
//
// Values are in the diagram's unit: cd/klm for relative photometry (!p.absolute and a rated lamp flux > 0;
// value = cd * 1000 / rated lamp flux), otherwise cd. The rings are a "nice" step (1, 2, 2.5 or 5 times a
// power of ten) chosen so that 4 to 6 rings cover the larger of the two curves' maxima plus 2 % headroom.
#pragma once

#include <lumx/core/diagnostic.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/metrics.h>
#include <lumx/photometry/photometry.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// One sample of a polar curve.
struct PolarPoint {
  double angle_deg = 0;  ///< signed angle from nadir, degrees, in [-180, 180] (+ = C0 or C90 side)
  double value = 0;      ///< intensity in the diagram's unit (PolarDiagram::unit), >= 0
};

/// One plane of the diagram.
struct PolarCurve {
  SpreadPlane plane = SpreadPlane::c0_c180;
  std::string name;            ///< legend text, e.g. "C0 – C180" (UTF-8)
  std::string positive_side;   ///< the half drawn on the right (theta > 0), e.g. "C0"
  std::string negative_side;   ///< the half drawn on the left (theta < 0), e.g. "C180"
  std::vector<PolarPoint> points;  ///< increasing angle, from -180 to +180 inclusive
  double max_value = 0;        ///< largest sample value, in the diagram's unit
};

/// Ring layout: `ring_count` circles at ring_step, 2 * ring_step, ..., outer_radius = ring_count * ring_step.
struct PolarRingScale {
  double ring_step = 1;
  int ring_count = 4;
  double outer_radius = 4;
};

struct PolarDiagramOptions {
  double step_deg = 0.5;  ///< sampling step of the curves, degrees; must divide into (0, 180]
  bool force_cd = false;  ///< plot absolute cd even for relative photometry
};

/// Everything a renderer needs. Values of `c0_c180`, `c90_c270` and the rings are in `unit`.
struct PolarDiagram {
  PolarCurve c0_c180;
  PolarCurve c90_c270;
  bool relative = false;     ///< true if values are cd/klm
  std::string unit = "cd";   ///< "cd/klm" or "cd"
  double scale = 1;          ///< unit value = cd * scale (1000 / rated lamp flux for cd/klm, else 1)
  PolarRingScale rings;      ///< covers 1.02 * max(c0_c180.max_value, c90_c270.max_value)

  std::string title;         ///< luminaire name, else catalogue number, else the source file's name
  std::string file_name;     ///< the source file's name without folders (may be empty)
  double luminaire_flux_lm = 0;   ///< total flux of the interpolated table (IntensityTable::flux_lm)
  double rated_lamp_flux_lm = 0;  ///< sum of the lamp sets (0 for absolute photometry)
  double max_cd = 0;              ///< largest stored intensity in the whole file, cd (any plane)
  double max_horizontal_deg = 0;  ///< where that maximum is stored (C or H)
  double max_vertical_deg = 0;    ///< (gamma or V)
};

/// make_polar_diagram() sizes the rings for this multiple of the curves' maximum.
inline constexpr double kPolarRingHeadroom = 1.02;

/// Ring step and count for a curve maximum `max_value` (any unit): the smallest step m * 10^k,
/// m in {1, 2, 2.5, 5}, with ceil(max_value / step) <= 6 rings. Consecutive candidates differ by at most a
/// factor 2, so the step one below needs more than 6 rings, hence this one needs more than 3: the count is
/// always 4 to 6 and outer_radius >= max_value. A maximum of 0 (or not finite) gives 4 rings of 1.
inline PolarRingScale nice_ring_scale(double max_value) {
  PolarRingScale s;
  if (!(max_value > 0) || !std::isfinite(max_value)) return s;
  static const double kMantissas[] = {1.0, 2.0, 2.5, 5.0};
  // Start a decade below the one that holds max_value / 6 and walk up.
  int k = static_cast<int>(std::floor(std::log10(max_value / 6.0))) - 1;
  for (int guard = 0; guard < 8; ++guard, ++k) {
    const double p10 = std::pow(10.0, k);
    for (double m : kMantissas) {
      const double step = m * p10;
      // The fewest rings n with n * step >= max_value, checked on the products actually used, so that
      // a maximum of exactly 5 * step gives 5 rings (not 6 through rounding of the quotient).
      double n = std::max(1.0, std::ceil(max_value / step));
      while (n > 1 && (n - 1) * step >= max_value) n -= 1;
      while (n * step < max_value) n += 1;
      if (n <= 6) {
        s.ring_step = step;
        s.ring_count = static_cast<int>(n);
        s.outer_radius = n * step;
        return s;
      }
    }
  }
  return s;  // not reached for finite positive input
}

/// A ring value as a label: as many decimals as the step needs (0 for steps >= 1, "2.5" for 2.5,
/// "0.25" for 0.25), never scientific notation for steps down to 1e-6.
inline std::string format_ring_value(double value, double ring_step) {
  int decimals = 0;
  for (double s = ring_step; decimals < 6; ++decimals, s *= 10) {
    if (std::abs(s - std::round(s)) <= 1e-9 * std::max(1.0, std::abs(s))) break;
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

namespace detail {
inline std::string polar_base_name(const std::string& path) {
  const std::size_t slash = path.find_last_of("/\\");
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

inline std::string polar_first_line(const std::string& s) {
  std::string line = s.substr(0, s.find('\n'));
  const auto b = line.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  const auto e = line.find_last_not_of(" \t\r");
  return line.substr(b, e - b + 1);
}
}  // namespace detail

/// The diagram's default title: the IES [LUMINAIRE] keyword, else the EULUMDAT luminaire name, else
/// [LUMCAT] / the EULUMDAT luminaire number, else the source file's name, else "Photometry".
inline std::string polar_default_title(const Photometry& p) {
  auto keyword = [&](const char* name) {
    const Keyword* k = p.find_keyword(name);
    return k ? detail::polar_first_line(k->value) : std::string();
  };
  for (std::string t : {keyword("LUMINAIRE"), detail::polar_first_line(p.ldt.luminaire_name), keyword("LUMCAT"),
                        detail::polar_first_line(p.ldt.luminaire_number),
                        detail::polar_base_name(p.source.file)})
    if (!t.empty()) return t;
  return "Photometry";
}

/// Samples one plane of `t`: points at -180, -180 + step, ..., 180 (the last one forced to exactly 180),
/// each value = t.intensity(plane_direction(plane, theta)) * scale, negatives and NaN clamped to 0.
inline std::vector<PolarPoint> sample_polar_plane(const IntensityTable& t, SpreadPlane plane, double scale,
                                                  double step_deg = 0.5) {
  if (!(step_deg > 0) || step_deg > 180)
    throw std::invalid_argument("sample_polar_plane: step must be in (0, 180] degrees");
  const int n = static_cast<int>(std::ceil(360.0 / step_deg - 1e-9));
  std::vector<PolarPoint> pts;
  pts.reserve(static_cast<std::size_t>(n) + 1);
  for (int i = 0; i <= n; ++i) {
    const double theta = i == n ? 180.0 : -180.0 + i * step_deg;
    double v = t.intensity(plane_direction(plane, theta)) * scale;
    if (!(v > 0)) v = 0;  // also NaN
    pts.push_back({theta, v});
  }
  return pts;
}

/// Computes the diagram for `p`. Throws lumx::Error (field "intensity table") if `p`'s table is unusable
/// (see IntensityTable's constructor), or (field "step") for a bad options.step_deg.
PolarDiagram make_polar_diagram(const Photometry& p, const PolarDiagramOptions& options = {});

LUMX_NAMESPACE_END
