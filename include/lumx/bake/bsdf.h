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
//
// Model (glTF 2.0 Appendix B with KHR_materials_{ior,specular,transmission,diffuse_transmission,volume}):
// metal and dielectric share one GGX reflection lobe; the dielectric's base is a Lambertian reflector /
// diffuse transmitter and, with weight `transmission`, a rough dielectric interface (Walter et al. 2007)
// that refracts (volume) or passes light straight through (thin-walled). docs/bsdf.md states the lobe
// weights and the sampling mixture; the scattering kernel is defined for the particle arriving from wo
// (importance), and radiance mode is its adjoint f(wo, wi) = f*(wi, wo).
#pragma once

#include <lumx/bake/material.h>
#include <lumx/bake/microfacet.h>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <optional>

LUMX_NAMESPACE_BEGIN
namespace bake {

enum class TransportMode { radiance, importance };

struct BsdfSample {
  glm::dvec3 wi{0.0};        ///< sampled direction, local frame, away from the surface
  Rgb weight{0.0};           ///< f(wo, wi) |cos θi| / pdf, per channel (the throughput multiplier)
  double pdf = 0.0;          ///< solid-angle density of wi (for a delta lobe: the probability of picking it)
  bool delta = false;        ///< wi came from a specular (Dirac) lobe; eval() and pdf() are zero for it
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
  std::optional<BsdfSample> sample(const glm::dvec3& wo, double u_lobe, const glm::dvec2& u, TransportMode mode) const;

  bool has_delta_lobe() const { return has_delta_; }
  const Material& material() const { return material_; }

  /// GGX α below which the specular lobes are treated as smooth (Dirac) lobes.
  static constexpr double kSmoothAlpha = 1e-3;
  /// |ior − 1| below which a volume's interface is index-matched: it neither reflects nor bends light.
  static constexpr double kIndexMatchedTolerance = 1e-3;

 private:
  struct LobeProbabilities {
    double specular = 0.0;              ///< GGX / mirror reflection (metal and the opaque dielectric's coat)
    double interface = 0.0;             ///< the transmissive dielectric interface (reflects or transmits)
    double diffuse = 0.0;               ///< Lambertian reflection
    double diffuse_transmission = 0.0;  ///< Lambertian transmission to the other side
  };

  // Fresnel of the dielectric layer seen from outside, per channel, before the specular factor.
  Rgb dielectric_fresnel(double cos_theta) const;
  double dielectric_fresnel_max(double cos_theta) const;
  Rgb metal_fresnel(double cos_theta) const;
  double diffuse_coupling(double cos_o, double cos_i) const;
  double interface_reflect_probability(double cos_theta) const;
  LobeProbabilities lobe_probabilities(double cos_o) const;

  Rgb kernel(const glm::dvec3& wo, const glm::dvec3& wi) const;
  Rgb kernel_inside(const glm::dvec3& wo, const glm::dvec3& wi) const;
  double pdf_inside(const glm::dvec3& wo, const glm::dvec3& wi) const;
  std::optional<BsdfSample> sample_inside(const glm::dvec3& wo, double u_lobe, const glm::dvec2& u,
                                          TransportMode mode) const;
  std::optional<BsdfSample> finish_sample(const glm::dvec3& wo, const glm::dvec3& wi, TransportMode mode) const;

  Material material_;
  bool has_delta_ = false;
  GgxDistribution ggx_{1.0};
  bool smooth_ = false;
  bool index_matched_ = false;
  double eta_ = 1.5;  ///< sanitised ior (η of the solid against the outside)
  double metallic_ = 0.0, transmission_ = 0.0, specular_ = 1.0, diffuse_transmission_ = 0.0;
  Rgb base_{1.0}, diffuse_transmission_color_{1.0};
  Rgb dielectric_f0_{0.04};       ///< min(F0(ior) · specular_color, 1) per channel
  double plain_f0_ = 0.04;        ///< F0(ior), the bare interface's normal reflectance
  double base_max_ = 1.0;         ///< max channel of the base colour (transmission tint)
  double coupling_norm_ = 1.0;    ///< 1 − specular · 2∫ F̂(μ) μ dμ (diffuse coupling normaliser)
  double coupling_margin_ = 1.0;  ///< κ: 1 − kRoughCouplingMargin · specular for rough layers, else 1
  /// Share of the diffuse coupling a rough specular layer withholds (covers the visible-microfacet Fresnel
  /// average exceeding the macro-normal Fresnel; see src/bake/bsdf.cpp).
  static constexpr double kRoughCouplingMargin = 0.005;
};

}  // namespace bake
LUMX_NAMESPACE_END
