// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/plot_canvas.cpp — the cairo plumbing shared by the plot renderers (see plot_canvas.h).
#include "plot_canvas.h"

#include <lumx/core/diagnostic.h>
#include <lumx/io/atomic_file.h>

#include <cairo-svg.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

LUMX_NAMESPACE_BEGIN

namespace {

// cairo write callback: appends to a std::string. Must not throw across the C boundary.
cairo_status_t append_bytes(void* closure, const unsigned char* data, unsigned int length) {
  try {
    static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
    return CAIRO_STATUS_SUCCESS;
  } catch (...) {
    return CAIRO_STATUS_NO_MEMORY;
  }
}

std::string lower_extension(const std::string& path) {
  const std::size_t slash = path.find_last_of("/\\");
  const std::size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return {};
  std::string ext = path.substr(dot);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace

void throw_plot_error(const std::string& out_path, const char* field, const std::string& message) {
  throw_at_line(out_path, 0, field, message);
}

std::string format_quantity(double v) {
  char buf[64];
  const double a = std::abs(v);
  if (a >= 100 || a == 0)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else if (a >= 10)
    std::snprintf(buf, sizeof buf, "%.1f", v);
  else if (a >= 1)
    std::snprintf(buf, sizeof buf, "%.2f", v);
  else
    std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::string format_quantity_compact(double v) {
  if (std::abs(v) < 1e7 && std::isfinite(v)) return format_quantity(v);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

void Painter::check(const char* step) const {
  const cairo_status_t st = cairo_status(cr_);
  if (st != CAIRO_STATUS_SUCCESS)
    throw_plot_error(out_path_, "output",
                     std::string("cairo failed while drawing the ") + step + ": " + cairo_status_to_string(st));
}

void Painter::font(double size, bool bold) const {
  cairo_select_font_face(cr_, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr_, size);
}

cairo_text_extents_t Painter::extents(const std::string& s) const {
  cairo_text_extents_t e{};
  cairo_text_extents(cr_, s.c_str(), &e);
  return e;
}

void Painter::fit_font(const std::string& s, double size, bool bold, double max_width, double min_factor) const {
  font(size, bold);
  const double w = extents(s).x_advance;
  if (w > max_width && w > 0) font(std::max(size * min_factor, size * max_width / w), bold);
}

void Painter::title_and_caption(const std::string& title, const std::string& caption, double width, double title_y,
                                double caption_y) const {
  color(kTextColor);
  fit_font(title, 0.032 * width, true, 0.94 * width);
  text_centered(title, 0.5 * width, title_y);
  color(kMutedColor);
  fit_font(caption, 0.021 * width, false, 0.94 * width);
  text_centered(caption, 0.5 * width, caption_y);
}

void Painter::text_centered(const std::string& s, double x, double y) const {
  const cairo_text_extents_t e = extents(s);
  cairo_move_to(cr_, x - (e.x_bearing + e.width / 2), y - (e.y_bearing + e.height / 2));
  cairo_show_text(cr_, s.c_str());
}

void Painter::text_baseline(const std::string& s, double x, double y, double align) const {
  const cairo_text_extents_t e = extents(s);
  cairo_move_to(cr_, x - align * e.x_advance, y);
  cairo_show_text(cr_, s.c_str());
}

void Painter::text_middle(const std::string& s, double x, double y, double align) const {
  const cairo_text_extents_t e = extents(s);
  cairo_move_to(cr_, x - align * e.x_advance, y - (e.y_bearing + e.height / 2));
  cairo_show_text(cr_, s.c_str());
}

bool is_svg_output(const std::string& out_path) {
  const std::string ext = lower_extension(out_path);
  if (ext != ".svg" && ext != ".png")
    throw_plot_error(out_path, "output",
                     "cannot tell the image format from the extension '" + ext + "' (use .svg or .png)");
  return ext == ".svg";
}

void render_and_write(const std::string& out_path, bool svg, double width, double height,
                      const std::function<void(Painter&)>& draw) {
  std::string bytes;
  SurfacePtr surface(
      svg ? cairo_svg_surface_create_for_stream(append_bytes, &bytes, width, height)
          : cairo_image_surface_create(CAIRO_FORMAT_ARGB32, static_cast<int>(width), static_cast<int>(height)));
  auto check_surface = [&](const char* step) {
    const cairo_status_t st = cairo_surface_status(surface.get());
    if (st != CAIRO_STATUS_SUCCESS)
      throw_plot_error(out_path, "output", std::string("cairo failed to ") + step + ": " + cairo_status_to_string(st));
  };
  check_surface("create the surface");
#if CAIRO_VERSION >= CAIRO_VERSION_ENCODE(1, 15, 10)
  if (svg) cairo_svg_surface_set_document_unit(surface.get(), CAIRO_SVG_UNIT_PX);
#endif
  {
    ContextPtr cr(cairo_create(surface.get()));
    Painter painter(cr.get(), out_path);
    painter.check("context");
    cairo_set_antialias(cr.get(), CAIRO_ANTIALIAS_BEST);
    cairo_set_source_rgb(cr.get(), 1, 1, 1);
    cairo_paint(cr.get());
    painter.check("background");
    draw(painter);
    painter.check("image");
  }
  cairo_surface_flush(surface.get());
  check_surface("flush the image");
  if (svg) {
    cairo_surface_finish(surface.get());  // emits the SVG document through append_bytes
    check_surface("finish the SVG document");
  } else {
    const cairo_status_t st = cairo_surface_write_to_png_stream(surface.get(), append_bytes, &bytes);
    if (st != CAIRO_STATUS_SUCCESS)
      throw_plot_error(out_path, "output",
                       std::string("cairo failed to encode the PNG: ") + cairo_status_to_string(st));
  }
  if (bytes.empty()) throw_plot_error(out_path, "output", "cairo produced no image data");
  write_file_atomically(out_path, bytes);
}

LUMX_NAMESPACE_END
