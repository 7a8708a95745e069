// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/bake/path_state.h — what a path through a luminaire carries from one hit to the next, shared by the
// particle tracer (bake/tracer.cpp) and the eye paths of the appearance renderer (render/appearance.cpp):
// the shading frame at a hit, the stack of solids the path is inside, and where its next ray starts.
#pragma once

#include <lumx/version.h>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace bake::detail {

/// Where rays start, for a luminaire whose box is [lo, hi]. Embree intersects in float, so vertices and ray
/// origins are given to it relative to the box centre (`to_embree`): tracing adds no loss of precision for
/// a luminaire far from the origin (its vertices keep their own float precision). A new ray starts ε off the surface it leaves: 10⁻⁵ of the diagonal (5 µm
/// for a 0.5 m luminaire), far above float rounding of the vertices, far below any modelled wall.
struct RayStarts {
  glm::dvec3 centre{0.0};
  double scale = 1e-6;  // m

  RayStarts() = default;
  RayStarts(const glm::dvec3& lo, const glm::dvec3& hi)
      : centre(0.5 * (lo + hi)), scale(1e-5 * std::max(glm::length(hi - lo), 1e-3)) {}

  glm::vec3 to_embree(const glm::dvec3& world) const { return glm::vec3(world - centre); }

  /// ε at p: the scale, or 8 float steps of p's largest coordinate in Embree's frame where that is more.
  double eps(const glm::dvec3& world) const {
    const glm::dvec3 p = world - centre;
    return scale + 8.0 * FLT_EPSILON * std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  }

  /// p moved ε along the geometric normal ng to the side direction d leaves on.
  glm::dvec3 off_surface(const glm::dvec3& p, const glm::dvec3& ng, const glm::dvec3& d) const {
    const double e = eps(p);
    return p + (glm::dot(d, ng) >= 0.0 ? e : -e) * ng;
  }

  /// Start of the next ray after the hit p = origin + t·d_in, leaving along d_out. A reflection steps back
  /// along the arriving segment, which Embree found free of surfaces, to the distance ε from the surface:
  /// at a concave edge an offset along one face's normal stays in the other face's plane (or crosses it,
  /// below 90°), which the next ray could then pass through. A transmission, or a reflection after a
  /// segment too short or too grazing for that, moves along the normal.
  glm::dvec3 after_hit(const glm::dvec3& p, const glm::dvec3& ng, const glm::dvec3& d_in, double t,
                       const glm::dvec3& d_out) const {
    const double e = eps(p);
    const double in = glm::dot(d_in, ng), out = glm::dot(d_out, ng);
    const bool reflected = (in < 0.0) == (out > 0.0);
    if (reflected && std::abs(in) > 0.0 && e / std::abs(in) <= 0.5 * t) return p - (e / std::abs(in)) * d_in;
    return off_surface(p, ng, d_out);
  }
};

/// Orthonormal basis around unit n (Duff et al. 2017, "Building an Orthonormal Basis, Revisited", JCGT 6(1)).
struct Frame {
  glm::dvec3 s, t, n;
  explicit Frame(const glm::dvec3& normal) : n(normal) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double b = n.x * n.y * a;
    s = {1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x};
    t = {b, sign + n.y * n.y * a, -n.y};
  }
  glm::dvec3 to_local(const glm::dvec3& v) const { return {glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)}; }
  glm::dvec3 to_world(const glm::dvec3& v) const { return v.x * s + v.y * t + v.z * n; }
};

/// The volume parts a path is inside, innermost on top (nested solids: a bulb inside a glass globe).
struct MediumStack {
  static constexpr int kCapacity = 8;
  std::uint32_t part[kCapacity];
  int size = 0;
  void push(std::uint32_t p) {
    if (size < kCapacity) part[size++] = p;
  }
  void remove(std::uint32_t p) {
    for (int i = size - 1; i >= 0; --i)
      if (part[i] == p) {
        for (int j = i; j + 1 < size; ++j) part[j] = part[j + 1];
        --size;
        return;
      }
  }
  bool empty() const { return size == 0; }
  std::uint32_t top() const { return part[size - 1]; }
};

/// The unit shading normal at barycentrics (u, v) of triangle `tri`: its vertex normals (3 per triangle in
/// `triangle_normals`, empty for flat shading) interpolated, and turned to the side of the unit geometric
/// normal `ng` when they point against the winding (the winding's side is trusted); `ng` itself when there
/// are none or they cancel.
inline glm::dvec3 shading_normal(const glm::dvec3& ng, const std::vector<glm::vec3>& triangle_normals, std::size_t tri,
                                 double u, double v) {
  if (triangle_normals.empty()) return ng;
  const glm::dvec3 interpolated = (1.0 - u - v) * glm::dvec3(triangle_normals[3 * tri]) +
                                  u * glm::dvec3(triangle_normals[3 * tri + 1]) +
                                  v * glm::dvec3(triangle_normals[3 * tri + 2]);
  const double len = glm::length(interpolated);
  glm::dvec3 ns = len > 0.0 && std::isfinite(len) ? interpolated / len : ng;
  if (glm::dot(ns, ng) < 0.0) ns = -ns;
  return ns;
}

}  // namespace bake::detail
LUMX_NAMESPACE_END
