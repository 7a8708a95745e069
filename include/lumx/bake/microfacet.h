// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/microfacet.h — the isotropic GGX (Trowbridge–Reitz) microfacet distribution: normal density D,
// Smith masking (separable G1 and height-correlated G2) and visible-normal sampling (Heitz 2018).
//
// Directions are in the local frame with the macro-surface normal +z. α is GGX's width (glTF: α = roughness²).
#pragma once

#include <lumx/math/constants.h>
#include <lumx/version.h>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

LUMX_NAMESPACE_BEGIN
namespace bake {

class GgxDistribution {
 public:
  explicit GgxDistribution(double alpha) : alpha_(alpha) {}
  double alpha() const { return alpha_; }

  /// Normal distribution (Walter et al. 2007 eq. 33): D(m) = α² / (π (cos²θₘ (α² − 1) + 1)²) for m.z > 0.
  double normal_density(const glm::dvec3& m) const {
    if (m.z <= 0.0) return 0.0;
    const double a2 = alpha_ * alpha_;
    const double t = m.z * m.z * (a2 - 1.0) + 1.0;
    return a2 / (kPi * t * t);
  }

  /// Smith's Λ for GGX (Heitz 2014 eq. 72): Λ(ω) = (√(1 + α² tan²θ) − 1) / 2.
  double smith_lambda(const glm::dvec3& w) const {
    const double c2 = w.z * w.z;
    if (c2 <= 0.0) return std::numeric_limits<double>::infinity();
    const double tan2 = std::max(0.0, 1.0 - c2) / c2;
    return 0.5 * (std::sqrt(1.0 + alpha_ * alpha_ * tan2) - 1.0);
  }

  /// Separable masking of one direction: G1(ω) = 1 / (1 + Λ(ω)).
  double masking(const glm::dvec3& w) const { return 1.0 / (1.0 + smith_lambda(w)); }

  /// Height-correlated masking-shadowing (Heitz 2014 eq. 99): G2(ωo, ωi) = 1 / (1 + Λ(ωo) + Λ(ωi)).
  double masking_shadowing(const glm::dvec3& wo, const glm::dvec3& wi) const {
    return 1.0 / (1.0 + smith_lambda(wo) + smith_lambda(wi));
  }

  /// Density of visible normals seen from wo (wo.z > 0; Heitz 2018 eq. 1):
  /// D_wo(m) = G1(wo) max(0, wo·m) D(m) / cos θo.
  double visible_normal_density(const glm::dvec3& wo, const glm::dvec3& m) const {
    if (wo.z <= 0.0) return 0.0;
    const double wo_dot_m = glm::dot(wo, m);
    if (wo_dot_m <= 0.0) return 0.0;
    const double d = masking(wo) * wo_dot_m * normal_density(m) / wo.z;
    return std::isfinite(d) ? d : 0.0;
  }

  /// Draws a visible normal m ~ D_wo (Heitz 2018, "Sampling the GGX Distribution of Visible Normals",
  /// JCGT 7(4), listing 1): stretch wo to the α = 1 configuration, sample the projected hemisphere there,
  /// unstretch. wo.z > 0; u ∈ [0,1)².
  glm::dvec3 sample_visible_normal(const glm::dvec3& wo, const glm::dvec2& u) const {
    const glm::dvec3 vh = glm::normalize(glm::dvec3(alpha_ * wo.x, alpha_ * wo.y, wo.z));
    const double len2 = vh.x * vh.x + vh.y * vh.y;
    const glm::dvec3 t1 = len2 > 0.0 ? glm::dvec3(-vh.y, vh.x, 0.0) / std::sqrt(len2) : glm::dvec3(1.0, 0.0, 0.0);
    const glm::dvec3 t2 = glm::cross(vh, t1);
    const double r = std::sqrt(std::clamp(u.x, 0.0, 1.0));
    const double phi = 2.0 * kPi * u.y;
    const double p1 = r * std::cos(phi);
    double p2 = r * std::sin(phi);
    const double s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * p2;
    const glm::dvec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return glm::normalize(glm::dvec3(alpha_ * nh.x, alpha_ * nh.y, std::max(1e-12, nh.z)));
  }

 private:
  double alpha_;
};

}  // namespace bake
LUMX_NAMESPACE_END
