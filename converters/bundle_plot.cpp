// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/bundle_plot.cpp — cairo renderers for APL bundles (sphere-map images, APL position views).
//
// Sphere-map image (texel scale s, content width CW = max(2Rs + gap, 600)): title and caption at the top;
// the hemisphere names above the two squares, which are drawn s px per texel with a small gap between
// them; a horizontal inferno colour bar below with the unit at its right end; a note on how to read a
// square below that. The image is built at one pixel per texel; PNG output scales it with the NEAREST
// filter, SVG output embeds an upscaled copy (SVG viewers would smooth a scaled image).
//
// APL positions (width S): title and caption; three square panels (top x–y, front x–z, side y–z) with
// metre ticks on the left and bottom; a legend row below (largest disc, a 10 % disc, the bounding sphere).
#include "bundle_plot.h"

#include "plot_canvas.h"

#include <lumx/photometry/photometric_frame.h>

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

namespace {

constexpr Rgb kFrame{0.35, 0.35, 0.35};
constexpr Rgb kGrid{0.86, 0.86, 0.86};
constexpr Rgb kAplFill{0.96, 0.52, 0.08};
constexpr Rgb kAplEdge{0.55, 0.22, 0.00};
constexpr Rgb kBounds{0.07, 0.27, 0.80};

// An azimuth in [0, 360) with at most one decimal ("12", "29.4"); 359.97 becomes "0".
std::string format_azimuth(double deg) {
  if (std::round(deg * 10.0) >= 3600.0) deg = 0.0;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", deg);
  std::string s = buf;
  if (s.size() > 2 && s.compare(s.size() - 2, 2, ".0") == 0) s.resize(s.size() - 2);
  return s;
}

// Metres with three significant digits ("0.3 m", "0.0012 m").
std::string format_metres(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3g m", v);
  return buf;
}

// A power of ten as a colour-bar label: "1000", "1", "0.01", "1e-05".
std::string format_decade(int k) {
  char buf[48];
  if (k >= 0 && k <= 9)
    std::snprintf(buf, sizeof buf, "%.0f", std::pow(10.0, k));
  else if (k < 0 && k >= -4)
    std::snprintf(buf, sizeof buf, "%.*f", -k, std::pow(10.0, k));
  else
    std::snprintf(buf, sizeof buf, "1e%d", k);
  return buf;
}

// A tick value with `decimals` digits after the point; never "-0". Very small steps and very large
// values fall back to three significant digits.
std::string format_tick(double v, int decimals) {
  char buf[48];
  if (decimals > 6 || std::abs(v) >= 1e7)
    std::snprintf(buf, sizeof buf, "%.3g", v);
  else
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s = buf;
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

// 1, 2 or 5 times a power of ten, at least `raw` (raw > 0).
double nice_step(double raw) {
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / p;
  return (f <= 1.0 ? 1.0 : f <= 2.0 ? 2.0 : f <= 5.0 ? 5.0 : 10.0) * p;
}

// Digits after the point that a tick step needs.
int step_decimals(double step) {
  return std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
}

// The lines above a plot, from the top margin down: the optional title (bold, 1.45 × the label size), the
// caption, and a row of labels (hemisphere names, panel titles). Baselines in px from the top of the image.
struct HeaderLayout {
  double label_pt = 0, title_pt = 0;
  double title_base = 0, caption_base = 0, labels_base = 0;
  double bottom = 0;  // below the row of labels

  HeaderLayout() = default;
  // `caption_height` and `labels_height` are the rows' heights in units of the label size.
  HeaderLayout(double top, bool has_title, double label_size, double caption_height, double labels_height)
      : label_pt(label_size), title_pt(1.45 * label_size) {
    double y = top;
    if (has_title) {
      title_base = y + title_pt;
      y += 1.45 * title_pt;
    }
    caption_base = y + label_pt;
    y += caption_height * label_pt;
    labels_base = y + label_pt;
    y += labels_height * label_pt;
    bottom = y;
  }

  // Title and caption centred on x = centre_x, shrunk to `max_width` (at most to `min_font_factor`).
  void draw(const Painter& pt, const std::string& title, const std::string& caption, double centre_x, double max_width,
            double min_font_factor) const {
    if (!title.empty()) {
      pt.color(kTextColor);
      pt.fit_font(title, title_pt, true, max_width, min_font_factor);
      pt.text_baseline(title, centre_x, title_base, 0.5);
    }
    pt.color(kMutedColor);
    pt.fit_font(caption, 0.95 * label_pt, false, max_width, min_font_factor);
    pt.text_baseline(caption, centre_x, caption_base, 0.5);
  }
};

// ---------------------------------------------------------------------------------------------------------
// Sphere-map image

// Matplotlib's "inferno" sampled at i/9 (perceptually uniform, black to pale yellow).
constexpr std::uint32_t kInferno[10] = {0x000004, 0x1b0c41, 0x4a0c6b, 0x781c6d, 0xa52c60,
                                        0xcf4446, 0xed6925, 0xfb9b06, 0xf7d13d, 0xfcffa4};

Rgb stop_color(int i) {
  const std::uint32_t c = kInferno[i];
  return {((c >> 16) & 0xff) / 255.0, ((c >> 8) & 0xff) / 255.0, (c & 0xff) / 255.0};
}

Rgb colormap(double t) {
  if (!(t > 0)) return stop_color(0);
  if (t >= 1) return stop_color(9);
  const double x = t * 9.0;
  const int i = std::min(8, static_cast<int>(x));
  const double f = x - i;
  const Rgb a = stop_color(i), b = stop_color(i + 1);
  return {a.r + f * (b.r - a.r), a.g + f * (b.g - a.g), a.b + f * (b.b - a.b)};
}

std::uint32_t to_argb(const Rgb& c) {
  auto byte = [](double v) { return static_cast<std::uint32_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); };
  return 0xff000000u | (byte(c.r) << 16) | (byte(c.g) << 8) | byte(c.b);
}

constexpr double kLogDecades = 4.0;
constexpr int kMaxImageWidth = 8192;

struct ToneMap {
  bool log = true;
  double peak = 0;  // > 0 unless all zero
  bool all_zero = false;
  // Position on the colour bar / in the colour map, 0..1.
  double t(double v) const {
    if (all_zero) return 0.0;
    if (!(v > 0)) return 0.0;
    if (!log) return std::min(1.0, v / peak);
    return std::clamp((std::log10(v / peak) + kLogDecades) / kLogDecades, 0.0, 1.0);
  }
  double lo() const { return all_zero ? 0.0 : log ? peak * std::pow(10.0, -kLogDecades) : 0.0; }
  double hi() const { return all_zero ? 1.0 : peak; }
};

struct Tick {
  double t;  // 0..1 along the bar
  bool major;
  std::string label;
};

std::vector<Tick> bar_ticks(const ToneMap& tm) {
  std::vector<Tick> out;
  if (tm.log && !tm.all_zero) {
    const double lo = tm.lo(), hi = tm.hi();
    const int k0 = static_cast<int>(std::floor(std::log10(lo))), k1 = static_cast<int>(std::ceil(std::log10(hi)));
    for (int k = k0; k <= k1; ++k)
      for (int m = 1; m <= 9; ++m) {
        const double v = m * std::pow(10.0, k);
        if (v < lo * (1 - 1e-9) || v > hi * (1 + 1e-9)) continue;
        out.push_back({tm.t(v), m == 1, m == 1 ? format_decade(k) : std::string()});
      }
    return out;
  }
  const double hi = tm.hi();
  const double step = nice_step(hi / 5.0);
  const int dec = step_decimals(step);
  for (int i = 0;; ++i) {
    const double v = i * step;
    if (v > hi * (1 + 1e-9)) break;
    out.push_back({v / hi, true, hi >= 100 ? format_quantity_compact(v) : format_tick(v, dec)});
    if (i > 100) break;
  }
  return out;
}

class MapRenderer {
 public:
  MapRenderer(const SphereMap& map, const MapImageOptions& o, int scale) : map_(map), o_(o), s_(scale) {
    R_ = map.resolution();
    const int tw = map.width(), th = map.height();
    lum_.assign(std::size_t(tw) * th, 0.0f);
    for (int y = 0; y < th; ++y)
      for (int x = 0; x < tw; ++x) {
        const glm::vec3 v = map.texel(x, y);
        const double l = map.channels() == 1 ? double(v.x) : 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z;
        const bool ok = std::isfinite(l) && l >= 0 && std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
        if (!ok) ++bad_;
        const float lf = ok ? static_cast<float>(l) : 0.0f;
        lum_[std::size_t(y) * tw + x] = std::isfinite(lf) ? lf : 0.0f;  // a huge double may overflow float
        if (lum_[std::size_t(y) * tw + x] > peak_) {
          peak_ = lum_[std::size_t(y) * tw + x];
          peak_x_ = x;
          peak_y_ = y;
        }
      }
    tm_.log = o.log_scale;
    tm_.peak = peak_;
    tm_.all_zero = !(peak_ > 0);

    side_ = double(R_) * s_;
    const double img_w_guess = 2 * side_;
    cw_ = std::max(img_w_guess + 8, 600.0);
    label_pt_ = std::max(10.0, 0.015 * cw_);
    gap_ = std::max(4.0, std::round(0.6 * label_pt_));
    img_w_ = 2 * side_ + gap_;
    cw_ = std::max(img_w_, 600.0);
    lw_ = std::max(1.0, cw_ / 1000.0);
    m_ = std::round(std::max(12.0, 0.025 * cw_));
    W_ = std::ceil(cw_ + 2 * m_);
    header_ = HeaderLayout(m_, !o.title.empty(), label_pt_, 1.9, 1.6);
    img_x_ = std::round(m_ + 0.5 * (cw_ - img_w_));
    img_y_ = std::round(header_.bottom);
    double y = img_y_ + side_ + 1.1 * label_pt_;
    bar_y_ = std::round(y);
    bar_h_ = std::round(1.1 * label_pt_);
    y = bar_y_ + bar_h_ + 0.4 * label_pt_;
    ticks_base_ = y + label_pt_;
    y += 1.9 * label_pt_;
    note_base_ = y + 0.85 * label_pt_;
    y += 1.3 * label_pt_;
    H_ = std::ceil(y + m_);
  }

  double width() const { return W_; }
  double height() const { return H_; }

  void draw(Painter& pt, bool svg) const {
    draw_header(pt);
    draw_image(pt, svg);
    draw_bar(pt);
  }

 private:
  void draw_header(Painter& pt) const {
    std::string cap;
    if (tm_.all_zero) {
      cap = "all zero";
    } else {
      cap = "peak " + format_quantity_compact(peak_) + " " + o_.unit;
      const glm::vec3 w = sphere_map::uv_to_direction(
          glm::vec2((peak_x_ + 0.5f) / float(map_.width()), (peak_y_ + 0.5f) / float(map_.height())));
      const PhotometricAngles a = angles_from_direction(PhotometricType::C, glm::dvec3(w));
      cap += " at C " + format_azimuth(a.horizontal_deg) + "° γ " + format_azimuth(a.vertical_deg) + "°";
      cap += tm_.log ? "   ·   log scale, 4 decades" : "   ·   linear scale";
    }
    cap += "   ·   " + std::to_string(map_.width()) + " × " + std::to_string(map_.height()) + " texels, " +
           (map_.channels() == 1 ? "1 channel" : "RGB (Rec. 709 Y)");
    if (bad_ > 0) cap += "   ·   " + std::to_string(bad_) + " NaN/negative texels shown as 0";
    header_.draw(pt, o_.title, cap, 0.5 * W_, cw_, 0.55);

    // Hemisphere names, centred over their squares unless the squares are too narrow for that.
    const std::string up = "upper hemisphere (z ≥ 0)", down = "lower hemisphere (z < 0)";
    pt.color(kTextColor);
    pt.font(label_pt_, true);
    const double wu = pt.extents(up).x_advance, wd = pt.extents(down).x_advance;
    const double cl = img_x_ + 0.5 * side_, cr = img_x_ + side_ + gap_ + 0.5 * side_;
    if (cl + 0.5 * wu + label_pt_ < cr - 0.5 * wd) {
      pt.text_baseline(up, cl, header_.labels_base, 0.5);
      pt.text_baseline(down, cr, header_.labels_base, 0.5);
    } else {
      const double mid = img_x_ + side_ + 0.5 * gap_;
      pt.fit_font(up, label_pt_, true, 0.5 * cw_ - label_pt_);
      pt.text_baseline(up, mid - 0.5 * label_pt_, header_.labels_base, 1);
      pt.fit_font(down, label_pt_, true, 0.5 * cw_ - label_pt_);
      pt.text_baseline(down, mid + 0.5 * label_pt_, header_.labels_base, 0);
    }
    pt.check("title");
  }

  // Fills an ARGB32 image surface of w × h pixels, `f` px per texel.
  SurfacePtr make_texels(int f) const {
    const int tw = map_.width(), th = map_.height();
    SurfacePtr img(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, tw * f, th * f));
    if (cairo_surface_status(img.get()) != CAIRO_STATUS_SUCCESS) return img;
    cairo_surface_flush(img.get());
    unsigned char* data = cairo_image_surface_get_data(img.get());
    const int stride = cairo_image_surface_get_stride(img.get());
    std::vector<std::uint32_t> row(std::size_t(tw) * f);
    for (int ty = 0; ty < th; ++ty) {
      for (int tx = 0; tx < tw; ++tx) {
        const std::uint32_t c = to_argb(colormap(tm_.t(lum_[std::size_t(ty) * tw + tx])));
        std::fill(row.begin() + std::ptrdiff_t(tx) * f, row.begin() + std::ptrdiff_t(tx + 1) * f, c);
      }
      for (int k = 0; k < f; ++k)
        std::memcpy(data + std::ptrdiff_t(ty * f + k) * stride, row.data(), row.size() * sizeof(std::uint32_t));
    }
    cairo_surface_mark_dirty(img.get());
    return img;
  }

  void draw_image(Painter& pt, bool svg) const {
    cairo_t* cr = pt.cr();
    // SVG viewers smooth scaled raster images, so the SVG gets an upscaled copy; the PNG is scaled by
    // cairo with the NEAREST filter.
    const int f = svg ? s_ : 1;
    SurfacePtr img = make_texels(f);
    if (cairo_surface_status(img.get()) != CAIRO_STATUS_SUCCESS)
      throw_plot_error("", "output",
                       std::string("cairo failed to create the texel image: ") +
                           cairo_status_to_string(cairo_surface_status(img.get())));
    for (int half = 0; half < 2; ++half) {
      const double x0 = img_x_ + half * (side_ + gap_);
      cairo_save(cr);
      cairo_rectangle(cr, x0, img_y_, side_, side_);
      cairo_clip(cr);
      cairo_translate(cr, x0 - half * side_, img_y_);
      cairo_scale(cr, double(s_) / f, double(s_) / f);
      cairo_set_source_surface(cr, img.get(), 0, 0);
      cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
      cairo_paint(cr);
      cairo_restore(cr);
      // Frame just outside the square.
      cairo_rectangle(cr, x0 - 0.5 * lw_, img_y_ - 0.5 * lw_, side_ + lw_, side_ + lw_);
      cairo_set_line_width(cr, lw_);
      pt.color(kFrame);
      cairo_stroke(cr);
    }
    pt.check("map image");
    if (tm_.all_zero) {
      pt.font(1.6 * label_pt_, true);
      pt.color(Rgb{1, 1, 1}, 0.85);
      for (int half = 0; half < 2; ++half)
        if (side_ >= 4 * label_pt_)
          pt.text_centered("all zero", img_x_ + half * (side_ + gap_) + 0.5 * side_, img_y_ + 0.5 * side_);
      pt.check("all-zero note");
    }
  }

  void draw_bar(Painter& pt) const {
    cairo_t* cr = pt.cr();
    pt.font(label_pt_);
    const std::string unit = o_.unit;
    const double unit_w = unit.empty() ? 0.0 : pt.extents(unit).x_advance + 0.6 * label_pt_;
    // Room for half a tick label at either end.
    const double x0 = m_ + 1.5 * label_pt_, x1 = m_ + cw_ - unit_w - 1.5 * label_pt_;
    const double bw = x1 - x0;

    PatternPtr grad(cairo_pattern_create_linear(x0, 0, x1, 0));
    for (int i = 0; i < 10; ++i) {
      const Rgb c = stop_color(i);
      cairo_pattern_add_color_stop_rgb(grad.get(), i / 9.0, c.r, c.g, c.b);
    }
    cairo_rectangle(cr, x0, bar_y_, bw, bar_h_);
    cairo_set_source(cr, grad.get());
    cairo_fill(cr);
    cairo_rectangle(cr, x0 - 0.5 * lw_, bar_y_ - 0.5 * lw_, bw + lw_, bar_h_ + lw_);
    cairo_set_line_width(cr, lw_);
    pt.color(kFrame);
    cairo_stroke(cr);

    const std::vector<Tick> ticks = bar_ticks(tm_);
    pt.font(0.9 * label_pt_);
    double last_right = -1e300;
    for (const Tick& t : ticks) {
      const double x = x0 + t.t * bw;
      const double len = (t.major ? 0.45 : 0.25) * label_pt_;
      cairo_move_to(cr, x, bar_y_ + bar_h_);
      cairo_line_to(cr, x, bar_y_ + bar_h_ + len);
      cairo_set_line_width(cr, (t.major ? 1.2 : 0.8) * lw_);
      pt.color(kFrame);
      cairo_stroke(cr);
      if (!t.label.empty()) {
        const double w = pt.extents(t.label).x_advance;
        if (x - 0.5 * w < last_right + 0.5 * label_pt_) continue;  // would overlap the previous label
        pt.color(kTextColor);
        pt.text_baseline(t.label, x, ticks_base_, 0.5);
        last_right = x + 0.5 * w;
      }
    }
    if (!unit.empty()) {
      pt.color(kTextColor);
      pt.font(label_pt_, true);
      pt.text_middle(unit, x1 + 1.5 * label_pt_, bar_y_ + 0.5 * bar_h_, 0);
    }
    const std::string note = tm_.all_zero ? "all zero: the bar shows 0..1"
                                          : "each square is equal-area: pole at the centre, horizon at the edge; "
                                            "C0 to the right, C90 downwards";
    pt.color(kMutedColor);
    pt.fit_font(note, 0.85 * label_pt_, false, cw_);
    pt.text_baseline(note, 0.5 * W_, note_base_, 0.5);
    pt.check("colour bar");
  }

  const SphereMap& map_;
  const MapImageOptions& o_;
  int s_, R_ = 0;
  std::vector<float> lum_;
  float peak_ = 0;
  int peak_x_ = 0, peak_y_ = 0;
  std::size_t bad_ = 0;
  ToneMap tm_;
  double side_, cw_, label_pt_, gap_, img_w_, lw_, m_, W_, H_ = 0;
  HeaderLayout header_;
  double img_x_ = 0, img_y_ = 0, bar_y_ = 0, bar_h_ = 0, ticks_base_ = 0, note_base_ = 0;
};

// ---------------------------------------------------------------------------------------------------------
// APL positions

constexpr double kMinExtentM = 1e-3;  // the smallest extent shown, so coincident APLs stay drawable
constexpr double kMaxCoordM = 1e6;    // positions farther out are treated as garbage and not drawn

bool drawable(const glm::dvec3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::abs(p.x) <= kMaxCoordM &&
         std::abs(p.y) <= kMaxCoordM && std::abs(p.z) <= kMaxCoordM;
}

struct View {
  const char* name;
  int u, v, depth;      // axis indices: horizontal, vertical, towards the viewer
  double depth_sign;    // +1: larger depth coordinate is nearer the viewer
  const char* u_label;  // axis names
  const char* v_label;
};

// Top: looking down −Z (x right, y up, +z nearest). Front: looking along +Y (x right, z up, −y nearest).
// Side: looking along −X (y right, z up, +x nearest).
constexpr View kViews[3] = {
    {"top (x–y, looking down −Z)", 0, 1, 2, +1, "x [m]", "y [m]"},
    {"front (x–z, looking along +Y)", 0, 2, 1, -1, "x [m]", "z [m]"},
    {"side (y–z, looking along −X)", 1, 2, 0, +1, "y [m]", "z [m]"},
};

class AplRenderer {
 public:
  AplRenderer(const AplLevel& level, ChannelLayout channels, const BoundingSphere& bounds, const AplPlotOptions& o)
      : o_(o), bounds_(bounds) {
    for (const Apl& a : level.apls) {
      const glm::dvec3 p(a.position);
      if (!drawable(p)) {
        ++skipped_;
        continue;
      }
      double f = luminance_of(channels, a.flux);
      if (!std::isfinite(f) || f < 0) f = 0;
      pos_.push_back(p);
      flux_.push_back(f);
      fmax_ = std::max(fmax_, f);
      total_ += f;
    }
    count_ = level.apls.size();
    show_bounds_ =
        std::isfinite(bounds.radius) && bounds.radius > 0 && bounds.radius <= kMaxCoordM && drawable(bounds.center);

    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    for (const glm::dvec3& p : pos_) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    if (show_bounds_) {
      lo = glm::min(lo, bounds.center - glm::dvec3(bounds.radius));
      hi = glm::max(hi, bounds.center + glm::dvec3(bounds.radius));
    }
    if (!(lo.x <= hi.x)) lo = hi = glm::dvec3(0.0);
    centre_ = 0.5 * (lo + hi);
    half_ = 0.5 * kMinExtentM;
    for (int k = 0; k < 3; ++k) half_ = std::max(half_, 0.5 * (hi[k] - lo[k]));

    S_ = o.size_px;
    W_ = S_;
    m_ = std::round(std::max(10.0, 0.02 * S_));
    label_pt_ = std::max(8.0, 0.0125 * S_);
    gap_ = 1.2 * label_pt_;
    header_ = HeaderLayout(m_, !o.title.empty(), label_pt_, 2.0, 1.7);
    plot_y_ = std::round(header_.bottom);
  }

  // Fixes the horizontal layout; needs a context to measure the tick labels.
  void layout(Painter& pt) {
    pt.font(0.9 * label_pt_);
    double gutter = 5.0 * label_pt_;
    for (int pass = 0; pass < 2; ++pass) {
      p_ = std::floor((W_ - 2 * m_ - 3 * gutter - 2 * gap_) / 3.0);
      r_max_ = std::clamp(0.04 * p_, 6.0, 60.0);
      const double pad = r_max_ + 2.0;
      scale_ = (p_ - 2 * pad) / (2 * half_);       // px per metre
      visible_half_ = 0.5 * p_ / scale_;           // metres from the centre to a panel edge
      step_ = nice_step(2 * visible_half_ / 5.0);  // about five ticks per axis
      decimals_ = step_decimals(step_);
      double widest = 0;
      for (int k = 0; k < 3; ++k)
        for (double t : ticks(k)) widest = std::max(widest, pt.extents(format_tick(t, decimals_)).x_advance);
      gutter = widest + 0.5 * label_pt_ + 1.8 * label_pt_;
    }
    gutter_ = gutter;
    const double y = plot_y_ + p_ + 0.4 * label_pt_;
    tick_base_ = y + label_pt_;
    axis_label_base_ = y + 2.4 * label_pt_;
    const std::vector<LegendRow> rows = legend_rows(pt);
    double bottom = axis_label_base_;
    for (const LegendRow& r : rows) {
      double half_h = 0.7 * label_pt_;
      for (const LegendItem& it : r.items) half_h = std::max(half_h, it.r + 1.0);
      bottom = std::max(bottom, r.y + half_h);
    }
    H_ = std::ceil(bottom + std::max(0.5 * label_pt_, m_));
  }

  double width() const { return W_; }
  double height() const { return H_; }

  void draw(Painter& pt) const {
    draw_header(pt);
    for (int i = 0; i < 3; ++i) draw_panel(pt, i);
    draw_legend(pt);
  }

 private:
  // Ticks on axis k inside the visible range.
  std::vector<double> ticks(int k) const {
    std::vector<double> out;
    const double a = centre_[k] - visible_half_, b = centre_[k] + visible_half_;
    const double first = std::ceil(a / step_ - 1e-9) * step_;
    for (int i = 0; i < 40; ++i) {
      const double t = first + i * step_;
      if (t > b + 1e-9 * step_) break;
      out.push_back(std::abs(t) < 1e-9 * step_ ? 0.0 : t);
    }
    return out;
  }

  double panel_x(int i) const { return m_ + gutter_ + i * (p_ + gap_ + gutter_); }
  void project(int i, const glm::dvec3& p, double& x, double& y) const {
    const View& v = kViews[i];
    x = panel_x(i) + 0.5 * p_ + (p[v.u] - centre_[v.u]) * scale_;
    y = plot_y_ + 0.5 * p_ - (p[v.v] - centre_[v.v]) * scale_;
  }
  double radius(double f) const { return fmax_ > 0 ? std::max(1.5, r_max_ * std::sqrt(f / fmax_)) : 1.5; }

  // One APL (in a panel or the legend): a translucent orange disc with a darker edge; lw = base line width.
  static void draw_apl_disc(const Painter& pt, double x, double y, double r, double lw) {
    cairo_t* cr = pt.cr();
    cairo_new_sub_path(cr);
    cairo_arc(cr, x, y, r, 0, 2 * kPi);
    pt.color(kAplFill, 0.55);
    cairo_fill_preserve(cr);
    pt.color(kAplEdge, 0.85);
    cairo_set_line_width(cr, 0.8 * lw);
    cairo_stroke(cr);
  }

  // Strokes the current path as the bounding sphere is drawn (in a panel or the legend): dashed blue.
  static void stroke_as_bounds(const Painter& pt, double lw) {
    cairo_t* cr = pt.cr();
    const double d[] = {5 * lw, 3.5 * lw};
    cairo_set_dash(cr, d, 2, 0);
    cairo_set_line_width(cr, 1.3 * lw);
    pt.color(kBounds, 0.8);
    cairo_stroke(cr);
    cairo_set_dash(cr, nullptr, 0, 0);
  }

  void draw_header(Painter& pt) const {
    std::string cap = std::to_string(count_) + (count_ == 1 ? " APL" : " APLs") + "   ·   Σ flux " +
                      format_quantity_compact(total_) + " " + o_.flux_unit;
    if (show_bounds_) cap += "   ·   bounding sphere r = " + format_metres(bounds_.radius);
    cap += "   ·   grid " + format_metres(step_);
    if (skipped_ > 0) cap += "   ·   " + std::to_string(skipped_) + " with non-finite or absurd positions not drawn";
    header_.draw(pt, o_.title, cap, 0.5 * W_, W_ - 2 * m_, 0.35);
    pt.check("title");
  }

  void draw_panel(Painter& pt, int i) const {
    cairo_t* cr = pt.cr();
    const View& v = kViews[i];
    const double x0 = panel_x(i), y0 = plot_y_;
    const double lw = std::max(1.0, S_ / 1000.0);

    pt.color(kTextColor);
    pt.fit_font(v.name, label_pt_, true, p_ + std::min(gap_, 2 * m_), 0.35);
    pt.text_baseline(v.name, x0 + 0.5 * p_, header_.labels_base, 0.5);

    cairo_rectangle(cr, x0, y0, p_, p_);
    cairo_set_source_rgb(cr, 0.985, 0.985, 0.985);
    cairo_fill(cr);

    // Grid at the ticks, and the photometric axes (coordinate 0) a little stronger.
    const std::vector<double> tu = ticks(v.u), tv = ticks(v.v);
    cairo_set_line_width(cr, lw);
    for (double t : tu) {
      const double x = x0 + 0.5 * p_ + (t - centre_[v.u]) * scale_;
      cairo_move_to(cr, x, y0);
      cairo_line_to(cr, x, y0 + p_);
      pt.color(t == 0 ? Rgb{0.62, 0.62, 0.62} : kGrid);
      cairo_stroke(cr);
    }
    for (double t : tv) {
      const double y = y0 + 0.5 * p_ - (t - centre_[v.v]) * scale_;
      cairo_move_to(cr, x0, y);
      cairo_line_to(cr, x0 + p_, y);
      pt.color(t == 0 ? Rgb{0.62, 0.62, 0.62} : kGrid);
      cairo_stroke(cr);
    }
    pt.check("grid");

    cairo_save(cr);
    cairo_rectangle(cr, x0, y0, p_, p_);
    cairo_clip(cr);
    if (show_bounds_) {
      double cx, cy;
      project(i, bounds_.center, cx, cy);
      cairo_new_sub_path(cr);
      cairo_arc(cr, cx, cy, bounds_.radius * scale_, 0, 2 * kPi);
      stroke_as_bounds(pt, lw);
      const double c = 0.4 * label_pt_;  // centre mark
      cairo_move_to(cr, cx - c, cy);
      cairo_line_to(cr, cx + c, cy);
      cairo_move_to(cr, cx, cy - c);
      cairo_line_to(cr, cx, cy + c);
      cairo_set_line_width(cr, lw);
      cairo_stroke(cr);
    }
    // Far APLs first, so nearer ones are drawn on top.
    std::vector<std::size_t> order(pos_.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return v.depth_sign * pos_[a][v.depth] < v.depth_sign * pos_[b][v.depth];
    });
    for (std::size_t k : order) {
      double x, y;
      project(i, pos_[k], x, y);
      draw_apl_disc(pt, x, y, radius(flux_[k]), lw);
    }
    cairo_restore(cr);
    pt.check("APLs");

    cairo_rectangle(cr, x0, y0, p_, p_);
    cairo_set_line_width(cr, lw);
    pt.color(kFrame);
    cairo_stroke(cr);

    // Ticks and labels: bottom (u) and left (v).
    const double tl = 0.35 * label_pt_;
    pt.font(0.9 * label_pt_);
    double last_right = -1e300;
    for (double t : tu) {
      const double x = x0 + 0.5 * p_ + (t - centre_[v.u]) * scale_;
      cairo_move_to(cr, x, y0 + p_);
      cairo_line_to(cr, x, y0 + p_ + tl);
      pt.color(kFrame);
      cairo_stroke(cr);
      const std::string s = format_tick(t, decimals_);
      const double w = pt.extents(s).x_advance;
      if (x - 0.5 * w < last_right + 0.4 * label_pt_) continue;
      pt.color(kTextColor);
      pt.text_baseline(s, x, tick_base_, 0.5);
      last_right = x + 0.5 * w;
    }
    for (double t : tv) {
      const double y = y0 + 0.5 * p_ - (t - centre_[v.v]) * scale_;
      cairo_move_to(cr, x0, y);
      cairo_line_to(cr, x0 - tl, y);
      pt.color(kFrame);
      cairo_stroke(cr);
      pt.color(kTextColor);
      pt.text_middle(format_tick(t, decimals_), x0 - tl - 0.25 * label_pt_, y, 1);
    }
    pt.font(label_pt_);
    pt.color(kTextColor);
    pt.text_baseline(v.u_label, x0 + 0.5 * p_, axis_label_base_, 0.5);
    cairo_save(cr);
    cairo_translate(cr, x0 - gutter_ + 0.9 * label_pt_, y0 + 0.5 * p_);
    cairo_rotate(cr, -0.5 * kPi);
    pt.text_middle(v.v_label, 0, 0, 0.5);
    cairo_restore(cr);
    pt.check("axes");
  }

  struct LegendItem {
    std::string text;
    double r;      // > 0: disc of that radius; 0: dashed line sample; < 0: text only
    double width;  // mark + text
  };
  struct LegendRow {
    std::vector<LegendItem> items;
    double width = 0, y = 0;
  };

  // Splits the legend into centred rows that fit the image width (sets the legend font).
  std::vector<LegendRow> legend_rows(Painter& pt) const {
    std::vector<LegendItem> items;
    if (pos_.empty()) {
      items.push_back({"no APL to draw", -1, 0});
    } else {
      items.push_back({"largest APL: " + format_quantity_compact(fmax_) + " " + o_.flux_unit, radius(fmax_), 0});
      if (fmax_ > 0 && radius(0.1 * fmax_) > 1.5)
        items.push_back({"10 %: " + format_quantity_compact(0.1 * fmax_) + " " + o_.flux_unit, radius(0.1 * fmax_), 0});
      items.push_back({"disc area ∝ flux (at least 1.5 px)", -1, 0});
    }
    if (show_bounds_) items.push_back({"bounding sphere", 0, 0});
    pt.font(label_pt_);
    const double between = 2.0 * label_pt_, inner = 0.5 * label_pt_, sample = 2.4 * label_pt_;
    std::vector<LegendRow> rows(1);
    for (LegendItem& it : items) {
      const double mark = it.r > 0 ? 2 * it.r : it.r == 0 ? sample : 0.0;
      it.width = mark + (mark > 0 ? inner : 0) + pt.extents(it.text).x_advance;
      LegendRow& row = rows.back();
      if (!row.items.empty() && row.width + between + it.width > W_ - 2 * m_) rows.emplace_back();
      LegendRow& r = rows.back();
      r.width += (r.items.empty() ? 0 : between) + it.width;
      r.items.push_back(it);
    }
    double y = axis_label_base_ + 0.8 * label_pt_;
    for (LegendRow& r : rows) {
      double half_h = 0.7 * label_pt_;
      for (const LegendItem& it : r.items) half_h = std::max(half_h, it.r + 1.0);
      r.y = y + half_h;
      y += 2 * half_h + 0.3 * label_pt_;
    }
    return rows;
  }

  void draw_legend(Painter& pt) const {
    cairo_t* cr = pt.cr();
    const double lw = std::max(1.0, S_ / 1000.0);
    const double between = 2.0 * label_pt_, inner = 0.5 * label_pt_, sample = 2.4 * label_pt_;
    for (const LegendRow& row : legend_rows(pt)) {
      double x = std::max(m_, 0.5 * (W_ - row.width));
      const double y = row.y;
      for (const LegendItem& it : row.items) {
        const double x_end = x + it.width;
        if (it.r > 0) {
          draw_apl_disc(pt, x + it.r, y, it.r, lw);
          x += 2 * it.r + inner;
        } else if (it.r == 0) {
          cairo_move_to(cr, x, y);
          cairo_line_to(cr, x + sample, y);
          stroke_as_bounds(pt, lw);
          x += sample + inner;
        }
        pt.color(it.r < 0 ? kMutedColor : kTextColor);
        pt.text_middle(it.text, x, y, 0);
        x = x_end + between;
      }
    }
    pt.check("legend");
  }

  const AplPlotOptions& o_;
  BoundingSphere bounds_;
  std::vector<glm::dvec3> pos_;
  std::vector<double> flux_;
  double fmax_ = 0, total_ = 0;
  std::size_t skipped_ = 0, count_ = 0;
  bool show_bounds_ = false;
  glm::dvec3 centre_{0.0};
  double half_ = 0;
  double S_, W_, H_ = 0, m_, label_pt_, gap_;
  HeaderLayout header_;
  double plot_y_ = 0;
  double p_ = 0, r_max_ = 0, scale_ = 1, visible_half_ = 1, step_ = 1, gutter_ = 0;
  int decimals_ = 0;
  double tick_base_ = 0, axis_label_base_ = 0;
};

}  // namespace

void write_sphere_map_image(const SphereMap& map, const std::string& out_path, const MapImageOptions& o) {
  const bool svg = is_svg_output(out_path);
  if (map.empty() || map.resolution() < 1) throw_plot_error(out_path, "map", "the sphere map is empty");
  if (o.scale < 0) throw_plot_error(out_path, "scale", "scale " + std::to_string(o.scale) + " is negative");
  const int tw = map.width();
  const int scale = o.scale > 0 ? o.scale : std::max(1, static_cast<int>(std::lround(1024.0 / tw)));
  if (static_cast<long long>(scale) * tw > kMaxImageWidth)
    throw_plot_error(out_path, "scale",
                     "scale " + std::to_string(scale) + " would make the image " +
                         std::to_string(static_cast<long long>(scale) * tw) + " px wide (at most " +
                         std::to_string(kMaxImageWidth) + ")");
  const MapRenderer renderer(map, o, scale);
  render_and_write(out_path, svg, renderer.width(), renderer.height(), [&](Painter& pt) { renderer.draw(pt, svg); });
}

void write_apl_positions_plot(const AplLevel& level, ChannelLayout channels, const BoundingSphere& bounds,
                              const std::string& out_path, const AplPlotOptions& o) {
  const bool svg = is_svg_output(out_path);
  if (o.size_px < 300 || o.size_px > 8000)
    throw_plot_error(out_path, "size", "plot size " + std::to_string(o.size_px) + " px is outside 300..8000");
  AplRenderer renderer(level, channels, bounds, o);
  {
    // Measure the tick labels on a scratch surface to fix the layout (and so the image height).
    SurfacePtr scratch(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 1, 1));
    ContextPtr cr(cairo_create(scratch.get()));
    Painter painter(cr.get(), out_path);
    painter.check("layout");
    renderer.layout(painter);
  }
  render_and_write(out_path, svg, renderer.width(), renderer.height(), [&](Painter& pt) { renderer.draw(pt); });
}

LUMX_NAMESPACE_END
