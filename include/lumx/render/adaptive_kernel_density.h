// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/render/adaptive_kernel_density.h — illuminance on a flat rectangle reconstructed from particle
// deposits by adaptive-kernel density estimation: a kernel per deposit whose width follows the local deposit
// density (Collins 1995, seed 004 §3–5; Silverman 1986 §5.3), so the estimate is smooth where deposits are
// sparse and sharp where they are dense, without a fixed bin size.
//
// A deposit is a particle's flux (lm) landing at (u, v) on a rectangle [0, width] × [0, height] (m); the
// estimate is flux per area, lm/m² = lx. Kernels that reach past the rectangle's edges are corrected so that
// the flux of every deposit stays on the rectangle (no darkening along walls' edges).
#pragma once

#include <lumx/version.h>

#include <cstdint>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace render {

struct Deposit2D {
  double u = 0.0;       ///< m, in [0, width]
  double v = 0.0;       ///< m, in [0, height]
  double flux_lm = 0.0;
};

struct AdaptiveKernelOptions {
  /// Pilot bandwidth h0, m; 0 = chosen from the deposits (a normal-reference rule on their spread).
  double pilot_bandwidth_m = 0.0;
  /// Sensitivity α of the local bandwidth factor λ_i = (f̃(x_i) / g)^−α (g: geometric mean of the pilot
  /// density at the deposits); α = 1/2 in two dimensions (Abramson's choice, Collins §4).
  double sensitivity = 0.5;
  /// Local factors are clamped to [1 / max_factor, max_factor] so a lone deposit cannot spread over the
  /// whole rectangle nor a cluster collapse to a spike.
  double max_factor = 8.0;
  int threads = 0;  ///< 0 = all hardware threads; results do not depend on it
};

/// The estimator, built once from the deposits of one surface and evaluated at any point.
class AdaptiveKernelDensity2D {
 public:
  AdaptiveKernelDensity2D(std::vector<Deposit2D> deposits, double width_m, double height_m,
                          const AdaptiveKernelOptions& options = {});
  ~AdaptiveKernelDensity2D();
  AdaptiveKernelDensity2D(AdaptiveKernelDensity2D&&) noexcept;
  AdaptiveKernelDensity2D& operator=(AdaptiveKernelDensity2D&&) noexcept;

  /// Illuminance at (u, v), lx.
  double evaluate(double u, double v) const;
  /// Illuminance at the centres of an nx × ny grid of cells over the rectangle, row-major ([iy · nx + ix],
  /// iy = 0 at v = 0), lx.
  std::vector<double> evaluate_grid(int nx, int ny) const;
  /// Pilot bandwidth used, m, and the range of local bandwidths (for reports).
  double pilot_bandwidth_m() const;
  double min_bandwidth_m() const;
  double max_bandwidth_m() const;

 private:
  struct Impl;
  Impl* impl_ = nullptr;
};

}  // namespace render
LUMX_NAMESPACE_END
