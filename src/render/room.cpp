// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/render/room.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

LUMX_NAMESPACE_BEGIN
namespace render {

glm::dvec2 RoomSurface::uv(const glm::dvec3& x) const {
  const glm::dvec3 d = x - origin;
  return {glm::dot(d, u_axis), glm::dot(d, v_axis)};
}

namespace {

bool finite3(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::string vec_text(const glm::dvec3& v) {
  char s[96];
  std::snprintf(s, sizeof s, "(%g, %g, %g)", v.x, v.y, v.z);
  return s;
}

RoomSurface make_surface(std::string name, const glm::dvec3& origin, int u_axis, int v_axis, const glm::dvec3& normal,
                         const glm::dvec3& extent, double texel) {
  RoomSurface s;
  s.name = std::move(name);
  s.origin = origin;
  s.u_axis = glm::dvec3(0.0);
  s.u_axis[u_axis] = 1.0;
  s.v_axis = glm::dvec3(0.0);
  s.v_axis[v_axis] = 1.0;
  s.normal = normal;
  s.width_m = extent[u_axis];
  s.height_m = extent[v_axis];
  s.texels_u = std::max(1, int(std::ceil(s.width_m / texel - 1e-9)));
  s.texels_v = std::max(1, int(std::ceil(s.height_m / texel - 1e-9)));
  return s;
}

}  // namespace

std::string invalid_reason(const Room& room) {
  const glm::dvec3& s = room.size_m;
  if (!finite3(s) || !(s.x > 0 && s.y > 0 && s.z > 0) || std::max({s.x, s.y, s.z}) > 1e4)
    return "room size must be three finite lengths in (0, 10000] m, got " + vec_text(s);
  if (!(room.albedo >= 0.0 && room.albedo <= 1.0)) return "albedo must be in [0, 1]";
  if (!(room.texel_size_m > 0.0) || !std::isfinite(room.texel_size_m)) return "texel size must be a positive length";
  const double texels = (s.x * s.y + s.y * s.z + s.x * s.z) * 2.0 / (room.texel_size_m * room.texel_size_m);
  if (texels > 5e7) return "texel size too small for the room (more than 5e7 texels)";
  const glm::dvec3& p = room.luminaire_position_m;
  if (!finite3(p) || p.x <= 0 || p.y <= 0 || p.z <= 0 || p.x >= s.x || p.y >= s.y || p.z >= s.z)
    return "luminaire position " + vec_text(p) + " m is not inside the room " + vec_text(s) + " m";
  for (std::size_t i = 0; i < room.occluders.size(); ++i) {
    const Box& b = room.occluders[i];
    const std::string name = "occluder " + std::to_string(i + 1);
    if (!finite3(b.lo) || !finite3(b.hi) || !(b.lo.x < b.hi.x && b.lo.y < b.hi.y && b.lo.z < b.hi.z))
      return name + " must have lo < hi on every axis, got " + vec_text(b.lo) + " " + vec_text(b.hi);
    if (b.lo.x < 0 || b.lo.y < 0 || b.lo.z < 0 || b.hi.x > s.x || b.hi.y > s.y || b.hi.z > s.z)
      return name + " " + vec_text(b.lo) + " " + vec_text(b.hi) + " is not inside the room";
  }
  return {};
}

std::vector<RoomSurface> room_surfaces(const Room& room) {
  const glm::dvec3 s = room.size_m;
  const double t = room.texel_size_m;
  std::vector<RoomSurface> out;
  out.push_back(make_surface("floor", {0, 0, 0}, 0, 1, {0, 0, 1}, s, t));
  out.push_back(make_surface("ceiling", {0, 0, s.z}, 0, 1, {0, 0, -1}, s, t));
  out.push_back(make_surface("wall x=0", {0, 0, 0}, 1, 2, {1, 0, 0}, s, t));
  out.push_back(make_surface("wall x=W", {s.x, 0, 0}, 1, 2, {-1, 0, 0}, s, t));
  out.push_back(make_surface("wall y=0", {0, 0, 0}, 0, 2, {0, 1, 0}, s, t));
  out.push_back(make_surface("wall y=D", {0, s.y, 0}, 0, 2, {0, -1, 0}, s, t));
  static const char* kSide[] = {"-x", "+x", "-y", "+y", "-z", "+z"};
  for (std::size_t i = 0; i < room.occluders.size(); ++i) {
    const Box& b = room.occluders[i];
    const glm::dvec3 e = b.hi - b.lo;
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        const int ua = axis == 0 ? 1 : 0, va = axis == 2 ? 1 : 2;
        glm::dvec3 origin = b.lo, normal(0.0);
        if (side == 1) origin[axis] = b.hi[axis];
        normal[axis] = side == 1 ? 1.0 : -1.0;
        out.push_back(make_surface("occluder " + std::to_string(i + 1) + " " + kSide[2 * axis + side], origin, ua, va,
                                   normal, e, t));
      }
  }
  return out;
}

glm::dvec3 default_luminaire_position(const glm::dvec3& size, const BoundingSphere& bounds) {
  const double r = std::max(0.0, bounds.radius), gap = 0.1;
  glm::dvec3 centre(size.x - gap - r, 0.5 * size.y, size.z - gap - r);
  if (centre.x < 0.5 * size.x) centre.x = 0.5 * size.x;
  if (centre.z < 0.5 * size.z) centre.z = 0.5 * size.z;
  return centre - bounds.center;
}

PinholeCamera default_room_camera(const Room& room) {
  const glm::dvec3 s = room.size_m;
  PinholeCamera c;
  c.position = {0.25 * s.x, 0.15 * s.y, 0.55 * s.z};
  c.look_at = {s.x, 0.6 * s.y, 0.4 * s.z};
  c.up = {0, 0, 1};
  c.vertical_fov_deg = 75.0;
  c.width = 480;
  c.height = 320;
  return c;
}

}  // namespace render
LUMX_NAMESPACE_END
