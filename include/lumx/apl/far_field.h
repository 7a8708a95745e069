// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/apl/far_field.h — between APL sets and far-field photometry (IES LM-63, EULUMDAT).
//
// far_field_photometry: an APL level → Type C photometry, for IES/EULUMDAT export.
// Far from the luminaire every APL is seen from the same direction, so the luminaire's intensity is the
// sum of the APLs' intensities: I(ω) = Σ_i I_i(ω) (algorithms.md §10; 000 §6.1, level 1 = the classic far
// field). This samples that sum on a Type C (C, γ) grid covering the whole sphere (no symmetry assumed),
// the model that io/photometry_io.h writes as IES LM-63 or EULUMDAT. The flux of the result is the exact
// integral of the bilinear table (IntensityTable::flux_lm), which converges to the maps' flux as the
// grid refines; the default 2.5° × 1° grid keeps smooth distributions within 0.1 %.
#pragma once

#include <lumx/apl/evaluation.h>
#include <lumx/photometry/far_field_grid.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/photometric_frame.h>
#include <lumx/photometry/photometry.h>

#include <cmath>
#include <stdexcept>
#include <string>

LUMX_NAMESPACE_BEGIN

/// Type C photometry (absolute cd, full sphere) of `set.levels[level_index]` in the far-field limit.
/// RGB sets export their Rec. 709 luminance Y.
inline Photometry far_field_photometry(const AplSet& set, std::size_t level_index, const FarFieldGrid& grid = {}) {
  if (level_index >= set.levels.size())
    throw std::invalid_argument("far_field_photometry: level " + std::to_string(level_index) + " does not exist");
  const int nc = detail::far_field_steps(grid.c_step_deg, 360.0, "far_field_photometry: c_step_deg");
  const int ng = detail::far_field_steps(grid.gamma_step_deg, 180.0, "far_field_photometry: gamma_step_deg");
  double scale = 1.0;
  if (set.quantity == PhotometricQuantity::radiometric) {
    if (!(grid.luminous_efficacy_lm_per_w > 0) || !std::isfinite(grid.luminous_efficacy_lm_per_w))
      throw std::invalid_argument(
          "far_field_photometry: the set is radiometric (W/sr); give luminous_efficacy_lm_per_w to export cd");
    scale = grid.luminous_efficacy_lm_per_w;
  }
  Photometry p;
  p.type = PhotometricType::C;
  p.symmetry = Symmetry::none;
  p.absolute = true;
  for (int i = 0; i <= nc; ++i) p.horizontal_deg.push_back(i == nc ? 360.0 : i * grid.c_step_deg);
  for (int j = 0; j <= ng; ++j) p.vertical_deg.push_back(j == ng ? 180.0 : j * grid.gamma_step_deg);
  p.candela.resize(p.horizontal_deg.size() * p.vertical_deg.size());
  const AplLevel& level = set.levels[level_index];
  for (std::size_t ih = 0; ih < p.horizontal_deg.size(); ++ih)
    for (std::size_t iv = 0; iv < p.vertical_deg.size(); ++iv) {
      const glm::dvec3 w = direction_from_angles(PhotometricType::C, p.horizontal_deg[ih], p.vertical_deg[iv]);
      p.at(ih, iv) = scale * luminance_of(set.channels, far_field_intensity(level, glm::vec3(w)));
    }
  LampSet lamps;
  lamps.count = 1;
  lamps.type = "APL set level " + std::to_string(level.size());
  p.lamp_sets.push_back(lamps);
  p.keywords.push_back({"TEST", "lumx far field of an APL set"});
  p.keywords.push_back({"MANUFAC", set.provenance.count("manufacturer") ? set.provenance.at("manufacturer") : "unknown"});
  p.source.format = "lumx APL set";
  return p;
}

/// The one-APL set of a far-field photometry file: a point at the photometric centre whose map holds the
/// file's intensity distribution — the model legacy tools assume (000 §6.1, "one APL = classic far field").
/// Each texel is the mean of `supersampling`² stratified lookups of the bilinear table; the map is then
/// scaled so its integral equals the table's exact flux (IntensityTable::flux_lm), because flux is the
/// quantity photometry guarantees and the piecewise-constant map would otherwise miss it by O(1/R²).
/// The bounding sphere is half the luminous opening's largest dimension.
inline AplSet apl_set_from_photometry(const Photometry& p, int map_resolution = 64, int supersampling = 3) {
  const IntensityTable table(p);
  AplSet set;
  set.quantity = PhotometricQuantity::photometric;
  set.channels = ChannelLayout::luminance;
  set.bounds.radius = 0.5 * p.opening.max_dimension_m();
  if (!p.source.file.empty()) set.provenance["source"] = p.source.file;
  set.provenance["converted_from"] = p.source.format.empty() ? "photometry" : p.source.format;
  AplLevel level;
  level.map_resolution = map_resolution;
  Apl apl;
  apl.map = SphereMap(map_resolution, 1);
  const int n = std::max(1, supersampling);
  const int width = apl.map.width(), R = map_resolution;
  for (int y = 0; y < R; ++y)
    for (int x = 0; x < width; ++x) {
      double sum = 0;
      for (int sy = 0; sy < n; ++sy)
        for (int sx = 0; sx < n; ++sx) {
          const glm::vec2 uv((float(x) + (float(sx) + 0.5f) / float(n)) / float(width),
                             (float(y) + (float(sy) + 0.5f) / float(n)) / float(R));
          sum += table.intensity(glm::dvec3(sphere_map::uv_to_direction(uv)));
        }
      apl.map.at(x, y, 0) = float(sum / double(n * n));
    }
  const double map_flux = apl.map.integral().x, table_flux = table.flux_lm();
  if (map_flux > 0)
    for (float& v : apl.map.values()) v = float(double(v) * (table_flux / map_flux));
  apl.flux = apl.map.integral();
  level.apls.push_back(std::move(apl));
  set.levels.push_back(std::move(level));
  return set;
}

LUMX_NAMESPACE_END
