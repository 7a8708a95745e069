// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// A procedural luminaire of about 280 k triangles for tracing benchmarks: a small emissive core inside a rough
// glass bulb (icosphere, 81 920 triangles) under a ridged, thin, rough-transmissive cylindrical shade open at
// the bottom (512 × 190 cells, 194 560 triangles), and a white reflector disk on top.
#pragma once

#include <lumx/bake/luminaire.h>
#include <lumx/math/constants.h>

#include <glm/geometric.hpp>

#include <array>
#include <cmath>
#include <map>
#include <vector>

namespace lumx_bench {

namespace detail {

inline void add_icosphere(lumx::bake::LuminaireScene& s, const glm::dvec3& centre, double radius, int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<glm::dvec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                               {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p = glm::normalize(p);
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                       {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                                       {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(glm::normalize(v[a] + v[b]));
      return mid[key] = int(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& tri : f) {
      const int a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]), c = midpoint(tri[2], tri[0]);
      next.push_back({tri[0], a, c});
      next.push_back({tri[1], b, a});
      next.push_back({tri[2], c, b});
      next.push_back({a, b, c});
    }
    f.swap(next);
  }
  const auto base = std::uint32_t(s.positions.size());
  for (const auto& p : v) {
    s.positions.emplace_back(centre + radius * p);
    s.normals.emplace_back(p);
  }
  for (const auto& tri : f) {
    for (int k : tri) s.indices.push_back(base + std::uint32_t(k));
    s.triangle_part.push_back(std::uint32_t(s.parts.size() - 1));
    s.parts.back().triangle_count += 1;
  }
}

inline void begin_part(lumx::bake::LuminaireScene& s, const char* name, std::uint32_t material) {
  lumx::bake::Part p;
  p.name = name;
  p.material = material;
  p.first_triangle = std::uint32_t(s.triangle_count());
  s.parts.push_back(p);
}

}  // namespace detail

inline lumx::bake::LuminaireScene prismatic_pendant() {
  using lumx::bake::Material;
  lumx::bake::LuminaireScene s;
  s.name = "procedural prismatic pendant";
  Material core;
  core.name = "core";
  core.base_color = lumx::bake::Rgb{0.0};
  core.metallic = 0.0;
  core.emissive = lumx::bake::Rgb{1.0};
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
  shade.base_color = lumx::bake::Rgb{0.95};
  shade.double_sided = true;
  Material reflector;
  reflector.name = "reflector";
  reflector.metallic = 0.0;
  reflector.roughness = 1.0;
  reflector.base_color = lumx::bake::Rgb{0.85};
  reflector.double_sided = true;
  s.materials = {core, glass, shade, reflector};

  detail::begin_part(s, "core", 0);
  detail::add_icosphere(s, {0, 0, 0}, 0.01, 3);  // 1 280 triangles
  lumx::bake::Emitter e;
  e.kind = lumx::bake::EmitterKind::surface;
  e.name = "core";
  e.part = 0;
  s.emitters.push_back(e);
  detail::begin_part(s, "bulb", 1);
  detail::add_icosphere(s, {0, 0, 0}, 0.05, 6);  // 81 920 triangles

  // Shade: radius 0.15 m with 64 prism ridges around (±3 %), z from −0.15 to +0.15 m, 512 × 190 cells.
  detail::begin_part(s, "shade", 2);
  const int around = 512, up = 190;
  auto shade_point = [&](int i, int j) {
    const double phi = 2 * lumx::kPi * i / around, z = -0.15 + 0.3 * j / up;
    const double r = 0.15 * (1.0 + 0.03 * std::abs(std::sin(32 * phi)));
    return glm::dvec3(r * std::cos(phi), r * std::sin(phi), z);
  };
  for (int i = 0; i < around; ++i)
    for (int j = 0; j < up; ++j) {
      const glm::dvec3 a = shade_point(i, j), b = shade_point(i + 1, j), c = shade_point(i + 1, j + 1),
                       d = shade_point(i, j + 1);
      for (const auto& tri : {std::array<glm::dvec3, 3>{a, b, c}, std::array<glm::dvec3, 3>{a, c, d}}) {
        for (const auto& p : tri) {
          s.indices.push_back(std::uint32_t(s.positions.size()));
          s.positions.emplace_back(p);
        }
        s.triangle_part.push_back(2);
        s.parts.back().triangle_count += 1;
      }
    }
  // Flat shading for the shade: per-vertex normals equal to the facet normal.
  s.normals.resize(s.positions.size());
  for (std::size_t t = s.parts[2].first_triangle; t < s.parts[2].first_triangle + s.parts[2].triangle_count; ++t) {
    const glm::dvec3 a = s.positions[s.indices[3 * t]], b = s.positions[s.indices[3 * t + 1]],
                     c = s.positions[s.indices[3 * t + 2]];
    const glm::vec3 n(glm::normalize(glm::cross(b - a, c - a)));
    for (int k = 0; k < 3; ++k) s.normals[s.indices[3 * t + k]] = n;
  }
  // Reflector disk closing the top (facing down), 64 triangles.
  detail::begin_part(s, "reflector", 3);
  for (int i = 0; i < 64; ++i) {
    const double a0 = 2 * lumx::kPi * i / 64, a1 = 2 * lumx::kPi * (i + 1) / 64;
    const glm::dvec3 p[3] = {{0, 0, 0.15}, {0.16 * std::cos(a1), 0.16 * std::sin(a1), 0.15},
                             {0.16 * std::cos(a0), 0.16 * std::sin(a0), 0.15}};
    for (const auto& q : p) {
      s.indices.push_back(std::uint32_t(s.positions.size()));
      s.positions.emplace_back(q);
      s.normals.emplace_back(0.0f, 0.0f, -1.0f);
    }
    s.triangle_part.push_back(3);
    s.parts.back().triangle_count += 1;
  }
  return s;
}

}  // namespace lumx_bench
