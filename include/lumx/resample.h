// lumx/resample.h — re-gridding a photometry, and converting between photometric types A, B and C.
//
// Resampling evaluates the source's bilinear interpolant (lumx/intensity_table.h) at the new grid's
// directions, so values at directions the two grids share are reproduced exactly, and elsewhere the
// error is that of bilinear interpolation of the source: O(h^2 * curvature), h the source's angular
// step. Flux is preserved to the same order; tests bound both on real files (1 degree target grids keep
// flux within 0.2 %).
#pragma once

#include <lumx/intensity_table.h>
#include <lumx/photometry.h>

#include <vector>

LUMX_NAMESPACE_BEGIN

/// Evenly spaced angles first, first + step, ..., last (last included; step > 0).
inline std::vector<double> angle_range(double first, double last, double step) {
  std::vector<double> v;
  const long n = static_cast<long>(std::floor((last - first) / step + 1e-9));
  for (long i = 0; i <= n; ++i) v.push_back(first + static_cast<double>(i) * step);
  if (v.empty() || std::abs(v.back() - last) > 1e-9) v.push_back(last);
  return v;
}

/// `p` sampled on a new grid of type `to` (no symmetry). Descriptive data (lamps, keywords, opening)
/// is copied; TILT data too.
inline Photometry resample(const Photometry& p, PhotometricType to, const std::vector<double>& horizontal_deg,
                           const std::vector<double>& vertical_deg) {
  const IntensityTable t(p);
  Photometry out = p;
  out.type = to;
  out.symmetry = Symmetry::none;
  out.horizontal_deg = horizontal_deg;
  out.vertical_deg = vertical_deg;
  out.candela.assign(horizontal_deg.size() * vertical_deg.size(), 0.0);
  out.source.horizontal_lines.clear();
  out.source.vertical_lines.clear();
  out.source.candela_lines.clear();
  for (std::size_t ih = 0; ih < horizontal_deg.size(); ++ih)
    for (std::size_t iv = 0; iv < vertical_deg.size(); ++iv)
      out.at(ih, iv) = t.intensity(direction_from_angles(to, horizontal_deg[ih], vertical_deg[iv]));
  return out;
}

/// Type C copy of `p` on a regular grid: C = 0..360 by `step_c_deg`, gamma = 0..180 by `step_gamma_deg`.
/// A Type C input is returned unchanged.
inline Photometry to_type_c(const Photometry& p, double step_c_deg = 1.0, double step_gamma_deg = 1.0) {
  if (p.type == PhotometricType::C) return p;
  return resample(p, PhotometricType::C, angle_range(0, 360, step_c_deg), angle_range(0, 180, step_gamma_deg));
}

LUMX_NAMESPACE_END
