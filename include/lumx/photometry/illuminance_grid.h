// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/illuminance_grid.h — horizontal illuminance (lx) that one luminaire casts on a plane
// below it, by the inverse-square cosine law E = I cos(incidence) / r²: the data of an isolux diagram.
//
// Frame: the plane is z = 0, the luminaire's photometric centre at (0, 0, mounting height); plane axes x
// and y are the photometric +X (C0) and +Y (C90) before tilting. A tilt turns the luminaire about its X
// axis (C0-C180), carrying its nadir towards +y: a floodlight aimed tilt degrees up from straight down.
#pragma once

#include <lumx/photometry/intensity_table.h>

#include <vector>

LUMX_NAMESPACE_BEGIN

struct IlluminanceGridOptions {
  double mounting_height_m = 3.0;  ///< > 0
  double tilt_deg = 0;             ///< in [0, 85]
  /// Plane region: 0 = automatic (the box where E >= 0.5 % of its maximum, padded by 10 %, at least
  /// ± the mounting height, at most ± 10 mounting heights).
  double x_min_m = 0, x_max_m = 0, y_min_m = 0, y_max_m = 0;
  int samples = 161;  ///< points along the longer side (>= 3, <= 4001)
};

struct IlluminanceGrid {
  double x_min_m = 0, x_max_m = 0, y_min_m = 0, y_max_m = 0;
  int nx = 0, ny = 0;
  std::vector<double> lux;  ///< [iy * nx + ix]
  double max_lux = 0;
  double x(int ix) const { return x_min_m + (x_max_m - x_min_m) * ix / (nx - 1); }
  double y(int iy) const { return y_min_m + (y_max_m - y_min_m) * iy / (ny - 1); }
  double at(int ix, int iy) const { return lux[static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(ix)]; }
};

/// Illuminance at one point (x, y) of the plane, lx.
double illuminance_lx(const IntensityTable& t, double x_m, double y_m, double mounting_height_m, double tilt_deg);

/// Throws std::invalid_argument for options out of range.
IlluminanceGrid illuminance_grid(const IntensityTable& t, const IlluminanceGridOptions& options = {});

LUMX_NAMESPACE_END
