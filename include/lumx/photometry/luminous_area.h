// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/luminous_area.h — the luminous parts of a luminaire as its file describes them, and
// their area projected towards a direction: the A_p of the luminance L = I / A_p and of a glare source's
// solid angle ω = A_p / r² (CIE 117:1995 §4.2).
#pragma once

#include <lumx/photometry/photometry.h>

#include <glm/vec3.hpp>

#include <string>

LUMX_NAMESPACE_BEGIN

/// Luminous parts in the photometric frame (+X = C0, +Y = C90, -Z = nadir), metres.
struct LuminousArea {
  enum class Kind {
    none,        ///< a point source: no luminous area is known
    rectangle,   ///< horizontal bottom face size_x × size_y, with optional vertical luminous sides
    ellipse,     ///< horizontal elliptic (circular) bottom face of diameters size_x, size_y, optional sides
    sphere,      ///< sphere (ellipsoids are taken as the sphere of their mean diameter), diameter size_x
    cylinder_x,  ///< horizontal cylinder along X: length size_x, diameter size_y
    cylinder_y,  ///< horizontal cylinder along Y: length size_y, diameter size_x
    disk_x,      ///< vertical disk facing ±X, diameters size_y (width) × height (side_height_m[0])
  };
  Kind kind = Kind::none;
  double size_x_m = 0;  ///< extent along X (C0-C180)
  double size_y_m = 0;  ///< extent along Y (C90-C270)
  /// Luminous height of the side facing C0, C90, C180, C270 (EULUMDAT lines 18-21; IES: the opening's
  /// height on all four sides).
  double side_height_m[4] = {0, 0, 0, 0};

  /// Area of the luminous parts seen from unit direction `d` (from the luminaire towards the viewer),
  /// m² (>= 0).
  double projected_m2(const glm::dvec3& d) const;
};

/// The luminous area of `p`: EULUMDAT's luminous area (lines 16-21) for EULUMDAT-read data, otherwise
/// the IES luminous opening (LM-63-2019 §5.11 Table 1). The rectangle's length lies along X (C0), as
/// lumx maps both formats (docs/photometry.md). Kind::none for a point or an unknown sign pattern.
LuminousArea luminous_area(const Photometry& p);

/// Why luminous_area(p) is Kind::none, in words for an error message: a point (all sizes zero) or an
/// IES sign pattern LM-63-2019 Table 1 does not list.
std::string missing_luminous_area_reason(const Photometry& p);

LUMX_NAMESPACE_END
