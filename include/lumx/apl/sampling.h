// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/apl/sampling.h — importance sampling of an APL level, for renderers.
//
// Two samplers, each with a pdf function that returns exactly what sampling returned, so estimators
// that combine strategies (multiple importance sampling, Veach 1997 ch. 9) weight them correctly:
//  - Emission (light tracing, photon mapping, BDPT): pick an APL with probability ∝ its flux, then a
//    direction, piecewise-constant over the equal-area map's texels (pdf_ω = pdf_uv / 4π; algorithms.md
//    §3) in proportion to the map dilated by one texel (SphereMap::dilated). The sample's flux is the
//    bilinear I(ω) — the same intensity every other query uses — over p_apl · pdf_ω; the dilation makes
//    pdf_ω > 0 wherever I(ω) > 0, so the estimator is unbiased. A masked APL (apl_set.h) is drawn from
//    the same density: its I(ω) is positive only where the bilinear map is, inside the mask, so the
//    sample's flux is its masked I(ω) over the same pdf (0 for a sample outside the mask: exact, at the
//    cost of the samples the dilated texels put outside the border).
//  - Light selection at a shading point (next-event estimation): pick one APL with probability ∝ an
//    estimate of its contribution, Φ_i · max(0, cos θ_i) / r_i², where Φ_i is its flux (as if it were
//    isotropic) and θ_i the angle at the receiver. Every APL that can contribute (cos θ > 0) has a
//    non-zero probability, so E = I_i(ω_i) cos θ_i / r_i² / p_i is unbiased. The estimate costs no map
//    lookup, so choosing is O(N) arithmetic; APLs are points, so a BSDF-sampled ray never hits one and
//    the probability is what a renderer needs for MIS between its light-selection strategies.
#pragma once

#include <lumx/apl/apl_set.h>
#include <lumx/apl/evaluation.h>
#include <lumx/math/piecewise_constant_2d.h>
#include <lumx/math/sphere_map_sampler.h>

#include <glm/glm.hpp>

#include <cstddef>
#include <vector>

LUMX_NAMESPACE_BEGIN

struct EmissionSample {
  std::size_t apl = 0;
  glm::vec3 position{0.0f};   ///< m
  glm::vec3 direction{0.0f};  ///< unit
  float pdf_apl = 0;          ///< probability of choosing this APL
  float pdf_direction = 0;    ///< per steradian
  glm::vec3 flux{0.0f};       ///< I(ω) / (pdf_apl · pdf_direction): the sample's flux, lm or W per channel
  bool valid() const { return pdf_apl > 0 && pdf_direction > 0; }
};

/// Emission sampling of one level. Holds one SphereMapSampler per APL (4 bytes per texel).
class AplEmissionSampler {
 public:
  AplEmissionSampler(const AplSet& set, std::size_t level_index) : level_(&set.levels.at(level_index)) {
    std::vector<float> power;
    for (const Apl& a : level_->apls) {
      power.push_back(float(std::max(0.0, luminance_of(set.channels, a.flux))));
      samplers_.emplace_back(a.map.dilated());
    }
    choose_ = PiecewiseConstant1D(power.data(), power.size());
  }

  bool is_zero() const { return choose_.is_zero(); }

  /// One emission sample from three uniform numbers in [0, 1). Invalid (pdf 0) for an all-dark level.
  EmissionSample sample(float u_apl, float u1, float u2) const {
    EmissionSample s;
    const PiecewiseConstant1D::Sample c = choose_.sample(u_apl);
    if (c.cell < 0) return s;
    s.apl = std::size_t(c.cell);
    s.pdf_apl = float(choose_.probability(s.apl));
    const Apl& a = level_->apls[s.apl];
    s.position = a.position;
    // Drawn in the level's map frame and turned to the photometric frame (a rotation keeps solid angle,
    // so the density is the same in both). The density and intensity are then read at the turned
    // direction turned back, exactly as pdf() and a renderer's lookup read it, so that MIS weights agree
    // with the sample bit for bit; rounding can move that direction into a neighbouring texel only
    // within ~1e-7 rad of a texel edge.
    const DirectionSample d = samplers_[s.apl].sample(u1, u2);
    if (!(d.pdf > 0)) return s;
    s.direction = level_->frame.world_direction(d.direction);
    const glm::vec3 m = level_->frame.map_direction(s.direction);
    s.pdf_direction = samplers_[s.apl].pdf(m);
    if (s.valid()) s.flux = a.map.lookup(m) * detail::mask_factor(a, m, s.direction) / (s.pdf_apl * s.pdf_direction);
    return s;
  }

  /// Probability of choosing APL i.
  float pdf_apl(std::size_t i) const { return float(choose_.probability(i)); }
  /// Solid-angle density of direction w given APL i.
  float pdf_direction(std::size_t i, const glm::vec3& w) const {
    return samplers_.at(i).pdf(level_->frame.map_direction(w));
  }
  /// Joint density: pdf_apl(i) · pdf_direction(i, w); equals the product returned by sample().
  float pdf(std::size_t i, const glm::vec3& w) const { return pdf_apl(i) * pdf_direction(i, w); }

 private:
  const AplLevel* level_;
  std::vector<SphereMapSampler> samplers_;
  PiecewiseConstant1D choose_;
};

struct LightChoice {
  std::size_t apl = 0;
  float probability = 0;  ///< 0: no APL can light this point
  bool valid() const { return probability > 0; }
};

namespace detail {
/// The unnormalised selection weight of APL a for a receiver at x with normal n (n = 0: no cosine).
inline float selection_weight(const AplSet& set, const Apl& a, const glm::vec3& x, const glm::vec3& n,
                              float min_r2) {
  const glm::vec3 d = a.position - x;  // toward the light
  const float r2 = std::max(glm::dot(d, d), min_r2);
  float cosine = 1.0f;
  if (n != glm::vec3(0.0f)) {
    cosine = glm::dot(n, d) / std::sqrt(r2);
    if (!(cosine > 0.0f)) return 0.0f;
  }
  const float power = float(luminance_of(set.channels, a.flux));
  return power > 0 ? power * cosine / r2 : 0.0f;
}
inline float selection_min_r2(const AplSet& set) {
  const float r = float(std::max(1e-9, 2e-6 * set.bounds.radius));
  return r * r;
}
}  // namespace detail

/// Chooses one APL of `level_index` for the shading point (x, n) with u ∈ [0, 1).
inline LightChoice choose_light(const AplSet& set, std::size_t level_index, const glm::vec3& x, const glm::vec3& n,
                                float u) {
  const AplLevel& level = set.levels.at(level_index);
  const float min_r2 = detail::selection_min_r2(set);
  double total = 0;
  for (const Apl& a : level.apls) total += detail::selection_weight(set, a, x, n, min_r2);
  LightChoice c;
  if (!(total > 0)) return c;
  const double target = double(std::min(std::max(u, 0.0f), 0x1.fffffep-1f)) * total;
  double running = 0;
  std::size_t last_positive = 0;
  for (std::size_t i = 0; i < level.apls.size(); ++i) {
    const float w = detail::selection_weight(set, level.apls[i], x, n, min_r2);
    if (w <= 0) continue;
    last_positive = i;
    running += w;
    if (target < running) {
      c.apl = i;
      c.probability = float(double(w) / total);
      return c;
    }
  }
  // Rounding put the target past the sum: the last APL with weight.
  c.apl = last_positive;
  c.probability = float(double(detail::selection_weight(set, level.apls[last_positive], x, n, min_r2)) / total);
  return c;
}

/// The probability with which choose_light picks APL `apl` at (x, n).
inline float light_choice_probability(const AplSet& set, std::size_t level_index, const glm::vec3& x,
                                      const glm::vec3& n, std::size_t apl) {
  const AplLevel& level = set.levels.at(level_index);
  const float min_r2 = detail::selection_min_r2(set);
  double total = 0;
  for (const Apl& a : level.apls) total += detail::selection_weight(set, a, x, n, min_r2);
  if (!(total > 0)) return 0.0f;
  return float(double(detail::selection_weight(set, level.apls.at(apl), x, n, min_r2)) / total);
}

LUMX_NAMESPACE_END
