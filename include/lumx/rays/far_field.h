// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/rays/far_field.h — far-field photometry straight from a rayset.
//
// Far away, only a ray's direction matters: the luminous intensity toward a direction is the flux of the
// rays leaving into a small solid angle around it, divided by that solid angle (algorithms.md §10). The
// IES/EULUMDAT table stores values at angle vertices (C_i, γ_j), so each vertex gets the cell around it:
//   γ ∈ [γ_j − Δγ/2, γ_j + Δγ/2] ∩ [0°, 180°],  C ∈ [C_i − ΔC/2, C_i + ΔC/2] (wrapping at 360°),
//   Ω_ij = (cos γ_lo − cos γ_hi) · ΔC (radians), I_ij = Φ_ij / Ω_ij.
// The pole rows (γ = 0° and 180°) are caps shared by every C plane, so they hold the cap's flux over
// the cap's solid angle in every plane; C = 360° repeats C = 0°. With this normalisation the table's
// flux (IntensityTable::flux_lm) converges to the rays' flux as the grid refines.
#pragma once

#include <lumx/photometry/far_field_grid.h>
#include <lumx/photometry/photometry.h>
#include <lumx/photometry/photometric_frame.h>
#include <lumx/rays/rayset.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// Type C photometry (absolute cd) of every ray in `rays`, on `grid` (FarFieldGrid of photometry/far_field_grid.h;
/// radiometric raysets need grid.luminous_efficacy_lm_per_w). Streams the rays once.
inline Photometry far_field_from_rays(RaySource& rays, const FarFieldGrid& grid = {}) {
  const int nc = detail::far_field_steps(grid.c_step_deg, 360.0, "far_field_from_rays: c_step_deg");
  const int ng = detail::far_field_steps(grid.gamma_step_deg, 180.0, "far_field_from_rays: gamma_step_deg");
  double scale = 1.0;
  if (rays.info().quantity == PhotometricQuantity::radiometric) {
    if (!(grid.luminous_efficacy_lm_per_w > 0) || !std::isfinite(grid.luminous_efficacy_lm_per_w))
      throw std::invalid_argument("far_field_from_rays: the rays carry W; give luminous_efficacy_lm_per_w to export cd");
    scale = grid.luminous_efficacy_lm_per_w;
  }
  const double dc = grid.c_step_deg, dg = grid.gamma_step_deg;
  // Flux per (C cell, γ cell); the pole rows use only column 0.
  std::vector<double> flux(std::size_t(nc) * std::size_t(ng + 1), 0.0);
  RayChunk chunk;
  rays.rewind();
  while (rays.next(chunk, 1 << 16))
    for (std::size_t i = 0; i < chunk.size(); ++i) {
      const PhotometricAngles a = angles_from_direction(PhotometricType::C, glm::dvec3(chunk.direction(i)));
      if (!std::isfinite(a.horizontal_deg) || !std::isfinite(a.vertical_deg)) continue;
      const int j = std::min(ng, std::max(0, int(std::floor(a.vertical_deg / dg + 0.5))));
      int c = 0;
      if (j > 0 && j < ng) c = int(std::floor(std::fmod(a.horizontal_deg / dc + 0.5, double(nc)) + double(nc))) % nc;
      flux[std::size_t(c) * std::size_t(ng + 1) + std::size_t(j)] += double(chunk.flux[i]);
    }
  Photometry p;
  p.type = PhotometricType::C;
  p.symmetry = Symmetry::none;
  p.absolute = true;
  for (int i = 0; i <= nc; ++i) p.horizontal_deg.push_back(i == nc ? 360.0 : i * dc);
  for (int j = 0; j <= ng; ++j) p.vertical_deg.push_back(j == ng ? 180.0 : j * dg);
  p.candela.assign(p.horizontal_deg.size() * p.vertical_deg.size(), 0.0);
  const double dc_rad = dc * kDegToRad;
  for (int j = 0; j <= ng; ++j) {
    const double g0 = std::max(0.0, (j - 0.5) * dg) * kDegToRad, g1 = std::min(180.0, (j + 0.5) * dg) * kDegToRad;
    const double band = std::cos(g0) - std::cos(g1);  // solid angle of the γ band per radian of C
    for (int i = 0; i <= nc; ++i) {
      const int c = i % nc;
      double cd;
      if (j == 0 || j == ng) cd = flux[std::size_t(j)] / (band * 2 * kPi);  // pole cap: all C planes
      else cd = flux[std::size_t(c) * std::size_t(ng + 1) + std::size_t(j)] / (band * dc_rad);
      p.at(std::size_t(i), std::size_t(j)) = scale * cd;
    }
  }
  LampSet lamps;
  lamps.count = 1;
  lamps.type = "rayset " + rays.info().file;
  p.lamp_sets.push_back(lamps);
  p.keywords.push_back({"TEST", "lumx far field of a rayset"});
  p.keywords.push_back({"MANUFAC", "unknown"});
  p.source.format = "lumx rayset far field";
  return p;
}

LUMX_NAMESPACE_END
