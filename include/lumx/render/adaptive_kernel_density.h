// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/render/adaptive_kernel_density.h — illuminance on a flat rectangle reconstructed from particle
// deposits by adaptive-kernel density estimation: a kernel per deposit whose width follows the local deposit
// density (Collins 1995, seed 004 §3–5; Silverman 1986 §5.3), so the estimate is smooth where deposits are
// sparse and sharp where they are dense, without a fixed bin size.
//
// A deposit is a particle's flux (lm) landing at (u, v) on a rectangle [0, width] × [0, height] (m); the
// estimate is flux per area, lm/m² = lx:
//
//   E(x) = Σ_i Φ_i K_{h_i}(x − x_i),   K_h(r) = 3/(π h²) · (1 − r²/h²)²  for r < h (biweight, compact),
//   h_i = h₀ λ_i,   λ_i = clamp((f̃(x_i) / g)^{−α}, 1/max_factor, max_factor),
//
// with f̃ the fixed-bandwidth pilot estimate (bandwidth h₀) and g the flux-weighted geometric mean of f̃ at
// the deposits. Kernels that reach past the rectangle's edges are mirrored back into it (reflection
// method): the flux of every deposit stays on the rectangle exactly, and a uniform illuminance stays
// unbiased up to the edges and corners (no darkening along walls' edges). Bandwidths are capped at
// min(width, height) so that the mirror images hold each kernel's whole mass. docs/render.md, section
// "Adaptive-kernel reconstruction", states the rules and the bias and noise measured against exact
// densities.
#pragma once

#include <lumx/version.h>

#include <cstdint>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace render {

/// One particle's flux on the rectangle. Positions up to 10⁻⁹ × the rectangle's size outside it (rounding
/// of hit points) are moved onto the edge; farther ones, non-finite values and negative flux are errors.
/// Zero-flux deposits are allowed and carry nothing.
struct Deposit2D {
  double u = 0.0;       ///< m, in [0, width]
  double v = 0.0;       ///< m, in [0, height]
  double flux_lm = 0.0;  ///< lm, ≥ 0
};

struct AdaptiveKernelOptions {
  /// Pilot bandwidth h0 (the biweight kernel's radius), m; 0 = chosen from the deposits: the 2D
  /// normal-reference rule h₀ = bandwidth_scale · 2.7788 · σ · n_eff^{−1/6} on their flux-weighted robust spread σ, with
  /// n_eff = (ΣΦ)²/ΣΦ² (so h₀ shrinks, and bias and noise both fall, as deposits grow). Capped at
  /// min(width, height).
  double pilot_bandwidth_m = 0.0;
  /// Multiplies the rule's h₀ (ignored when pilot_bandwidth_m is given). The normal reference
  /// oversmooths anything but one Gaussian blob; 0.7 gave the least relative RMSE summed over the test
  /// fields (uniform, point source, shadow edge, narrow spot) at 10⁴ and 10⁵ deposits (docs/render.md).
  double bandwidth_scale = 0.7;
  /// Sensitivity α of the local bandwidth factor λ_i = (f̃(x_i) / g)^−α (g: geometric mean of the pilot
  /// density at the deposits); α = 1/2 in two dimensions (Abramson's choice, Collins §4).
  double sensitivity = 0.5;
  /// Local factors are clamped to [1 / max_factor, max_factor] so a lone deposit cannot spread over the
  /// whole rectangle nor a cluster collapse to a spike. Sensitivity 0 gives the fixed-bandwidth estimate.
  double max_factor = 8.0;
  int threads = 0;  ///< 0 = all hardware threads; results do not depend on it
};

/// The estimator, built once from the deposits of one surface and evaluated at any point. Building costs
/// O(N log N) plus a pilot tabulated at ≈ h₀/4 spacing; a point evaluation visits, through a kd-tree over
/// the kernels' supports, only the deposits whose kernel covers the point. Results do not depend on the
/// thread count. Immutable once built: evaluate() may be called from many threads at once.
class AdaptiveKernelDensity2D {
 public:
  /// Throws lumx::Error naming the field ("deposits[12].u", "width", "sensitivity", …) for bad input:
  /// width or height not positive and finite, a deposit outside the rectangle, non-finite, or with
  /// negative flux, options out of range. No deposits gives zero everywhere.
  AdaptiveKernelDensity2D(std::vector<Deposit2D> deposits, double width_m, double height_m,
                          const AdaptiveKernelOptions& options = {});
  ~AdaptiveKernelDensity2D();
  AdaptiveKernelDensity2D(AdaptiveKernelDensity2D&&) noexcept;
  AdaptiveKernelDensity2D& operator=(AdaptiveKernelDensity2D&&) noexcept;

  /// Illuminance at (u, v), lx; 0 outside the rectangle. Costs a visit per kernel covering the point
  /// (thousands at 10⁶ deposits): for an image of a face, evaluate_grid and interpolate.
  double evaluate(double u, double v) const;
  /// Illuminance at the centres of an nx × ny grid of cells over the rectangle, row-major ([iy · nx + ix],
  /// iy = 0 at v = 0), lx: evaluate() at ((ix + ½) width/nx, (iy + ½) height/ny), equal to rounding, by
  /// splatting each kernel once (nx, ny ≥ 1, else lumx::Error).
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
