// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/intensity_table.h — the full-sphere lookup table behind every photometric query.
//
// Built once from a Photometry: the stored subset is mirrored by its symmetry (lumx/photometry/symmetry.h), the
// vertical angle becomes a polar angle theta in [0,180] (gamma for Type C, V+90 for A and B, so that the
// solid-angle element is sin(theta) dtheta dphi for every type), pole rows are replaced by their
// azimuth-weighted mean and a C360 plane and C0 by their mean, so that the interpolant is single-valued,
// hence continuous, at the poles and across the seam.
//
// intensity() is bilinear in (horizontal, theta); it wraps across the 0/360 seam when the planes cover
// the circle, and is zero outside the measured vertical range (e.g. above gamma 90 for a downlight file).
// flux_lm() is the *exact* integral of that same interpolant over the sphere, so flux, intensity and any
// re-gridding stay consistent: for each cell the integrand is bilinear, the azimuth integral is the
// trapezoid rule and the polar integral of a linear function times sin(theta) has the closed form
//   int_a^b (t - t0) sin t dt = [ -(t - t0) cos t + sin t ]_a^b .
#pragma once

#include <lumx/photometry/photometric_frame.h>
#include <lumx/photometry/photometry.h>
#include <lumx/photometry/symmetry.h>

#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

LUMX_NAMESPACE_BEGIN

class IntensityTable {
 public:
  /// Throws std::invalid_argument if the table is empty, has fewer than 2 vertical angles, angles that
  /// are not strictly increasing, or a stored range that contradicts the symmetry.
  explicit IntensityTable(const Photometry& p) : type_(p.type) {
    if (p.vertical_deg.size() < 2) throw std::invalid_argument("IntensityTable: fewer than 2 vertical angles");
    if (p.horizontal_deg.empty()) throw std::invalid_argument("IntensityTable: no horizontal angles");
    if (p.candela.size() != p.horizontal_deg.size() * p.vertical_deg.size())
      throw std::invalid_argument("IntensityTable: candela count != horizontal x vertical");
    AngleTable full = expand(stored_table(p), p.symmetry);
    az_ = full.horizontal_deg;
    th_ = full.vertical_deg;
    if (type_ != PhotometricType::C)
      for (double& t : th_) t += 90.0;  // V in [-90,90] -> theta in [0,180]
    for (std::size_t i = 1; i < th_.size(); ++i)
      if (!(th_[i] > th_[i - 1])) throw std::invalid_argument("IntensityTable: vertical angles not increasing");
    for (std::size_t i = 1; i < az_.size(); ++i)
      if (!(az_[i] > az_[i - 1])) throw std::invalid_argument("IntensityTable: horizontal angles not increasing");
    cd_ = std::move(full.candela);
    periodic_ = type_ == PhotometricType::C || (az_.back() - az_.front() >= 360.0 - 1e-9);
    average_seam_planes();
    average_pole_rows();
  }

  PhotometricType type() const { return type_; }
  /// Horizontal angles after symmetry expansion, degrees.
  const std::vector<double>& horizontal_deg() const { return az_; }
  /// Polar angles theta (gamma for Type C, V + 90 for A/B), degrees.
  const std::vector<double>& polar_deg() const { return th_; }
  /// Candela after expansion and pole averaging, [ih * polar.size() + ip].
  const std::vector<double>& candela() const { return cd_; }
  /// True if the horizontal planes cover the full circle (interpolation wraps across the seam).
  bool periodic() const { return periodic_; }

  /// Intensity (cd) at photometric angles of the table's own type (C, gamma) or (H, V), degrees.
  double at_angles(double h_deg, double v_deg) const {
    return lookup(h_deg, type_ == PhotometricType::C ? v_deg : v_deg + 90.0);
  }

  /// Intensity (cd) towards direction `d` in the photometric frame (need not be normalised).
  double intensity(const glm::dvec3& d) const {
    const PhotometricAngles a = angles_from_direction(type_, d);
    return at_angles(a.horizontal_deg, a.vertical_deg);
  }

  /// Largest tabulated intensity, cd (the interpolant never exceeds it).
  double max_cd() const {
    double m = 0;
    for (double c : cd_) m = std::max(m, c);
    return m;
  }

  /// Luminous flux (lm) emitted into polar angles theta in [theta_min, theta_max] (degrees), the exact
  /// integral of the bilinear interpolant. Defaults give the total flux. For Type C theta is gamma, so
  /// [0, 90] is the downward (lower-hemisphere) flux.
  double flux_lm(double theta_min_deg = 0.0, double theta_max_deg = 180.0) const {
    const std::vector<double> colint = polar_integrals(theta_min_deg, theta_max_deg);
    if (colint.empty()) return 0.0;
    const std::size_t nh = az_.size();
    if (nh == 1) return 2.0 * kPi * colint[0];
    double phi = 0;
    for (std::size_t i = 0; i + 1 < nh; ++i)
      phi += 0.5 * (az_[i + 1] - az_[i]) * kDegToRad * (colint[i] + colint[i + 1]);
    if (periodic_) {
      const double gap = az_.front() + 360.0 - az_.back();
      if (gap > 1e-12) phi += 0.5 * gap * kDegToRad * (colint[nh - 1] + colint[0]);
    }
    return phi;
  }

  /// Luminous flux (lm) emitted into horizontal angles [h_min, h_max] (degrees; a span of at most 360),
  /// every polar angle: the exact integral of the bilinear interpolant, as flux_lm() (the azimuthal
  /// interpolant is linear, so each clipped plane interval is a trapezoid). Wraps when the planes cover
  /// the circle. For Types A and B, whose polar axis is horizontal, [−90, 90] is the downward hemisphere
  /// (z = −cos V cos H < 0). Returns 0 for an empty or non-finite range.
  double flux_lm_horizontal(double h_min_deg, double h_max_deg) const {
    if (!std::isfinite(h_min_deg) || !std::isfinite(h_max_deg) || !(h_max_deg > h_min_deg)) return 0.0;
    h_max_deg = std::min(h_max_deg, h_min_deg + 360.0);
    const std::size_t nh = az_.size();
    const std::vector<double> g = polar_integrals(th_.front(), th_.back());
    if (g.empty()) return 0.0;
    if (nh == 1) return (h_max_deg - h_min_deg) * kDegToRad * g[0];  // no azimuthal variation
    if (periodic_) {  // the range from [az0, az0 + 360): two turns of the planes then cover it
      const double shift = 360.0 * std::floor((h_min_deg - az_.front()) / 360.0);
      h_min_deg -= shift;
      h_max_deg -= shift;
    }
    const auto segment = [&](double a, double ga, double b, double gb) {  // ∫ over [a, b] ∩ [h_min, h_max]
      const double lo = std::max(a, h_min_deg), hi = std::min(b, h_max_deg);
      if (!(hi > lo)) return 0.0;
      const auto at = [&](double x) { return ga + (gb - ga) * (x - a) / (b - a); };
      return 0.5 * (hi - lo) * (at(lo) + at(hi));
    };
    double sum = 0;
    for (int turn = 0; turn < (periodic_ ? 2 : 1); ++turn) {
      const double shift = 360.0 * turn;
      for (std::size_t i = 0; i + 1 < nh; ++i) sum += segment(az_[i] + shift, g[i], az_[i + 1] + shift, g[i + 1]);
      const double gap_end = az_.front() + 360.0;
      if (periodic_ && gap_end - az_.back() > 1e-12) sum += segment(az_.back() + shift, g[nh - 1], gap_end + shift, g[0]);
    }
    return sum * kDegToRad;
  }

 private:
  /// For every plane i, ∫ I(h_i, θ) sin θ dθ over [θ_min, θ_max] ∩ the table's span (degrees in, θ in
  /// radians inside): the exact integral of the column's linear pieces, each cell's lower and upper value
  /// weighted by ∫ (1 − u) sin θ and ∫ u sin θ over its clipped part. Empty when the span is.
  std::vector<double> polar_integrals(double theta_min_deg, double theta_max_deg) const {
    const std::size_t nt = th_.size(), nh = az_.size();
    const double a = std::max(theta_min_deg, th_.front()) * kDegToRad;
    const double b = std::min(theta_max_deg, th_.back()) * kDegToRad;
    if (!(b > a)) return {};
    std::vector<double> w0(nt, 0.0), w1(nt, 0.0);
    for (std::size_t j = 0; j + 1 < nt; ++j) {
      const double t0 = th_[j] * kDegToRad, t1 = th_[j + 1] * kDegToRad;
      const double lo = std::max(a, t0), hi = std::min(b, t1);
      if (!(hi > lo)) continue;
      const double dt = t1 - t0;
      const double s = std::cos(lo) - std::cos(hi);                        // ∫ sin t
      const double k = (-(hi - t0) * std::cos(hi) + std::sin(hi)) -        // ∫ (t − t0) sin t
                       (-(lo - t0) * std::cos(lo) + std::sin(lo));
      w1[j] = k / dt;
      w0[j] = s - k / dt;
    }
    std::vector<double> out(nh, 0.0);
    for (std::size_t i = 0; i < nh; ++i) {
      const double* col = &cd_[i * nt];
      for (std::size_t j = 0; j + 1 < nt; ++j) out[i] += col[j] * w0[j] + col[j + 1] * w1[j];
    }
    return out;
  }

  // Bilinear lookup in (azimuth, theta), both degrees.
  double lookup(double az, double theta) const {
    const std::size_t nt = th_.size();
    constexpr double eps = 1e-9;
    if (!(theta >= th_.front() - eps && theta <= th_.back() + eps)) return 0.0;  // also rejects NaN
    theta = std::clamp(theta, th_.front(), th_.back());
    std::size_t j = static_cast<std::size_t>(std::upper_bound(th_.begin(), th_.end(), theta) - th_.begin());
    j = std::min(std::max<std::size_t>(j, 1), nt - 1) - 1;
    const double tt = (theta - th_[j]) / (th_[j + 1] - th_[j]);

    const std::size_t nh = az_.size();
    std::size_t i0 = 0, i1 = 0;
    double ta = 0;
    if (nh > 1) {
      if (periodic_) {
        az = az - 360.0 * std::floor((az - az_.front()) / 360.0);  // into [az0, az0 + 360)
        if (!(az >= az_.front())) az = az_.front();
      } else if (!(az >= az_.front() - eps && az <= az_.back() + eps)) {
        return 0.0;
      }
      std::size_t i = static_cast<std::size_t>(std::upper_bound(az_.begin(), az_.end(), az) - az_.begin());
      i = std::max<std::size_t>(i, 1) - 1;
      if (i + 1 < nh) {
        i0 = i;
        i1 = i + 1;
        ta = (az - az_[i]) / (az_[i + 1] - az_[i]);
      } else if (periodic_) {  // the wrap interval [last, first + 360)
        i0 = nh - 1;
        i1 = 0;
        const double gap = az_.front() + 360.0 - az_.back();
        ta = gap > 0 ? (az - az_.back()) / gap : 0.0;
      } else {
        i0 = i1 = nh - 1;
      }
      ta = std::clamp(ta, 0.0, 1.0);
    }
    const double c00 = cd_[i0 * nt + j], c01 = cd_[i0 * nt + j + 1];
    const double c10 = cd_[i1 * nt + j], c11 = cd_[i1 * nt + j + 1];
    return (1 - ta) * ((1 - tt) * c00 + tt * c01) + ta * ((1 - tt) * c10 + tt * c11);
  }

  // A table that stores both C0 and C360 (IES with no symmetry) holds two values for one direction;
  // measured files often differ there. Both become their mean, so the interpolant is continuous
  // across the seam and a format that stores C0 only (EULUMDAT) carries the same distribution.
  void average_seam_planes() {
    const std::size_t nh = az_.size(), nt = th_.size();
    if (!periodic_ || nh < 2 || az_.back() - az_.front() < 360.0 - 1e-9) return;
    for (std::size_t j = 0; j < nt; ++j) {
      const double mean = 0.5 * (cd_[j] + cd_[(nh - 1) * nt + j]);
      cd_[j] = cd_[(nh - 1) * nt + j] = mean;
    }
  }

  // At theta = 0 or 180 every plane meets in one direction; use the plane-width-weighted mean there.
  void average_pole_rows() {
    const std::size_t nh = az_.size(), nt = th_.size();
    if (nh < 2) return;
    std::vector<double> w(nh, 0.0);
    for (std::size_t i = 0; i < nh; ++i) {
      const double prev = i > 0 ? az_[i] - az_[i - 1] : (periodic_ ? az_[0] + 360.0 - az_[nh - 1] : 0.0);
      const double next = i + 1 < nh ? az_[i + 1] - az_[i] : (periodic_ ? az_[0] + 360.0 - az_[nh - 1] : 0.0);
      w[i] = 0.5 * (prev + next);
    }
    for (std::size_t j : {std::size_t{0}, nt - 1}) {
      if (std::abs(th_[j]) > 1e-9 && std::abs(th_[j] - 180.0) > 1e-9) continue;
      double sum = 0, wsum = 0;
      for (std::size_t i = 0; i < nh; ++i) {
        sum += w[i] * cd_[i * nt + j];
        wsum += w[i];
      }
      const double mean = wsum > 0 ? sum / wsum : cd_[j];
      for (std::size_t i = 0; i < nh; ++i) cd_[i * nt + j] = mean;
    }
  }

  PhotometricType type_;
  std::vector<double> az_, th_, cd_;
  bool periodic_ = true;
};

LUMX_NAMESPACE_END
