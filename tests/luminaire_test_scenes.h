// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Luminaires with exact answers, built in code: meshes (disk, sphere with a port, paraboloid, box with holes)
// and the materials whose behaviour is known in closed form (Lambertian without a specular layer, black,
// perfect mirror, smooth glass).
#pragma once

#include <lumx/bake/luminaire.h>
#include <lumx/math/constants.h>

#include <glm/geometric.hpp>

#include <cmath>
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

/// Builds parts: add_part(name, material, triangles as vertex triples with per-vertex normals).
class SceneBuilder {
 public:
  explicit SceneBuilder(std::string name) { scene_.name = std::move(name); }

  std::uint32_t add_material(const Material& m) {
    scene_.materials.push_back(m);
    return std::uint32_t(scene_.materials.size() - 1);
  }

  /// Starts a part; triangles added until the next begin_part belong to it.
  std::uint32_t begin_part(const std::string& name, std::uint32_t material) {
    lumx::bake::Part p;
    p.name = name;
    p.source = "/test/" + name;
    p.material = material;
    p.first_triangle = std::uint32_t(scene_.triangle_count());
    scene_.parts.push_back(p);
    if (scene_.materials[material].emissive_any()) {
      lumx::bake::Emitter e;
      e.kind = lumx::bake::EmitterKind::surface;
      e.name = name;
      e.part = std::uint32_t(scene_.parts.size() - 1);
      scene_.emitters.push_back(e);
    }
    return std::uint32_t(scene_.parts.size() - 1);
  }

  /// Counter-clockwise (a, b, c) seen from the front; normals per vertex.
  void triangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& na,
                const glm::dvec3& nb, const glm::dvec3& nc) {
    for (const auto& [p, n] : {std::pair{a, na}, std::pair{b, nb}, std::pair{c, nc}}) {
      scene_.indices.push_back(std::uint32_t(scene_.positions.size()));
      scene_.positions.emplace_back(p);
      scene_.normals.emplace_back(glm::normalize(n));
    }
    scene_.triangle_part.push_back(std::uint32_t(scene_.parts.size() - 1));
    scene_.parts.back().triangle_count += 1;
  }
  void flat_triangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
    triangle(a, b, c, n, n, n);
  }
  /// Quad a b c d, counter-clockwise from the front.
  void flat_quad(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d) {
    flat_triangle(a, b, c);
    flat_triangle(a, c, d);
  }

  void point_light(const glm::dvec3& position, double intensity_cd) {
    lumx::bake::Emitter e;
    e.kind = lumx::bake::EmitterKind::point;
    e.name = "point";
    e.to_world = glm::dmat4(1.0);
    e.to_world[3] = glm::dvec4(position, 1.0);
    e.intensity_cd = Rgb{intensity_cd};
    scene_.emitters.push_back(e);
  }

  LuminaireScene& scene() { return scene_; }

 private:
  LuminaireScene scene_;
};

/// Disk of radius r at z = 0 facing +z, as a fan of `segments` triangles.
inline void add_disk(SceneBuilder& b, double radius, int segments) {
  for (int i = 0; i < segments; ++i) {
    const double a0 = 2 * lumx::kPi * i / segments, a1 = 2 * lumx::kPi * (i + 1) / segments;
    b.flat_triangle({0, 0, 0}, {radius * std::cos(a0), radius * std::sin(a0), 0},
                    {radius * std::cos(a1), radius * std::sin(a1), 0});
  }
}

/// Exact area of add_disk's polygon.
inline double disk_polygon_area(double radius, int segments) {
  return 0.5 * segments * radius * radius * std::sin(2 * lumx::kPi / segments);
}

/// Sphere of radius r about the origin by latitude/longitude, without the cap θ < port_half_angle around
/// +z (0: closed). Vertex normals are radial; `outward` chooses the front side.
inline void add_sphere(SceneBuilder& b, double radius, int rings, int sectors, double port_half_angle,
                       bool outward) {
  auto point = [&](double theta, double phi) {
    return glm::dvec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  };
  const double theta0 = port_half_angle;
  for (int i = 0; i < rings; ++i) {
    const double t0 = theta0 + (lumx::kPi - theta0) * i / rings, t1 = theta0 + (lumx::kPi - theta0) * (i + 1) / rings;
    for (int j = 0; j < sectors; ++j) {
      const double p0 = 2 * lumx::kPi * j / sectors, p1 = 2 * lumx::kPi * (j + 1) / sectors;
      const glm::dvec3 a = point(t0, p0), bb = point(t1, p0), c = point(t1, p1), d = point(t0, p1);
      // Outward counter-clockwise order is a, b, c, d (θ grows downwards, φ eastwards).
      auto tri = [&](const glm::dvec3& x, const glm::dvec3& y, const glm::dvec3& z) {
        if (glm::length(glm::cross(y - x, z - x)) < 1e-14) return;  // collapsed at a pole
        if (outward)
          b.triangle(radius * x, radius * y, radius * z, x, y, z);
        else
          b.triangle(radius * x, radius * z, radius * y, -x, -z, -y);
      };
      tri(a, bb, c);
      tri(a, c, d);
    }
  }
}

/// Paraboloid mirror z = ρ²/(4f) − f with its focus at the origin, opening towards +z, for ρ ≤ rim_radius;
/// the front (and the normals) face the focus.
inline void add_paraboloid(SceneBuilder& b, double focal_length, double rim_radius, int rings, int sectors) {
  auto point = [&](double rho, double phi) {
    return glm::dvec3(rho * std::cos(phi), rho * std::sin(phi), rho * rho / (4 * focal_length) - focal_length);
  };
  auto normal = [&](double rho, double phi) {  // −∇(z − ρ²/4f) points inwards (towards the axis and up)
    return glm::normalize(glm::dvec3(-rho * std::cos(phi) / (2 * focal_length), -rho * std::sin(phi) / (2 * focal_length), 1.0));
  };
  for (int i = 0; i < rings; ++i) {
    const double r0 = rim_radius * i / rings, r1 = rim_radius * (i + 1) / rings;
    for (int j = 0; j < sectors; ++j) {
      const double p0 = 2 * lumx::kPi * j / sectors, p1 = 2 * lumx::kPi * (j + 1) / sectors;
      // Seen from above (inside), counter-clockwise is increasing φ.
      if (i == 0) {
        b.triangle(point(0, 0), point(r1, p0), point(r1, p1), normal(0, 0), normal(r1, p0), normal(r1, p1));
        continue;
      }
      b.triangle(point(r0, p0), point(r1, p0), point(r1, p1), normal(r0, p0), normal(r1, p0), normal(r1, p1));
      b.triangle(point(r0, p0), point(r1, p1), point(r0, p1), normal(r0, p0), normal(r1, p1), normal(r0, p1));
    }
  }
}

/// Axis-aligned square hole on a cube face: face axis (0 x, 1 y, 2 z), side (+1/−1), centre (u, v) in the
/// face's other two coordinates (in increasing axis order) and half size h.
struct Hole {
  int axis;
  int side;
  double u, v, half;
};

/// Cube [−s, s]³ whose faces face inwards, with square holes, meshed on an n × n grid per face; a cell is
/// left out when its centre lies in a hole, so holes must be aligned with the grid (hole() below does it).
inline void add_box_with_holes(SceneBuilder& b, double s, int n, const std::vector<Hole>& holes) {
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
          for (const Hole& h : holes) {
            if (h.axis != axis || h.side != side) continue;
            const double cu = ua == lo_axis ? uc : vc, cv = ua == lo_axis ? vc : uc;
            if (std::abs(cu - h.u) < h.half && std::abs(cv - h.v) < h.half) in_hole = true;
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

/// Solid angle of the planar triangle (a, b, c) seen from the origin (Van Oosterom & Strackee 1983).
inline double triangle_solid_angle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const double numerator = glm::dot(a, glm::cross(b, c));
  const double denominator = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
  return std::abs(2.0 * std::atan2(numerator, denominator));
}

}  // namespace lumx_test
