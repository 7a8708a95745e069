// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/eval_plot.cpp — log-log line charts (see eval_plot.h).
//
// Layout (W × H): title and caption at the top; the plot area below with a left margin for the y tick
// labels and the y axis title, a bottom margin for the x tick labels and axis title, and a legend column
// on the right. Axes are logarithmic, fitted to the data; labelled grid lines (darker) at the decades, and
// at 2 and 5 × each decade when the axis spans at most three; the other 2..9 × lines lighter.
#include "eval_plot.h"

#include "plot_canvas.h"

#include <lumx/photometry/photometric_frame.h>

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

namespace {

// Matplotlib's "tab10": distinct hues that stay apart when printed in grey.
constexpr Rgb kPalette[10] = {{0.122, 0.467, 0.706}, {1.000, 0.498, 0.055}, {0.173, 0.627, 0.173},
                              {0.839, 0.153, 0.157}, {0.580, 0.404, 0.741}, {0.549, 0.337, 0.294},
                              {0.890, 0.467, 0.761}, {0.737, 0.741, 0.133}, {0.090, 0.745, 0.812},
                              {0.498, 0.498, 0.498}};
constexpr Rgb kGrey{0.45, 0.45, 0.45};
constexpr Rgb kFrame{0.30, 0.30, 0.30};
constexpr Rgb kMajorGrid{0.80, 0.80, 0.80};
constexpr Rgb kMinorGrid{0.92, 0.92, 0.92};

Rgb series_color(int i) { return i < 0 ? kGrey : kPalette[i % 10]; }

bool usable(double v) { return std::isfinite(v) && v > 0; }

// A tick label: m × 10^k as "0.002" .. "500000", else "2e-04", "5e+06".
std::string tick_label(int m, int k) {
  char buf[32];
  const double v = m * std::pow(10.0, k);
  if (k >= 0 && k <= 5)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else if (k < 0 && k >= -3)
    std::snprintf(buf, sizeof buf, "%.*f", -k, v);
  else
    std::snprintf(buf, sizeof buf, "%de%+03d", m, k);
  return buf;
}

// A log axis over the usable values, padded by 10 % on each side (log scale) and at least one decade wide
// ([1, 10] if there is no usable value). Ticks at 1, 2 and 5 × each decade when the axis spans at most
// three decades, else at the decades only.
struct LogAxis {
  double lo = 0, hi = 1;  // log10 of the ends
  void fit(const std::vector<double>& values) {
    double mn = INFINITY, mx = -INFINITY;
    for (double v : values)
      if (usable(v)) mn = std::min(mn, v), mx = std::max(mx, v);
    if (!(mn <= mx)) return;
    lo = std::log10(mn);
    hi = std::log10(mx);
    const double pad = std::max(0.04, 0.06 * (hi - lo));
    lo -= pad;
    hi += pad;
    if (hi - lo < 1) {
      const double mid = 0.5 * (lo + hi);
      lo = mid - 0.5, hi = mid + 0.5;
    }
  }
  double t(double v) const { return (std::log10(v) - lo) / (hi - lo); }  // 0..1 inside the axis
  bool inside(double v) const { return std::log10(v) >= lo - 1e-9 && std::log10(v) <= hi + 1e-9; }
  struct Tick {
    double v;
    bool labelled;
    int m, k;
  };
  std::vector<Tick> ticks() const {
    std::vector<Tick> out;
    const bool fine = hi - lo <= 3.0;
    for (int k = int(std::floor(lo)); k <= int(std::ceil(hi)); ++k)
      for (int m = 1; m <= 9; ++m) {
        const double v = m * std::pow(10.0, k);
        if (!inside(v)) continue;
        out.push_back({v, m == 1 || (fine && (m == 2 || m == 5)), m, k});
      }
    return out;
  }
};

}  // namespace

void write_loglog_chart(const LogLogChart& chart, const std::string& out_path) {
  const bool svg = is_svg_output(out_path);
  std::vector<double> xs, ys;
  for (const ChartSeries& s : chart.series) {
    xs.insert(xs.end(), s.x.begin(), s.x.end());
    for (double y : s.y) ys.push_back(y * chart.y_display_scale);
  }
  LogAxis ax, ay;
  ax.fit(xs);
  ay.fit(ys);
  const double W = chart.width, H = chart.height;
  render_and_write(out_path, svg, W, H, [&](Painter& pt) {
    cairo_t* cr = pt.cr();
    const double label_pt = std::max(11.0, H / 48.0);
    // Legend width from the longest label.
    pt.font(label_pt);
    double legend_w = 0;
    for (const ChartSeries& s : chart.series) legend_w = std::max(legend_w, pt.extents(s.label).x_advance);
    if (legend_w == 0) legend_w = 4 * label_pt;
    legend_w = std::min(legend_w + 3.2 * label_pt, 0.35 * W);
    const double left = 5.5 * label_pt, right = W - legend_w - 1.5 * label_pt;
    double top = 1.2 * label_pt;
    if (!chart.title.empty()) {
      pt.color(kTextColor);
      pt.fit_font(chart.title, 1.4 * label_pt, true, W - 2 * label_pt);
      pt.text_baseline(chart.title, W / 2, top + 1.4 * label_pt, 0.5);
      top += 2.1 * label_pt;
    }
    if (!chart.caption.empty()) {
      pt.color(kMutedColor);
      pt.fit_font(chart.caption, 0.95 * label_pt, false, W - 2 * label_pt);
      pt.text_baseline(chart.caption, W / 2, top + label_pt, 0.5);
      top += 1.8 * label_pt;
    }
    top += 0.8 * label_pt;
    const double bottom = H - 4.0 * label_pt;
    const double pw = right - left, ph = bottom - top;
    auto X = [&](double v) { return left + ax.t(v) * pw; };
    auto Y = [&](double v) { return bottom - ay.t(v) * ph; };

    // Grid: minor lines (unlabelled ticks) then major ones (labelled), inside the plot area.
    const std::vector<LogAxis::Tick> xt = ax.ticks(), yt = ay.ticks();
    cairo_set_line_width(cr, 1.0);
    for (int pass = 0; pass < 2; ++pass) {
      pt.color(pass == 0 ? kMinorGrid : kMajorGrid);
      for (const auto& t : xt)
        if (t.labelled == (pass == 1)) {
          cairo_move_to(cr, X(t.v), top);
          cairo_line_to(cr, X(t.v), bottom);
        }
      for (const auto& t : yt)
        if (t.labelled == (pass == 1)) {
          cairo_move_to(cr, left, Y(t.v));
          cairo_line_to(cr, right, Y(t.v));
        }
      cairo_stroke(cr);
    }
    pt.check("grid");
    pt.color(kFrame);
    cairo_set_line_width(cr, 1.2);
    cairo_rectangle(cr, left, top, pw, ph);
    cairo_stroke(cr);

    // Tick labels and axis titles.
    pt.color(kTextColor);
    pt.font(0.9 * label_pt);
    for (const auto& t : xt)
      if (t.labelled) pt.text_baseline(tick_label(t.m, t.k), X(t.v), bottom + 1.4 * label_pt, 0.5);
    for (const auto& t : yt)
      if (t.labelled) pt.text_middle(tick_label(t.m, t.k), left - 0.5 * label_pt, Y(t.v), 1.0);
    pt.font(label_pt);
    pt.text_baseline(chart.x_label, left + pw / 2, H - 1.0 * label_pt, 0.5);
    cairo_save(cr);
    cairo_translate(cr, 1.4 * label_pt, top + ph / 2);
    cairo_rotate(cr, -kPi / 2);
    pt.text_baseline(chart.y_label, 0, 0, 0.5);
    cairo_restore(cr);
    pt.check("axes");

    // Series, clipped to the plot area.
    auto stroke_style = [&](const ChartSeries& s) {
      pt.color(series_color(s.color), s.dashed ? 0.75 : 1.0);
      cairo_set_line_width(cr, s.dashed ? 3.5 : 2.0);
      if (s.dashed) {
        const double dash[2] = {7.0, 4.0};
        cairo_set_dash(cr, dash, 2, 0);
      } else {
        cairo_set_dash(cr, nullptr, 0, 0);
      }
    };
    cairo_save(cr);
    cairo_rectangle(cr, left, top, pw, ph);
    cairo_clip(cr);
    // Dashed reference curves first, wider and translucent, so a solid curve on top of one stays visible.
    std::vector<const ChartSeries*> order;
    for (const ChartSeries& s : chart.series)
      if (s.dashed) order.push_back(&s);
    for (const ChartSeries& s : chart.series)
      if (!s.dashed) order.push_back(&s);
    for (const ChartSeries* sp : order) {
      const ChartSeries& s = *sp;
      const std::size_t n = std::min(s.x.size(), s.y.size());
      stroke_style(s);
      if (s.line) {
        bool pen = false;
        for (std::size_t i = 0; i < n; ++i) {
          const double yv = s.y[i] * chart.y_display_scale;
          if (!usable(s.x[i]) || !usable(yv)) {
            pen = false;
            continue;
          }
          if (pen)
            cairo_line_to(cr, X(s.x[i]), Y(yv));
          else
            cairo_move_to(cr, X(s.x[i]), Y(yv));
          pen = true;
        }
        cairo_stroke(cr);
      }
      cairo_set_dash(cr, nullptr, 0, 0);
      for (std::size_t i = 0; i < n; ++i) {
        const double yv = s.y[i] * chart.y_display_scale;
        if (!usable(s.x[i]) || !usable(yv)) continue;
        cairo_new_sub_path(cr);
        cairo_arc(cr, X(s.x[i]), Y(yv), s.line ? 3.5 : 5.0, 0, 2 * kPi);
      }
      cairo_fill(cr);
    }
    cairo_restore(cr);
    pt.check("series");

    // Legend.
    pt.font(0.9 * label_pt);
    double ly = top + 0.8 * label_pt;
    const double lx = right + 1.2 * label_pt;
    for (const ChartSeries& s : chart.series) {
      if (s.label.empty()) continue;
      stroke_style(s);
      if (s.line) {
        cairo_move_to(cr, lx, ly);
        cairo_line_to(cr, lx + 2.0 * label_pt, ly);
        cairo_stroke(cr);
      }
      cairo_set_dash(cr, nullptr, 0, 0);
      cairo_new_sub_path(cr);
      cairo_arc(cr, lx + 1.0 * label_pt, ly, s.line ? 3.5 : 5.0, 0, 2 * kPi);
      cairo_fill(cr);
      pt.color(kTextColor);
      pt.fit_font(s.label, 0.9 * label_pt, false, W - (lx + 2.6 * label_pt) - 4);
      pt.text_middle(s.label, lx + 2.6 * label_pt, ly, 0.0);
      ly += 1.6 * label_pt;
      if (ly > bottom) break;
    }
    pt.check("legend");
  });
}

LUMX_NAMESPACE_END
