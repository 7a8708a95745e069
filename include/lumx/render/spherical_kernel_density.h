// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/render/spherical_kernel_density.h — intensity on the sphere of directions reconstructed from
// weighted directions (particles leaving a luminaire, flux in lm) by adaptive-kernel density estimation:
// the spherical counterpart of adaptive_kernel_density.h (Collins 1995, seed 004 §4; Silverman 1986 §5.3).
//
//   I(ω) = Σ_i Φ_i K_{h_i}(ω, ω_i),   K_h = 3/(π h²) · (1 − c²/h²)²  for chord c = |ω − ω_i| < h,
//
// in cd = lm/sr. With c² = 2(1 − cos θ) and dω = 2π d(cos θ), ∫ K dω = 1 exactly for every chord radius
// h ≤ 2, so the flux of each direction stays on the sphere (there are no edges to correct).
// h_i = h₀ λ_i, λ_i = clamp((Ĩ(ω_i)/g)^{−α}, 1/max_factor, max_factor) with Ĩ the fixed-h₀ pilot and g
// the flux-weighted geometric mean of Ĩ at the directions. docs/render.md, "Adaptive kernels on the
// sphere", states the rules and the accuracy measured against exact intensity distributions.
#pragma once

#include <lumx/version.h>

#include <glm/vec3.hpp>

#include <vector>

LUMX_NAMESPACE_BEGIN
namespace render {

/// One particle's flux leaving in a direction (normalised on input; a zero or non-finite direction and a
/// negative or non-finite flux are errors; zero flux is allowed and carries nothing).
struct DirectionDeposit {
  glm::dvec3 direction{0.0, 0.0, 1.0};
  double flux_lm = 0.0;  ///< lm, ≥ 0
};

struct SphericalKernelOptions {
  /// Pilot bandwidth h₀ as a chord of the unit sphere (chord 2 sin(θ/2) for an angular radius θ); 0 = the
  /// normal-reference rule h₀ = bandwidth_scale · 2.7788 · σ · n_eff^{−1/6} with σ² = 1 − R̄ (R̄ the
  /// flux-weighted mean resultant length: the tangent-plane variance per axis of a concentrated
  /// distribution, 1 for a uniform one) and n_eff = (ΣΦ)²/ΣΦ². Capped at 2 (the whole sphere).
  double pilot_bandwidth = 0.0;
  double bandwidth_scale = 0.7;  ///< as AdaptiveKernelOptions::bandwidth_scale
  double sensitivity = 0.5;      ///< α; 0 = one fixed bandwidth
  double max_factor = 8.0;       ///< λ_i clamped to [1/max_factor, max_factor]
};

/// The estimator, built once from the directions and evaluated in any direction (thread-safe, immutable).
/// The pilot is the fixed-h₀ estimate tabulated on an equal-area sphere map (math/sphere_map.h) with
/// texels ≈ h₀/8 across and read bilinearly at each direction, so building costs O(N log N + N (h₀/δ)²);
/// a query visits, through a kd-tree over the kernels' supports, only the kernels that cover it. No
/// threads: results depend only on the input.
class AdaptiveKernelDensitySphere {
 public:
  /// Throws lumx::Error naming the field ("deposits[4].direction", "deposits[4].flux_lm", "sensitivity", …).
  explicit AdaptiveKernelDensitySphere(std::vector<DirectionDeposit> deposits, const SphericalKernelOptions& options = {});
  ~AdaptiveKernelDensitySphere();
  AdaptiveKernelDensitySphere(AdaptiveKernelDensitySphere&&) noexcept;
  AdaptiveKernelDensitySphere& operator=(AdaptiveKernelDensitySphere&&) noexcept;

  /// Intensity in `direction` (need not be unit; zero or non-finite gives 0), cd.
  double intensity_cd(const glm::dvec3& direction) const;
  /// Chord bandwidths used (pilot, smallest, largest); angular radius = 2 asin(chord / 2).
  double pilot_bandwidth() const;
  double min_bandwidth() const;
  double max_bandwidth() const;

 private:
  struct Impl;
  Impl* impl_ = nullptr;
};

}  // namespace render
LUMX_NAMESPACE_END
