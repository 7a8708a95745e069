// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/polar_plot.cpp — cairo renderer for the polar intensity diagram.
//
// Layout (S = options.size_px, image S x round(1.02 S)): title and caption at the top; the polar grid in
// the middle (nadir at the bottom, zenith at the top, C0/C90 halves on the right, C180/C270 mirrored on
// the left); the half names in the top corners, the unit in the bottom-left corner, the LOR (relative
// photometry) in the bottom-right corner; the legend in a row below. Ring values are written on the ray
// that crosses the curves least (near the zenith for a downlight), on a translucent white box.
#include "polar_plot.h"

#include "plot_canvas.h"

#include <lumx/photometry/polar_diagram.h>

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

namespace {

constexpr Rgb kC0Color{0.80, 0.07, 0.07};   // C0-C180: red, solid
constexpr Rgb kC90Color{0.07, 0.27, 0.80};  // C90-C270: blue, dashed

std::string format_angle(double deg) {
  char buf[32];
  if (std::abs(deg - std::round(deg)) < 1e-6)
    std::snprintf(buf, sizeof buf, "%.0f", deg);
  else
    std::snprintf(buf, sizeof buf, "%.1f", deg);
  return buf;
}

struct Box {
  double x0, y0, x1, y1;
  bool contains(double x, double y) const { return x >= x0 && x <= x1 && y >= y0 && y <= y1; }
};

class PolarRenderer {
 public:
  PolarRenderer(const PolarDiagram& dg, const std::string& title, bool type_c, double size)
      : dg_(dg), title_(title), type_c_(type_c), S_(size) {
    W_ = S_;
    H_ = std::round(1.02 * S_);
    R_ = 0.375 * S_;
    cx_ = 0.5 * S_;
    cy_ = 0.535 * S_;
    grid_lw_ = std::max(0.5, S_ / 800.0);
    curve_lw_ = std::max(1.0, S_ / 340.0);
    // Labels grow to 8.5 px on small images, but no further than the layout allows (2.6 % of S keeps the
    // corner texts clear of the 150-degree and 30-degree labels).
    label_pt_ = std::max(0.0175 * S_, std::min(8.5, 0.026 * S_));
  }

  double width() const { return W_; }
  double height() const { return H_; }

  // Draws on a white surface of width() × height().
  void draw(Painter& pt) const {
    draw_header(pt);
    draw_grid(pt);
    draw_curve(pt, dg_.c0_c180, kC0Color, false);
    draw_curve(pt, dg_.c90_c270, kC90Color, true);
    draw_ring_labels(pt);
    draw_corners(pt);
    draw_legend(pt);
  }

 private:
  // Pixel position of a value at a signed angle from nadir (theta > 0 on the right, nadir at the bottom).
  void to_xy(double theta_deg, double value, double& x, double& y) const {
    const double r = dg_.rings.outer_radius > 0 ? R_ * value / dg_.rings.outer_radius : 0.0;
    const double t = theta_deg * kDegToRad;
    x = cx_ + r * std::sin(t);
    y = cy_ + r * std::cos(t);
  }

  void draw_header(Painter& pt) const {
    pt.color(kTextColor);
    pt.fit_font(title_, 0.030 * S_, true, 0.94 * W_);
    pt.text_baseline(title_, 0.5 * W_, 0.050 * S_, 0.5);

    std::string cap = "Φ luminaire " + format_quantity(dg_.luminaire_flux_lm) + " lm";
    if (dg_.rated_lamp_flux_lm > 0) cap += "   ·   Φ lamps " + format_quantity(dg_.rated_lamp_flux_lm) + " lm";
    cap += "   ·   I max " + format_quantity(dg_.max_cd) + " cd";
    if (dg_.relative) cap += " (" + format_quantity(dg_.max_cd * dg_.scale) + " cd/klm)";
    if (dg_.max_cd > 0) {
      const std::string h = format_angle(dg_.max_horizontal_deg), v = format_angle(dg_.max_vertical_deg);
      cap += type_c_ ? " at C" + h + " γ" + v + "°" : " at H" + h + "° V" + v + "°";
    }
    // The file name leads the caption when the title is something else, unless that would make the
    // caption too small to read.
    const double cap_pt = std::max(0.0185 * S_, std::min(8.5, 0.026 * S_)), cap_width = 0.94 * W_;
    if (!dg_.file_name.empty() && dg_.file_name != title_) {
      const std::string with_file = dg_.file_name + "   ·   " + cap;
      pt.font(cap_pt);
      if (pt.extents(with_file).x_advance <= cap_width / 0.85) cap = with_file;
    }
    pt.color(kMutedColor);
    pt.fit_font(cap, cap_pt, false, cap_width);
    pt.text_baseline(cap, 0.5 * W_, 0.087 * S_, 0.5);
    pt.check("title");
  }

  void draw_grid(Painter& pt) const {
    cairo_t* cr = pt.cr();
    const int n = dg_.rings.ring_count;
    // Radial lines every 15 degrees; the vertical and horizontal axes a little stronger.
    for (int a = -165; a <= 180; a += 15) {
      const bool axis = a % 90 == 0;
      double x, y;
      to_xy(a, dg_.rings.outer_radius, x, y);
      cairo_move_to(cr, cx_, cy_);
      cairo_line_to(cr, x, y);
      cairo_set_line_width(cr, grid_lw_);
      if (axis)
        cairo_set_source_rgb(cr, 0.55, 0.55, 0.55);
      else
        cairo_set_source_rgb(cr, 0.82, 0.82, 0.82);
      cairo_stroke(cr);
    }
    for (int k = 1; k <= n; ++k) {
      const double r = R_ * k / n;
      cairo_new_sub_path(cr);
      cairo_arc(cr, cx_, cy_, r, 0, 2 * kPi);
      if (k == n) {
        cairo_set_line_width(cr, 1.4 * grid_lw_);
        cairo_set_source_rgb(cr, 0.35, 0.35, 0.35);
      } else {
        cairo_set_line_width(cr, grid_lw_);
        cairo_set_source_rgb(cr, 0.72, 0.72, 0.72);
      }
      cairo_stroke(cr);
    }
    // Angle labels every 30 degrees, on both halves; 0 at nadir, 180 at the zenith.
    pt.color(kTextColor);
    for (const auto& [b, text] : angle_label_boxes(pt))
      pt.text_centered(text, 0.5 * (b.x0 + b.x1), 0.5 * (b.y0 + b.y1));
    pt.check("grid");
  }

  void draw_curve(Painter& pt, const PolarCurve& c, const Rgb& col, bool dashed) const {
    if (c.points.empty()) return;
    cairo_t* cr = pt.cr();
    cairo_new_path(cr);
    for (std::size_t i = 0; i < c.points.size(); ++i) {
      double x, y;
      to_xy(c.points[i].angle_deg, c.points[i].value, x, y);
      if (i == 0)
        cairo_move_to(cr, x, y);
      else
        cairo_line_to(cr, x, y);
    }
    cairo_close_path(cr);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_set_line_cap(cr, dashed ? CAIRO_LINE_CAP_BUTT : CAIRO_LINE_CAP_ROUND);
    cairo_set_line_width(cr, curve_lw_);
    if (dashed) {
      const double d[] = {4.5 * curve_lw_, 2.5 * curve_lw_};
      cairo_set_dash(cr, d, 2, 0);
    }
    pt.color(col);
    cairo_stroke(cr);
    cairo_set_dash(cr, nullptr, 0, 0);
    pt.check("curves");
  }

  // Ink boxes of the angle labels (sets the label font).
  std::vector<std::pair<Box, std::string>> angle_label_boxes(Painter& pt) const {
    std::vector<std::pair<Box, std::string>> out;
    pt.font(label_pt_);
    const double gap = 0.014 * S_;
    for (int a = -150; a <= 180; a += 30) {
      std::string s = std::to_string(std::abs(a)) + "°";
      const cairo_text_extents_t e = pt.extents(s);
      const double t = a * kDegToRad;
      const double reach = R_ + gap + std::abs(std::sin(t)) * e.width / 2 + std::abs(std::cos(t)) * e.height / 2;
      const double x = cx_ + reach * std::sin(t), y = cy_ + reach * std::cos(t);
      out.push_back({Box{x - e.width / 2, y - e.height / 2, x + e.width / 2, y + e.height / 2}, std::move(s)});
    }
    return out;
  }

  // Label boxes of all rings if written on the ray at `theta` (signed degrees from nadir).
  std::vector<std::pair<Box, std::string>> ring_label_boxes(Painter& pt, double theta) const {
    std::vector<std::pair<Box, std::string>> out;
    const int n = dg_.rings.ring_count;
    const double pad = 0.25 * label_pt_;
    for (int k = 1; k <= n; ++k) {
      const double v = dg_.rings.ring_step * k;
      std::string s = format_ring_value(v, dg_.rings.ring_step);
      const cairo_text_extents_t e = pt.extents(s);
      double x, y;
      to_xy(theta, v, x, y);
      const double hw = e.width / 2 + pad, hh = e.height / 2 + pad;
      out.push_back({Box{x - hw, y - hh, x + hw, y + hh}, std::move(s)});
    }
    return out;
  }

  // Curve ink (both curves, segments subdivided to ~1.5 px) inside any of `boxes`.
  int curve_hits(const std::vector<std::pair<Box, std::string>>& boxes) const {
    int hits = 0;
    const double step_px = 1.5;
    for (const PolarCurve* c : {&dg_.c0_c180, &dg_.c90_c270}) {
      double px = 0, py = 0;
      for (std::size_t i = 0; i < c->points.size(); ++i) {
        double x, y;
        to_xy(c->points[i].angle_deg, c->points[i].value, x, y);
        const int sub = i == 0 ? 1 : std::max(1, static_cast<int>(std::ceil(std::hypot(x - px, y - py) / step_px)));
        for (int s = 1; s <= sub; ++s) {
          const double f = static_cast<double>(s) / sub;
          const double qx = i == 0 ? x : px + f * (x - px), qy = i == 0 ? y : py + f * (y - py);
          for (const auto& b : boxes)
            if (b.first.contains(qx, qy)) ++hits;
        }
        px = x;
        py = y;
      }
    }
    return hits;
  }

  void draw_ring_labels(Painter& pt) const {
    cairo_t* cr = pt.cr();
    const auto angle_boxes = angle_label_boxes(pt);
    pt.font(0.9 * label_pt_);
    // Candidate rays every 7.5 degrees. Cost: curve ink near the labels, then overlap with an angle
    // label, then distance from the vertical axis (the zenith side first). Rays on an unlabelled grid
    // line (odd multiples of 15) are preferred, so the labels neither float between grid lines nor crowd
    // an angle label: a downlight gets its values up the 165-degree ray, an uplight down the 15-degree one.
    double best_theta = 165, best_cost = 1e300;
    for (int i = 0; i < 48; ++i) {
      const double theta = 180.0 - 7.5 * i;  // 180, 172.5, ..., -172.5
      const double dist = std::abs(theta);
      const auto boxes = ring_label_boxes(pt, theta);
      auto keep_clear = boxes;  // curves should pass no closer than half a label height
      for (auto& kb : keep_clear) {
        const double m = 0.5 * label_pt_;
        kb.first = Box{kb.first.x0 - m, kb.first.y0 - m, kb.first.x1 + m, kb.first.y1 + m};
      }
      int clashes = 0;
      for (const auto& rb : boxes)
        for (const auto& ab : angle_boxes)
          if (rb.first.x0 < ab.first.x1 && ab.first.x0 < rb.first.x1 && rb.first.y0 < ab.first.y1 &&
              ab.first.y0 < rb.first.y1)
            ++clashes;
      const bool odd_grid = std::fmod(dist, 30.0) == 15.0;
      const double cost = curve_hits(keep_clear) * 1000.0 + clashes * 500.0 + std::min(180.0 - dist, dist + 5.0) +
                          (odd_grid ? 0.0 : 20.0);
      if (cost < best_cost) {
        best_cost = cost;
        best_theta = theta;
      }
    }
    for (const auto& [b, s] : ring_label_boxes(pt, best_theta)) {
      cairo_rectangle(cr, b.x0, b.y0, b.x1 - b.x0, b.y1 - b.y0);
      cairo_set_source_rgba(cr, 1, 1, 1, 0.82);
      cairo_fill(cr);
      pt.color(kMutedColor);
      pt.text_centered(s, 0.5 * (b.x0 + b.x1), 0.5 * (b.y0 + b.y1));
    }
    pt.check("ring labels");
  }

  void draw_corners(Painter& pt) const {
    const double top = cy_ - R_ + 0.2 * label_pt_;
    const double bottom = cy_ + R_;
    pt.font(label_pt_);
    pt.color(kC0Color);
    pt.text_baseline(dg_.c0_c180.negative_side, cx_ - R_, top, 0);
    pt.text_baseline(dg_.c0_c180.positive_side, cx_ + R_, top, 1);
    pt.color(kC90Color);
    pt.text_baseline(dg_.c90_c270.negative_side, cx_ - R_, top + 1.35 * label_pt_, 0);
    pt.text_baseline(dg_.c90_c270.positive_side, cx_ + R_, top + 1.35 * label_pt_, 1);

    pt.color(kTextColor);
    pt.font(1.15 * label_pt_, true);
    pt.text_baseline(dg_.unit, cx_ - R_, bottom, 0);
    if (dg_.relative && dg_.rated_lamp_flux_lm > 0) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "η = %.0f %%", 100.0 * dg_.luminaire_flux_lm / dg_.rated_lamp_flux_lm);
      pt.font(label_pt_);
      pt.text_baseline(buf, cx_ + R_, bottom, 1);
    }
    pt.check("corner labels");
  }

  void draw_legend(Painter& pt) const {
    cairo_t* cr = pt.cr();
    pt.font(1.05 * label_pt_);
    const double seg = 0.06 * S_, gap = 0.012 * S_, between = 0.05 * S_;
    const double w0 = pt.extents(dg_.c0_c180.name).x_advance, w1 = pt.extents(dg_.c90_c270.name).x_advance;
    const double total = seg + gap + w0 + between + seg + gap + w1;
    const double y = 0.985 * S_;
    double x = 0.5 * (W_ - total);
    struct Item {
      const PolarCurve* c;
      Rgb col;
      bool dashed;
      double w;
    };
    for (const Item& it : {Item{&dg_.c0_c180, kC0Color, false, w0}, Item{&dg_.c90_c270, kC90Color, true, w1}}) {
      cairo_new_path(cr);
      cairo_move_to(cr, x, y);
      cairo_line_to(cr, x + seg, y);
      cairo_set_line_width(cr, curve_lw_);
      cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
      if (it.dashed) {
        const double d[] = {4.5 * curve_lw_, 2.5 * curve_lw_};
        cairo_set_dash(cr, d, 2, 0);
      }
      pt.color(it.col);
      cairo_stroke(cr);
      cairo_set_dash(cr, nullptr, 0, 0);
      pt.color(kTextColor);
      const cairo_text_extents_t e = pt.extents(it.c->name);
      cairo_move_to(cr, x + seg + gap, y - (e.y_bearing + e.height / 2));
      cairo_show_text(cr, it.c->name.c_str());
      x += seg + gap + it.w + between;
    }
    pt.check("legend");
  }

  const PolarDiagram& dg_;
  std::string title_;
  bool type_c_;
  double S_, W_, H_, R_, cx_, cy_, grid_lw_, curve_lw_, label_pt_;
};

}  // namespace

void write_polar_plot(const Photometry& p, const std::string& out_path, const PolarPlotOptions& opts) {
  const bool svg = is_svg_output(out_path);
  if (opts.size_px < 200 || opts.size_px > 8000)
    throw_plot_error(out_path, "size", "plot size " + std::to_string(opts.size_px) + " px is outside 200..8000");

  PolarDiagramOptions dopt;
  dopt.force_cd = opts.force_cd;
  const PolarDiagram dg = make_polar_diagram(p, dopt);
  const PolarRenderer renderer(dg, opts.title.empty() ? dg.title : opts.title, p.type == PhotometricType::C,
                               opts.size_px);
  render_and_write(out_path, svg, renderer.width(), renderer.height(), [&](Painter& pt) { renderer.draw(pt); });
}

LUMX_NAMESPACE_END
