// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/room_plot.h — the pictures of `lumx render room` (docs/render.md): a room's luminance with
// iso-contours equally spaced in log luminance, the relative difference against the reference in false
// colour with its colour bar, and several pictures side by side.
#pragma once

#include <lumx/render/image.h>

#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// Contour levels shared by every method: `per_decade` levels a decade, equally spaced in log L, from
/// the 99.5th percentile of `reference_luminance` (cd/m², pixels > 0) down over `decades` decades.
std::vector<double> log_contour_levels(const render::Image& reference_luminance, int per_decade = 4, int decades = 3);

/// Grey-scale luminance (channel "Y", gamma 2.2 below `white_cd_m2`, clipped above) with black iso-lines
/// at `levels` and a caption; PNG written atomically.
void write_contour_png(const std::string& path, const render::Image& view, double white_cd_m2,
                       const std::vector<double>& levels, const std::string& title, const std::string& caption);

/// Relative difference d = (E − E_ref) / max(E_ref, floor) per pixel (channel "E"; floor = 1 % of the
/// reference's 99.5th percentile, so dark corners do not blow up), blue (−range) – white – red (+range),
/// with a colour bar; PNG written atomically.
void write_difference_png(const std::string& path, const render::Image& view, const render::Image& reference,
                          double range, const std::string& title, const std::string& caption);

/// PNG pictures of equal size side by side (e.g. reference | 512 APLs | far field), written atomically.
void write_side_by_side_png(const std::string& path, const std::vector<std::string>& pngs);

/// The q-quantile (0…1) of the positive values of channel `c`; 0 when there are none.
double positive_quantile(const render::Image& image, int c, double q);

LUMX_NAMESPACE_END
