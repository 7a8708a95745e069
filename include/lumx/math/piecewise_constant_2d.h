// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/piecewise_constant_2d.h — sampling piecewise-constant densities on [0,1] and [0,1]².
//
// The method is the classic one (pbrt-v4 §A.5, PiecewiseConstant1D/2D): a 1D density over n equal cells
// is sampled by inverting its CDF; a 2D density over nx × ny cells is sampled by picking a row from the
// marginal (row sums), then a column from that row's conditional density, reusing the position of u
// inside the chosen cell as the continuous offset in it.
//
// Storage. CDFs are accumulated in double and stored as 32-bit integer counts of quanta of 1/T,
// T = 2³² − 1 (4 bytes per cell). Rounding is done so that every cell with positive weight keeps at
// least one quantum and every zero-weight cell keeps none. The probabilities this class reports (pdf,
// probability) are those stored counts, so sampling and pdf agree exactly; they differ from the weights'
// exact shares by at most about one quantum per cell (a relative 2.3e-10 of the whole).
//
// Sampling never returns a point in a zero-weight cell: u selects the integer quantum k = ⌊u·T⌋ and the
// cell is the one whose CDF interval [Q_i, Q_{i+1}) holds k. Zero-weight cells have empty intervals, so
// plateaus of the CDF are skipped by construction and u = 1 − ε cannot step past the last cell. The
// continuous point is then rounded to a float that still lies inside the chosen cell.
//
// Limitation shared by every CDF inversion from a float u: u has 2²⁴ distinct values in [0.5, 1), so a
// cell holding less than ~6e-8 of the mass near the top of the CDF may be unreachable.
#pragma once

#include <lumx/version.h>

#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

namespace piecewise_constant {

/// The CDF's unit: probabilities are stored as multiples of 1 / kQuanta.
inline constexpr std::uint32_t kQuanta = 0xFFFFFFFFu;

/// Largest number of cells along one axis. Keeps a cell wider than one float ulp on [0,1) (so a float
/// inside every cell exists) and makes float(x) · n exact in double.
inline constexpr std::size_t kMaxCells = std::size_t(1) << 24;

/// The largest float below 1 (pbrt's OneMinusEpsilon).
inline constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

/// u clamped into [0, 1): NaN and negative values become 0, values ≥ 1 become 1 − ε.
inline float clamp_unit(float u) {
  if (!(u > 0.0f)) return 0.0f;
  return u < 1.0f ? u : kOneMinusEpsilon;
}

/// Throws std::invalid_argument unless w is finite and ≥ 0. `what` names the caller; `index` the cell.
inline void check_weight(float w, const char* what, std::size_t index) {
  if (!(std::isfinite(w) && w >= 0.0f))
    throw std::invalid_argument(std::string(what) + ": weight " + std::to_string(index) +
                                " is negative or not finite (" + std::to_string(w) + ")");
}

/// Fills cdf[0..n] with the quantised CDF of w[0..n) (total = Σ w > 0, summed in the same order):
/// cdf[0] = 0, cdf[n] = kQuanta, cdf[i+1] − cdf[i] ≥ 1 exactly when w[i] > 0, and otherwise 0.
inline void build_cdf(const double* w, std::size_t n, double total, std::uint32_t* cdf) {
  std::size_t positive_left = 0;
  for (std::size_t i = 0; i < n; ++i) positive_left += w[i] > 0.0 ? 1 : 0;
  double running = 0.0;
  cdf[0] = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(w[i] > 0.0)) {
      cdf[i + 1] = cdf[i];
      continue;
    }
    running += w[i];
    --positive_left;
    // Nearest quantum to the exact CDF, kept ≥ one quantum above the previous cell and low enough to
    // leave one quantum for each positive cell still to come; the last positive cell ends at kQuanta.
    const double share = std::min(1.0, running / total);
    const std::uint64_t target = std::uint64_t(std::llround(share * double(kQuanta)));
    const std::uint64_t lo = std::uint64_t(cdf[i]) + 1;
    const std::uint64_t hi = std::uint64_t(kQuanta) - positive_left;
    cdf[i + 1] = positive_left == 0 ? kQuanta : std::uint32_t(std::clamp(target, lo, hi));
  }
}

/// Cell i of the quantised CDF cdf[0..n] holding u (clamped to [0,1)), and u's offset inside that cell's
/// interval, in [0, 1). Requires cdf[n] = kQuanta.
inline std::size_t find_cell(const std::uint32_t* cdf, std::size_t n, float u, double& offset) {
  const double t = double(clamp_unit(u)) * double(kQuanta);  // in [0, kQuanta)
  const std::uint32_t k = std::uint32_t(t);                  // ⌊t⌋ ≤ kQuanta − 1
  // Last i with cdf[i] ≤ k; cdf[0] = 0 ≤ k < kQuanta = cdf[n], so i ∈ [0, n) and cdf[i+1] > k ≥ cdf[i].
  const std::size_t i = std::size_t(std::upper_bound(cdf, cdf + n + 1, k) - cdf) - 1;
  offset = (t - double(cdf[i])) / double(cdf[i + 1] - cdf[i]);
  return i;
}

/// The float nearest (i + offset) / n that lies in cell i, i.e. in [i/n, (i+1)/n). float(x) · n is exact
/// in double because n ≤ kMaxCells, so the membership test below is exact.
inline float point_in_cell(std::size_t i, double offset, std::size_t n) {
  float x = float((double(i) + offset) / double(n));
  const double dn = double(n);
  while (double(x) * dn >= double(i + 1)) x = std::nextafter(x, 0.0f);
  while (double(x) * dn < double(i)) x = std::nextafter(x, 1.0f);
  return x;
}

/// Cell of a coordinate x ∈ [0, 1] among n (x = 1 belongs to the last cell).
inline std::size_t cell_of(float x, std::size_t n) {
  return std::min(n - 1, std::size_t(double(x) * double(n)));
}

}  // namespace piecewise_constant

/// A piecewise-constant density on [0, 1] with n equal cells, proportional to non-negative weights.
class PiecewiseConstant1D {
 public:
  struct Sample {
    float x = 0.0f;    ///< point in [0, 1), inside cell `cell`
    float pdf = 0.0f;  ///< density at x (w.r.t. dx); 0 marks an invalid sample (all-zero function)
    int cell = -1;     ///< index of the cell x lies in; −1 when invalid
  };

  PiecewiseConstant1D() = default;
  /// n ≥ 1 finite, non-negative weights (std::invalid_argument otherwise; n ≤ 2²⁴). All zero is allowed.
  PiecewiseConstant1D(const float* weights, std::size_t n) {
    check_size(n);
    std::vector<double> w(n);
    for (std::size_t i = 0; i < n; ++i) {
      piecewise_constant::check_weight(weights[i], "PiecewiseConstant1D", i);
      w[i] = double(weights[i]);
    }
    build(w);
  }
  explicit PiecewiseConstant1D(const std::vector<float>& weights)
      : PiecewiseConstant1D(weights.data(), weights.size()) {}
  /// Double weights (used for the marginal of PiecewiseConstant2D); same requirements.
  explicit PiecewiseConstant1D(std::vector<double> weights) {
    check_size(weights.size());
    for (std::size_t i = 0; i < weights.size(); ++i)
      if (!(std::isfinite(weights[i]) && weights[i] >= 0.0))
        throw std::invalid_argument("PiecewiseConstant1D: weight " + std::to_string(i) + " is negative or not finite");
    build(weights);
  }

  std::size_t size() const { return cdf_.empty() ? 0 : cdf_.size() - 1; }
  /// ∫₀¹ f(x) dx = Σ w / n (0 for an all-zero or empty function).
  double integral() const { return integral_; }
  bool is_zero() const { return !(integral_ > 0.0); }

  /// Inverts the CDF at u ∈ [0, 1) (clamped). Invalid (pdf 0) when the function is zero.
  Sample sample(float u) const {
    if (is_zero()) return {};
    double offset;
    const std::size_t n = size();
    const std::size_t i = piecewise_constant::find_cell(cdf_.data(), n, u, offset);
    return {piecewise_constant::point_in_cell(i, offset, n), cell_pdf(i), int(i)};
  }

  /// Density at x ∈ [0, 1]; 0 outside it, for NaN, and for a zero function.
  float pdf(float x) const {
    if (is_zero() || !(x >= 0.0f && x <= 1.0f)) return 0.0f;
    return cell_pdf(piecewise_constant::cell_of(x, size()));
  }

  /// Probability of cell i (the stored, quantised share of its weight).
  double probability(std::size_t i) const {
    return is_zero() ? 0.0 : double(cdf_[i + 1] - cdf_[i]) / double(piecewise_constant::kQuanta);
  }

  /// Bytes of table data held in memory.
  std::size_t bytes() const { return cdf_.size() * sizeof(std::uint32_t); }

 private:
  static void check_size(std::size_t n) {
    if (n == 0 || n > piecewise_constant::kMaxCells)
      throw std::invalid_argument("PiecewiseConstant1D: " + std::to_string(n) + " cells; need 1 to " +
                                  std::to_string(piecewise_constant::kMaxCells));
  }

  void build(const std::vector<double>& w) {
    const std::size_t n = w.size();
    double total = 0.0;
    for (double v : w) total += v;
    if (!std::isfinite(total)) throw std::invalid_argument("PiecewiseConstant1D: weights sum to infinity");
    cdf_.assign(n + 1, 0);
    integral_ = total / double(n);
    if (total > 0.0) piecewise_constant::build_cdf(w.data(), n, total, cdf_.data());
  }

  float cell_pdf(std::size_t i) const { return float(probability(i) * double(size())); }

  std::vector<std::uint32_t> cdf_;  // n + 1 quantised CDF values
  double integral_ = 0.0;
};

/// A piecewise-constant density on [0, 1]² over nx × ny equal cells, proportional to non-negative
/// weights given row by row (weights[y · nx + x]; x runs along the first coordinate).
class PiecewiseConstant2D {
 public:
  struct Sample {
    glm::vec2 point{0.0f};  ///< (x, y) ∈ [0, 1)², inside cell (cell_x, cell_y)
    float pdf = 0.0f;       ///< density at point (w.r.t. dx dy); 0 marks an invalid sample
    int cell_x = -1, cell_y = -1;
  };

  PiecewiseConstant2D() = default;
  /// nx, ny ≥ 1 (≤ 2²⁴ each); weights finite and ≥ 0, else std::invalid_argument. All zero is allowed.
  PiecewiseConstant2D(const float* weights, int nx, int ny) : nx_(nx), ny_(ny) {
    if (nx < 1 || ny < 1 || std::size_t(nx) > piecewise_constant::kMaxCells ||
        std::size_t(ny) > piecewise_constant::kMaxCells)
      throw std::invalid_argument("PiecewiseConstant2D: size " + std::to_string(nx) + " x " + std::to_string(ny) +
                                  " outside [1, 2^24]");
    const std::size_t w = std::size_t(nx), h = std::size_t(ny);
    conditional_cdf_.assign(h * (w + 1), 0);
    std::vector<double> row(w), row_sums(h);
    for (std::size_t y = 0; y < h; ++y) {
      double sum = 0.0;
      for (std::size_t x = 0; x < w; ++x) {
        const float v = weights[y * w + x];
        piecewise_constant::check_weight(v, "PiecewiseConstant2D", y * w + x);
        row[x] = double(v);
        sum += row[x];
      }
      if (!std::isfinite(sum)) throw std::invalid_argument("PiecewiseConstant2D: a row sums to infinity");
      row_sums[y] = sum;
      if (sum > 0.0) piecewise_constant::build_cdf(row.data(), w, sum, &conditional_cdf_[y * (w + 1)]);
    }
    marginal_ = PiecewiseConstant1D(std::move(row_sums));  // integral = Σ row sums / ny
    integral_ = marginal_.integral() / double(nx);
  }
  PiecewiseConstant2D(const std::vector<float>& weights, int nx, int ny)
      : PiecewiseConstant2D(checked_data(weights, nx, ny), nx, ny) {}

  int width() const { return nx_; }
  int height() const { return ny_; }
  /// ∫∫ f dx dy = Σ w / (nx · ny).
  double integral() const { return integral_; }
  bool is_zero() const { return !(integral_ > 0.0); }

  /// Row from u2 (marginal), then column from u1 (that row's conditional); u clamped to [0, 1).
  /// Invalid (pdf 0) when the function is zero; otherwise never in a zero-weight cell.
  Sample sample(float u1, float u2) const {
    if (is_zero()) return {};
    const PiecewiseConstant1D::Sample row = marginal_.sample(u2);
    const std::size_t y = std::size_t(row.cell), w = std::size_t(nx_);
    double offset;
    const std::size_t x = piecewise_constant::find_cell(row_cdf(y), w, u1, offset);
    Sample s;
    s.point = {piecewise_constant::point_in_cell(x, offset, w), row.x};
    s.cell_x = int(x);
    s.cell_y = int(y);
    s.pdf = cell_pdf(x, y);
    return s;
  }

  /// Density at (x, y) ∈ [0, 1]²; 0 outside, for NaN, and for a zero function.
  float pdf(float x, float y) const { return pdf(glm::vec2(x, y)); }
  float pdf(const glm::vec2& p) const {
    if (is_zero() || !(p.x >= 0.0f && p.x <= 1.0f && p.y >= 0.0f && p.y <= 1.0f)) return 0.0f;
    return cell_pdf(piecewise_constant::cell_of(p.x, std::size_t(nx_)),
                    piecewise_constant::cell_of(p.y, std::size_t(ny_)));
  }

  /// Probability of cell (x, y): marginal share of row y × conditional share of column x in it.
  double probability(int x, int y) const {
    if (is_zero()) return 0.0;
    const std::uint32_t* cdf = row_cdf(std::size_t(y));
    return marginal_.probability(std::size_t(y)) * double(cdf[x + 1] - cdf[x]) / double(piecewise_constant::kQuanta);
  }

  /// Bytes of table data held in memory.
  std::size_t bytes() const { return conditional_cdf_.size() * sizeof(std::uint32_t) + marginal_.bytes(); }

 private:
  static const float* checked_data(const std::vector<float>& weights, int nx, int ny) {
    if (nx < 1 || ny < 1 || weights.size() != std::size_t(nx) * std::size_t(ny))
      throw std::invalid_argument("PiecewiseConstant2D: " + std::to_string(weights.size()) + " weights for " +
                                  std::to_string(nx) + " x " + std::to_string(ny) + " cells");
    return weights.data();
  }

  const std::uint32_t* row_cdf(std::size_t y) const { return &conditional_cdf_[y * (std::size_t(nx_) + 1)]; }

  float cell_pdf(std::size_t x, std::size_t y) const {
    return float(probability(int(x), int(y)) * double(nx_) * double(ny_));
  }

  int nx_ = 0, ny_ = 0;
  std::vector<std::uint32_t> conditional_cdf_;  // ny rows of nx + 1 quantised CDF values
  PiecewiseConstant1D marginal_;
  double integral_ = 0.0;
};

LUMX_NAMESPACE_END
