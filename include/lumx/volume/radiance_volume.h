// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/volume/radiance_volume.h — the luminaire's low-frequency internal radiance field ("glow") as a uniform grid
// of cubic voxels, each holding spherical-harmonic coefficients per colour channel (dissertation 000 §4.4,
// after Moon et al.; lumx/math/spherical_harmonics.h for the basis).
//
// Estimator. A particle carrying flux Φ (W) along direction ω whose path crosses a voxel of volume V over
// a length ℓ adds the track-length estimate of radiance, L(ω') += Φ ℓ δ(ω' - ω) / V, whose projection is
//   c_lm += Φ ℓ Y_lm(ω) / V.
// Summed over particles whose fluxes add up to the source's power, c_00 Y_00 = ∫L dω / (4π), so the grid
// holds radiance in W/(m²·sr) when flux is in W and lengths in m (any other consistent units likewise:
// flux unit / (length unit² · sr)). Directions are *propagation* directions of the light, both for
// add_segment() and radiance(); an eye ray looking along v sees radiance(x, -v).
//
// Traversal is the 3D DDA of Amanatides & Woo, "A Fast Voxel Traversal Algorithm for Ray Tracing"
// (Eurographics 1987), made robust: the segment is first clipped to the grid (slab clip, lumx/math/aabb.h); the
// start voxel is floor((p - lo)/s) clamped into the grid (floor, not truncation, so negative coordinates
// are right); a zero direction component never crosses (t = +inf); each crossing time is recomputed from
// the voxel index, (lo + i s - o)/d, not accumulated; the walk ends when t reaches the clipped exit, never
// by counting voxels; ties (edges, corners) step one axis at a time, the zero-length visits in between
// deposit nothing. Every piece of [t_enter, t_exit] is deposited exactly once, so Σ ℓ equals the clipped
// length (mass conservation) up to the rounding of a telescoping sum.
//
// Layout of coefficients(): voxel (i, j, k), channel c, coefficient q = sh::index(l, m) at
//   ((k * ny + j) * nx + i) * channels * ncoef + c * ncoef + q,   ncoef = bands².
// Deposits are computed in double and accumulated in float (the stored format, 000 §4.6); for long runs
// accumulate per-thread partial volumes and merge them with accumulate().
#pragma once

#include <lumx/math/aabb.h>
#include <lumx/math/spherical_harmonics.h>

#include <glm/vec3.hpp>
#include <glm/vector_relational.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

class RadianceVolume {
 public:
  static constexpr int kMaxTargetVoxels = 1 << 24;
  static constexpr int kMaxBands = 8;

  /// A grid of cubic voxels of edge s = cbrt(volume / target_voxel_count) over `box`, with
  /// max(1, ceil(extent / s)) voxels per axis, centred on the box and covering it. Flat axes (extent 0, or
  /// thinner than s) get one voxel and s is solved over the remaining axes so that the voxel count still
  /// approximates the target (a 1 x 1 x 0 box and target 32768 gives 182 x 182 x 1); a single-point box
  /// gets one voxel of edge 1. Coefficients start at zero; the window starts as sh::Window::vallee_poussin.
  /// Throws std::invalid_argument naming the field: box (non-finite, lo > hi, or an extent that is not
  /// representable), target_voxel_count (outside [1, 2^24]), bands (outside [1, 8]), channels (not 1 or 3).
  explicit RadianceVolume(const Aabb& box, int target_voxel_count = 32768, int bands = 4, int channels = 3)
      : bands_(bands), channels_(channels) {
    if (!box.valid() || !std::isfinite(box.extent().x) || !std::isfinite(box.extent().y) ||
        !std::isfinite(box.extent().z))
      throw std::invalid_argument("RadianceVolume: box must have finite corners with lo <= hi");
    if (target_voxel_count < 1 || target_voxel_count > kMaxTargetVoxels)
      throw std::invalid_argument("RadianceVolume: target_voxel_count must be in [1, " +
                                  std::to_string(kMaxTargetVoxels) + "], got " + std::to_string(target_voxel_count));
    if (bands < 1 || bands > kMaxBands)
      throw std::invalid_argument("RadianceVolume: bands must be in [1, " + std::to_string(kMaxBands) + "], got " +
                                  std::to_string(bands));
    if (channels != 1 && channels != 3)
      throw std::invalid_argument("RadianceVolume: channels must be 1 or 3, got " + std::to_string(channels));
    layout_grid(box, target_voxel_count);
    ncoef_ = sh::coefficient_count(bands_);
    coeffs_.assign(voxel_count() * std::size_t(channels_) * std::size_t(ncoef_), 0.0f);
    set_window(sh::Window::vallee_poussin);
  }

  /// A volume with an explicit grid, as stored in a file: `lo` is the grid's lower corner, `counts` the
  /// voxels per axis and `voxel_size` their edge (the upper corner is lo + counts · voxel_size). Throws
  /// std::invalid_argument for counts outside [1, 4096], a product above kMaxTargetVoxels, a voxel size
  /// that is not finite and positive, or bands/channels as for the other constructor.
  static RadianceVolume from_grid(const glm::dvec3& lo, const glm::ivec3& counts, double voxel_size, int bands,
                                  int channels) {
    for (int a = 0; a < 3; ++a)
      if (counts[a] < 1 || counts[a] > 4096)
        throw std::invalid_argument("RadianceVolume::from_grid: counts must be in [1, 4096] per axis");
    if (double(counts.x) * counts.y * counts.z > double(kMaxTargetVoxels))
      throw std::invalid_argument("RadianceVolume::from_grid: more than 2^24 voxels");
    if (!(voxel_size > 0) || !std::isfinite(voxel_size) || !finite(lo))
      throw std::invalid_argument("RadianceVolume::from_grid: voxel_size and lo must be finite, voxel_size > 0");
    RadianceVolume v(Aabb{glm::dvec3(0.0), glm::dvec3(0.0)}, 1, bands, channels);
    v.counts_ = counts;
    v.size_ = voxel_size;
    v.bounds_.lo = lo;
    v.bounds_.hi = lo + voxel_size * glm::dvec3(counts);
    v.coeffs_.assign(v.voxel_count() * std::size_t(channels) * std::size_t(v.ncoef_), 0.0f);
    return v;
  }

  /// Voxels per axis (nx, ny, nz).
  glm::ivec3 counts() const { return counts_; }
  std::size_t voxel_count() const { return std::size_t(counts_.x) * std::size_t(counts_.y) * std::size_t(counts_.z); }
  /// Edge length s of the cubic voxels.
  double voxel_size() const { return size_; }
  double voxel_volume() const { return size_ * size_ * size_; }
  /// The grid's own bounds: lo + (nx, ny, nz) s, centred on the construction box and covering it.
  const Aabb& bounds() const { return bounds_; }
  int bands() const { return bands_; }
  int coefficient_count() const { return ncoef_; }
  int channels() const { return channels_; }

  /// The window applied by radiance() (not to the stored coefficients).
  sh::Window window() const { return window_; }
  void set_window(sh::Window w) {
    window_ = w;
    const std::vector<double> sigma = sh::window_weights(bands_, w);
    for (int l = 0; l < bands_; ++l)
      for (int m = -l; m <= l; ++m) window_per_coefficient_[sh::index(l, m)] = sigma[l];
  }

  /// All coefficients, in the layout stated at the top of this file.
  const std::vector<float>& coefficients() const { return coeffs_; }
  /// Replaces all coefficients (e.g. when reading a file); throws std::invalid_argument on a size mismatch.
  void set_coefficients(std::vector<float> values) {
    if (values.size() != coeffs_.size())
      throw std::invalid_argument("RadianceVolume::set_coefficients: expected " + std::to_string(coeffs_.size()) +
                                  " values, got " + std::to_string(values.size()));
    coeffs_ = std::move(values);
  }
  /// Index into coefficients() of coefficient 0 of voxel (i, j, k), channel c; throws std::out_of_range.
  std::size_t offset(int i, int j, int k, int c) const {
    if (i < 0 || i >= counts_.x || j < 0 || j >= counts_.y || k < 0 || k >= counts_.z || c < 0 || c >= channels_)
      throw std::out_of_range("RadianceVolume: voxel or channel index out of range");
    return unchecked_offset(i, j, k) + std::size_t(c) * std::size_t(ncoef_);
  }
  /// The bands² coefficients of voxel (i, j, k), channel c; throws std::out_of_range.
  const float* voxel_coefficients(int i, int j, int k, int c) const { return coeffs_.data() + offset(i, j, k, c); }
  glm::dvec3 voxel_center(int i, int j, int k) const {
    return bounds_.lo + size_ * glm::dvec3(i + 0.5, j + 0.5, k + 0.5);
  }

  /// Deposits the segment origin + t ω, t in [0, length], ω = direction / |direction|, carrying
  /// flux_per_channel (channel c uses component c; a single-channel volume uses component 0) into every
  /// voxel it crosses, as c_lm += Φ ℓ Y_lm(ω) / V. The parts outside the grid are ignored. Returns the
  /// length deposited (the clipped length). A zero length deposits nothing and accepts any direction.
  /// Throws std::invalid_argument for a negative or non-finite length, a non-finite origin or flux, or a
  /// zero or non-finite direction.
  double add_segment(const glm::dvec3& origin, const glm::dvec3& direction, double length,
                     const glm::vec3& flux_per_channel) {
    if (!(length >= 0.0) || !std::isfinite(length))
      throw std::invalid_argument("RadianceVolume::add_segment: length must be finite and >= 0");
    if (length == 0.0) return 0.0;
    if (!finite(origin)) throw std::invalid_argument("RadianceVolume::add_segment: origin must be finite");
    const glm::dvec3 dir = unit(direction, "RadianceVolume::add_segment");
    std::array<double, 3> scale{};  // Φ_c / V
    for (int c = 0; c < channels_; ++c) {
      if (!std::isfinite(flux_per_channel[c]))
        throw std::invalid_argument("RadianceVolume::add_segment: flux_per_channel must be finite");
      scale[c] = double(flux_per_channel[c]) / voxel_volume();
    }
    const RayInterval span = bounds_.clip(origin, dir, 0.0, length);
    if (span.empty() || !(span.t1 > span.t0)) return 0.0;

    std::array<double, sh::coefficient_count(kMaxBands)> y;
    sh::evaluate(dir, bands_, y.data());

    // Start voxel and the time of the next crossing on each axis.
    const glm::dvec3 start = origin + span.t0 * dir;
    int cell[3], step[3];
    double t_cross[3];
    for (int a = 0; a < 3; ++a) {
      const double u = std::clamp(std::floor((start[a] - bounds_.lo[a]) / size_), 0.0, double(counts_[a] - 1));
      cell[a] = int(u);
      step[a] = dir[a] > 0 ? 1 : (dir[a] < 0 ? -1 : 0);
      t_cross[a] = step[a] == 0 ? std::numeric_limits<double>::infinity()
                                : crossing_time(a, cell[a] + (step[a] > 0 ? 1 : 0), origin, dir);
    }

    double t = span.t0, deposited = 0.0;
    for (;;) {
      int a = 0;  // axis crossed first; ties go to the lowest axis, the others follow at zero length
      if (t_cross[1] < t_cross[a]) a = 1;
      if (t_cross[2] < t_cross[a]) a = 2;
      const double t_end = std::min(t_cross[a], span.t1);
      if (t_end > t) {
        deposit(cell, t_end - t, scale, y.data());
        deposited += t_end - t;
        t = t_end;
      }
      if (t >= span.t1) break;
      const int next = cell[a] + step[a];
      if (next < 0 || next >= counts_[a]) {  // rounding put the exit past the clip: stay in the border voxel
        t_cross[a] = std::numeric_limits<double>::infinity();
        continue;
      }
      cell[a] = next;
      t_cross[a] = crossing_time(a, next + (step[a] > 0 ? 1 : 0), origin, dir);
    }
    return deposited;
  }

  /// True if `other` has the same counts, bounds, voxel size, bands and channels.
  bool same_grid(const RadianceVolume& other) const {
    return counts_ == other.counts_ && bounds_.lo == other.bounds_.lo && bounds_.hi == other.bounds_.hi &&
           size_ == other.size_ && bands_ == other.bands_ && channels_ == other.channels_;
  }

  /// Adds `other`'s coefficients (a per-thread partial volume over the same grid); throws
  /// std::invalid_argument if the grids differ.
  void accumulate(const RadianceVolume& other) {
    if (!same_grid(other))
      throw std::invalid_argument(
          "RadianceVolume::accumulate: grids differ (counts, bounds, voxel size, bands or "
          "channels)");
    for (std::size_t n = 0; n < coeffs_.size(); ++n) coeffs_[n] += other.coeffs_[n];
  }

  /// Radiance at point x travelling along `direction` (normalised here): the coefficients are
  /// interpolated trilinearly between voxel centres (clamped to the border voxels outside the centres'
  /// box, so points outside the grid get the nearest border values), windowed by window(), evaluated,
  /// and each channel clamped at >= 0. A single-channel volume returns (v, v, v). Throws
  /// std::invalid_argument for a non-finite x or a zero or non-finite direction.
  glm::vec3 radiance(const glm::dvec3& x, const glm::dvec3& direction) const {
    if (!finite(x)) throw std::invalid_argument("RadianceVolume::radiance: x must be finite");
    const glm::dvec3 dir = unit(direction, "RadianceVolume::radiance");
    std::array<double, sh::coefficient_count(kMaxBands)> y;
    sh::evaluate(dir, bands_, y.data());
    for (int q = 0; q < ncoef_; ++q) y[q] *= window_per_coefficient_[q];

    int lo[3], hi[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
      const double u = std::clamp((x[a] - bounds_.lo[a]) / size_ - 0.5, 0.0, double(counts_[a] - 1));
      lo[a] = std::min(int(u), std::max(counts_[a] - 2, 0));
      hi[a] = std::min(lo[a] + 1, counts_[a] - 1);
      f[a] = u - lo[a];
    }
    std::array<double, 3> value{};
    for (int corner = 0; corner < 8; ++corner) {
      double w = 1.0;
      int idx[3];
      for (int a = 0; a < 3; ++a) {
        const bool upper = (corner >> a) & 1;
        w *= upper ? f[a] : 1.0 - f[a];
        idx[a] = upper ? hi[a] : lo[a];
      }
      if (w == 0.0) continue;
      const float* voxel = coeffs_.data() + unchecked_offset(idx[0], idx[1], idx[2]);
      for (int c = 0; c < channels_; ++c) {
        const float* cc = voxel + std::size_t(c) * std::size_t(ncoef_);
        double sum = 0.0;
        for (int q = 0; q < ncoef_; ++q) sum += double(cc[q]) * y[q];
        value[c] += w * sum;
      }
    }
    for (double& v : value) v = std::max(v, 0.0);
    if (channels_ == 1) return glm::vec3(float(value[0]));
    return glm::vec3(float(value[0]), float(value[1]), float(value[2]));
  }

  /// Memory held: the coefficient array plus the object itself.
  std::size_t bytes() const { return sizeof(*this) + coeffs_.capacity() * sizeof(float); }

 private:
  static bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

  // v / |v|, scaled by the largest component first so that tiny or huge finite vectors normalise too.
  static glm::dvec3 unit(const glm::dvec3& v, const char* who) {
    const double m = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    if (!finite(v) || !(m > 0.0))
      throw std::invalid_argument(std::string(who) + ": direction must be finite and non-zero");
    const glm::dvec3 w = v / m;
    return w / std::sqrt(w.x * w.x + w.y * w.y + w.z * w.z);
  }

  // t at which origin + t dir meets the plane of voxel boundary b on axis a (dir[a] != 0).
  double crossing_time(int a, int b, const glm::dvec3& origin, const glm::dvec3& dir) const {
    return (bounds_.lo[a] + b * size_ - origin[a]) / dir[a];
  }

  std::size_t unchecked_offset(int i, int j, int k) const {
    const std::size_t voxel =
        (std::size_t(k) * std::size_t(counts_.y) + std::size_t(j)) * std::size_t(counts_.x) + std::size_t(i);
    return voxel * std::size_t(channels_) * std::size_t(ncoef_);
  }

  void deposit(const int cell[3], double length, const std::array<double, 3>& scale, const double* y) {
    float* voxel = coeffs_.data() + unchecked_offset(cell[0], cell[1], cell[2]);
    for (int c = 0; c < channels_; ++c) {
      const double s = scale[c] * length;
      float* cc = voxel + std::size_t(c) * std::size_t(ncoef_);
      for (int q = 0; q < ncoef_; ++q) cc[q] += float(s * y[q]);
    }
  }

  // Voxel edge: solve Π_a max(1, e_a / s) = target for s. Axes are taken thinnest first; an axis thinner
  // than the s solved over the remaining ones gets one voxel and drops out. Then round the counts up
  // (tolerating rounding of e/s just above an integer), widen s if needed so n s >= e on every axis,
  // and centre the grid on the box.
  void layout_grid(const Aabb& box, int target) {
    const glm::dvec3 e = box.extent();
    std::array<int, 3> order{0, 1, 2};
    std::sort(order.begin(), order.end(), [&](int p, int q) { return e[p] < e[q]; });
    double s = 0.0;
    for (int k = 0; k < 3 && s == 0.0; ++k) {
      const double thinnest = e[order[k]];
      if (!(thinnest > 0.0)) continue;  // flat axis: one voxel
      double log_product = 0.0;
      for (int q = k; q < 3; ++q) log_product += std::log(e[order[q]]);
      const double candidate = std::exp((log_product - std::log(double(target))) / (3 - k));
      if (candidate <= thinnest) s = candidate;
    }
    if (s == 0.0) s = 1.0;  // single-point box
    if (!(s >= std::numeric_limits<double>::min()) || !std::isfinite(s))
      throw std::invalid_argument("RadianceVolume: box extent too small or too large for a voxel grid");
    for (int a = 0; a < 3; ++a) {
      const double n = std::max(1.0, std::ceil(e[a] / s - 1e-9));
      counts_[a] = int(n);
      s = std::max(s, e[a] / n);
    }
    const glm::dvec3 center = box.center();
    for (int attempt = 0; attempt < 64; ++attempt) {  // an ulp or two of s if rounding uncovers a face
      bounds_.lo = center - 0.5 * s * glm::dvec3(counts_);
      bounds_.hi = bounds_.lo + s * glm::dvec3(counts_);
      if (glm::all(glm::lessThanEqual(bounds_.lo, box.lo)) && glm::all(glm::greaterThanEqual(bounds_.hi, box.hi)))
        break;
      s = std::nextafter(s, std::numeric_limits<double>::infinity());
    }
    if (!finite(bounds_.lo) || !finite(bounds_.hi))
      throw std::invalid_argument("RadianceVolume: box extent too small or too large for a voxel grid");
    size_ = s;
  }

  int bands_ = 4;
  int channels_ = 3;
  int ncoef_ = 16;
  glm::ivec3 counts_{1, 1, 1};
  double size_ = 1.0;
  Aabb bounds_;
  sh::Window window_ = sh::Window::vallee_poussin;
  std::array<double, sh::coefficient_count(kMaxBands)> window_per_coefficient_{};
  std::vector<float> coeffs_;
};

LUMX_NAMESPACE_END
