// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/cone_diagram.h — the cone diagram of a downlight or spot: at distances along the
// nadir axis, the diameters of the beam (50 % of the plane's peak) and field (10 %) cones on a plane
// across the axis, the illuminance on the axis and the mean illuminance over the beam's footprint.
#pragma once

#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/metrics.h>

#include <vector>

LUMX_NAMESPACE_BEGIN

struct ConeRow {
  double distance_m = 0;
  double beam_diameter_m[2] = {0, 0};   ///< in C0-C180 and C90-C270: 2 d tan(beam angle / 2)
  double field_diameter_m[2] = {0, 0};  ///< same for the field angle
  double center_lux = 0;                ///< I(nadir) / d²
  double mean_beam_lux = 0;             ///< flux inside the beam cone / area of its (elliptic) footprint
};

struct ConeDiagram {
  Spread c0_c180, c90_c270;
  double beam_flux_lm = 0;  ///< flux inside the beam cone
  std::vector<ConeRow> rows;
};

/// Throws std::invalid_argument for a distance that is not > 0, or a beam wider than 170° (its
/// footprint on a plane is unbounded or meaningless).
ConeDiagram cone_diagram(const IntensityTable& t, const std::vector<double>& distances_m);

LUMX_NAMESPACE_END
