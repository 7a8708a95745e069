// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Inline definitions for lumx/photometry/photometry.h. Not a public header on its own.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>

LUMX_NAMESPACE_BEGIN

inline const char* to_string(Symmetry s) {
  switch (s) {
    case Symmetry::none: return "none";
    case Symmetry::rotational: return "rotational";
    case Symmetry::plane_c0_c180: return "C0-C180 plane";
    case Symmetry::plane_c90_c270: return "C90-C270 plane";
    case Symmetry::quadrant: return "quadrant (C0-C180 and C90-C270)";
    case Symmetry::lateral: return "lateral (H = -H)";
  }
  return "?";
}

inline const char* to_string(PhotometricType t) {
  switch (t) {
    case PhotometricType::A: return "A";
    case PhotometricType::B: return "B";
    case PhotometricType::C: return "C";
  }
  return "?";
}

inline const char* to_string(LuminousShape s) {
  switch (s) {
    case LuminousShape::point: return "point";
    case LuminousShape::rectangle: return "rectangle";
    case LuminousShape::rectangle_with_luminous_sides: return "rectangle with luminous sides";
    case LuminousShape::circle: return "circle";
    case LuminousShape::ellipse: return "ellipse";
    case LuminousShape::vertical_cylinder: return "vertical cylinder";
    case LuminousShape::vertical_elliptical_cylinder: return "vertical elliptical cylinder";
    case LuminousShape::sphere: return "sphere";
    case LuminousShape::ellipsoid: return "ellipsoidal spheroid";
    case LuminousShape::horizontal_cylinder_along_length: return "horizontal cylinder along length";
    case LuminousShape::horizontal_elliptical_cylinder_along_length:
      return "horizontal elliptical cylinder along length";
    case LuminousShape::horizontal_cylinder_along_width: return "horizontal cylinder along width";
    case LuminousShape::horizontal_elliptical_cylinder_along_width:
      return "horizontal elliptical cylinder along width";
    case LuminousShape::vertical_circle: return "vertical circle";
    case LuminousShape::vertical_ellipse: return "vertical ellipse";
    case LuminousShape::unknown: return "unknown";
  }
  return "?";
}

inline LuminousShape LuminousOpening::shape() const {
  // Sign of each dimension: -1, 0, +1.
  auto sg = [](double v) { return v > 0 ? 1 : (v < 0 ? -1 : 0); };
  const int w = sg(width_m), l = sg(length_m), h = sg(height_m);
  auto same = [](double a, double b) { return std::abs(std::abs(a) - std::abs(b)) <= 1e-9 * (std::abs(a) + std::abs(b)); };
  if (w == 0 && l == 0 && h == 0) return LuminousShape::point;
  if (w > 0 && l > 0 && h == 0) return LuminousShape::rectangle;
  if (w > 0 && l > 0 && h > 0) return LuminousShape::rectangle_with_luminous_sides;
  if (w < 0 && l < 0 && h == 0)
    return same(width_m, length_m) ? LuminousShape::circle : LuminousShape::ellipse;
  if (w < 0 && l < 0 && h > 0)
    return same(width_m, length_m) ? LuminousShape::vertical_cylinder
                                   : LuminousShape::vertical_elliptical_cylinder;
  if (w < 0 && l < 0 && h < 0)
    return (same(width_m, length_m) && same(width_m, height_m)) ? LuminousShape::sphere
                                                                : LuminousShape::ellipsoid;
  if (w < 0 && l > 0 && h < 0)
    return same(width_m, height_m) ? LuminousShape::horizontal_cylinder_along_length
                                   : LuminousShape::horizontal_elliptical_cylinder_along_length;
  if (w > 0 && l < 0 && h < 0)
    return same(length_m, height_m) ? LuminousShape::horizontal_cylinder_along_width
                                    : LuminousShape::horizontal_elliptical_cylinder_along_width;
  if (w < 0 && l == 0 && h < 0)
    return same(width_m, height_m) ? LuminousShape::vertical_circle : LuminousShape::vertical_ellipse;
  return LuminousShape::unknown;
}

inline double LuminousOpening::max_dimension_m() const {
  return std::max({std::abs(width_m), std::abs(length_m), std::abs(height_m)});
}

inline double TiltTable::multiplier_at(double tilt_deg) const {
  const std::size_t n = std::min(angles_deg.size(), multipliers.size());
  if (n == 0) return 1.0;
  if (n == 1 || !(tilt_deg > angles_deg[0])) return multipliers[0];  // also NaN: never index past the end
  if (tilt_deg >= angles_deg[n - 1]) return multipliers[n - 1];
  const auto it = std::upper_bound(angles_deg.begin(), angles_deg.begin() + static_cast<long>(n), tilt_deg);
  const std::size_t i = static_cast<std::size_t>(it - angles_deg.begin()) - 1;
  const double t = (tilt_deg - angles_deg[i]) / (angles_deg[i + 1] - angles_deg[i]);
  return (1 - t) * multipliers[i] + t * multipliers[i + 1];
}

inline bool is_lm63_2019_file_generation_type(double v) {
  static const double kValid[] = {1.00001, 1.00010, 1.00000, 1.00100, 1.01000,
                                  1.01100, 1.10000, 1.10100, 1.11000, 1.11100};
  for (double k : kValid)
    if (std::abs(v - k) < 5e-6) return true;
  return false;
}

inline double Photometry::rated_lamp_flux_lm() const {
  if (absolute) return 0;
  double sum = 0;
  for (const auto& l : lamp_sets) sum += l.flux_lm;
  return sum;
}

inline int Photometry::lamp_count() const {
  int n = 0;
  for (const auto& l : lamp_sets) n += std::abs(l.count);
  return n;
}

inline const Keyword* Photometry::find_keyword(const std::string& name) const {
  for (const auto& k : keywords)
    if (k.name == name) return &k;
  return nullptr;
}

inline Photometry apply_tilt(const Photometry& p, double tilt_deg) {
  Photometry out = p;
  if (!p.tilt) return out;
  const double m = p.tilt->multiplier_at(tilt_deg);
  for (double& c : out.candela) c *= m;
  return out;
}

LUMX_NAMESPACE_END
