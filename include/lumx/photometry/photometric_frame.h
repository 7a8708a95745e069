// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/photometric_frame.h — directions <-> photometric angles for Types A, B and C.
//
// Frame and formulas are stated in lumx/photometry/photometry.h. Inverse maps use atan2 on both components, never
// acos/asin of a dot product, so directions at the poles or at grazing angles cannot produce NaN
// (hard-cases.md §3 "Grazing angles").
#pragma once

#include <lumx/math/constants.h>
#include <lumx/photometry/photometry.h>

#include <glm/vec3.hpp>

#include <cmath>

LUMX_NAMESPACE_BEGIN

/// Horizontal and vertical photometric angles in degrees.
struct PhotometricAngles {
  double horizontal_deg = 0;  ///< C in [0,360) for Type C; H in (-180,180] for A and B
  double vertical_deg = 0;    ///< gamma in [0,180] for Type C; V in [-90,90] for A and B
};

/// Unit direction for photometric angles of the given type.
inline glm::dvec3 direction_from_angles(PhotometricType type, double h_deg, double v_deg) {
  const double h = h_deg * kDegToRad, v = v_deg * kDegToRad;
  switch (type) {
    case PhotometricType::C:
      return {std::sin(v) * std::cos(h), std::sin(v) * std::sin(h), -std::cos(v)};
    case PhotometricType::B:
      return {std::cos(v) * std::sin(h), std::sin(v), -std::cos(v) * std::cos(h)};
    case PhotometricType::A:
      return {std::sin(v), std::cos(v) * std::sin(h), -std::cos(v) * std::cos(h)};
  }
  return {0, 0, -1};
}

/// Photometric angles of a direction (need not be normalised; the zero vector maps to the photometric
/// zero). At a pole the horizontal angle is 0.
inline PhotometricAngles angles_from_direction(PhotometricType type, const glm::dvec3& d) {
  PhotometricAngles a;
  switch (type) {
    case PhotometricType::C: {
      const double rho = std::hypot(d.x, d.y);
      a.vertical_deg = std::atan2(rho, -d.z) * kRadToDeg;
      double c = rho > 0 ? std::atan2(d.y, d.x) * kRadToDeg : 0.0;
      if (c < 0) c += 360.0;
      if (c >= 360.0) c -= 360.0;
      a.horizontal_deg = c;
      break;
    }
    case PhotometricType::B: {
      const double rho = std::hypot(d.x, d.z);
      a.vertical_deg = std::atan2(d.y, rho) * kRadToDeg;
      a.horizontal_deg = rho > 0 ? std::atan2(d.x, -d.z) * kRadToDeg : 0.0;
      break;
    }
    case PhotometricType::A: {
      const double rho = std::hypot(d.y, d.z);
      a.vertical_deg = std::atan2(d.x, rho) * kRadToDeg;
      a.horizontal_deg = rho > 0 ? std::atan2(d.y, -d.z) * kRadToDeg : 0.0;
      break;
    }
  }
  return a;
}

LUMX_NAMESPACE_END
