// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Writes four procedural luminaires as glTF 2.0, modelled on the optical structures near-field representations
// are judged on (dissertation 000 §5): light hidden behind refractors, among reflectors, in boxes and glass.
//
//   sample_luminaires OUT_DIR
//     troffer.glb        three T8 tubes (3 × 3000 lm) in a white housing behind a prismatic refractor, 1.2 × 0.6 m
//     pendant.glb        an "artichoke": one opal bulb (1500 lm) among 72 copper leaves in six tiers
//                        (meshes Draco-compressed: KHR_draco_mesh_compression)
//     shape_sorter.glb   four coloured emitters in a white box with a circle, a square, a triangle and a star cut out
//     chandelier.glb     five candle emitters under rough-glass shades on brass arms around a glass stem
//
// Every luminaire is in metres with +z up and its optical centre near the origin; luminances are chosen so
// each emitter's flux (π L A) is the stated one.
#include <lumx/bake/gltf_writer.h>
#include <lumx/bake/luminaire_builder.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cstdio>
#include <filesystem>
#include <string>

namespace {

using lumx::bake::LuminaireBuilder;
using lumx::bake::Material;
using lumx::bake::Rgb;
constexpr double kPi = lumx::kPi;

Material paint(const char* name, double reflectance) {
  Material m;
  m.name = name;
  m.base_color = Rgb{reflectance};
  m.metallic = 0.0;
  m.roughness = 0.6;
  m.double_sided = true;
  return m;
}

Material metal(const char* name, const Rgb& f0, double roughness) {
  Material m;
  m.name = name;
  m.base_color = f0;
  m.metallic = 1.0;
  m.roughness = roughness;
  m.double_sided = true;
  return m;
}

/// Thin-walled clear or frosted plastic/glass (no bending: sheets and shades).
Material thin_glass(const char* name, double roughness, double ior) {
  Material m;
  m.name = name;
  m.metallic = 0.0;
  m.roughness = roughness;
  m.transmission = 1.0;
  m.ior = ior;
  m.double_sided = true;
  return m;
}

/// A Lambertian emitter whose flux over `area_m2` (one-sided) is `flux_lm`: L = Φ / (π A).
Material emitter(const char* name, double flux_lm, double area_m2, const Rgb& colour = Rgb{1.0}) {
  Material m;
  m.name = name;
  m.base_color = Rgb{0.5};
  m.metallic = 0.0;
  m.roughness = 1.0;
  m.emissive = colour;
  m.emissive_strength = flux_lm / (kPi * area_m2 * lumx::bake::luminance(colour));
  return m;
}

glm::dmat4 at(const glm::dvec3& p) { return LuminaireBuilder::translation(p); }

lumx::bake::LuminaireScene troffer() {
  LuminaireBuilder b("troffer");
  const double lx = 0.6, ly = 0.3, depth = 0.08;  // half length, half width, housing depth (m)
  // Housing: back panel (facing down) and four side walls (facing in), white paint.
  b.begin_part("housing", b.add_material(paint("white paint", 0.9)));
  b.flat_quad({-lx, -ly, depth}, {-lx, ly, depth}, {lx, ly, depth}, {lx, -ly, depth});
  b.flat_quad({-lx, -ly, 0}, {lx, -ly, 0}, {lx, -ly, depth}, {-lx, -ly, depth});
  b.flat_quad({lx, ly, 0}, {-lx, ly, 0}, {-lx, ly, depth}, {lx, ly, depth});
  b.flat_quad({-lx, ly, 0}, {-lx, -ly, 0}, {-lx, -ly, depth}, {-lx, ly, depth});
  b.flat_quad({lx, -ly, 0}, {lx, ly, 0}, {lx, ly, depth}, {lx, -ly, depth});
  // Three T8 tubes (26 mm, 1.14 m) along x, 3000 lm each.
  const double r = 0.013, length = 1.14;
  const double area = 2 * kPi * r * length + 2 * kPi * r * r;
  const auto tube = b.add_material(emitter("T8 phosphor", 3000.0, area));
  const glm::dmat4 along_x = glm::rotate(glm::dmat4(1.0), kPi / 2, glm::dvec3(0, 1, 0));
  for (int k = -1; k <= 1; ++k) {
    b.begin_part("tube " + std::to_string(k + 2), tube);
    b.cylinder(at({-length / 2, 0.15 * k, 0.045}) * along_x, r, length, 48, 1, true, true);
  }
  // Prismatic refractor at z = 0: 60 ridges along x, 10 mm pitch, 4 mm high, pointing into the housing.
  b.begin_part("refractor", b.add_material(thin_glass("prismatic acrylic", 0.1, 1.49)));
  const int ridges = 60;
  for (int i = 0; i < ridges; ++i) {
    const double y0 = -ly + 2 * ly * i / ridges, y1 = -ly + 2 * ly * (i + 1) / ridges, ym = 0.5 * (y0 + y1);
    b.flat_quad({-lx, y0, 0}, {lx, y0, 0}, {lx, ym, 0.004}, {-lx, ym, 0.004});
    b.flat_quad({-lx, ym, 0.004}, {lx, ym, 0.004}, {lx, y1, 0}, {-lx, y1, 0});
  }
  return b.take();
}

lumx::bake::LuminaireScene pendant() {
  LuminaireBuilder b("pendant");
  const double bulb_r = 0.03;
  b.begin_part("bulb", b.add_material(emitter("opal bulb", 1500.0, 4 * kPi * bulb_r * bulb_r)));
  b.sphere(glm::dmat4(1.0), bulb_r, 24, 48);
  // Six tiers of twelve leaves: curved copper plates, each tilted outwards and down, staggered per tier.
  b.begin_part("leaves", b.add_material(metal("copper", Rgb{0.955, 0.638, 0.538}, 0.35)));
  for (int tier = 0; tier < 6; ++tier) {
    const double z = 0.12 - 0.045 * tier, radius = 0.05 + 0.018 * (tier < 3 ? tier : 5 - tier) + 0.02;
    for (int k = 0; k < 12; ++k) {
      const double phi = 2 * kPi * (k + 0.5 * (tier % 2)) / 12;
      const glm::dmat4 frame = glm::rotate(at({0, 0, z}), phi, glm::dvec3(0, 0, 1));
      // Leaf in its own frame: x outwards from the axis, bent about y, 0.07 wide and 0.09 long.
      b.surface(
          [&](double u, double v) {
            const double s = (u - 0.5) * 0.07, t = v * 0.09;
            const glm::dvec3 p{radius + 0.35 * t + 0.6 * s * s, s, -t};
            return glm::dvec3(frame * glm::dvec4(p, 1.0));
          },
          [&](double u, double) {
            const double s = (u - 0.5) * 0.07;
            return glm::normalize(glm::dmat3(frame) * glm::dvec3(-1.0, 1.2 * s, -0.35));
          },
          6, 8);
    }
  }
  return b.take();
}

lumx::bake::LuminaireScene shape_sorter() {
  LuminaireBuilder b("shape sorter");
  const double h = 0.15;  // half size of the box
  const int n = 48;       // cells per face side
  auto inside_shape = [](int face, double u, double v) {  // u, v in [−1, 1] on the face
    switch (face) {
      case 0: return u * u + v * v < 0.25;                                  // circle
      case 1: return std::abs(u) < 0.4 && std::abs(v) < 0.4;                // square
      case 2: return v > -0.4 && v < 0.5 - 1.6 * std::abs(u) && v < 0.5;     // triangle
      case 3: {                                                              // five-pointed star
        const double r = std::hypot(u, v), a = std::atan2(v, u);
        const double k = std::fmod(a + 10 * kPi + kPi / 2, 2 * kPi / 5) / (2 * kPi / 5);
        return r < 0.22 + 0.3 * std::abs(1 - 2 * k);
      }
      default: return false;
    }
  };
  b.begin_part("box", b.add_material(paint("white box", 0.85)));
  int face = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {-1, 1}) {
      const int a = (axis + 1) % 3, c = (axis + 2) % 3;
      const int shape = axis == 2 ? -1 : face++;  // the four side walls carry the shapes; top and bottom are whole
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const double u0 = -1 + 2.0 * i / n, u1 = -1 + 2.0 * (i + 1) / n, v0 = -1 + 2.0 * j / n, v1 = -1 + 2.0 * (j + 1) / n;
          if (inside_shape(shape, 0.5 * (u0 + u1), 0.5 * (v0 + v1))) continue;
          auto P = [&](double u, double v) {
            glm::dvec3 p;
            p[axis] = side * h;
            p[a] = u * h;
            p[c] = v * h;
            return p;
          };
          if (side > 0)  // faces inwards
            b.flat_quad(P(u0, v0), P(u0, v1), P(u1, v1), P(u1, v0));
          else
            b.flat_quad(P(u0, v0), P(u1, v0), P(u1, v1), P(u0, v1));
        }
    }
  const Rgb colours[4] = {{1.0, 0.1, 0.1}, {0.1, 1.0, 0.1}, {0.15, 0.2, 1.0}, {1.0, 0.85, 0.1}};
  const glm::dvec3 where[4] = {{0.06, 0.05, -0.05}, {-0.06, 0.04, 0.02}, {0.03, -0.07, 0.06}, {-0.05, -0.05, -0.04}};
  const double r = 0.012;
  for (int k = 0; k < 4; ++k) {
    b.begin_part("emitter " + std::to_string(k + 1), b.add_material(emitter("coloured emitter", 100.0, 4 * kPi * r * r, colours[k])));
    b.sphere(at(where[k]), r, 12, 24);
  }
  return b.take();
}

lumx::bake::LuminaireScene chandelier() {
  LuminaireBuilder b("chandelier");
  const auto brass = b.add_material(metal("brass", Rgb{0.91, 0.78, 0.42}, 0.25));
  const auto frosted = b.add_material(thin_glass("frosted glass", 0.45, 1.5));
  Material stem_glass = thin_glass("clear glass stem", 0.02, 1.5);
  stem_glass.volume = true;
  stem_glass.double_sided = false;
  stem_glass.thickness_m = 0.03;
  stem_glass.attenuation_color = Rgb{0.92, 0.95, 0.93};
  stem_glass.attenuation_distance_m = 0.1;
  const double candle_r = 0.008;
  const auto candle = b.add_material(emitter("candle bulb", 250.0, 4 * kPi * candle_r * candle_r, Rgb{1.0, 0.85, 0.65}));
  b.begin_part("stem", b.add_material(stem_glass));
  b.cylinder(at({0, 0, -0.1}), 0.02, 0.3, 32, 4, true, true);
  for (int k = 0; k < 5; ++k) {
    const double phi = 2 * kPi * k / 5;
    const glm::dvec3 tip{0.22 * std::cos(phi), 0.22 * std::sin(phi), 0.0};
    // Arm: a brass rod from the stem to under the candle.
    const glm::dvec3 from{0.02 * std::cos(phi), 0.02 * std::sin(phi), -0.05};
    const glm::dvec3 axis = glm::normalize(tip - glm::dvec3(0, 0, 0.02) - from);
    const glm::dvec3 z{0, 0, 1};
    const glm::dmat4 rod = at(from) * glm::dmat4(glm::dmat3(glm::normalize(glm::cross(axis, z)),
                                                            glm::cross(axis, glm::normalize(glm::cross(axis, z))), axis));
    b.begin_part("arm " + std::to_string(k + 1), brass);
    b.cylinder(rod, 0.005, glm::length(tip - glm::dvec3(0, 0, 0.02) - from), 12, 1, true, true);
    b.begin_part("candle " + std::to_string(k + 1), candle);
    b.sphere(at(tip + glm::dvec3(0, 0, 0.02)), candle_r, 10, 20);
    // Shade: a frosted bell (a sphere open at the bottom) around the candle.
    b.begin_part("shade " + std::to_string(k + 1), frosted);
    b.sphere(at(tip + glm::dvec3(0, 0, 0.035)) * glm::rotate(glm::dmat4(1.0), kPi, glm::dvec3(1, 0, 0)), 0.045, 12,
             32, 0.9, true);
  }
  return b.take();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  try {
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    const std::pair<const char*, lumx::bake::LuminaireScene> all[] = {
        {"troffer.glb", troffer()}, {"pendant.glb", pendant()}, {"shape_sorter.glb", shape_sorter()},
        {"chandelier.glb", chandelier()}};
    for (const auto& [name, scene] : all) {
      lumx::bake::GltfWriteOptions options;
      options.draco = std::string(name) == "pendant.glb";
      lumx::bake::write_gltf_luminaire(scene, (dir / name).string(), options);
      double flux = 0.0;
      for (const auto& e : scene.emitters) flux += lumx::bake::emitter_flux_lm(scene, e);
      std::printf("%-18s %6zu triangles, %zu parts, %zu emitters, %.0f lm\n", (dir / name).string().c_str(),
                  scene.triangle_count(), scene.parts.size(), scene.emitters.size(), flux);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sample_luminaires: %s\n", e.what());
    return 1;
  }
  return 0;
}
