// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/core/diagnostic.h>
#include <lumx/math/constants.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/luminance_table.h>
#include <lumx/photometry/luminous_area.h>

#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>

LUMX_NAMESPACE_BEGIN

LuminanceTable luminance_table(const Photometry& p, std::vector<double> c_deg, std::vector<double> gamma_deg) {
  const LuminousArea area = luminous_area(p);
  if (area.kind == LuminousArea::Kind::none)
    throw_at_line(p.source.file, p.source.format == "EULUMDAT" ? 16 : 0, "luminous area",
                  missing_luminous_area_reason(p) + ": luminance needs the luminous area");
  const IntensityTable t(p);
  LuminanceTable out;
  out.c_deg = std::move(c_deg);
  out.gamma_deg = std::move(gamma_deg);
  for (double c : out.c_deg)
    for (double g : out.gamma_deg) {
      const double gr = g * kDegToRad, cr = c * kDegToRad;
      const glm::dvec3 d(std::sin(gr) * std::cos(cr), std::sin(gr) * std::sin(cr), -std::cos(gr));
      const double ap = area.projected_m2(d);
      const double l = ap > 0 ? t.intensity(d) / ap : 0.0;
      out.cd_m2.push_back(l);
      out.max_cd_m2 = std::max(out.max_cd_m2, l);
    }
  return out;
}

LUMX_NAMESPACE_END
