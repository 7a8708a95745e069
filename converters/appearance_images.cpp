// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The PNG pictures of `lumx render appearance` (appearance_images.h): tone-mapped images and false-colour
// differences with a colour bar, drawn with cairo through plot_canvas.h.
#include "appearance_images.h"

#include "plot_canvas.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace lumx_cli {

namespace {

using lumx::render::Image;

double luminance_at(const Image& im, std::size_t p) {
  return 0.2126 * im.pixels[3 * p] + 0.7152 * im.pixels[3 * p + 1] + 0.0722 * im.pixels[3 * p + 2];
}

/// sRGB transfer curve (IEC 61966-2-1) of a linear value in [0, 1].
double srgb(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

std::uint32_t argb(double r, double g, double b) {
  auto byte = [](double v) { return std::uint32_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); };
  return 0xff000000u | (byte(r) << 16) | (byte(g) << 8) | byte(b);
}

/// Diverging blue–white–red for t ∈ [−1, 1].
lumx::Rgb diverging(double t) {
  t = std::clamp(t, -1.0, 1.0);
  const lumx::Rgb blue{0.23, 0.30, 0.75}, white{0.97, 0.97, 0.97}, red{0.71, 0.02, 0.15};
  const lumx::Rgb& end = t < 0 ? blue : red;
  const double f = std::abs(t);
  return {white.r + f * (end.r - white.r), white.g + f * (end.g - white.g), white.b + f * (end.b - white.b)};
}

constexpr int kMinWidth = 320;
constexpr double kHeader = 56;   // title and caption, px
constexpr double kFooter = 56;   // colour bar and its labels, px

/// Draws `argb_pixels` (w × h) scaled by the whole factor `f` with its top-left corner at (x0, y0).
void draw_pixels(lumx::Painter& pt, const std::vector<std::uint32_t>& argb_pixels, int w, int h, int f, double x0,
                 double y0, const std::string& path) {
  lumx::SurfacePtr img(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w * f, h * f));
  if (cairo_surface_status(img.get()) != CAIRO_STATUS_SUCCESS)
    lumx::throw_plot_error(path, "output", "cairo failed to create the image");
  cairo_surface_flush(img.get());
  unsigned char* data = cairo_image_surface_get_data(img.get());
  const int stride = cairo_image_surface_get_stride(img.get());
  std::vector<std::uint32_t> row(std::size_t(w) * std::size_t(f));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x)
      std::fill(row.begin() + std::ptrdiff_t(x) * f, row.begin() + std::ptrdiff_t(x + 1) * f,
                argb_pixels[std::size_t(y) * std::size_t(w) + std::size_t(x)]);
    for (int k = 0; k < f; ++k)
      std::memcpy(data + std::ptrdiff_t(y * f + k) * stride, row.data(), row.size() * sizeof(std::uint32_t));
  }
  cairo_surface_mark_dirty(img.get());
  cairo_set_source_surface(pt.cr(), img.get(), x0, y0);
  cairo_paint(pt.cr());
  pt.check("image");
}

int scale_factor(int width) { return std::max(1, (kMinWidth + width - 1) / std::max(width, 1)); }

}  // namespace

double reinhard_exposure(const Image& reference) {
  double log_sum = 0.0;
  std::size_t n = 0;
  for (std::size_t p = 0; p < reference.pixel_count(); ++p) {
    const double y = luminance_at(reference, p);
    if (!(y > 0.0) || !std::isfinite(y)) continue;
    log_sum += std::log(1e-6 + y);
    ++n;
  }
  if (n == 0) return 1.0;
  return 0.18 / std::exp(log_sum / double(n));
}

void write_tone_mapped_png(const Image& image, double exposure, const std::string& path, const std::string& title,
                           const std::string& caption) {
  const int f = scale_factor(image.width);
  const double w = double(image.width * f), h = double(image.height * f);
  std::vector<std::uint32_t> px(image.pixel_count());
  for (std::size_t p = 0; p < px.size(); ++p) {
    double c[3];
    for (int k = 0; k < 3; ++k) {
      const double v = std::max(0.0, double(image.pixels[3 * p + std::size_t(k)])) * exposure;
      c[k] = srgb(std::isfinite(v) ? v / (1.0 + v) : 1.0);
    }
    px[p] = argb(c[0], c[1], c[2]);
  }
  lumx::render_and_write(path, false, w, h + kHeader, [&](lumx::Painter& pt) {
    pt.title_and_caption(title, caption, w, 0.4 * kHeader, 0.8 * kHeader);
    draw_pixels(pt, px, image.width, image.height, f, 0, kHeader, path);
  });
}

void write_difference_png(const Image& image, const Image& reference, const std::string& path,
                          const std::string& title, const std::string& caption) {
  std::vector<double> ref_y(reference.pixel_count());
  for (std::size_t p = 0; p < ref_y.size(); ++p) ref_y[p] = luminance_at(reference, p);
  std::vector<double> sorted = ref_y;
  double floor = 0.0;
  if (!sorted.empty()) {
    const std::size_t k = std::min(sorted.size() - 1, std::size_t(0.99 * double(sorted.size())));
    std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(k), sorted.end());
    floor = 0.01 * sorted[k];
  }
  floor = std::max(floor, 1e-9);
  const int f = scale_factor(image.width);
  const double w = double(image.width * f), h = double(image.height * f);
  std::vector<std::uint32_t> px(image.pixel_count());
  for (std::size_t p = 0; p < px.size(); ++p) {
    const double d = (luminance_at(image, p) - ref_y[p]) / std::max(ref_y[p], floor);
    const lumx::Rgb c = diverging(std::isfinite(d) ? d : 1.0);
    px[p] = argb(c.r, c.g, c.b);
  }
  lumx::render_and_write(path, false, w, h + kHeader + kFooter, [&](lumx::Painter& pt) {
    pt.title_and_caption(title, caption, w, 0.4 * kHeader, 0.8 * kHeader);
    draw_pixels(pt, px, image.width, image.height, f, 0, kHeader, path);
    // Colour bar: −100 % … +100 % of the reference's luminance.
    const int bar_w = int(std::max(64.0, 0.8 * w)), bar_h = 12;
    std::vector<std::uint32_t> bar(static_cast<std::size_t>(bar_w));
    for (int x = 0; x < bar_w; ++x) {
      const lumx::Rgb c = diverging(2.0 * (x + 0.5) / bar_w - 1.0);
      bar[std::size_t(x)] = argb(c.r, c.g, c.b);
    }
    std::vector<std::uint32_t> bar_rows;
    for (int y = 0; y < bar_h; ++y) bar_rows.insert(bar_rows.end(), bar.begin(), bar.end());
    const double bx = 0.5 * (w - bar_w), by = kHeader + h + 8;
    draw_pixels(pt, bar_rows, bar_w, bar_h, 1, bx, by, path);
    pt.color(lumx::kTextColor);
    pt.font(10);
    const double ly = by + bar_h + 14;
    pt.text_baseline("-100 %", bx, ly, 0);
    pt.text_baseline("0", bx + 0.5 * bar_w, ly, 0.5);
    pt.text_baseline("+100 %", bx + bar_w, ly, 1);
    pt.color(lumx::kMutedColor);
    pt.font(9);
    pt.text_baseline("(Y - Y_ref) / Y_ref, luminance", 0.5 * w, ly + 14, 0.5);
    pt.check("colour bar");
  });
}

}  // namespace lumx_cli
