// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/eval_plot.h — log-log line charts for `lumx eval --rays --plots`: error against relative
// distance per level (the dissertation's Figure 5.8), error against evaluation time and against bytes.
#pragma once

#include <lumx/version.h>

#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// One curve: points joined in the given order (points with a non-positive or non-finite coordinate are
/// left out and break the line).
struct ChartSeries {
  std::string label;      ///< legend text; empty: not in the legend
  std::vector<double> x, y;
  int color = 0;          ///< index into a ten-colour qualitative palette; −1 = grey
  bool dashed = false;
  bool line = true;       ///< false: markers only
};

struct LogLogChart {
  std::string title, caption;
  std::string x_label, y_label;
  std::vector<ChartSeries> series;
  double width = 960, height = 640;
  /// Values shown on the y axis are multiplied by this (100: fractions drawn as percent).
  double y_display_scale = 1;
};

/// Writes `chart` as SVG or PNG (by extension) with log axes fitted to the data (at least one decade),
/// ticks labelled at 1 (and 2, 5 when the axis spans at most three decades) × 10^k, a grid, and a legend
/// on the right; dashed series are drawn first, wider and translucent. Written atomically;
/// throws lumx::Error ("output") for an unknown extension or a cairo failure.
void write_loglog_chart(const LogLogChart& chart, const std::string& out_path);

LUMX_NAMESPACE_END
