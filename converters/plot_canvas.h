// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/plot_canvas.h — the cairo plumbing shared by the plot renderers (polar_plot.cpp for the polar
// intensity diagram, bundle_plot.cpp for sphere-map images and APL position views): RAII handles, the
// error helper, the datasheet number format, the text colours, the Painter (fonts and text placement), and
// render_and_write (surface by extension, white background, PNG/SVG encoding, atomic write). They live in
// one place so that every lumx image is laid out, numbered and written the same way, and fails with the
// same messages.
#pragma once

#include <lumx/version.h>

#include <cairo.h>

#include <functional>
#include <memory>
#include <string>
#include <utility>

LUMX_NAMESPACE_BEGIN

/// Throws lumx::Error about the image `out_path` ("output", "size", ...; no line number).
[[noreturn]] void throw_plot_error(const std::string& out_path, const char* field, const std::string& message);

struct CairoSurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct CairoContextDeleter {
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};
struct CairoPatternDeleter {
  void operator()(cairo_pattern_t* p) const { cairo_pattern_destroy(p); }
};
using SurfacePtr = std::unique_ptr<cairo_surface_t, CairoSurfaceDeleter>;
using ContextPtr = std::unique_ptr<cairo_t, CairoContextDeleter>;
using PatternPtr = std::unique_ptr<cairo_pattern_t, CairoPatternDeleter>;

struct Rgb {
  double r, g, b;
};
constexpr Rgb kTextColor{0.10, 0.10, 0.10};   // titles, labels
constexpr Rgb kMutedColor{0.38, 0.38, 0.38};  // captions, notes

/// "1234", "12.3", "0.456": no more digits than a datasheet would print (large values keep all digits).
std::string format_quantity(double v);

/// As format_quantity, but magnitudes from 1e7 up (and non-finite values) with three significant digits
/// ("1.5e+09"), for sums that may be huge.
std::string format_quantity_compact(double v);

/// A cairo context with the plot fonts (DejaVu Sans) and text placement; failures become lumx::Error about
/// the output file.
class Painter {
 public:
  Painter(cairo_t* cr, std::string out_path) : cr_(cr), out_path_(std::move(out_path)) {}

  /// Throws ("output") if cairo has failed while drawing `step` ("title", "grid", ...).
  void check(const char* step) const;

  void color(const Rgb& c, double alpha = 1.0) const { cairo_set_source_rgba(cr_, c.r, c.g, c.b, alpha); }
  void font(double size, bool bold = false) const;
  cairo_text_extents_t extents(const std::string& s) const;

  /// Shrinks the current font until `s` fits `max_width` (never below `min_factor` of `size`).
  void fit_font(const std::string& s, double size, bool bold, double max_width, double min_factor = 0.55) const;

  /// Text whose ink box is centred on (x, y).
  void text_centered(const std::string& s, double x, double y) const;

  /// A diagram's heading across an image `width` wide: the bold title centred at title_y, the muted caption
  /// at caption_y, both shrunk to fit 94 % of the width.
  void title_and_caption(const std::string& title, const std::string& caption, double width, double title_y,
                         double caption_y) const;

  /// Text on baseline y: align 0 = left edge at x, 0.5 = centred, 1 = right edge at x.
  void text_baseline(const std::string& s, double x, double y, double align) const;

  /// Text vertically centred on y (by ink), horizontally aligned as in text_baseline.
  void text_middle(const std::string& s, double x, double y, double align) const;

  cairo_t* cr() const { return cr_; }

 private:
  cairo_t* cr_;
  std::string out_path_;
};

/// The image format of `out_path` by its extension (case-insensitive): true for .svg, false for .png;
/// throws ("output") for anything else.
bool is_svg_output(const std::string& out_path);

/// Creates a width × height surface (SVG stream or ARGB32 image), paints it white, lets `draw` paint on
/// it, encodes it (SVG or PNG) in memory and writes it atomically to `out_path`, so a failure never leaves
/// a partial file. Cairo failures throw ("output"); write errors as lumx::write_file_atomically reports them.
void render_and_write(const std::string& out_path, bool svg, double width, double height,
                      const std::function<void(Painter&)>& draw);

LUMX_NAMESPACE_END
