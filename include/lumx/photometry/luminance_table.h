// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/luminance_table.h — the luminaire's mean luminance L = I / A_p (cd/m²) over its
// luminous area at the viewing angles datasheets tabulate for glare assessment: gamma 45° … 85° in 5°
// steps (the angles CIE 117 and EN 12464-1's luminance limits look at), in chosen C planes.
#pragma once

#include <lumx/photometry/photometry.h>

#include <vector>

LUMX_NAMESPACE_BEGIN

struct LuminanceTable {
  std::vector<double> c_deg;      ///< planes
  std::vector<double> gamma_deg;  ///< viewing angles from nadir
  std::vector<double> cd_m2;      ///< [ic * gamma.size() + ig]; 0 where no luminous area is seen
  double max_cd_m2 = 0;
  double at(std::size_t ic, std::size_t ig) const { return cd_m2[ic * gamma_deg.size() + ig]; }
};

/// Default planes C0, C45 … C315; default angles 45° … 85°. Throws lumx::Error (field "luminous area")
/// when the file gives no luminous area.
LuminanceTable luminance_table(const Photometry& p, std::vector<double> c_deg = {0, 45, 90, 135, 180, 225, 270, 315},
                               std::vector<double> gamma_deg = {45, 50, 55, 60, 65, 70, 75, 80, 85});

LUMX_NAMESPACE_END
