// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Placeholder scattering: Lambertian reflection with the base colour (replaced by the glTF material model).
#include <lumx/bake/bsdf.h>

#include <lumx/math/constants.h>

#include <algorithm>
#include <cmath>

LUMX_NAMESPACE_BEGIN
namespace bake {

Bsdf::Bsdf(const Material& material) : material_(material) {}

Rgb Bsdf::eval(const glm::dvec3& wo, const glm::dvec3& wi, TransportMode) const {
  if (wo.z <= 0.0 || wi.z <= 0.0) return Rgb{0.0};
  return material_.base_color * (1.0 - material_.metallic) / kPi;
}

double Bsdf::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
  return wi.z / kPi;
}

std::optional<BsdfSample> Bsdf::sample(const glm::dvec3& wo, double, const glm::dvec2& u, TransportMode) const {
  if (wo.z <= 0.0) return std::nullopt;
  const double r = std::sqrt(u.x), phi = 2.0 * kPi * u.y;
  BsdfSample s;
  s.wi = {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u.x))};
  s.pdf = s.wi.z / kPi;
  s.weight = material_.base_color * (1.0 - material_.metallic);
  if (s.pdf <= 0.0) return std::nullopt;
  return s;
}

}  // namespace bake
LUMX_NAMESPACE_END
