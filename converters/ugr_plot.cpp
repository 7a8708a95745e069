// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/ugr_plot.cpp — the UGR table as a datasheet prints it (lumx/photometry/ugr.h): three header
// rows of reflectances (ceiling, walls, floor) over the crosswise and endwise halves, then the 19 rooms
// (X, Y in multiples of H), grouped by X, values to one decimal.
//
// Layout (S = size, image S × 1.05 S): title and caption; the table; a footnote with the method and its
// parameters.
#include "metric_plots.h"
#include "plot_canvas.h"

#include <lumx/photometry/polar_diagram.h>
#include <lumx/photometry/ugr.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

LUMX_NAMESPACE_BEGIN

namespace {

std::string one_decimal(double v) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

std::string percent(double v) { return std::to_string(static_cast<int>(std::lround(100 * v))); }

}  // namespace

PlotSummary write_ugr_plot(const Photometry& p, const std::string& out, const MetricPlotOptions& o) {
  if (o.size_px < 200 || o.size_px > 8000) throw_plot_error(out, "size", "image size must lie in 200..8000 pixels");
  const bool svg = is_svg_output(out);
  UgrTableOptions uo;
  uo.spacing_to_height = o.spacing_to_height;
  UgrTable t;
  try {
    t = ugr_table(p, uo);
  } catch (const std::invalid_argument& e) {
    throw_plot_error(out, "ugr", e.what());
  }
  const std::size_t nr = uo.rooms.size(), nk = uo.reflectances.size();
  PlotSummary sum{"ugr", {"Ceiling", "Walls", "Floor", "Viewed crosswise", "Viewed endwise"}};
  for (std::size_t r = 0; r < nr; ++r)
    for (UgrView v : {UgrView::crosswise, UgrView::endwise})
      for (std::size_t k = 0; k < nk; ++k) sum.labels.push_back(one_decimal(t.at(r, k, v)));
  const double S = o.size_px, W = S, H = std::round(1.05 * S);
  const std::string title = o.title.empty() ? polar_default_title(p) : o.title;
  char cap[256];
  std::snprintf(cap, sizeof cap, "UGR table (CIE 117/190 tabular method), luminaire flux %s lm",
                format_quantity(t.luminaire_flux_lm).c_str());
  const std::string caption = cap;
  render_and_write(out, svg, W, H, [&](Painter& pt) {
    cairo_t* cr = pt.cr();
    pt.title_and_caption(title, caption, S, 0.04 * S, 0.078 * S);
    // Columns: X, Y, then 2 × nk values; a gap between the halves.
    const double left = 0.05 * S, col_xy = 0.065 * S, gap = 0.03 * S;
    const double col = (0.9 * S - 2 * col_xy - gap) / static_cast<double>(2 * nk);
    auto value_x = [&](int half, std::size_t k) {
      return left + 2 * col_xy + half * (static_cast<double>(nk) * col + gap) + (static_cast<double>(k) + 0.5) * col;
    };
    const double row_h = 0.036 * S, top = 0.12 * S;
    const double f = 0.019 * S;
    // Header: the halves, then the reflectance rows.
    pt.font(f, true);
    for (int half = 0; half < 2; ++half)
      pt.text_centered(half == 0 ? "Viewed crosswise" : "Viewed endwise",
                       0.5 * (value_x(half, 0) + value_x(half, nk - 1)), top);
    const char* names[3] = {"Ceiling", "Walls", "Floor"};
    for (int row = 0; row < 3; ++row) {
      const double y = top + (row + 1) * row_h;
      pt.font(f, true);
      pt.text_middle(names[row], left, y, 0);
      pt.font(f);
      for (int half = 0; half < 2; ++half)
        for (std::size_t k = 0; k < nk; ++k) {
          const Reflectances& rf = uo.reflectances[k];
          pt.text_centered(percent(row == 0 ? rf.ceiling : row == 1 ? rf.walls : rf.floor), value_x(half, k), y);
        }
    }
    double y = top + 4 * row_h;
    pt.font(f, true);
    pt.text_centered("X", left + 0.5 * col_xy, y);
    pt.text_centered("Y", left + 1.5 * col_xy, y);
    pt.font(f * 0.85);
    pt.color(kMutedColor);
    pt.text_centered("room size (H)", 0.5 * (value_x(0, 0) + value_x(1, nk - 1)), y);
    cairo_set_line_width(cr, std::max(0.8, S / 900));
    pt.color(kTextColor);
    cairo_move_to(cr, left, y + 0.5 * row_h);
    cairo_line_to(cr, 0.95 * S, y + 0.5 * row_h);
    cairo_stroke(cr);
    double prev_x = -1;
    for (std::size_t r = 0; r < nr; ++r) {
      y += row_h;
      const UgrRoom& room = uo.rooms[r];
      if (prev_x >= 0 && room.x_h != prev_x) {  // a rule between the groups of X
        pt.color(kMutedColor);
        cairo_set_line_width(cr, std::max(0.5, S / 1600));
        cairo_move_to(cr, left, y - 0.5 * row_h);
        cairo_line_to(cr, 0.95 * S, y - 0.5 * row_h);
        cairo_stroke(cr);
      }
      pt.color(kTextColor);
      pt.font(f);
      char xs[16], ys[16];
      std::snprintf(xs, sizeof xs, "%gH", room.x_h);
      std::snprintf(ys, sizeof ys, "%gH", room.y_h);
      if (room.x_h != prev_x) pt.text_centered(xs, left + 0.5 * col_xy, y);
      pt.text_centered(ys, left + 1.5 * col_xy, y);
      for (int half = 0; half < 2; ++half)
        for (std::size_t k = 0; k < nk; ++k)
          pt.text_centered(one_decimal(t.at(r, k, half == 0 ? UgrView::crosswise : UgrView::endwise)), value_x(half, k), y);
      prev_x = room.x_h;
    }
    pt.color(kMutedColor);
    char note[256];
    std::snprintf(note, sizeof note,
                  "Luminaire spacing S = %s H; H = %s m above the eye; reflectances in %%; crosswise: C0 along the line of sight.",
                  format_quantity(uo.spacing_to_height).c_str(), format_quantity(uo.height_m).c_str());
    pt.fit_font(note, 0.017 * S, false, 0.9 * S);
    pt.text_baseline(note, left, y + 1.2 * row_h, 0);
    pt.check("table");
  });
  return sum;
}

LUMX_NAMESPACE_END
