// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/luminaire_builder.h — luminaires built in code: parts of triangles with a material, the common shapes
// of luminaire parts (disks, spheres with a port, cylinders and tubes, boxes, paraboloid reflectors, ridged
// sheets) placed by a frame, and punctual lights. A part whose material is emissive becomes a surface emitter.
// Counter-clockwise seen from the front, as in glTF; shapes face outwards (or inwards when asked), with
// smooth vertex normals where the surface is curved. Write the result with lumx/bake/gltf_writer.h.
#pragma once

#include <lumx/bake/luminaire.h>
#include <lumx/math/constants.h>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>

#include <cmath>
#include <functional>
#include <string>
#include <utility>

LUMX_NAMESPACE_BEGIN
namespace bake {

class LuminaireBuilder {
 public:
  explicit LuminaireBuilder(std::string name) { scene_.name = std::move(name); }

  std::uint32_t add_material(const Material& m) {
    scene_.materials.push_back(m);
    return std::uint32_t(scene_.materials.size() - 1);
  }

  /// Starts a part: triangles added until the next begin_part belong to it.
  std::uint32_t begin_part(const std::string& name, std::uint32_t material) {
    Part p;
    p.name = name;
    p.source = "/parts/" + std::to_string(scene_.parts.size());
    p.material = material;
    p.first_triangle = std::uint32_t(scene_.triangle_count());
    scene_.parts.push_back(p);
    if (scene_.materials.at(material).emissive_any()) {
      Emitter e;
      e.kind = EmitterKind::surface;
      e.name = name;
      e.part = std::uint32_t(scene_.parts.size() - 1);
      scene_.emitters.push_back(e);
    }
    return std::uint32_t(scene_.parts.size() - 1);
  }

  /// Triangle a b c (counter-clockwise from the front) with vertex normals, in world space (m).
  void triangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& na,
                const glm::dvec3& nb, const glm::dvec3& nc) {
    if (scene_.parts.empty()) throw std::logic_error("LuminaireBuilder: begin_part before adding triangles");
    const std::pair<glm::dvec3, glm::dvec3> corners[3] = {{a, na}, {b, nb}, {c, nc}};
    for (const auto& [p, n] : corners) {
      scene_.indices.push_back(std::uint32_t(scene_.positions.size()));
      scene_.positions.emplace_back(p);
      scene_.normals.emplace_back(glm::normalize(n));
    }
    scene_.triangle_part.push_back(std::uint32_t(scene_.parts.size() - 1));
    scene_.parts.back().triangle_count += 1;
  }
  void flat_triangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 n = glm::cross(b - a, c - a);
    if (!(glm::length(n) > 0.0)) return;  // collapsed (a pole, a zero-width ring)
    triangle(a, b, c, n, n, n);
  }
  /// Quad a b c d, counter-clockwise from the front (split along a–c).
  void flat_quad(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d) {
    flat_triangle(a, b, c);
    flat_triangle(a, c, d);
  }

  /// A parametric surface p(u, v), u, v ∈ [0, 1], meshed on nu × nv cells; counter-clockwise order is
  /// p(u0,v0) p(u1,v0) p(u1,v1), so ∂p/∂u × ∂p/∂v is the front. normal(u, v) gives smooth normals (front side);
  /// an empty `normal` gives flat facets (prisms, ridged sheets).
  void surface(const std::function<glm::dvec3(double, double)>& p,
               const std::function<glm::dvec3(double, double)>& normal, int nu, int nv) {
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        const double u0 = double(i) / nu, u1 = double(i + 1) / nu, v0 = double(j) / nv, v1 = double(j + 1) / nv;
        smooth_triangle(p, normal, {u0, v0}, {u1, v0}, {u1, v1});
        smooth_triangle(p, normal, {u0, v0}, {u1, v1}, {u0, v1});
      }
  }

  /// Disk of radius r in the frame's z = 0 plane, facing +z (−z when !up), as a fan of `segments`.
  void disk(const glm::dmat4& frame, double radius, int segments, bool up = true) {
    const glm::dvec3 c = point(frame, {0, 0, 0});
    for (int i = 0; i < segments; ++i) {
      const glm::dvec3 p0 = point(frame, radius * around(double(i) / segments));
      const glm::dvec3 p1 = point(frame, radius * around(double(i + 1) / segments));
      if (up)
        flat_triangle(c, p0, p1);
      else
        flat_triangle(c, p1, p0);
    }
  }

  /// Sphere of radius r about the frame's origin by latitude (θ from +z) and longitude, without the cap
  /// θ < port_half_angle (0: closed); radial normals, facing outwards or inwards.
  void sphere(const glm::dmat4& frame, double radius, int rings, int sectors, double port_half_angle = 0.0,
              bool outward = true) {
    const double t0 = port_half_angle;
    auto dir = [&](double u, double v) {  // u: longitude, v: latitude from the pole down
      if (v >= 1.0) return glm::dvec3(0.0, 0.0, -1.0);  // the pole exactly, whatever the longitude
      const double th = t0 + (kPi - t0) * v;
      return std::sin(th) * around(u) + glm::dvec3(0.0, 0.0, std::cos(th));
    };
    // ∂/∂u × ∂/∂v points inwards for this parametrisation; swap the roles for the outward front.
    if (outward)
      surface([&](double u, double v) { return point(frame, radius * dir(v, u)); },
              [&](double u, double v) { return normal(frame, dir(v, u)); }, rings, sectors);
    else
      surface([&](double u, double v) { return point(frame, radius * dir(u, v)); },
              [&](double u, double v) { return -normal(frame, dir(u, v)); }, sectors, rings);
  }

  /// Cylinder wall of radius r along the frame's z from 0 to height, facing outwards (or inwards), with
  /// optional flat caps facing away from the inside (closed tube: a solid for volume materials).
  void cylinder(const glm::dmat4& frame, double radius, double height, int sectors, int rows = 1,
                bool outward = true, bool caps = false) {
    auto p = [&](double u, double v) { return point(frame, radius * around(u) + glm::dvec3(0.0, 0.0, height * v)); };
    auto n = [&](double u, double) { return normal(frame, around(u)); };
    if (outward)
      surface(p, n, sectors, rows);
    else
      surface([&](double u, double v) { return p(v, u); }, [&](double u, double v) { return -n(v, u); }, rows,
              sectors);
    if (caps) {
      disk(frame * translation({0, 0, height}), radius, sectors, outward);
      disk(frame, radius, sectors, !outward);
    }
  }

  /// Axis-aligned box of half sizes h about the frame's origin, faces outwards (or inwards).
  void box(const glm::dmat4& frame, const glm::dvec3& h, bool outward = true) {
    for (int axis = 0; axis < 3; ++axis)
      for (int side : {-1, 1}) {
        const int a = (axis + 1) % 3, b = (axis + 2) % 3;  // (a, b, axis) right-handed
        auto corner = [&](double s, double t) {
          glm::dvec3 q;
          q[axis] = side * h[axis];
          q[a] = s * h[a];
          q[b] = t * h[b];
          return point(frame, q);
        };
        const bool ccw_from_plus = (side > 0) == outward;
        if (ccw_from_plus)
          flat_quad(corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1));
        else
          flat_quad(corner(-1, -1), corner(-1, 1), corner(1, 1), corner(1, -1));
      }
  }

  /// Paraboloid z = ρ²/(4f) − f (focus at the frame's origin, opening towards +z) for ρ ≤ rim, front (and
  /// normals) facing the focus.
  void paraboloid(const glm::dmat4& frame, double focal_length, double rim_radius, int rings, int sectors) {
    auto p = [&](double u, double v) {  // u: radius fraction, v: angle fraction
      const double rho = rim_radius * u;
      return point(frame, rho * around(v) + glm::dvec3(0.0, 0.0, rho * rho / (4 * focal_length) - focal_length));
    };
    auto n = [&](double u, double v) {
      const double rho = rim_radius * u;
      return normal(frame, -rho / (2 * focal_length) * around(v) + glm::dvec3(0.0, 0.0, 1.0));
    };
    surface(p, n, rings, sectors);
  }

  void point_light(const glm::dvec3& position, const Rgb& intensity_cd, const std::string& name = "point") {
    Emitter e;
    e.kind = EmitterKind::point;
    e.name = name;
    e.to_world = translation(position);
    e.intensity_cd = intensity_cd;
    scene_.emitters.push_back(e);
  }

  void point_light(const glm::dvec3& position, double intensity_cd) { point_light(position, Rgb{intensity_cd}); }

  LuminaireScene& scene() { return scene_; }
  LuminaireScene take() { return std::move(scene_); }

  static glm::dmat4 translation(const glm::dvec3& t) {
    glm::dmat4 m(1.0);
    m[3] = glm::dvec4(t, 1.0);
    return m;
  }

 private:
  /// (cos 2πf, sin 2πf, 0), with f = 1 giving exactly f = 0's point so that seams and fans weld.
  static glm::dvec3 around(double f) {
    const double a = 2 * kPi * (f >= 1.0 ? 0.0 : f);
    return {std::cos(a), std::sin(a), 0.0};
  }
  static glm::dvec3 point(const glm::dmat4& frame, const glm::dvec3& p) { return glm::dvec3(frame * glm::dvec4(p, 1.0)); }
  static glm::dvec3 normal(const glm::dmat4& frame, const glm::dvec3& n) {
    return glm::normalize(glm::transpose(glm::inverse(glm::dmat3(frame))) * n);
  }
  void smooth_triangle(const std::function<glm::dvec3(double, double)>& p,
                       const std::function<glm::dvec3(double, double)>& normal_at, glm::dvec2 a, glm::dvec2 b,
                       glm::dvec2 c) {
    const glm::dvec3 pa = p(a.x, a.y), pb = p(b.x, b.y), pc = p(c.x, c.y);
    if (!(glm::length(glm::cross(pb - pa, pc - pa)) > 1e-14 * (1.0 + glm::length(pa)))) return;  // collapsed
    if (!normal_at) {
      flat_triangle(pa, pb, pc);
      return;
    }
    triangle(pa, pb, pc, normal_at(a.x, a.y), normal_at(b.x, b.y), normal_at(c.x, c.y));
  }

  LuminaireScene scene_;
};

}  // namespace bake
LUMX_NAMESPACE_END
