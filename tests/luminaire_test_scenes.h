// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Luminaires with exact answers, built in code: meshes (disk, sphere with a port, paraboloid, box with holes)
// and the materials whose behaviour is known in closed form (Lambertian without a specular layer, black,
// perfect mirror, smooth glass).
#pragma once

#include <lumx/bake/gltf_writer.h>
#include <lumx/bake/luminaire_builder.h>
#include <lumx/math/constants.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace lumx_test {

using lumx::bake::LuminaireScene;
using lumx::bake::Material;
using lumx::bake::Rgb;

inline Material lambertian(double albedo) {
  Material m;
  m.name = "lambertian";
  m.base_color = Rgb{albedo};
  m.metallic = 0.0;
  m.roughness = 1.0;
  m.specular = 0.0;  // no dielectric layer: a pure Lambertian of albedo base_color
  m.double_sided = true;
  return m;
}

inline Material black() {
  Material m = lambertian(0.0);
  m.name = "black";
  return m;
}

inline Material mirror() {
  Material m;
  m.name = "mirror";
  m.base_color = Rgb{1.0};
  m.metallic = 1.0;
  m.roughness = 0.0;
  return m;
}

inline Material smooth_glass(double ior, double attenuation_color, double attenuation_distance_m) {
  Material m;
  m.name = "glass";
  m.base_color = Rgb{1.0};
  m.metallic = 0.0;
  m.roughness = 0.0;
  m.transmission = 1.0;
  m.ior = ior;
  m.volume = true;
  m.thickness_m = 0.01;
  m.attenuation_color = Rgb{attenuation_color};
  m.attenuation_distance_m = attenuation_distance_m;
  return m;
}

inline Material emissive(double luminance_cd_m2, bool double_sided = false) {
  Material m = black();
  m.name = "emitter";
  m.emissive = Rgb{1.0};
  m.emissive_strength = luminance_cd_m2;
  m.double_sided = double_sided;
  return m;
}

/// Luminaires are built with lumx's own builder; the shapes below place them at the origin.
using SceneBuilder = lumx::bake::LuminaireBuilder;

/// Disk of radius r at z = 0 facing +z, as a fan of `segments` triangles.
inline void add_disk(SceneBuilder& b, double radius, int segments) { b.disk(glm::dmat4(1.0), radius, segments); }

/// Exact area of add_disk's polygon.
inline double disk_polygon_area(double radius, int segments) {
  return 0.5 * segments * radius * radius * std::sin(2 * lumx::kPi / segments);
}

/// Sphere of radius r about the origin without the cap θ < port_half_angle around +z (0: closed).
inline void add_sphere(SceneBuilder& b, double radius, int rings, int sectors, double port_half_angle,
                       bool outward) {
  b.sphere(glm::dmat4(1.0), radius, rings, sectors, port_half_angle, outward);
}

/// Paraboloid mirror z = ρ²/(4f) − f with its focus at the origin, opening towards +z, facing the focus.
inline void add_paraboloid(SceneBuilder& b, double focal_length, double rim_radius, int rings, int sectors) {
  b.paraboloid(glm::dmat4(1.0), focal_length, rim_radius, rings, sectors);
}

/// Axis-aligned square hole on a cube face: face axis (0 x, 1 y, 2 z), side (+1/−1), centre (u, v) in the
/// face's other two coordinates (in increasing axis order) and half size h.
struct Hole {
  int axis;
  int side;
  double u, v, half;
};

/// Axis-aligned rectangular hole on a cube face: face axis, side (+1/−1), and its extent [u0, u1] × [v0, v1]
/// in the face's other two coordinates (in increasing axis order).
struct RectHole {
  int axis;
  int side;
  double u0, u1, v0, v1;
};

/// Cube [−s, s]³ whose faces face inwards, with rectangular holes, meshed on an n × n grid per face; a cell
/// is left out when its centre lies in a hole, so holes must be aligned with the grid.
inline void add_box_with_holes(SceneBuilder& b, double s, int n, const std::vector<RectHole>& holes) {
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {-1, 1}) {
      const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
      const int lo_axis = std::min(ua, va);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const double u0 = -s + 2 * s * i / n, u1 = -s + 2 * s * (i + 1) / n;
          const double v0 = -s + 2 * s * j / n, v1 = -s + 2 * s * (j + 1) / n;
          const double uc = 0.5 * (u0 + u1), vc = 0.5 * (v0 + v1);
          bool in_hole = false;
          for (const RectHole& h : holes) {
            if (h.axis != axis || h.side != side) continue;
            const double cu = ua == lo_axis ? uc : vc, cv = ua == lo_axis ? vc : uc;
            if (cu > h.u0 && cu < h.u1 && cv > h.v0 && cv < h.v1) in_hole = true;
          }
          if (in_hole) continue;
          auto P = [&](double u, double v) {
            glm::dvec3 p;
            p[axis] = side * s;
            p[ua] = u;
            p[va] = v;
            return p;
          };
          // (ua, va, axis) is right-handed, so P(u0,v0) P(u1,v0) P(u1,v1) is counter-clockwise seen from +axis;
          // an inward-facing front on the +side face needs the reverse order.
          if (side > 0)
            b.flat_quad(P(u0, v0), P(u0, v1), P(u1, v1), P(u1, v0));
          else
            b.flat_quad(P(u0, v0), P(u1, v0), P(u1, v1), P(u0, v1));
        }
    }
}

/// Cube [−s, s]³ whose faces face inwards, with square holes (Hole: centre and half size).
inline void add_box_with_holes(SceneBuilder& b, double s, int n, const std::vector<Hole>& holes) {
  std::vector<RectHole> rect;
  for (const Hole& h : holes) rect.push_back({h.axis, h.side, h.u - h.half, h.u + h.half, h.v - h.half, h.v + h.half});
  add_box_with_holes(b, s, n, rect);
}

/// Solid angle of the planar triangle (a, b, c) seen from the origin (Van Oosterom & Strackee 1983).
inline double triangle_solid_angle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const double numerator = glm::dot(a, glm::cross(b, c));
  const double denominator = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
  return std::abs(2.0 * std::atan2(numerator, denominator));
}

/// A Lambertian emissive disk (L = 1000 cd/m², r = 5 cm, 64 segments) written as dir/disk.glb: every particle
/// leaves at once.
inline std::filesystem::path write_disk_luminaire(const std::filesystem::path& dir) {
  SceneBuilder b("disk");
  b.begin_part("disk", b.add_material(emissive(1000.0)));
  add_disk(b, 0.05, 64);
  const std::filesystem::path path = dir / "disk.glb";
  lumx::bake::write_gltf_luminaire(b.scene(), path.string());
  return path;
}

/// A point light inside a white Lambertian sphere (r = 10 cm) with a port of half-angle 0.5 rad, written as
/// dir/sphere.glb: particles bounce (segments for the volume) and leave after a random number of bounces.
inline std::filesystem::path write_sphere_luminaire(const std::filesystem::path& dir) {
  SceneBuilder b("sphere");
  b.begin_part("wall", b.add_material(lambertian(0.8)));
  add_sphere(b, 0.1, 16, 32, 0.5, false);
  b.point_light({0.01, 0.0, 0.0}, 1.0);
  const std::filesystem::path path = dir / "sphere.glb";
  lumx::bake::write_gltf_luminaire(b.scene(), path.string());
  return path;
}

/// A white closed sphere (r = 10 cm, `rings` × `sectors`, smooth normals) around a point light, written to
/// `path` as .glb (`binary`) or .gltf with its buffer as a data URI; `albedo` tells two versions apart (the
/// writers' failure and kill tests).
inline void write_white_sphere_luminaire(const std::filesystem::path& path, int rings, int sectors, double albedo,
                                         bool binary) {
  SceneBuilder b("white sphere");
  Material m;
  m.name = "wall";
  m.base_color = Rgb{albedo};
  b.begin_part("wall", b.add_material(m));
  b.sphere(glm::dmat4(1.0), 0.1, rings, sectors, 0.0, true);
  b.point_light({0.0, 0.0, 0.0}, 1.0);
  lumx::bake::GltfWriteOptions o;
  o.binary = binary;
  lumx::bake::write_gltf_luminaire(b.scene(), path.string(), o);
}

}  // namespace lumx_test
