// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Exact illuminance fields on a 3 m × 2 m wall, particle deposits drawn from them exactly, and the bias,
// noise and error of a reconstruction measured over repeated seeds: what the adaptive-kernel tests and
// benchmark compare lumx::render::AdaptiveKernelDensity2D (and a fixed kernel, and a histogram) against.
#pragma once

#include <lumx/render/adaptive_kernel_density.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numeric>
#include <random>
#include <string>
#include <vector>

namespace lumx_test {

/// A wall-sized rectangle, m, and the flux landing on it, lm.
constexpr double kWallWidth = 3.0, kWallHeight = 2.0, kWallFlux = 1000.0;

/// Uniform doubles in [0, 1) from the standard-specified 64-bit Mersenne twister (same numbers on every
/// standard library, unlike std::uniform_real_distribution).
class UnitRandom {
 public:
  explicit UnitRandom(std::uint64_t seed) : engine_(seed) {}
  double operator()() { return double(engine_() >> 11) * 0x1.0p-53; }

 private:
  std::mt19937_64 engine_;
};

/// An exact illuminance field E(u, v) (lx) on the wall, total flux kWallFlux, and an exact sampler of
/// deposit positions with density E / kWallFlux.
struct WallField {
  std::string name;
  std::function<double(double, double)> illuminance_lx;
  std::function<void(UnitRandom&, double&, double&)> sample;
};

/// E = Φ / (W H).
inline WallField uniform_field() {
  return {"uniform", [](double, double) { return kWallFlux / (kWallWidth * kWallHeight); },
          [](UnitRandom& r, double& u, double& v) {
            u = r() * kWallWidth;
            v = r() * kWallHeight;
          }};
}

/// An isotropic point source at height h above (u0, v0): E ∝ h / (ρ² + h²)^{3/2}. The flux within radius ρ on
/// the infinite plane is ∝ 1 − h/√(ρ² + h²), inverted for ρ; deposits off the wall are drawn again
/// (exact sampling of the truncated field). Its flux on the wall is I·Ω with Ω the solid angle of the
/// rectangle seen from the source (sum of atan(xy / (h √(x² + y² + h²))) over the corners).
inline WallField point_source_field(double u0 = 1.0, double v0 = 0.8, double h = 0.5) {
  const auto corner = [h](double x, double y) { return std::atan(x * y / (h * std::sqrt(x * x + y * y + h * h))); };
  const double omega = corner(kWallWidth - u0, kWallHeight - v0) - corner(-u0, kWallHeight - v0) -
                       corner(kWallWidth - u0, -v0) + corner(-u0, -v0);
  const double intensity = kWallFlux / omega;  // cd
  return {"point source",
          [=](double u, double v) {
            const double r2 = (u - u0) * (u - u0) + (v - v0) * (v - v0) + h * h;
            return intensity * h / (r2 * std::sqrt(r2));
          },
          [=](UnitRandom& r, double& u, double& v) {
            for (;;) {
              const double q = r(), phi = 2.0 * 3.14159265358979323846 * r();
              const double s = 1.0 / (1.0 - q);
              const double rho = h * std::sqrt(std::max(0.0, s * s - 1.0));
              u = u0 + rho * std::cos(phi);
              v = v0 + rho * std::sin(phi);
              if (u >= 0.0 && u <= kWallWidth && v >= 0.0 && v <= kWallHeight) return;
            }
          }};
}

/// A shadow's straight edge at u = edge: E_lit for u < edge, E_lit · ratio beyond.
inline WallField shadow_edge_field(double edge = 1.8, double ratio = 0.1) {
  const double lit = kWallFlux / (kWallHeight * (edge + ratio * (kWallWidth - edge)));
  const double lit_share = edge / (edge + ratio * (kWallWidth - edge));
  return {"shadow edge", [=](double u, double) { return u < edge ? lit : lit * ratio; },
          [=](UnitRandom& r, double& u, double& v) {
            u = r() < lit_share ? r() * edge : edge + r() * (kWallWidth - edge);
            v = r() * kWallHeight;
          }};
}

/// A narrow Gaussian spot (standard deviation s) holding `share` of the flux on a uniform background; the
/// spot is truncated to the wall by drawing again, its mass on the wall from erf.
inline WallField spot_field(double u0 = 2.0, double v0 = 1.1, double s = 0.06, double share = 0.4) {
  const auto mass_1d = [s](double a, double b, double c) {
    return 0.5 * (std::erf((b - c) / (s * std::sqrt(2.0))) - std::erf((a - c) / (s * std::sqrt(2.0))));
  };
  const double inside = mass_1d(0.0, kWallWidth, u0) * mass_1d(0.0, kWallHeight, v0);
  const double background = (1.0 - share) * kWallFlux / (kWallWidth * kWallHeight);
  return {"narrow spot",
          [=](double u, double v) {
            const double d2 = ((u - u0) * (u - u0) + (v - v0) * (v - v0)) / (s * s);
            return background + share * kWallFlux * std::exp(-0.5 * d2) / (2.0 * 3.14159265358979323846 * s * s * inside);
          },
          [=](UnitRandom& r, double& u, double& v) {
            if (r() >= share) {
              u = r() * kWallWidth;
              v = r() * kWallHeight;
              return;
            }
            for (;;) {  // Box–Muller
              const double a = std::sqrt(-2.0 * std::log(1.0 - r())), phi = 2.0 * 3.14159265358979323846 * r();
              u = u0 + s * a * std::cos(phi);
              v = v0 + s * a * std::sin(phi);
              if (u >= 0.0 && u <= kWallWidth && v >= 0.0 && v <= kWallHeight) return;
            }
          }};
}

/// n equal-flux deposits (kWallFlux / n lm each) drawn from `field` with `seed`.
inline std::vector<lumx::render::Deposit2D> draw_deposits(const WallField& field, std::size_t n, std::uint64_t seed) {
  UnitRandom r(seed);
  std::vector<lumx::render::Deposit2D> out(n);
  for (auto& d : out) {
    field.sample(r, d.u, d.v);
    d.flux_lm = kWallFlux / double(n);
  }
  return out;
}

/// A plain histogram of the deposits, bins by Scott's normal-reference rule for 2D histograms
/// (bin side 3.504 σ_a n^{-1/4} per axis, Scott 1992 §3.4), evaluated at the centres of an nx × ny grid.
inline std::vector<double> histogram_grid(const std::vector<lumx::render::Deposit2D>& deposits, int nx, int ny) {
  const double n = double(deposits.size());
  double mu = 0, mv = 0;
  for (const auto& d : deposits) mu += d.u / n, mv += d.v / n;
  double su = 0, sv = 0;
  for (const auto& d : deposits) su += (d.u - mu) * (d.u - mu) / n, sv += (d.v - mv) * (d.v - mv) / n;
  const int bu = std::max(1, int(std::lround(kWallWidth / (3.504 * std::sqrt(su) * std::pow(n, -0.25)))));
  const int bv = std::max(1, int(std::lround(kWallHeight / (3.504 * std::sqrt(sv) * std::pow(n, -0.25)))));
  std::vector<double> bins(std::size_t(bu) * std::size_t(bv), 0.0);
  for (const auto& d : deposits) {
    const int iu = std::min(bu - 1, int(d.u / kWallWidth * bu)), iv = std::min(bv - 1, int(d.v / kWallHeight * bv));
    bins[std::size_t(iv) * std::size_t(bu) + std::size_t(iu)] += d.flux_lm;
  }
  const double area = kWallWidth * kWallHeight / (double(bu) * double(bv));
  std::vector<double> out(std::size_t(nx) * std::size_t(ny));
  for (int iy = 0; iy < ny; ++iy)
    for (int ix = 0; ix < nx; ++ix) {
      const int iu = std::min(bu - 1, int((ix + 0.5) / nx * bu)), iv = std::min(bv - 1, int((iy + 0.5) / ny * bv));
      out[std::size_t(iy) * std::size_t(nx) + std::size_t(ix)] = bins[std::size_t(iv) * std::size_t(bu) + std::size_t(iu)] / area;
    }
  return out;
}

/// Accuracy of a reconstruction over repeated seeds at the centres of an nx × ny grid, restricted to the
/// points a mask selects. Relative figures are divided by the mean exact illuminance over those points.
struct ErrorFigures {
  double relative_bias = 0;   ///< √(mean over points of (mean over seeds − exact)² − variance/seeds)
  double relative_sd = 0;     ///< √(mean over points of the variance across seeds)
  double relative_rmse = 0;   ///< √(mean over seeds and points of (estimate − exact)²)
  double rmse_standard_error = 0;  ///< of relative_rmse: sd across seeds of the per-seed figure / √seeds
  std::vector<double> per_seed_rmse;  ///< relative, one per seed
};

/// `estimates[s]` is seed s's grid (row-major, as evaluate_grid), `exact` the field at the same points.
inline ErrorFigures error_figures(const std::vector<std::vector<double>>& estimates, const std::vector<double>& exact,
                                 const std::vector<char>& mask) {
  ErrorFigures f;
  const std::size_t seeds = estimates.size();
  double mean_exact = 0, bias2 = 0, variance = 0, count = 0;
  for (std::size_t p = 0; p < exact.size(); ++p) {
    if (!mask[p]) continue;
    double m = 0;
    for (const auto& e : estimates) m += e[p] / double(seeds);
    double s2 = 0;
    for (const auto& e : estimates) s2 += (e[p] - m) * (e[p] - m) / double(seeds - 1);
    bias2 += (m - exact[p]) * (m - exact[p]) - s2 / double(seeds);
    variance += s2;
    mean_exact += exact[p];
    count += 1;
  }
  mean_exact /= count;
  f.relative_bias = std::sqrt(std::max(0.0, bias2 / count)) / mean_exact;
  f.relative_sd = std::sqrt(variance / count) / mean_exact;
  double mse = 0, sum = 0, sum2 = 0;
  for (const auto& e : estimates) {
    double seed_mse = 0;
    for (std::size_t p = 0; p < exact.size(); ++p)
      if (mask[p]) seed_mse += (e[p] - exact[p]) * (e[p] - exact[p]) / count;
    mse += seed_mse / double(seeds);
    const double r = std::sqrt(seed_mse) / mean_exact;
    f.per_seed_rmse.push_back(r);
    sum += r;
    sum2 += r * r;
  }
  f.relative_rmse = std::sqrt(mse) / mean_exact;
  const double mean = sum / double(seeds);
  f.rmse_standard_error = std::sqrt(std::max(0.0, (sum2 / double(seeds) - mean * mean) * double(seeds) / double(seeds - 1)) / double(seeds));
  return f;
}

/// The exact field at the centres of an nx × ny grid over the wall.
inline std::vector<double> exact_grid(const WallField& field, int nx, int ny) {
  std::vector<double> out(std::size_t(nx) * std::size_t(ny));
  for (int iy = 0; iy < ny; ++iy)
    for (int ix = 0; ix < nx; ++ix)
      out[std::size_t(iy) * std::size_t(nx) + std::size_t(ix)] =
          field.illuminance_lx((ix + 0.5) * kWallWidth / nx, (iy + 0.5) * kWallHeight / ny);
  return out;
}

/// Evaluation points every 5 cm on the 3 m × 2 m wall.
constexpr int kGridX = 60, kGridY = 40;

/// Per seed, the kGridX × kGridY grid of each reconstruction (row-major, as evaluate_grid).
struct Study {
  std::vector<std::vector<double>> adaptive, fixed, histogram;
};

/// `seeds` draws of n deposits from `field` (seeds first_seed, first_seed + 1, …), each reconstructed three
/// ways: the default (adaptive) options, the same with sensitivity 0 (one fixed bandwidth h₀), and a
/// Scott's-rule histogram.
inline Study run_study(const WallField& field, std::size_t n, int seeds, int first_seed = 1) {
  using lumx::render::AdaptiveKernelDensity2D;
  Study s;
  for (int seed = first_seed; seed < first_seed + seeds; ++seed) {
    const auto d = draw_deposits(field, n, std::uint64_t(seed));
    lumx::render::AdaptiveKernelOptions o;
    s.adaptive.push_back(AdaptiveKernelDensity2D(d, kWallWidth, kWallHeight, o).evaluate_grid(kGridX, kGridY));
    o.sensitivity = 0.0;
    s.fixed.push_back(AdaptiveKernelDensity2D(d, kWallWidth, kWallHeight, o).evaluate_grid(kGridX, kGridY));
    s.histogram.push_back(histogram_grid(d, kGridX, kGridY));
  }
  return s;
}

/// The points a figure is taken over: all, the peak (E > 2 Ē) or the sparse part (E < Ē/2), Ē the mean
/// of `exact` over every point.
enum class Region { all, peak, sparse };

inline std::vector<char> region_mask(const std::vector<double>& exact, Region r) {
  const double mean = std::accumulate(exact.begin(), exact.end(), 0.0) / double(exact.size());
  std::vector<char> m(exact.size());
  for (std::size_t p = 0; p < exact.size(); ++p)
    m[p] = r == Region::all ? 1 : r == Region::peak ? exact[p] > 2.0 * mean : exact[p] < 0.5 * mean;
  return m;
}

}  // namespace lumx_test
