// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/zonal_flux.h — flux in zones of the sphere: the zonal lumen summary of IES
// photometric reports, the 10° zones, and the CIE flux code (CIE 52:1982 §2.3).
//
// Zones are in the Type C frame of the luminaire (gamma from nadir, C counter-clockwise from +X) whatever
// the photometric type, so Types A and B are summarised the way they hang.
#pragma once

#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/photometry.h>

#include <optional>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// Flux (lm) emitted into gamma in [gamma_min, gamma_max] and C in [c_min, c_max] (degrees, C may run
/// past 360). Full-circle zones of Type C tables use the table's exact integral; other zones a midpoint
/// rule on a grid no coarser than 0.25° × 0.5° whose cell edges fall on the zone's edges (error
/// O(step²), below 0.1 % of the zone flux for tabulated data).
double zone_flux_lm(const IntensityTable& t, double gamma_min_deg, double gamma_max_deg, double c_min_deg = 0.0,
                    double c_max_deg = 360.0);

struct Zone {
  double gamma_min_deg = 0, gamma_max_deg = 0;
  double lm = 0;
  std::optional<double> percent_lamp;  ///< of the rated lamp flux (relative photometry only)
  double percent_luminaire = 0;        ///< of the luminaire's flux
};

struct ZonalLumenSummary {
  double luminaire_lm = 0;
  std::optional<double> lamp_lm;  ///< rated lamp flux; none for absolute photometry
  /// IES report zones: 0-30, 0-40, 0-60, 0-90, 90-120, 90-130, 90-150, 90-180, 0-180 degrees.
  std::vector<Zone> summary;
  /// The eighteen 10° zones 0-10 … 170-180.
  std::vector<Zone> ten_degree;
};

ZonalLumenSummary zonal_lumen_summary(const Photometry& p);

/// CIE flux code N1 N2 N3 N4 N5 (CIE 52:1982): N1, N2, N3 the percentages of the downward flux within
/// 41.4°, 60° and 75.5° of nadir (cones of π/2, π and 3π/2 sr); N4 the downward share of the luminaire
/// flux (DLOR/LOR); N5 the luminaire flux as a percentage of the lamp flux (LOR; none for absolute
/// photometry). The code prints each rounded to an integer.
struct CieFluxCode {
  double n1 = 0, n2 = 0, n3 = 0, n4 = 0;
  std::optional<double> n5;
  std::string str() const;  ///< "77 97 100 100 65" (N5 as "-" when absent)
};

CieFluxCode cie_flux_code(const Photometry& p);

LUMX_NAMESPACE_END
