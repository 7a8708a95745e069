// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/render/apl_room_background.h — the simplest room a luminaire's appearance is seen against: an
// axis-aligned box of diffuse walls lit directly by one APL level (dissertation 000 §4.5: the room is lit by
// the APLs, the luminaire's own geometry kept out of the illumination), as a render::BackgroundLuminance.
//
// A ray from inside the box meets a wall at x with inward normal n; the wall's luminance is
//   L(x) = ρ E(x, n) / π   (cd/m² per channel; E in lx from apl::irradiance, no shadows, no inter-reflection),
// a Lambertian reflector of albedo ρ. E is tabulated at the centres of an N × N grid of cells per wall and
// interpolated bilinearly (clamped at the wall's edges), so a ray costs a box exit and four lookups; the
// table's error is that of bilinear interpolation of a smooth field, largest right next to the luminaire.
// A ray that starts outside the box, or leaves it through no wall (a zero direction), sees black.
#pragma once

#include <lumx/apl/evaluation.h>
#include <lumx/math/aabb.h>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace render {

struct AplRoomOptions {
  Aabb room;                  ///< the room's inner faces, m (must contain the luminaire for a meaningful picture)
  double albedo = 0.5;        ///< ρ of every wall, floor and ceiling
  int cells_per_wall = 48;    ///< N: irradiance samples per wall edge
};

/// A box room of 3 m × 3 m × 2 m (as the dissertation's set-up, 000 §5.2) around a luminaire box: centred on it
/// horizontally, its ceiling 5 cm above the luminaire's top; grown where the luminaire does not fit.
inline Aabb default_room_around(const Aabb& luminaire, double width_m = 3.0, double depth_m = 3.0,
                                double height_m = 2.0) {
  const glm::dvec3 c = luminaire.center();
  Aabb r;
  const double ceiling = luminaire.hi.z + 0.05;
  r.lo = {std::min(c.x - 0.5 * width_m, luminaire.lo.x - 0.05), std::min(c.y - 0.5 * depth_m, luminaire.lo.y - 0.05),
          std::min(ceiling - height_m, luminaire.lo.z - 0.05)};
  r.hi = {std::max(c.x + 0.5 * width_m, luminaire.hi.x + 0.05), std::max(c.y + 0.5 * depth_m, luminaire.hi.y + 0.05),
          ceiling};
  return r;
}

class AplRoomBackground {
 public:
  /// Tabulates the walls' irradiance from `set.levels[level]`. Throws std::invalid_argument for an invalid
  /// room, albedo outside [0, 1], cells outside [1, 1024] or a missing level.
  AplRoomBackground(const AplSet& set, std::size_t level, const AplRoomOptions& options)
      : room_(options.room), albedo_(options.albedo), n_(options.cells_per_wall) {
    if (!room_.valid() || !(room_.extent().x > 0 && room_.extent().y > 0 && room_.extent().z > 0))
      throw std::invalid_argument("AplRoomBackground: room must be a box with positive extent");
    if (!(albedo_ >= 0.0 && albedo_ <= 1.0)) throw std::invalid_argument("AplRoomBackground: albedo must be in [0, 1]");
    if (n_ < 1 || n_ > 1024) throw std::invalid_argument("AplRoomBackground: cells_per_wall must be in [1, 1024]");
    if (level >= set.levels.size()) throw std::invalid_argument("AplRoomBackground: no such APL level");
    for (int wall = 0; wall < 6; ++wall) {
      std::vector<glm::dvec3>& table = tables_[std::size_t(wall)];
      table.resize(std::size_t(n_) * std::size_t(n_));
      for (int j = 0; j < n_; ++j)
        for (int i = 0; i < n_; ++i) {
          const glm::dvec3 x = point_on(wall, (i + 0.5) / n_, (j + 0.5) / n_);
          table[std::size_t(j) * std::size_t(n_) + std::size_t(i)] =
              irradiance(set, level, glm::vec3(x), glm::vec3(inward_normal(wall))).irradiance;
        }
    }
  }

  /// Luminance seen from `origin` along unit `direction`, cd/m² per channel.
  glm::dvec3 operator()(const glm::dvec3& origin, const glm::dvec3& direction) const {
    double t_exit = std::numeric_limits<double>::infinity();
    int wall = -1;
    for (int a = 0; a < 3; ++a) {
      if (origin[a] < room_.lo[a] || origin[a] > room_.hi[a]) return glm::dvec3(0.0);
      if (direction[a] == 0.0) continue;
      const double t = ((direction[a] > 0 ? room_.hi[a] : room_.lo[a]) - origin[a]) / direction[a];
      if (t < t_exit) {
        t_exit = t;
        wall = 2 * a + (direction[a] > 0 ? 1 : 0);
      }
    }
    if (wall < 0) return glm::dvec3(0.0);
    const glm::dvec3 x = origin + t_exit * direction;
    double u, v;
    wall_coordinates(wall, x, u, v);
    return albedo_ / kPi * lookup(wall, u, v);
  }

  /// Tabulated irradiance (lx per channel) at the wall point with coordinates (u, v) ∈ [0, 1]².
  glm::dvec3 lookup(int wall, double u, double v) const {
    const double fu = std::clamp(u * n_ - 0.5, 0.0, double(n_ - 1)), fv = std::clamp(v * n_ - 0.5, 0.0, double(n_ - 1));
    const int i0 = std::min(int(fu), std::max(n_ - 2, 0)), j0 = std::min(int(fv), std::max(n_ - 2, 0));
    const int i1 = std::min(i0 + 1, n_ - 1), j1 = std::min(j0 + 1, n_ - 1);
    const double a = fu - i0, b = fv - j0;
    const std::vector<glm::dvec3>& t = tables_[std::size_t(wall)];
    auto at = [&](int i, int j) { return t[std::size_t(j) * std::size_t(n_) + std::size_t(i)]; };
    return (1 - a) * (1 - b) * at(i0, j0) + a * (1 - b) * at(i1, j0) + (1 - a) * b * at(i0, j1) + a * b * at(i1, j1);
  }

  const Aabb& room() const { return room_; }

  /// Wall index 2·axis + side (side 1 = the upper face) and its inward normal.
  static glm::dvec3 inward_normal(int wall) {
    glm::dvec3 n(0.0);
    n[wall / 2] = (wall % 2) ? -1.0 : 1.0;
    return n;
  }

 private:
  // The wall's two other axes in increasing order, parametrised over [0, 1]².
  glm::dvec3 point_on(int wall, double u, double v) const {
    const int a = wall / 2, ua = (a + 1) % 3 < (a + 2) % 3 ? (a + 1) % 3 : (a + 2) % 3, va = 3 - a - ua;
    glm::dvec3 x;
    x[a] = (wall % 2) ? room_.hi[a] : room_.lo[a];
    x[ua] = room_.lo[ua] + u * (room_.hi[ua] - room_.lo[ua]);
    x[va] = room_.lo[va] + v * (room_.hi[va] - room_.lo[va]);
    return x;
  }
  void wall_coordinates(int wall, const glm::dvec3& x, double& u, double& v) const {
    const int a = wall / 2, ua = (a + 1) % 3 < (a + 2) % 3 ? (a + 1) % 3 : (a + 2) % 3, va = 3 - a - ua;
    u = (x[ua] - room_.lo[ua]) / (room_.hi[ua] - room_.lo[ua]);
    v = (x[va] - room_.lo[va]) / (room_.hi[va] - room_.lo[va]);
  }

  Aabb room_;
  double albedo_;
  int n_;
  std::array<std::vector<glm::dvec3>, 6> tables_;
};

}  // namespace render
LUMX_NAMESPACE_END
