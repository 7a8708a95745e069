// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/render/room_scene.h — the room's surfaces and occluders as an Embree scene: the first surface an eye
// ray or a particle's straight flight hits, and shadow rays between two points (part of lumx::bake).
//
// Each RoomSurface is two triangles; a hit reports the surface index (room_surfaces() order), the point
// and its (u, v). The luminaire's own geometry is not in this scene: its self-occlusion is in its APL maps
// and in the particles' exits, so the room neither shadows nor reflects light back into it (000 §4.5).
#pragma once

#include <lumx/render/room.h>

#include <glm/vec3.hpp>

#include <memory>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace render {

struct RoomHit {
  int surface = -1;          ///< index into RoomScene::surfaces(), −1 = nothing hit
  double distance_m = 0.0;   ///< along the (unit) direction
  glm::dvec3 point{0.0};     ///< m
  double u = 0.0, v = 0.0;   ///< m, on the surface, clamped to its rectangle
  bool front = true;         ///< hit from the lit side (against the surface's normal)
};

class RoomScene {
 public:
  /// Throws lumx::Error ("room") when invalid_reason(room) is not empty.
  explicit RoomScene(const Room& room);
  ~RoomScene();
  RoomScene(const RoomScene&) = delete;
  RoomScene& operator=(const RoomScene&) = delete;

  const Room& room() const;
  const std::vector<RoomSurface>& surfaces() const;

  /// First surface hit by the ray origin + t · direction (unit), t ∈ (0, max_distance]. Thread-safe.
  RoomHit intersect(const glm::dvec3& origin, const glm::dvec3& direction, double max_distance = 1e30) const;
  /// True when nothing lies strictly between `from` and `to` (both ends excluded by a relative 1e-5 and
  /// 1 µm, so a receiver on a surface does not shadow itself). Thread-safe.
  bool visible(const glm::dvec3& from, const glm::dvec3& to) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace render
LUMX_NAMESPACE_END
