// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The representation seam in a room (the bake component): the tests' own isotropic point light
// (toy_light_model.h) lit through render::ModelRoomIlluminance, shadow rays and all.
#include "toy_light_model.h"

#include <lumx/render/room_render.h>

#include <gtest/gtest.h>

#include <cmath>

namespace {

using lumx_test::IsotropicPoint;
using lumx_test::kPi;
constexpr double kFlux = 1000.0;

// A box below the light: every texel of the room lit through ModelRoomIlluminance gets the toy's exact
// E = I cosθ / r², or 0 where the box stands between (decided here by a slab test, not by the renderer).
TEST(LightModelSeam, TheToyLightsARoomThroughTheGenericIlluminance) {
  lumx::render::Room room;
  room.luminaire_position_m = {1.5, 1.4, 1.6};
  room.texel_size_m = 0.1;
  const lumx::render::Box box{{1.2, 1.1, 0.0}, {1.8, 1.7, 0.7}};
  room.occluders.push_back(box);
  const lumx::render::RoomScene scene(room);
  const IsotropicPoint light(glm::dvec3(0.0), kFlux);  // at the bundle frame's origin
  const lumx::render::ModelRoomIlluminance lit(light, room.luminaire_position_m, scene);
  const lumx::render::SurfaceMaps maps = lumx::render::illuminance_maps(scene, lit, 2);
  const glm::dvec3 p = room.luminaire_position_m;
  std::size_t shadowed = 0, compared = 0;
  for (std::size_t s = 0; s < scene.surfaces().size(); ++s) {
    const lumx::render::RoomSurface& surface = scene.surfaces()[s];
    for (int iv = 0; iv < surface.texels_v; ++iv)
      for (int iu = 0; iu < surface.texels_u; ++iu) {
        const glm::dvec2 uv = surface.texel_centre(iu, iv);
        const glm::dvec3 x = surface.point(uv.x, uv.y);
        // Slab test of the open segment p → x against the box, with the entry and exit parameters.
        double t0 = 1e-6, t1 = 1 - 1e-6;
        for (int a = 0; a < 3; ++a) {
          const double d = x[a] - p[a];
          if (std::abs(d) < 1e-15) {
            if (p[a] < box.lo[a] || p[a] > box.hi[a]) t0 = 2;
            continue;
          }
          double ta = (box.lo[a] - p[a]) / d, tb = (box.hi[a] - p[a]) / d;
          if (ta > tb) std::swap(ta, tb);
          t0 = std::max(t0, ta), t1 = std::min(t1, tb);
        }
        const double to_light_len = glm::length(p - x);
        // Skip texels whose segment grazes the box (within 1 mm) or lies on it: their verdict is rounding.
        if (std::abs(t1 - t0) * to_light_len < 1e-3) continue;
        const bool blocked = t0 < t1;
        const double cosine = glm::dot(surface.normal, p - x) / to_light_len;
        const double exact = blocked || cosine <= 0 ? 0.0 : kFlux / (4 * kPi) * cosine / (to_light_len * to_light_len);
        const double got = maps[s][std::size_t(iv) * std::size_t(surface.texels_u) + std::size_t(iu)];
        ASSERT_NEAR(got, exact, 1e-9 * kFlux) << surface.name << " " << iu << "," << iv;
        shadowed += blocked && cosine > 0;
        ++compared;
      }
  }
  EXPECT_GT(shadowed, 20u);  // the box's shadow on the floor is seen
  EXPECT_GT(compared, 1000u);
}

}  // namespace
