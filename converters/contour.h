// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/contour.h — iso-lines of a sampled field for the isolux and isocandela diagrams: marching
// squares on a regular grid (segments, unjoined), and "nice" levels (1, 2, 5 × 10^k) below a maximum.
#pragma once

#include <lumx/version.h>

#include <vector>

LUMX_NAMESPACE_BEGIN

struct Segment {
  double x0, y0, x1, y1;  ///< grid coordinates (column, row), fractional
};

/// Segments where the field `v` (nx × ny, [iy * nx + ix]) crosses `level`, by linear interpolation along
/// cell edges. Saddle cells are split by the cell's mean. Non-finite samples end the line there.
std::vector<Segment> contour_segments(const std::vector<double>& v, int nx, int ny, double level);

/// Up to `max_levels` values of the 1-2-5 sequence in (min_fraction × max, 0.95 × max] (a level at the very
/// peak would draw a dot), largest first.
std::vector<double> nice_levels(double max, double min_fraction, int max_levels);

LUMX_NAMESPACE_END
