// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// A procedural luminaire of about 277 k triangles for tracing benchmarks: a small emissive core inside a rough
// glass bulb (81 280 triangles) under a ridged, thin, rough-transmissive cylindrical shade open at the bottom
// (512 × 190 cells, 194 560 triangles), and a white reflector disk on top.
#pragma once

#include <lumx/bake/luminaire_builder.h>

#include <cmath>

namespace lumx_bench {

inline lumx::bake::LuminaireScene prismatic_pendant() {
  using lumx::bake::Material;
  using lumx::bake::Rgb;
  lumx::bake::LuminaireBuilder b("procedural prismatic pendant");
  Material core;
  core.name = "core";
  core.base_color = Rgb{0.0};
  core.metallic = 0.0;
  core.emissive = Rgb{1.0};
  core.emissive_strength = 2.0e5;
  Material glass;
  glass.name = "bulb glass";
  glass.metallic = 0.0;
  glass.roughness = 0.3;
  glass.transmission = 1.0;
  glass.volume = true;
  glass.thickness_m = 0.002;
  Material shade;
  shade.name = "prismatic shade";
  shade.metallic = 0.0;
  shade.roughness = 0.5;
  shade.transmission = 0.9;
  shade.base_color = Rgb{0.95};
  shade.double_sided = true;
  Material reflector;
  reflector.name = "reflector";
  reflector.metallic = 0.0;
  reflector.roughness = 1.0;
  reflector.base_color = Rgb{0.85};
  reflector.double_sided = true;

  const glm::dmat4 identity(1.0);
  b.begin_part("core", b.add_material(core));
  b.sphere(identity, 0.01, 16, 40);
  b.begin_part("bulb", b.add_material(glass));
  b.sphere(identity, 0.05, 128, 320);
  // Shade: radius 0.15 m with 32 prism ridges around (±3 %), z from −0.15 to +0.15 m, flat facets.
  b.begin_part("shade", b.add_material(shade));
  b.surface(
      [](double u, double v) {
        const double phi = 2 * lumx::kPi * u, r = 0.15 * (1.0 + 0.03 * std::abs(std::sin(32 * phi)));
        return glm::dvec3(r * std::cos(phi), r * std::sin(phi), -0.15 + 0.3 * v);
      },
      nullptr, 512, 190);
  b.begin_part("reflector", b.add_material(reflector));
  b.disk(lumx::bake::LuminaireBuilder::translation({0.0, 0.0, 0.15}), 0.16, 64, false);
  return b.take();
}

}  // namespace lumx_bench
