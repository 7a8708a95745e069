// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/fresnel.h — Fresnel reflectance: Schlick's approximation (glTF 2.0 Appendix B) and the exact
// unpolarised dielectric equations with total internal reflection.
#pragma once

#include <lumx/version.h>

#include <algorithm>
#include <cmath>

LUMX_NAMESPACE_BEGIN
namespace bake {

/// Schlick 1994: F(c) = F0 + (F90 − F0)(1 − c)⁵ with c = |cos θ| clamped to [0, 1] (glTF's fresnel term).
inline double fresnel_schlick(double f0, double f90, double cos_theta) {
  const double c = std::clamp(std::abs(cos_theta), 0.0, 1.0);
  const double m = 1.0 - c, m2 = m * m;
  return f0 + (f90 - f0) * (m2 * m2 * m);
}

/// Normal-incidence reflectance of an interface between indices 1 and ior: F0 = ((ior − 1)/(ior + 1))².
inline double fresnel_f0_from_ior(double ior) {
  const double r = (ior - 1.0) / (ior + 1.0);
  return r * r;
}

/// Exact unpolarised reflectance of a smooth dielectric interface (Born & Wolf §1.5; Walter et al. 2007
/// eq. 22 in the form of rₛ, rₚ). cos_i = cosine between the incident direction and the normal on the
/// incident side (clamped to [0, 1]); eta = ηₜ/ηᵢ, the index beyond the interface over the index on the
/// incident side. Returns 1 under total internal reflection (sin²θₜ = (1 − cos²θᵢ)/η² ≥ 1).
inline double fresnel_dielectric(double cos_i, double eta) {
  const double ci = std::clamp(std::abs(cos_i), 0.0, 1.0);
  if (!(eta > 0.0)) return 1.0;
  const double sin2_t = (1.0 - ci * ci) / (eta * eta);
  if (sin2_t >= 1.0) return 1.0;
  const double ct = std::sqrt(std::max(0.0, 1.0 - sin2_t));
  const double rs = (ci - eta * ct) / (ci + eta * ct);
  const double rp = (eta * ci - ct) / (eta * ci + ct);
  const double f = 0.5 * (rs * rs + rp * rp);
  return std::isfinite(f) ? std::clamp(f, 0.0, 1.0) : 1.0;
}

}  // namespace bake
LUMX_NAMESPACE_END
