// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Where particles start: an emitter picked with probability ∝ its flux (luminance), then a point and a direction
// on it. Each sample carries a flux weight w (per channel) with E[w] over one emitter's samples equal to its
// flux colour Φ_rgb / Φ_Y, so N particles of flux Φ_total / N · w estimate every emitter's emission without
// bias:
//   surface  uniform by area, cosine-weighted about the geometric normal (πLA exactly), w = colour;
//   point    uniform on the sphere, w = colour;
//   spot     uniform in the outer cone, w = colour · falloff(θ) · Ω_cone / Ω_eff (Ω_eff = ∫ falloff dω);
//   ies      texel ∝ the largest intensity at its centre and corners (+10⁻³ of the peak) on an equal-area map,
//            uniform in the texel,
//            w = colour · I(ω) / (pdf(ω) Φ_profile);
//   rayset   a ray ∝ its flux, w = colour.
#pragma once

#include <lumx/bake/luminaire.h>
#include <lumx/bake/random.h>
#include <lumx/math/sphere_map_sampler.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/rays/rayset.h>

#include <glm/mat3x3.hpp>

#include <memory>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace bake {

struct EmittedParticle {
  glm::dvec3 position{0.0};
  glm::dvec3 direction{0.0, 0.0, 1.0};
  Rgb flux_weight{0.0};          ///< w above
  std::uint32_t emitter = 0;
  bool has_surface = false;      ///< started on a triangle (offset the first ray off it)
  glm::dvec3 surface_normal{0.0};  ///< that triangle's geometric normal, on the emitting side
};

class EmitterSampler {
 public:
  explicit EmitterSampler(const LuminaireScene& scene);
  EmittedParticle sample(Pcg32& rng) const;
  double total_flux_lm() const { return total_flux_lm_; }
  Rgb total_flux_rgb() const { return total_flux_rgb_; }

 private:
  struct Source {
    EmitterKind kind = EmitterKind::point;
    Rgb colour{1.0};                     // Φ_rgb / Φ_Y
    glm::dmat4 to_world{1.0};
    glm::dmat3 rotation{1.0};            // linear part with unit columns (directions)
    // surface
    std::vector<std::uint32_t> triangles;
    std::vector<double> area_cdf;
    bool two_sided = false;
    // spot
    double cos_outer = 0.0, cos_inner = 1.0, inner = 0.0, outer = 0.0, cone_over_effective = 1.0;
    // ies
    std::shared_ptr<IntensityTable> table;
    std::shared_ptr<SphereMapSampler> direction_sampler;
    double profile_flux = 0.0;
    // rayset
    RayChunk rays;
    std::vector<double> ray_cdf;
  };

  const LuminaireScene& scene_;
  std::vector<Source> sources_;
  std::vector<double> emitter_cdf_;
  std::vector<std::uint32_t> emitter_index_;
  double total_flux_lm_ = 0.0;
  Rgb total_flux_rgb_{0.0};
};

}  // namespace bake
LUMX_NAMESPACE_END
