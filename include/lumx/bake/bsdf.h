// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/bsdf.h — the scattering model of a glTF material, for tracing light particles.
//
// Frame. All directions are unit vectors in the local shading frame whose +z is the shading normal on the
// material's FRONT side (the side glTF's counter-clockwise winding faces); both wo and wi point AWAY from
// the surface. For a volume material (Material::volume) −z is the inside of the solid: wo.z < 0 means the
// particle arrives from inside and refraction uses η = 1/ior. For every other material the caller presents
// the side the particle arrives from as +z (double-sided, thin transmissive) or treats a back-face hit as
// absorbed (single-sided opaque); such a Bsdf returns zero / no sample for wo.z ≤ 0.
//
// Transport. TransportMode::importance is the adjoint (particle) direction: the particle travels along
// −wo into the surface and leaves along wi, and eval() returns f*(wo, wi) = f(wi, wo), without the 1/η²
// radiance scaling on refraction (Veach 1997 §5.2). TransportMode::radiance is the usual f(wo, wi).
#pragma once

#include <lumx/bake/material.h>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <optional>

LUMX_NAMESPACE_BEGIN
namespace bake {

enum class TransportMode { radiance, importance };

struct BsdfSample {
  glm::dvec3 wi{0.0};   ///< sampled direction, local frame, away from the surface
  Rgb weight{0.0};      ///< f(wo, wi) |cos θi| / pdf, per channel (the throughput multiplier)
  double pdf = 0.0;     ///< solid-angle density of wi (for a delta lobe: the probability of picking it)
  bool delta = false;   ///< wi came from a specular (Dirac) lobe; eval() and pdf() are zero for it
  bool transmitted = false;  ///< wi is on the other side of the surface from wo
};

class Bsdf {
 public:
  explicit Bsdf(const Material& material);

  /// f(wo, wi) per channel, 1/sr, excluding delta lobes (cosine not included).
  Rgb eval(const glm::dvec3& wo, const glm::dvec3& wi, TransportMode mode) const;
  /// The density sample() draws wi with, 1/sr, excluding delta lobes (the mixture over lobes).
  double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const;
  /// Draws wi from wo; u_lobe picks the lobe, u the direction. nullopt when nothing scatters.
  std::optional<BsdfSample> sample(const glm::dvec3& wo, double u_lobe, const glm::dvec2& u,
                                   TransportMode mode) const;

  bool has_delta_lobe() const { return has_delta_; }
  const Material& material() const { return material_; }

 private:
  Material material_;
  bool has_delta_ = false;
};

}  // namespace bake
LUMX_NAMESPACE_END
