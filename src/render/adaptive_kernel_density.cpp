// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Adaptive-kernel (sample-point, Abramson) density estimation of illuminance on a rectangle, with the
// reflection boundary correction. The maths and the measured accuracy are in docs/render.md, section
// "Adaptive-kernel reconstruction".
#include <lumx/render/adaptive_kernel_density.h>

#include <lumx/core/diagnostic.h>
#include <lumx/math/constants.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <utility>

LUMX_NAMESPACE_BEGIN
namespace render {

namespace {

// The biweight (quartic) kernel of radius h: K_h(r) = 3/(π h²) · (1 − r²/h²)² for r < h, 0 beyond.
// Compact (a query touches only deposits within h), C¹ (no kinks in contour plots), and 99.4 % as
// efficient as the MISE-optimal Epanechnikov kernel (Silverman 1986, Table 3.1).
constexpr double kBiweightNorm = 3.0 / kPi;

// A Gaussian-kernel bandwidth σ_K turned into the biweight radius with the same AMISE trade-off:
// h_B = σ_K · (R(K_B)/μ₂(K_B)² ÷ R(K_G)/μ₂(K_G)²)^{1/6} in 2D, R(K_B) = 9/(5π), μ₂(K_B) = 1/8,
// R(K_G) = 1/(4π), μ₂(K_G) = 1, i.e. (2304/5)^{1/6} = 2.7788 (Silverman 1986 §4.3.2, "canonical" kernels).
const double kBiweightPerGaussian = std::pow(2304.0 / 5.0, 1.0 / 6.0);

// Positions within this fraction of the rectangle's size outside it are rounding in the caller's
// hit-point arithmetic, and are moved onto the edge; farther ones are an error.
constexpr double kEdgeSlack = 1e-9;

// Cells per pilot bandwidth in the tabulated pilot: bilinear interpolation of the pilot between cell
// centres is then off by ~(δ/h₀)²/8 ≈ 1 % of its curvature term, which moves λ by half that.
constexpr double kPilotCellsPerBandwidth = 4.0;
constexpr int kMaxPilotCells = 2048;

constexpr int kLeafSize = 16;

[[noreturn]] void fail(const std::string& field, const std::string& message) {
  throw_at_field("", field, message);
}

std::string number(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

std::string deposit_field(std::size_t i, const char* name) {
  return "deposits[" + std::to_string(i) + "]." + name;
}

// A flux-weighted quantile from a histogram of `bins` cells over [0, extent] (linear inside a cell):
// enough resolution for a bandwidth rule, O(N) and independent of the input order.
double weighted_quantile(const std::vector<double>& histogram, double total, double extent, double q) {
  const double target = q * total;
  const double cell = extent / double(histogram.size());
  double below = 0.0;
  for (std::size_t b = 0; b < histogram.size(); ++b) {
    if (below + histogram[b] >= target && histogram[b] > 0.0)
      return (double(b) + (target - below) / histogram[b]) * cell;
    below += histogram[b];
  }
  return extent;
}

int resolve_threads(int requested) {
  return requested > 0 ? requested : int(std::max(1u, std::thread::hardware_concurrency()));
}

// Runs body(row_begin, row_end) over `rows` split into contiguous bands, one per thread. Every output
// cell belongs to exactly one band, so what a cell receives does not depend on the split.
template <class Body>
void for_row_bands(int rows, int threads, const Body& body) {
  threads = std::max(1, std::min(threads, rows));
  if (threads == 1) {
    body(0, rows);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(std::size_t(threads - 1));
  for (int t = 1; t < threads; ++t)
    pool.emplace_back([&, t] { body(rows * t / threads, rows * (t + 1) / threads); });
  body(0, rows / threads);
  for (auto& th : pool) th.join();
}

}  // namespace

struct AdaptiveKernelDensity2D::Impl {
  double width = 0.0, height = 0.0;
  double pilot_h = 0.0, min_h = 0.0, max_h = 0.0;
  int threads = 1;

  // Deposits in kd-tree order, structure of arrays.
  std::vector<double> u, v, radius, inv_radius2, flux, weight;  // weight = Φ_i · 3/(π h_i²), lx
  struct Node {
    double lo_u, hi_u, lo_v, hi_v;  // bounds of the kernels' supports (u ± h, v ± h)
    int begin, end;
    int left = -1, right = -1;  // children; -1 = leaf
  };
  std::vector<Node> nodes;

  // Σ_i K_{h_i}(x − x_i) over the plain deposits (no reflection), in storage order.
  double sum_at(double x, double y) const {
    if (nodes.empty()) return 0.0;
    double sum = 0.0;
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& n = nodes[std::size_t(stack[--top])];
      if (x < n.lo_u || x > n.hi_u || y < n.lo_v || y > n.hi_v) continue;
      if (n.left < 0) {
        for (int i = n.begin; i < n.end; ++i) {
          const double du = x - u[std::size_t(i)], dv = y - v[std::size_t(i)];
          const double t = (1.0 - dv * dv * inv_radius2[std::size_t(i)]) - du * du * inv_radius2[std::size_t(i)];
          if (t > 0.0) sum += weight[std::size_t(i)] * t * t;
        }
      } else {
        stack[top++] = n.right;  // left is popped first: leaves are visited in storage order
        stack[top++] = n.left;
      }
    }
    return sum;
  }

  // The reflection boundary correction: the estimate at x is the plain sum at x and at its mirror images
  // across the four edges and the four corners, which equals mirroring every deposit's kernel back into
  // the rectangle. With h_i ≤ min(width, height) the nine images hold each kernel's whole mass, so every
  // deposit's flux stays on the rectangle exactly, and a uniform density stays unbiased up to the edges
  // and corners (Silverman 1986 §2.10; Jones 1993).
  double evaluate(double x, double y) const {
    const double xs[3] = {x, -x, 2.0 * width - x};
    const double ys[3] = {y, -y, 2.0 * height - y};
    double sum = 0.0;
    for (double yy : ys)
      for (double xx : xs) sum += sum_at(xx, yy);
    return sum;
  }

  struct TreeItem {
    double u, v;
    std::size_t index;
  };

  void build_tree(std::vector<TreeItem>& order, const std::vector<Deposit2D>& d, const std::vector<double>& h) {
    nodes.clear();
    nodes.reserve(2 * order.size() / kLeafSize + 2);
    build_node(order, 0, int(order.size()));
    u.resize(order.size());
    v.resize(order.size());
    radius.resize(order.size());
    inv_radius2.resize(order.size());
    flux.resize(order.size());
    weight.resize(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) {
      const std::size_t i = order[k].index;
      u[k] = d[i].u;
      v[k] = d[i].v;
      radius[k] = h[i];
      inv_radius2[k] = 1.0 / (h[i] * h[i]);
      flux[k] = d[i].flux_lm;
      weight[k] = d[i].flux_lm * kBiweightNorm * inv_radius2[k];
    }
    for (auto it = nodes.rbegin(); it != nodes.rend(); ++it) {  // children come after parents
      Node& n = *it;
      if (n.left >= 0) {
        const Node &a = nodes[std::size_t(n.left)], &b = nodes[std::size_t(n.right)];
        n.lo_u = std::min(a.lo_u, b.lo_u);
        n.hi_u = std::max(a.hi_u, b.hi_u);
        n.lo_v = std::min(a.lo_v, b.lo_v);
        n.hi_v = std::max(a.hi_v, b.hi_v);
      } else {
        n.lo_u = n.lo_v = std::numeric_limits<double>::infinity();
        n.hi_u = n.hi_v = -std::numeric_limits<double>::infinity();
        for (int k = n.begin; k < n.end; ++k) {
          n.lo_u = std::min(n.lo_u, u[std::size_t(k)] - radius[std::size_t(k)]);
          n.hi_u = std::max(n.hi_u, u[std::size_t(k)] + radius[std::size_t(k)]);
          n.lo_v = std::min(n.lo_v, v[std::size_t(k)] - radius[std::size_t(k)]);
          n.hi_v = std::max(n.hi_v, v[std::size_t(k)] + radius[std::size_t(k)]);
        }
      }
    }
  }

  // Sorted in place on compact (u, v, index) items: the median splits stream through memory instead of
  // chasing indices into the deposits.
  int build_node(std::vector<TreeItem>& order, int begin, int end) {
    const int id = int(nodes.size());
    nodes.push_back(Node{0, 0, 0, 0, begin, end, -1, -1});
    if (end - begin <= kLeafSize) return id;
    double lo_u = order[std::size_t(begin)].u, hi_u = lo_u;
    double lo_v = order[std::size_t(begin)].v, hi_v = lo_v;
    for (int k = begin; k < end; ++k) {
      const TreeItem& p = order[std::size_t(k)];
      lo_u = std::min(lo_u, p.u), hi_u = std::max(hi_u, p.u);
      lo_v = std::min(lo_v, p.v), hi_v = std::max(hi_v, p.v);
    }
    const bool split_u = hi_u - lo_u >= hi_v - lo_v;
    const int mid = begin + (end - begin) / 2;
    // Ties broken by input index, so the tree depends only on the deposits, never on the sort's details.
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                     [split_u](const TreeItem& a, const TreeItem& b) {
                       const double ka = split_u ? a.u : a.v, kb = split_u ? b.u : b.v;
                       return ka < kb || (ka == kb && a.index < b.index);
                     });
    const int left = build_node(order, begin, mid);
    const int right = build_node(order, mid, end);
    nodes[std::size_t(id)].left = left;
    nodes[std::size_t(id)].right = right;
    return id;
  }
};

namespace {

// The inner loop over a row's columns is what evaluate_grid costs; src/CMakeLists.txt lets GCC vectorise
// it at -O2 (packed and scalar SSE2 round alike, so results do not change).
// Adds Σ_i Φ_i K_{h_i}(x − x_i) over the deposits and their eight mirror images to the centres of an
// nx × ny grid of cells over [0, width] × [0, height]. Each cell receives the terms in the order
// (image, deposit), whatever the number of threads.
void splat_reflected(const std::vector<double>& u, const std::vector<double>& v, const std::vector<double>& radius,
                     const std::vector<double>& flux, double width, double height, int nx, int ny, int threads,
                     std::vector<double>& grid) {
  grid.assign(std::size_t(nx) * std::size_t(ny), 0.0);
  const double cell_u = width / nx, cell_v = height / ny, per_u = nx / width, per_v = ny / height;
  std::vector<double> centre_u(std::size_t(nx) + 1);
  for (int ix = 0; ix < nx; ++ix) centre_u[std::size_t(ix)] = (ix + 0.5) * cell_u;
  const std::size_t n = u.size();
  for_row_bands(ny, threads, [&](int row_begin, int row_end) {
    for (int sv = 0; sv < 3; ++sv)
      for (int su = 0; su < 3; ++su) {
        for (std::size_t i = 0; i < n; ++i) {
          const double h = radius[i];
          const double cu = su == 0 ? u[i] : su == 1 ? -u[i] : 2.0 * width - u[i];
          const double cv = sv == 0 ? v[i] : sv == 1 ? -v[i] : 2.0 * height - v[i];
          if (cu + h <= 0.0 || cu - h >= width || cv + h <= 0.0 || cv - h >= height) continue;
          const int y0 = std::max(row_begin, int(std::ceil((cv - h) * per_v - 0.5)));
          const int y1 = std::min(row_end - 1, int(std::floor((cv + h) * per_v - 0.5)));
          if (y0 > y1) continue;
          const double inv_h2 = 1.0 / (h * h);
          const double w = flux[i] * kBiweightNorm * inv_h2;
          // The columns of the kernel's bounding square; along a row K is a polynomial in du,
          // t = a − du²/h² with a = 1 − dv²/h², clamped at 0 (cheaper than finding each row's chord).
          const int x0 = std::max(0, int(std::ceil((cu - h) * per_u - 0.5)));
          const int x1 = std::min(nx - 1, int(std::floor((cu + h) * per_u - 0.5)));
          for (int iy = y0; iy <= y1; ++iy) {
            const double dv = (iy + 0.5) * cell_v - cv;
            const double a = 1.0 - dv * dv * inv_h2;
            if (a <= 0.0) continue;
            double* row = grid.data() + std::size_t(iy) * std::size_t(nx);
            const double* xs = centre_u.data();
            for (int ix = x0; ix <= x1; ++ix) {
              const double du = xs[ix] - cu;
              const double t = std::max(0.0, a - du * du * inv_h2);
              row[ix] += w * t * t;
            }
          }
        }
      }
  });
}

}  // namespace

AdaptiveKernelDensity2D::AdaptiveKernelDensity2D(std::vector<Deposit2D> deposits, double width_m, double height_m,
                                                 const AdaptiveKernelOptions& options)
    : impl_(new Impl) {
  std::unique_ptr<Impl> guard(impl_);  // released on success; freed if a check throws
  if (!std::isfinite(width_m) || width_m <= 0.0) fail("width", "must be a positive number of metres, got " + number(width_m));
  if (!std::isfinite(height_m) || height_m <= 0.0) fail("height", "must be a positive number of metres, got " + number(height_m));
  if (!std::isfinite(options.pilot_bandwidth_m) || options.pilot_bandwidth_m < 0.0)
    fail("pilot_bandwidth_m", "must be 0 (chosen from the deposits) or a positive number of metres, got " +
                                  number(options.pilot_bandwidth_m));
  if (!std::isfinite(options.sensitivity) || options.sensitivity < 0.0 || options.sensitivity > 1.0)
    fail("sensitivity", "must lie in [0, 1], got " + number(options.sensitivity));
  if (!std::isfinite(options.max_factor) || options.max_factor < 1.0)
    fail("max_factor", "must be at least 1, got " + number(options.max_factor));
  if (!std::isfinite(options.bandwidth_scale) || options.bandwidth_scale <= 0.0)
    fail("bandwidth_scale", "must be positive, got " + number(options.bandwidth_scale));
  if (options.threads < 0) fail("threads", "must be 0 (all hardware threads) or positive, got " + std::to_string(options.threads));

  Impl& m = *impl_;
  m.width = width_m;
  m.height = height_m;
  m.threads = resolve_threads(options.threads);
  const double slack_u = kEdgeSlack * std::max(width_m, height_m), slack_v = slack_u;

  // Check every deposit; zero-flux deposits carry nothing and are dropped.
  std::vector<Deposit2D> kept;
  kept.reserve(deposits.size());
  for (std::size_t i = 0; i < deposits.size(); ++i) {
    Deposit2D d = deposits[i];
    if (!std::isfinite(d.u)) fail(deposit_field(i, "u"), "must be a finite number of metres, got " + number(d.u));
    if (!std::isfinite(d.v)) fail(deposit_field(i, "v"), "must be a finite number of metres, got " + number(d.v));
    if (!std::isfinite(d.flux_lm) || d.flux_lm < 0.0)
      fail(deposit_field(i, "flux_lm"), "must be a finite flux ≥ 0 lm, got " + number(d.flux_lm));
    if (d.u < -slack_u || d.u > width_m + slack_u)
      fail(deposit_field(i, "u"), number(d.u) + " m lies outside the rectangle's [0, " + number(width_m) + "] m");
    if (d.v < -slack_v || d.v > height_m + slack_v)
      fail(deposit_field(i, "v"), number(d.v) + " m lies outside the rectangle's [0, " + number(height_m) + "] m");
    d.u = std::clamp(d.u, 0.0, width_m);
    d.v = std::clamp(d.v, 0.0, height_m);
    if (d.flux_lm > 0.0) kept.push_back(d);
  }
  deposits.clear();
  deposits.shrink_to_fit();
  const std::size_t n = kept.size();
  const double max_radius = std::min(width_m, height_m);  // keeps each kernel within its nine images
  if (n == 0) {
    m.pilot_h = m.min_h = m.max_h = options.pilot_bandwidth_m > 0.0 ? std::min(options.pilot_bandwidth_m, max_radius) : 0.0;
    guard.release();
    return;
  }

  // Pilot bandwidth h₀: the normal-reference rule for a Gaussian kernel in 2D, σ · n_eff^{-1/6}
  // (Silverman 1986 eq. 4.14 with (4/(d+2))^{1/(d+4)} = 1), on a robust spread per axis
  // σ_a = min(sd_a, IQR_a / 1.349) (Silverman eq. 3.30), σ² = (σ_u² + σ_v²)/2, with the effective count
  // n_eff = (ΣΦ)² / ΣΦ² of weighted deposits; turned into the biweight radius (× 2.7788).
  double total = 0.0, total_sq = 0.0;
  for (const auto& d : kept) total += d.flux_lm, total_sq += d.flux_lm * d.flux_lm;
  double pilot = options.pilot_bandwidth_m;
  if (pilot <= 0.0) {
    const double n_eff = total * total / total_sq;
    double mean_u = 0.0, mean_v = 0.0;
    for (const auto& d : kept) mean_u += d.flux_lm * d.u, mean_v += d.flux_lm * d.v;
    mean_u /= total, mean_v /= total;
    double var_u = 0.0, var_v = 0.0;
    constexpr int kBins = 1024;
    std::vector<double> hist_u(kBins, 0.0), hist_v(kBins, 0.0);
    for (const auto& d : kept) {
      var_u += d.flux_lm * (d.u - mean_u) * (d.u - mean_u);
      var_v += d.flux_lm * (d.v - mean_v) * (d.v - mean_v);
      hist_u[std::size_t(std::min(kBins - 1, int(d.u / width_m * kBins)))] += d.flux_lm;
      hist_v[std::size_t(std::min(kBins - 1, int(d.v / height_m * kBins)))] += d.flux_lm;
    }
    const auto spread = [&](double variance, const std::vector<double>& hist, double extent) {
      const double sd = std::sqrt(variance / total);
      const double iqr = weighted_quantile(hist, total, extent, 0.75) - weighted_quantile(hist, total, extent, 0.25);
      return iqr > 0.0 ? std::min(sd, iqr / 1.349) : sd;
    };
    const double su = spread(var_u, hist_u, width_m), sv = spread(var_v, hist_v, height_m);
    const double sigma = std::sqrt(0.5 * (su * su + sv * sv));
    pilot = options.bandwidth_scale * kBiweightPerGaussian * sigma * std::pow(n_eff, -1.0 / 6.0);
    // All deposits at one point have no spread: the kernel is then as narrow as 1/1000 of the rectangle.
    pilot = std::max(pilot, 1e-3 * max_radius);
  }
  pilot = std::min(pilot, max_radius);
  m.pilot_h = pilot;

  // Local bandwidths h_i = h₀ λ_i, λ_i = (f̃(x_i)/g)^{-α}, log g = Σ Φ_i log f̃(x_i) / Σ Φ_i (Abramson 1982;
  // Silverman 1986 §5.3.1). The pilot f̃ is the fixed-h₀ estimate (reflected like the final one) tabulated
  // at cell centres of spacing ≈ h₀/4 and interpolated bilinearly; its reflection makes it even about
  // each edge, so clamping the interpolation at the outer half-cells is exact.
  std::vector<double> h(n, pilot);
  if (options.sensitivity > 0.0 && n > 1) {
    const int px = std::clamp(int(std::ceil(width_m / pilot * kPilotCellsPerBandwidth)), 1, kMaxPilotCells);
    const int py = std::clamp(int(std::ceil(height_m / pilot * kPilotCellsPerBandwidth)), 1, kMaxPilotCells);
    std::vector<double> pu(n), pv(n), pr(n, pilot), pf(n), table;
    for (std::size_t i = 0; i < n; ++i) pu[i] = kept[i].u, pv[i] = kept[i].v, pf[i] = kept[i].flux_lm;
    splat_reflected(pu, pv, pr, pf, width_m, height_m, px, py, m.threads, table);
    std::vector<double> log_pilot(n);
    double log_g = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double gx = std::clamp(kept[i].u / width_m * px - 0.5, 0.0, double(px - 1));
      const double gy = std::clamp(kept[i].v / height_m * py - 0.5, 0.0, double(py - 1));
      const int x0 = std::min(int(gx), px - 1), y0 = std::min(int(gy), py - 1);
      const int x1 = std::min(x0 + 1, px - 1), y1 = std::min(y0 + 1, py - 1);
      const double fx = gx - x0, fy = gy - y0;
      const auto at = [&](int x, int y) { return table[std::size_t(y) * std::size_t(px) + std::size_t(x)]; };
      const double f = (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
      // A deposit's own kernel puts at least Φ_i · 3/(π h₀²) · (1 − 1/16)² at its nearest cell centres,
      // so f > 0; the floor only guards the logarithm.
      log_pilot[i] = std::log(std::max(f, std::numeric_limits<double>::min()));
      log_g += kept[i].flux_lm * log_pilot[i];
    }
    log_g /= total;
    const double lo = 1.0 / options.max_factor, hi = options.max_factor;
    for (std::size_t i = 0; i < n; ++i) {
      const double lambda = std::clamp(std::exp(-options.sensitivity * (log_pilot[i] - log_g)), lo, hi);
      h[i] = std::min(pilot * lambda, max_radius);
    }
  }
  const auto [min_it, max_it] = std::minmax_element(h.begin(), h.end());
  m.min_h = *min_it;
  m.max_h = *max_it;

  std::vector<Impl::TreeItem> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = {kept[i].u, kept[i].v, i};
  m.build_tree(order, kept, h);
  guard.release();
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
  if (!impl_ || !std::isfinite(u) || !std::isfinite(v) || u < 0.0 || v < 0.0 || u > impl_->width || v > impl_->height)
    return 0.0;
  return impl_->evaluate(u, v);
}

std::vector<double> AdaptiveKernelDensity2D::evaluate_grid(int nx, int ny) const {
  if (nx < 1) fail("nx", "the grid needs at least one column, got " + std::to_string(nx));
  if (ny < 1) fail("ny", "the grid needs at least one row, got " + std::to_string(ny));
  std::vector<double> grid;
  if (!impl_ || impl_->u.empty()) return std::vector<double>(std::size_t(nx) * std::size_t(ny), 0.0);
  splat_reflected(impl_->u, impl_->v, impl_->radius, impl_->flux, impl_->width, impl_->height, nx, ny, impl_->threads, grid);
  return grid;
}

double AdaptiveKernelDensity2D::pilot_bandwidth_m() const { return impl_ ? impl_->pilot_h : 0.0; }
double AdaptiveKernelDensity2D::min_bandwidth_m() const { return impl_ ? impl_->min_h : 0.0; }
double AdaptiveKernelDensity2D::max_bandwidth_m() const { return impl_ ? impl_->max_h : 0.0; }

}  // namespace render
LUMX_NAMESPACE_END
