// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Emitter fluxes and geometry helpers of lumx/bake/luminaire.h.
#include <lumx/bake/luminaire.h>

#include <lumx/io/rayset_io.h>
#include <lumx/math/constants.h>
#include <lumx/photometry/intensity_table.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

LUMX_NAMESPACE_BEGIN
namespace bake {

const char* to_string(EmitterKind k) {
  switch (k) {
    case EmitterKind::surface: return "surface";
    case EmitterKind::point: return "point";
    case EmitterKind::spot: return "spot";
    case EmitterKind::ies: return "ies";
    case EmitterKind::rayset: return "rayset";
  }
  return "unknown";
}

double triangle_area(const LuminaireScene& scene, std::size_t t) {
  const glm::dvec3 a = scene.positions[scene.indices[3 * t]];
  const glm::dvec3 b = scene.positions[scene.indices[3 * t + 1]];
  const glm::dvec3 c = scene.positions[scene.indices[3 * t + 2]];
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}

double spot_falloff(double cos_theta, double inner_cone_rad, double outer_cone_rad) {
  // KHR_lights_punctual: scale = 1 / max(0.001, cos inner − cos outer), offset = −cos outer · scale,
  // attenuation = saturate(cos θ · scale + offset)².
  const double co = std::cos(outer_cone_rad);
  const double scale = 1.0 / std::max(0.001, std::cos(inner_cone_rad) - co);
  const double a = std::clamp((cos_theta - co) * scale, 0.0, 1.0);
  return a * a;
}

namespace {

/// ∫ over the sphere of spot_falloff, sr: 2π ∫_{-1}^{1} a(μ) dμ with a = clamp((μ − cos outer) s)², which
/// is s² (m − co)³ / 3 on the ramp [co, m], m = min(1, co + 1/s), plus 1 − m at full strength.
double spot_solid_angle(double inner_cone_rad, double outer_cone_rad) {
  const double co = std::cos(outer_cone_rad);
  const double s = 1.0 / std::max(0.001, std::cos(inner_cone_rad) - co);
  const double m = std::min(1.0, co + 1.0 / s);
  const double ramp = m > co ? s * s * (m - co) * (m - co) * (m - co) / 3.0 : 0.0;
  return 2.0 * kPi * (ramp + std::max(0.0, 1.0 - m));
}

}  // namespace

Rgb emitter_flux_rgb(const LuminaireScene& scene, const Emitter& e) {
  switch (e.kind) {
    case EmitterKind::surface: {
      if (e.part >= scene.parts.size()) return Rgb{0.0};
      const Part& part = scene.parts[e.part];
      double area = 0.0;
      for (std::uint32_t t = 0; t < part.triangle_count; ++t) area += triangle_area(scene, part.first_triangle + t);
      const Material& m = scene.materials.at(part.material);
      return kPi * area * (m.double_sided ? 2.0 : 1.0) * m.emitted_luminance();
    }
    case EmitterKind::point: return 4.0 * kPi * e.intensity_cd;
    case EmitterKind::spot: return spot_solid_angle(e.inner_cone_rad, e.outer_cone_rad) * e.intensity_cd;
    case EmitterKind::ies: {
      if (!e.photometry) return Rgb{0.0};
      return IntensityTable(*e.photometry).flux_lm() * e.multiplier * e.color;
    }
    case EmitterKind::rayset: {
      auto rays = open_rayset(e.rayset_path);
      // Particles carry photometric flux; rays in W would need a spectrum-weighted efficacy per ray.
      if (rays->info().quantity != PhotometricQuantity::photometric)
        throw_at_field(e.rayset_path, "flux quantity",
                       "the rays carry radiant flux (W); a rayset emitter needs luminous flux (lm) per ray");
      return summarize_rays(*rays).flux_sum * e.color;
    }
  }
  return Rgb{0.0};
}

double emitter_flux_lm(const LuminaireScene& scene, const Emitter& e) {
  return luminance(emitter_flux_rgb(scene, e));
}

}  // namespace bake
LUMX_NAMESPACE_END
