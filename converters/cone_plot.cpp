// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/cone_plot.cpp — the cone diagram (lumx/photometry/cone_diagram.h): the beam drawn as a cone
// from the luminaire at the top, one horizontal line per distance, and beside it a table of the distance,
// the beam diameters in both planes, the axial and the mean beam illuminance.
//
// Layout (S = size, image S × 0.9 S): title and caption at the top; the cone on the left third (its
// half-angle true to scale down to the largest distance); the table on the right.
#include "metric_plots.h"
#include "plot_canvas.h"

#include <lumx/math/constants.h>
#include <lumx/photometry/cone_diagram.h>
#include <lumx/photometry/polar_diagram.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN

PlotSummary write_cone_plot(const Photometry& p, const std::string& out, const MetricPlotOptions& o) {
  if (o.size_px < 200 || o.size_px > 8000) throw_plot_error(out, "size", "image size must lie in 200..8000 pixels");
  const bool svg = is_svg_output(out);
  if (o.distances_m.empty() || o.distances_m.size() > 12)
    throw_plot_error(out, "distances", "give 1 to 12 distances");
  ConeDiagram cd;
  try {
    cd = cone_diagram(IntensityTable(p), o.distances_m);
  } catch (const std::invalid_argument& e) {
    throw_plot_error(out, "cone", e.what());
  }
  const double S = o.size_px, W = S, H = std::round(0.9 * S);
  const std::string title = o.title.empty() ? polar_default_title(p) : o.title;
  char cap[256];
  std::snprintf(cap, sizeof cap, "Cone diagram: beam angle (50 %%) %s deg in C0-C180, %s deg in C90-C270; %s lm in the beam",
                format_quantity(cd.c0_c180.beam_deg).c_str(), format_quantity(cd.c90_c270.beam_deg).c_str(),
                format_quantity(cd.beam_flux_lm).c_str());
  const std::string caption = cap;
  PlotSummary sum{"cone", {}};
  const double dmax = *std::max_element(o.distances_m.begin(), o.distances_m.end());
  const char* heads[6] = {"h / m", "\xC3\x98 C0 / m", "\xC3\x98 C90 / m", "E axis / lx", "E mean / lx", ""};
  for (int k = 0; k < 5; ++k) sum.labels.push_back(heads[k]);
  for (const ConeRow& r : cd.rows)
    for (double v : {r.distance_m, r.beam_diameter_m[0], r.beam_diameter_m[1], r.center_lux, r.mean_beam_lux})
      sum.labels.push_back(format_quantity(v));
  render_and_write(out, svg, W, H, [&](Painter& pt) {
    cairo_t* cr = pt.cr();
    pt.title_and_caption(title, caption, S, 0.045 * S, 0.09 * S);
    // The cone: apex at (ax, ay), depth to the largest distance over 0.66 S; the half width is true to
    // scale but clipped to the drawing's third.
    const double ax = 0.2 * S, ay = 0.16 * S, depth = 0.66 * S, k = depth / dmax;
    const double half = std::tan(0.5 * cd.c0_c180.beam_deg * kDegToRad);
    const double spread = std::min(0.17 * S, half * depth);
    cairo_set_source_rgba(cr, 0.98, 0.80, 0.25, 0.35);
    cairo_move_to(cr, ax, ay);
    cairo_line_to(cr, ax - spread, ay + depth);
    cairo_line_to(cr, ax + spread, ay + depth);
    cairo_close_path(cr);
    cairo_fill(cr);
    pt.color(kTextColor);
    cairo_set_line_width(cr, std::max(1.0, S / 700));
    cairo_move_to(cr, ax - spread, ay + depth);
    cairo_line_to(cr, ax, ay);
    cairo_line_to(cr, ax + spread, ay + depth);
    cairo_stroke(cr);
    cairo_rectangle(cr, ax - 0.03 * S, ay - 0.015 * S, 0.06 * S, 0.015 * S);
    cairo_fill(cr);
    // Table columns.
    const double cols[5] = {0.48 * S, 0.595 * S, 0.715 * S, 0.835 * S, 0.955 * S};
    for (int c = 0; c < 5; ++c) {
      pt.fit_font(heads[c], 0.017 * S, true, 0.11 * S);
      pt.text_baseline(heads[c], cols[c], 0.15 * S, 1);
    }
    pt.font(0.019 * S);
    for (const ConeRow& r : cd.rows) {
      const double y = ay + r.distance_m * k;
      const double w = std::min(0.17 * S, half * r.distance_m * k);
      pt.color(kMutedColor);
      cairo_set_line_width(cr, std::max(0.6, S / 1000));
      cairo_move_to(cr, ax - w, y);
      cairo_line_to(cr, cols[4] + 0.005 * S, y);
      cairo_stroke(cr);
      pt.color(kTextColor);
      const double vals[5] = {r.distance_m, r.beam_diameter_m[0], r.beam_diameter_m[1], r.center_lux, r.mean_beam_lux};
      for (int c = 0; c < 5; ++c) pt.text_baseline(format_quantity(vals[c]), cols[c], y - 0.006 * S, 1);
    }
    pt.check("cone");
  });
  return sum;
}

LUMX_NAMESPACE_END
