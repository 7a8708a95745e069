// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/metric_plots.h — the datasheet diagrams besides the polar curve, drawn with cairo through
// plot_canvas (render_and_write: SVG or PNG by extension, written atomically): the isolux diagram
// (contour_plots.cpp), the isocandela diagram (contour_plots.cpp), the cone diagram (cone_plot.cpp) and
// the UGR table (ugr_plot.cpp).
#pragma once

#include <lumx/photometry/photometry.h>
#include <lumx/version.h>

#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

struct MetricPlotOptions {
  std::string title;                                   ///< default: the luminaire name, else the file name
  int size_px = 800;                                   ///< image width, 200..8000
  double mounting_height_m = 3.0;                      ///< isolux: luminaire above the plane
  double tilt_deg = 0;                                 ///< isolux: aiming tilt about the C0-C180 axis
  std::vector<double> distances_m = {1, 2, 3, 4, 5};   ///< cone: distances along the axis
  double spacing_to_height = 0.25;                     ///< UGR table: S/H of the luminaire grid
};

/// What a diagram shows in words: its kind and the texts it labels its content with (iso-line values,
/// table cells, …), for the command's report and for tests (cairo draws text as glyph outlines).
struct PlotSummary {
  std::string kind;
  std::vector<std::string> labels;
};

/// Each throws lumx::Error ("output" for an unknown extension or a cairo failure, "size" for a size out
/// of range) or the model's errors (a point source has no UGR, a lamp with no beam no cone diagram).
PlotSummary write_isolux_plot(const Photometry& p, const std::string& out_path, const MetricPlotOptions& o);
PlotSummary write_isocandela_plot(const Photometry& p, const std::string& out_path, const MetricPlotOptions& o);
PlotSummary write_cone_plot(const Photometry& p, const std::string& out_path, const MetricPlotOptions& o);
PlotSummary write_ugr_plot(const Photometry& p, const std::string& out_path, const MetricPlotOptions& o);

LUMX_NAMESPACE_END
