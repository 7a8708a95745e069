// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// A plain estimator behind the adaptive-kernel interface: one Gaussian bandwidth for all deposits (the
// pilot h0: given, or the normal-reference rule h0 = σ n_eff^(−1/6) of Silverman 1986 eq. 4.14 in two
// dimensions), deposits linearly binned onto a grid of h0/3 cells and convolved separably, the kernel
// mass that crosses an edge reflected back (mirror boundary), so each deposit's flux stays on the
// rectangle. Evaluation is bilinear between cell centres. The local-bandwidth factors of the interface
// are all 1 here (sensitivity and max_factor are not used).
#include <lumx/render/adaptive_kernel_density.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN
namespace render {

struct AdaptiveKernelDensity2D::Impl {
  double width = 0, height = 0, h = 0;
  int nx = 1, ny = 1;
  double cell_x = 1, cell_y = 1;
  std::vector<double> density;  // lx at cell centres, [iy * nx + ix]

  static int mirror(int i, int n) {
    while (i < 0 || i >= n) i = i < 0 ? -1 - i : 2 * n - 1 - i;
    return i;
  }

  void blur(std::vector<double>& g, int n_along, int n_across, int stride_along, int stride_across, double sigma_cells) {
    const int radius = std::max(1, int(std::ceil(4.0 * sigma_cells)));
    std::vector<double> kernel(std::size_t(2 * radius + 1));
    double sum = 0;
    for (int k = -radius; k <= radius; ++k) sum += kernel[std::size_t(k + radius)] = std::exp(-0.5 * k * k / (sigma_cells * sigma_cells));
    for (double& k : kernel) k /= sum;
    std::vector<double> line(static_cast<std::size_t>(n_along));
    for (int j = 0; j < n_across; ++j) {
      for (int i = 0; i < n_along; ++i) line[std::size_t(i)] = g[std::size_t(i * stride_along + j * stride_across)];
      for (int i = 0; i < n_along; ++i) {
        double acc = 0;
        for (int k = -radius; k <= radius; ++k) acc += kernel[std::size_t(k + radius)] * line[std::size_t(mirror(i + k, n_along))];
        g[std::size_t(i * stride_along + j * stride_across)] = acc;
      }
    }
  }
};

AdaptiveKernelDensity2D::AdaptiveKernelDensity2D(std::vector<Deposit2D> deposits, double width_m, double height_m,
                                                 const AdaptiveKernelOptions& options)
    : impl_(new Impl) {
  if (!(width_m > 0) || !(height_m > 0) || !std::isfinite(width_m) || !std::isfinite(height_m))
    throw std::invalid_argument("AdaptiveKernelDensity2D: the rectangle needs a positive finite size");
  Impl& m = *impl_;
  m.width = width_m;
  m.height = height_m;
  double w = 0, w2 = 0, mu = 0, mv = 0;
  for (const Deposit2D& d : deposits) {
    w += d.flux_lm;
    w2 += d.flux_lm * d.flux_lm;
    mu += d.flux_lm * d.u;
    mv += d.flux_lm * d.v;
  }
  double h = options.pilot_bandwidth_m;
  if (!(h > 0)) {
    double var = 0;
    if (w > 0) {
      mu /= w;
      mv /= w;
      for (const Deposit2D& d : deposits) var += d.flux_lm * ((d.u - mu) * (d.u - mu) + (d.v - mv) * (d.v - mv));
      var /= 2.0 * w;
    }
    const double n_eff = w2 > 0 ? w * w / w2 : 1.0;
    h = std::sqrt(std::max(var, 0.0)) * std::pow(std::max(n_eff, 1.0), -1.0 / 6.0);
  }
  const double size = std::max(width_m, height_m);
  h = std::clamp(std::isfinite(h) ? h : size, 1e-3 * size, size);
  m.h = h;
  m.nx = std::clamp(int(std::ceil(width_m / (h / 3.0))), 2, 2048);
  m.ny = std::clamp(int(std::ceil(height_m / (h / 3.0))), 2, 2048);
  m.cell_x = width_m / m.nx;
  m.cell_y = height_m / m.ny;
  m.density.assign(std::size_t(m.nx) * std::size_t(m.ny), 0.0);
  for (const Deposit2D& d : deposits) {  // linear binning, mirrored at the edges like the kernel
    const double fx = std::clamp(d.u, 0.0, width_m) / m.cell_x - 0.5, fy = std::clamp(d.v, 0.0, height_m) / m.cell_y - 0.5;
    const int ix = int(std::floor(fx)), iy = int(std::floor(fy));
    const double tx = fx - ix, ty = fy - iy;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        const int cx = Impl::mirror(ix + a, m.nx), cy = Impl::mirror(iy + b, m.ny);
        m.density[std::size_t(cy) * std::size_t(m.nx) + std::size_t(cx)] +=
            d.flux_lm * (a ? tx : 1 - tx) * (b ? ty : 1 - ty);
      }
  }
  m.blur(m.density, m.nx, m.ny, 1, m.nx, h / m.cell_x);
  m.blur(m.density, m.ny, m.nx, m.nx, 1, h / m.cell_y);
  const double inv_area = 1.0 / (m.cell_x * m.cell_y);
  for (double& v : m.density) v *= inv_area;
}

AdaptiveKernelDensity2D::~AdaptiveKernelDensity2D() { delete impl_; }
AdaptiveKernelDensity2D::AdaptiveKernelDensity2D(AdaptiveKernelDensity2D&& o) noexcept : impl_(o.impl_) { o.impl_ = nullptr; }
AdaptiveKernelDensity2D& AdaptiveKernelDensity2D::operator=(AdaptiveKernelDensity2D&& o) noexcept {
  if (this != &o) {
    delete impl_;
    impl_ = o.impl_;
    o.impl_ = nullptr;
  }
  return *this;
}

double AdaptiveKernelDensity2D::evaluate(double u, double v) const {
  const Impl& m = *impl_;
  const double fx = std::clamp(u / m.cell_x - 0.5, 0.0, double(m.nx - 1));
  const double fy = std::clamp(v / m.cell_y - 0.5, 0.0, double(m.ny - 1));
  const int ix = std::min(int(fx), m.nx - 2), iy = std::min(int(fy), m.ny - 2);
  const double tx = fx - ix, ty = fy - iy;
  auto at = [&](int x, int y) { return m.density[std::size_t(y) * std::size_t(m.nx) + std::size_t(x)]; };
  return (1 - ty) * ((1 - tx) * at(ix, iy) + tx * at(ix + 1, iy)) + ty * ((1 - tx) * at(ix, iy + 1) + tx * at(ix + 1, iy + 1));
}

std::vector<double> AdaptiveKernelDensity2D::evaluate_grid(int nx, int ny) const {
  std::vector<double> out(std::size_t(std::max(nx, 0)) * std::size_t(std::max(ny, 0)));
  for (int iy = 0; iy < ny; ++iy)
    for (int ix = 0; ix < nx; ++ix)
      out[std::size_t(iy) * std::size_t(nx) + std::size_t(ix)] =
          evaluate((ix + 0.5) * impl_->width / nx, (iy + 0.5) * impl_->height / ny);
  return out;
}

double AdaptiveKernelDensity2D::pilot_bandwidth_m() const { return impl_->h; }
double AdaptiveKernelDensity2D::min_bandwidth_m() const { return impl_->h; }
double AdaptiveKernelDensity2D::max_bandwidth_m() const { return impl_->h; }

}  // namespace render
LUMX_NAMESPACE_END
