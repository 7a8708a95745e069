// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/render/room.h — the room a luminaire lights in `lumx render room`: an empty axis-aligned box with
// diffuse (Lambertian) surfaces, optional box occluders, and where the luminaire hangs (000 §5.2).
//
// Frame: lumx's world frame (metres, +Z up). The room spans [0, W] × [0, D] × [0, H]; the dissertation's
// room is 3 m × 3 m × 2 m with the luminaire 10 cm from the right wall (000 Appendix A). The luminaire is
// placed by translation only: a point p of the bundle's frame (the frame its APLs, far field and glTF
// geometry share, −Z = nadir) is at p + luminaire_position in the room.
//
// Every surface (the six walls facing inwards, and the six faces of each occluder facing outwards) is a
// rectangle with coordinates (u, v) in metres from one corner, and a grid of square-ish texels on which
// illuminance maps are computed and compared.
#pragma once

#include <lumx/math/bounding_sphere.h>
#include <lumx/render/camera.h>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace render {

/// An axis-aligned box, m.
struct Box {
  glm::dvec3 lo{0.0};
  glm::dvec3 hi{0.0};
};

/// One flat rectangle of the room: x(u, v) = origin + u · u_axis + v · v_axis, u ∈ [0, width], v ∈ [0, height].
struct RoomSurface {
  std::string name;          ///< "floor", "ceiling", "wall x=0", ..., "occluder 1 +z"
  glm::dvec3 origin{0.0};    ///< m, the corner at (u, v) = (0, 0)
  glm::dvec3 u_axis{1, 0, 0};  ///< unit
  glm::dvec3 v_axis{0, 1, 0};  ///< unit
  glm::dvec3 normal{0, 0, 1};  ///< unit, the lit side (into the room for walls, outwards for occluders)
  double width_m = 0.0;      ///< extent along u
  double height_m = 0.0;     ///< extent along v
  int texels_u = 1;          ///< texel grid for illuminance maps
  int texels_v = 1;

  glm::dvec3 point(double u, double v) const { return origin + u * u_axis + v * v_axis; }
  glm::dvec2 uv(const glm::dvec3& x) const;
  /// Centre of texel (iu, iv), m in (u, v).
  glm::dvec2 texel_centre(int iu, int iv) const {
    return {(iu + 0.5) * width_m / texels_u, (iv + 0.5) * height_m / texels_v};
  }
  double texel_area_m2() const { return width_m * height_m / (double(texels_u) * double(texels_v)); }
  std::size_t texel_count() const { return std::size_t(texels_u) * std::size_t(texels_v); }
};

struct Room {
  glm::dvec3 size_m{3.0, 3.0, 2.0};  ///< W (x), D (y), H (z): the dissertation's empty room
  /// Diffuse reflectance of every surface, used for luminance L = ρ E / π (direct light only, so it scales
  /// pictures, not illuminance). 0.5: a mid-grey room.
  double albedo = 0.5;
  glm::dvec3 luminaire_position_m{0.0};  ///< where the bundle's frame origin sits in the room
  std::vector<Box> occluders;            ///< e.g. a table below the luminaire, for shadows and penumbrae
  double texel_size_m = 0.05;            ///< illuminance maps: texels at most this wide (5 cm)
};

/// Empty when the room is usable; otherwise why not (for a located error): sizes finite and positive,
/// albedo in [0, 1], occluders non-empty and inside the room, the luminaire position inside it.
std::string invalid_reason(const Room& room);

/// The room's surfaces: floor, ceiling, walls x = 0, x = W, y = 0, y = D (normals into the room), then
/// each occluder's faces −x, +x, −y, +y, −z, +z (normals outwards).
std::vector<RoomSurface> room_surfaces(const Room& room);

/// Where the bundle's frame origin hangs by default: its bounding sphere (centre c, radius r, in the
/// bundle's frame) 10 cm from the right wall (x = W) and 10 cm below the ceiling, at mid-depth
/// (000 Appendix A: "10 cm away from the right wall"). A sphere too large for that is centred instead.
glm::dvec3 default_luminaire_position(const glm::dvec3& room_size_m, const BoundingSphere& bounds);

/// The default view: from near the left wall (x = 0.25 W, y = 0.15 D, z = 0.55 H) towards the right wall
/// below the luminaire, so the wall near it, the floor and the ceiling are in the picture; 75° vertical
/// field, 480 × 320 pixels.
PinholeCamera default_room_camera(const Room& room);

}  // namespace render
LUMX_NAMESPACE_END
