// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include "room_plot.h"

#include "contour.h"
#include "plot_canvas.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

LUMX_NAMESPACE_BEGIN

namespace {

constexpr double kHeader = 44.0;  // px above the picture: title and caption

std::uint32_t argb(double r, double g, double b) {
  auto c = [](double v) { return std::uint32_t(std::lround(255.0 * std::clamp(v, 0.0, 1.0))); };
  return 0xFF000000u | (c(r) << 16) | (c(g) << 8) | c(b);
}

/// Paints `pixel(x, y)` (ARGB) as the picture at (0, kHeader).
template <class Pixel>
void paint_pixels(Painter& pt, int w, int h, Pixel pixel) {
  SurfacePtr img(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h));
  if (cairo_surface_status(img.get()) != CAIRO_STATUS_SUCCESS)
    throw_plot_error("", "output", "cairo failed to create the picture");
  cairo_surface_flush(img.get());
  unsigned char* data = cairo_image_surface_get_data(img.get());
  const int stride = cairo_image_surface_get_stride(img.get());
  for (int y = 0; y < h; ++y) {
    auto* row = reinterpret_cast<std::uint32_t*>(data + std::ptrdiff_t(y) * stride);
    for (int x = 0; x < w; ++x) row[x] = pixel(x, y);
  }
  cairo_surface_mark_dirty(img.get());
  cairo_t* cr = pt.cr();
  cairo_save(cr);
  cairo_set_source_surface(cr, img.get(), 0, kHeader);
  cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
  cairo_paint(cr);
  cairo_restore(cr);
}

}  // namespace

double positive_quantile(const render::Image& image, int c, double q) {
  std::vector<float> v;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (image.at(x, y, c) > 0.0f) v.push_back(image.at(x, y, c));
  if (v.empty()) return 0.0;
  const std::size_t k = std::min(v.size() - 1, std::size_t(q * double(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return double(v[k]);
}

std::vector<double> log_contour_levels(const render::Image& reference, int per_decade, int decades) {
  const double top = positive_quantile(reference, reference.channel_index("Y"), 0.995);
  std::vector<double> levels;
  if (!(top > 0)) return levels;
  // Levels at 10^(k / per_decade) cd/m², so they are round numbers and the same for every method.
  const int k_top = int(std::floor(std::log10(top) * per_decade));
  for (int k = k_top; k > k_top - per_decade * decades; --k) levels.push_back(std::pow(10.0, double(k) / per_decade));
  return levels;
}

void write_contour_png(const std::string& path, const render::Image& view, double white, const std::vector<double>& levels,
                       const std::string& title, const std::string& caption) {
  const int w = view.width, h = view.height, cy = view.channel_index("Y"), cs = view.channel_index("surface");
  render_and_write(path, false, w, h + kHeader, [&](Painter& pt) {
    pt.title_and_caption(title, caption, w, 17, 36);
    paint_pixels(pt, w, h, [&](int x, int y) {
      const double t = white > 0 ? std::pow(std::clamp(double(view.at(x, y, cy)) / white, 0.0, 1.0), 1.0 / 2.2) : 0.0;
      return argb(t, t, t);
    });
    // Iso-lines of L, in log L so the lines are where the eye sees the steps; pixels seeing nothing end them.
    std::vector<double> field(std::size_t(w) * std::size_t(h));
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double l = view.at(x, y, cy);
        field[std::size_t(y) * std::size_t(w) + std::size_t(x)] =
            (cs >= 0 && view.at(x, y, cs) < 0) || !(l > 0) ? NAN : std::log(l);
      }
    cairo_t* cr = pt.cr();
    cairo_set_line_width(cr, 1.0);
    cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);  // black bands, as the dissertation's pulse train draws them
    for (std::size_t k = 0; k < levels.size(); ++k) {
      for (const Segment& s : contour_segments(field, w, h, std::log(levels[k]))) {
        cairo_move_to(cr, s.x0 + 0.5, s.y0 + 0.5 + kHeader);
        cairo_line_to(cr, s.x1 + 0.5, s.y1 + 0.5 + kHeader);
      }
      cairo_stroke(cr);
    }
    pt.check("contours");
  });
}

void write_difference_png(const std::string& path, const render::Image& view, const render::Image& reference,
                          double range, const std::string& title, const std::string& caption) {
  const int w = view.width, h = view.height, ce = view.channel_index("E"), cs = view.channel_index("surface");
  const double floor = 0.01 * positive_quantile(reference, reference.channel_index("E"), 0.995);
  const int bar = 70;  // colour bar to the right
  auto colour = [&](double d) {  // blue – white – red
    const double t = std::clamp(d / range, -1.0, 1.0);
    return t < 0 ? argb(1 + t, 1 + t, 1) : argb(1, 1 - t, 1 - t);
  };
  render_and_write(path, false, w + bar, h + kHeader, [&](Painter& pt) {
    pt.title_and_caption(title, caption, w + bar, 17, 36);
    paint_pixels(pt, w, h, [&](int x, int y) {
      if (cs >= 0 && view.at(x, y, cs) < 0) return argb(0.5, 0.5, 0.5);
      const double e = view.at(x, y, ce), r = reference.at(x, y, ce);
      return colour((e - r) / std::max(r, floor > 0 ? floor : 1e-30));
    });
    cairo_t* cr = pt.cr();
    const double x0 = w + 10, y0 = kHeader + 10, bh = h - 20, bw = 14;
    for (int i = 0; i < int(bh); ++i) {
      const std::uint32_t c = colour(range * (1.0 - 2.0 * (i + 0.5) / bh));
      cairo_set_source_rgb(cr, ((c >> 16) & 255) / 255.0, ((c >> 8) & 255) / 255.0, (c & 255) / 255.0);
      cairo_rectangle(cr, x0, y0 + i, bw, 1.0);
      cairo_fill(cr);
    }
    pt.color(kTextColor);
    pt.font(10);
    for (int k = -2; k <= 2; ++k) {
      const double v = range * k / 2.0, y = y0 + bh * (0.5 - k / 4.0);
      char label[32];
      std::snprintf(label, sizeof label, "%+.0f %%", 100 * v);
      pt.text_middle(label, x0 + bw + 4, y, 0);
    }
    pt.check("colour bar");
  });
}

void write_side_by_side_png(const std::string& path, const std::vector<std::string>& pngs) {
  std::vector<SurfacePtr> parts;
  double width = 0, height = 0;
  for (const std::string& p : pngs) {
    parts.emplace_back(cairo_image_surface_create_from_png(p.c_str()));
    if (cairo_surface_status(parts.back().get()) != CAIRO_STATUS_SUCCESS)
      throw_plot_error(p, "input", "cannot read the PNG");
    width += cairo_image_surface_get_width(parts.back().get()) + (parts.size() > 1 ? 8 : 0);
    height = std::max(height, double(cairo_image_surface_get_height(parts.back().get())));
  }
  render_and_write(path, false, width, height, [&](Painter& pt) {
    double x = 0;
    for (const SurfacePtr& s : parts) {
      cairo_set_source_surface(pt.cr(), s.get(), x, 0);
      cairo_paint(pt.cr());
      x += cairo_image_surface_get_width(s.get()) + 8;
    }
  });
}

LUMX_NAMESPACE_END
