// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/material.h — a luminaire part's material, in glTF 2.0's terms (metallic-roughness core plus the
// KHR_materials_{ior,specular,transmission,diffuse_transmission,volume,emissive_strength} extensions).
//
// Colours are linear Rec. 709 / sRGB primaries (glTF's factors, no transfer curve). Photometric quantities
// are carried per channel with the convention Y = luminance(rgb) (Rec. 709 weights): an emissive factor
// (1, 1, 1) × strength 1000 is a white surface of luminance 1000 cd/m², and a particle whose flux is
// (Φ, Φ, Φ) carries Φ lm. The glTF defaults are the defaults here, so a material read from a file that
// states nothing is glTF's default material.
#pragma once

#include <lumx/version.h>

#include <glm/vec3.hpp>

#include <cmath>
#include <limits>
#include <string>

LUMX_NAMESPACE_BEGIN
namespace bake {

/// Linear RGB triple (Rec. 709 primaries); photometric when its luminance() is in photometric units.
using Rgb = glm::dvec3;

/// Luminance of a linear Rec. 709 triple (ITU-R BT.709 weights).
inline double luminance(const Rgb& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

struct Material {
  std::string name;
  Rgb base_color{1.0};          ///< pbrMetallicRoughness.baseColorFactor (rgb; alpha ignored)
  double metallic = 1.0;        ///< pbrMetallicRoughness.metallicFactor
  double roughness = 1.0;       ///< pbrMetallicRoughness.roughnessFactor; GGX α = roughness²
  double ior = 1.5;             ///< KHR_materials_ior.ior (dielectric index against air)
  double specular = 1.0;        ///< KHR_materials_specular.specularFactor (scales the dielectric F)
  Rgb specular_color{1.0};      ///< KHR_materials_specular.specularColorFactor (scales F0)
  double transmission = 0.0;    ///< KHR_materials_transmission.transmissionFactor
  double diffuse_transmission = 0.0;      ///< KHR_materials_diffuse_transmission.diffuseTransmissionFactor
  Rgb diffuse_transmission_color{1.0};    ///< ...diffuseTransmissionColorFactor
  /// KHR_materials_volume with thicknessFactor > 0: the part is a closed solid that refracts; otherwise a
  /// transmissive material is thin-walled (light passes through without bending).
  bool volume = false;
  double thickness_m = 0.0;     ///< KHR_materials_volume.thicknessFactor (informative; geometry decides)
  Rgb attenuation_color{1.0};   ///< KHR_materials_volume.attenuationColor
  double attenuation_distance_m = std::numeric_limits<double>::infinity();  ///< ...attenuationDistance
  Rgb emissive{0.0};            ///< emissiveFactor
  double emissive_strength = 1.0;  ///< KHR_materials_emissive_strength.emissiveStrength
  bool double_sided = false;    ///< doubleSided: emits and scatters on both faces

  /// Emitted luminance per channel, cd/m² (glTF: emissive × strength, read as photometric luminance).
  Rgb emitted_luminance() const { return emissive * emissive_strength; }
  bool emissive_any() const { return luminance(emitted_luminance()) > 0.0; }

  /// Beer–Lambert absorption coefficient per channel, 1/m (KHR_materials_volume: the colour a white ray
  /// has after travelling attenuationDistance inside, σ = −ln(c) / d). Zero when there is no volume.
  Rgb absorption_per_m() const {
    Rgb s{0.0};
    if (!volume || !(attenuation_distance_m > 0.0) || std::isinf(attenuation_distance_m)) return s;
    for (int c = 0; c < 3; ++c)
      s[c] = attenuation_color[c] > 0.0 ? -std::log(std::min(1.0, attenuation_color[c])) / attenuation_distance_m
                                        : std::numeric_limits<double>::infinity();
    return s;
  }
};

}  // namespace bake
LUMX_NAMESPACE_END
