// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/contour_plots.cpp — the isolux and isocandela diagrams: iso-lines of a sampled field, each
// labelled with its value where it reaches furthest right, and a legend of the levels.
//
// Isolux (S = size, image S × 1.08 S): title and caption at the top; the plane seen from above in a
// square of 0.66 S with metre ticks (x = photometric C0 to the right, y = C90 up), the luminaire's foot
// marked with a cross; the legend of levels (lx) on the right. Isocandela: the sphere around nadir drawn
// with gamma as radius (an azimuthal equidistant projection: C0 right, C90 up), rings every 15° or 30°,
// iso-candela lines at fractions of the peak, legend (cd) on the right.
#include "contour.h"
#include "metric_plots.h"
#include "plot_canvas.h"

#include <lumx/core/diagnostic.h>
#include <lumx/math/constants.h>
#include <lumx/photometry/illuminance_grid.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/polar_diagram.h>

#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

namespace {

constexpr Rgb kFrame{0.30, 0.30, 0.30};
constexpr Rgb kGrid{0.88, 0.88, 0.88};

// Level colours from dark blue (highest) through green to orange (lowest): distinct in grey too.
Rgb level_color(std::size_t i, std::size_t n) {
  const Rgb anchors[4] = {{0.19, 0.07, 0.45}, {0.13, 0.45, 0.56}, {0.30, 0.70, 0.30}, {0.95, 0.55, 0.10}};
  const double t = n <= 1 ? 0.0 : 3.0 * static_cast<double>(i) / static_cast<double>(n - 1);
  const int k = std::min(2, static_cast<int>(t));
  const double f = t - k;
  return {anchors[k].r + f * (anchors[k + 1].r - anchors[k].r), anchors[k].g + f * (anchors[k + 1].g - anchors[k].g),
          anchors[k].b + f * (anchors[k + 1].b - anchors[k].b)};
}

// Up to three significant digits, no trailing zeros: "200", "2.5", "0.05".
std::string short_number(double v) {
  char buf[32];
  if (std::abs(v) >= 1000)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else
    std::snprintf(buf, sizeof buf, "%.3g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}

std::string with_unit(double v, const char* unit) { return short_number(v) + " " + unit; }

void check_size(const std::string& out, int size) {
  if (size < 200 || size > 8000) throw_plot_error(out, "size", "image size must lie in 200..8000 pixels");
}

std::string title_of(const Photometry& p, const MetricPlotOptions& o) {
  return o.title.empty() ? polar_default_title(p) : o.title;
}

// A tick step of 1, 2 or 5 × 10^k giving about `target` intervals over `span`.
double tick_step(double span, double target) {
  const double raw = span / target, decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * decade >= raw) return m * decade;
  return 10 * decade;
}

// Iso-lines of `field` (nx × ny) in the box (x0, y0)-(x1, y1) of the image; grid (0, 0) maps to the
// bottom-left corner. Each label sits where its line reaches furthest from the field's maximum in a
// direction that alternates between up-right and down-right, so nested lines keep their labels apart.
// Returns the label texts drawn.
std::vector<std::string> draw_isolines(Painter& pt, const std::vector<double>& field, int nx, int ny,
                                       const std::vector<double>& levels, const char* unit, double x0, double y0,
                                       double x1, double y1, double line_w, double label_pt) {
  cairo_t* cr = pt.cr();
  std::vector<std::string> labels;
  auto px = [&](double gx) { return x0 + (x1 - x0) * gx / (nx - 1); };
  auto py = [&](double gy) { return y1 - (y1 - y0) * gy / (ny - 1); };
  std::size_t peak = 0;
  for (std::size_t k = 0; k < field.size(); ++k)
    if (std::isfinite(field[k]) && !(field[k] <= field[peak])) peak = k;
  const double cgx = static_cast<double>(peak % static_cast<std::size_t>(nx));
  const double cgy = static_cast<double>(peak / static_cast<std::size_t>(nx));
  for (std::size_t i = 0; i < levels.size(); ++i) {
    const std::vector<Segment> segs = contour_segments(field, nx, ny, levels[i]);
    if (segs.empty()) continue;
    pt.color(level_color(i, levels.size()));
    cairo_set_line_width(cr, line_w);
    const double ang = (i % 2 == 0 ? 35.0 : -35.0) * kDegToRad, ux = std::cos(ang), uy = std::sin(ang);
    const Segment* best = &segs.front();
    double best_score = -INFINITY;
    for (const Segment& s : segs) {
      cairo_move_to(cr, px(s.x0), py(s.y0));
      cairo_line_to(cr, px(s.x1), py(s.y1));
      const double mx = 0.5 * (s.x0 + s.x1) - cgx, my = 0.5 * (s.y0 + s.y1) - cgy;
      const double r = std::hypot(mx, my);
      const double score = r > 0 ? (mx * ux + my * uy) / r : -1.0;  // closest in direction
      if (score > best_score + 1e-9 || (std::abs(score - best_score) <= 1e-9 && r > 0)) {
        best_score = score;
        best = &s;
      }
    }
    cairo_stroke(cr);
    const Segment* right = best;
    const std::string text = short_number(levels[i]);
    pt.font(label_pt);
    const cairo_text_extents_t e = pt.extents(text);
    const double lx = std::clamp(px(0.5 * (right->x0 + right->x1)), x0 + e.width / 2 + 2, x1 - e.width / 2 - 2);
    const double ly = std::clamp(py(0.5 * (right->y0 + right->y1)), y0 + e.height / 2 + 2, y1 - e.height / 2 - 2);
    cairo_set_source_rgba(cr, 1, 1, 1, 0.85);
    cairo_rectangle(cr, lx - e.width / 2 - 2, ly - e.height / 2 - 2, e.width + 4, e.height + 4);
    cairo_fill(cr);
    pt.color(level_color(i, levels.size()));
    pt.text_centered(text, lx, ly);
    labels.push_back(with_unit(levels[i], unit));
  }
  pt.check("iso-lines");
  return labels;
}

// The legend column: a coloured line and the value of each level, top to bottom.
void draw_legend(Painter& pt, const std::vector<double>& levels, const char* unit, const std::string& heading, double x,
                 double y, double size) {
  cairo_t* cr = pt.cr();
  pt.color(kTextColor);
  pt.font(0.022 * size, true);
  pt.text_baseline(heading, x, y, 0);
  for (std::size_t i = 0; i < levels.size(); ++i) {
    const double yy = y + 0.04 * size * static_cast<double>(i + 1);
    pt.color(level_color(i, levels.size()));
    cairo_set_line_width(cr, std::max(1.5, size / 300));
    cairo_move_to(cr, x, yy - 0.006 * size);
    cairo_line_to(cr, x + 0.04 * size, yy - 0.006 * size);
    cairo_stroke(cr);
    pt.color(kTextColor);
    pt.font(0.02 * size);
    pt.text_baseline(with_unit(levels[i], unit), x + 0.05 * size, yy, 0);
  }
  pt.check("legend");
}

void draw_header(Painter& pt, const std::string& title, const std::string& caption, double size) {
  pt.title_and_caption(title, caption, size, 0.04 * size, 0.08 * size);
  pt.check("title");
}

}  // namespace

PlotSummary write_isolux_plot(const Photometry& p, const std::string& out, const MetricPlotOptions& o) {
  check_size(out, o.size_px);
  const bool svg = is_svg_output(out);
  const IntensityTable t(p);
  IlluminanceGridOptions go;
  go.mounting_height_m = o.mounting_height_m;
  go.tilt_deg = o.tilt_deg;
  go.samples = 241;
  IlluminanceGrid g;
  try {
    g = illuminance_grid(t, go);
  } catch (const std::invalid_argument& e) {
    throw_plot_error(out, "isolux", e.what());
  }
  if (!(g.max_lux > 0)) throw_plot_error(out, "isolux", "the luminaire lights nothing below it");
  const std::vector<double> levels = nice_levels(g.max_lux, 0.004, 9);
  const double S = o.size_px, W = S;
  const double box_h = 0.66 * S * (g.y_max_m - g.y_min_m) / std::max(g.x_max_m - g.x_min_m, g.y_max_m - g.y_min_m);
  const double H = std::round(std::max(0.13 * S + box_h + 0.1 * S, 0.6 * S));
  PlotSummary sum{"isolux", {}};
  char cap[256];
  std::snprintf(cap, sizeof cap, "Isolux diagram: horizontal illuminance at mounting height %s m, tilt %s deg; E max %s lx",
                short_number(o.mounting_height_m).c_str(), short_number(o.tilt_deg).c_str(),
                format_quantity(g.max_lux).c_str());
  const std::string title = title_of(p, o), caption = cap;
  render_and_write(out, svg, W, H, [&](Painter& pt) {
    cairo_t* cr = pt.cr();
    draw_header(pt, title, caption, S);
    const double wx = g.x_max_m - g.x_min_m, wy = g.y_max_m - g.y_min_m, side = 0.66 * S;
    const double scale = side / std::max(wx, wy);
    const double x0 = 0.11 * S, y0 = 0.13 * S, x1 = x0 + wx * scale, y1 = y0 + wy * scale;
    // Metre grid and ticks.
    const double step = tick_step(std::max(wx, wy), 8);
    pt.font(0.018 * S);
    cairo_set_line_width(cr, std::max(0.5, S / 1200));
    for (double v = std::ceil(g.x_min_m / step) * step; v <= g.x_max_m + 1e-9; v += step) {
      const double x = x0 + (v - g.x_min_m) * scale;
      pt.color(kGrid);
      cairo_move_to(cr, x, y0);
      cairo_line_to(cr, x, y1);
      cairo_stroke(cr);
      pt.color(kTextColor);
      pt.text_baseline(short_number(v), x, y1 + 0.03 * S, 0.5);
    }
    for (double v = std::ceil(g.y_min_m / step) * step; v <= g.y_max_m + 1e-9; v += step) {
      const double y = y1 - (v - g.y_min_m) * scale;
      pt.color(kGrid);
      cairo_move_to(cr, x0, y);
      cairo_line_to(cr, x1, y);
      cairo_stroke(cr);
      pt.color(kTextColor);
      pt.text_middle(short_number(v), x0 - 0.01 * S, y, 1);
    }
    pt.color(kTextColor);
    pt.font(0.02 * S);
    pt.text_baseline("x (C0) / m", 0.5 * (x0 + x1), y1 + 0.065 * S, 0.5);
    cairo_save(cr);
    cairo_translate(cr, x0 - 0.065 * S, 0.5 * (y0 + y1));
    cairo_rotate(cr, -kPi / 2);
    pt.text_baseline("y (C90) / m", 0, 0, 0.5);
    cairo_restore(cr);
    sum.labels = draw_isolines(pt, g.lux, g.nx, g.ny, levels, "lx", x0, y0, x1, y1, std::max(1.2, S / 450), 0.017 * S);
    // The luminaire's foot and the frame.
    const double fx = x0 - g.x_min_m * scale, fy = y1 + g.y_min_m * scale, c = 0.012 * S;
    pt.color(kTextColor);
    cairo_set_line_width(cr, std::max(1.0, S / 600));
    cairo_move_to(cr, fx - c, fy);
    cairo_line_to(cr, fx + c, fy);
    cairo_move_to(cr, fx, fy - c);
    cairo_line_to(cr, fx, fy + c);
    cairo_stroke(cr);
    pt.color(kFrame);
    cairo_rectangle(cr, x0, y0, x1 - x0, y1 - y0);
    cairo_stroke(cr);
    draw_legend(pt, levels, "lx", "E / lx", 0.81 * S, 0.16 * S, S);
  });
  sum.labels.push_back("x (C0) / m");
  sum.labels.push_back("E max " + with_unit(g.max_lux, "lx"));
  return sum;
}

PlotSummary write_isocandela_plot(const Photometry& p, const std::string& out, const MetricPlotOptions& o) {
  check_size(out, o.size_px);
  const bool svg = is_svg_output(out);
  const IntensityTable t(p);
  const double peak = t.max_cd();
  if (!(peak > 0)) throw_plot_error(out, "isocandela", "the luminaire emits nothing");
  const double up = t.flux_lm() > 0 ? 1 - t.flux_lm(0, 90) / t.flux_lm() : 0.0;
  const double gmax = (t.type() == PhotometricType::C && up < 0.005) ? 90.0 : 180.0;
  // The projected disk sampled on a square grid: radius = gamma, angle = C.
  const int n = 301;
  std::vector<double> field(static_cast<std::size_t>(n) * n, std::numeric_limits<double>::quiet_NaN());
  for (int iy = 0; iy < n; ++iy)
    for (int ix = 0; ix < n; ++ix) {
      const double x = -gmax + 2 * gmax * ix / (n - 1), y = -gmax + 2 * gmax * iy / (n - 1);
      const double g = std::hypot(x, y);
      if (g > gmax + 1e-9) continue;
      const double c = std::atan2(y, x), gr = g * kDegToRad;
      field[static_cast<std::size_t>(iy) * n + static_cast<std::size_t>(ix)] =
          t.intensity(glm::dvec3(std::sin(gr) * std::cos(c), std::sin(gr) * std::sin(c), -std::cos(gr)));
    }
  const std::vector<double> levels = nice_levels(peak, 0.02, 8);
  const double S = o.size_px, W = S, H = std::round(1.02 * S);
  PlotSummary sum{"isocandela", {}};
  char cap[256];
  std::snprintf(cap, sizeof cap, "Isocandela diagram: gamma 0-%s deg from nadir as radius, C0 right, C90 up; peak %s cd",
                short_number(gmax).c_str(), format_quantity(peak).c_str());
  const std::string title = title_of(p, o), caption = cap;
  render_and_write(out, svg, W, H, [&](Painter& pt) {
    cairo_t* cr = pt.cr();
    draw_header(pt, title, caption, S);
    const double R = 0.36 * S, cx = 0.42 * S, cy = 0.55 * S;
    cairo_set_line_width(cr, std::max(0.5, S / 1200));
    const double ring = gmax > 90 ? 30 : 15;
    pt.font(0.017 * S);
    for (double g = ring; g <= gmax + 1e-9; g += ring) {
      pt.color(kGrid);
      cairo_new_path(cr);
      cairo_arc(cr, cx, cy, R * g / gmax, 0, 2 * kPi);
      cairo_stroke(cr);
      pt.color(kMutedColor);
      pt.text_baseline(short_number(g) + "\xC2\xB0", cx + 3, cy - R * g / gmax - 3, 0);
    }
    for (int c = 0; c < 360; c += 30) {
      const double a = c * kDegToRad;
      pt.color(kGrid);
      cairo_move_to(cr, cx, cy);
      cairo_line_to(cr, cx + R * std::cos(a), cy - R * std::sin(a));
      cairo_stroke(cr);
      pt.color(kTextColor);
      pt.text_centered("C" + std::to_string(c), cx + (R + 0.03 * S) * std::cos(a), cy - (R + 0.03 * S) * std::sin(a));
    }
    sum.labels = draw_isolines(pt, field, n, n, levels, "cd", cx - R, cy - R, cx + R, cy + R, std::max(1.2, S / 450),
                               0.016 * S);
    pt.color(kFrame);
    cairo_new_path(cr);
    cairo_arc(cr, cx, cy, R, 0, 2 * kPi);
    cairo_stroke(cr);
    draw_legend(pt, levels, "cd", "I / cd", 0.83 * S, 0.16 * S, S);
  });
  sum.labels.push_back("C0");
  sum.labels.push_back("peak " + with_unit(peak, "cd"));
  return sum;
}

LUMX_NAMESPACE_END
