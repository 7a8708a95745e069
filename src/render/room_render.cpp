// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/render/room_render.h>

#include <lumx/math/constants.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN
namespace render {

namespace {

template <class F>
void parallel_rows(int threads, std::size_t n, F&& body) {
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
    });
  });
}

std::uint64_t total_texels(const RoomScene& scene) {
  std::uint64_t n = 0;
  for (const RoomSurface& s : scene.surfaces()) n += s.texel_count();
  return n;
}

void check_shape(const RoomScene& scene, const SurfaceMaps& maps, const char* what) {
  const auto& surfaces = scene.surfaces();
  bool ok = maps.size() == surfaces.size();
  for (std::size_t s = 0; ok && s < surfaces.size(); ++s) ok = maps[s].size() == surfaces[s].texel_count();
  if (!ok) throw std::invalid_argument(std::string("room maps: ") + what + " does not match the room's texels");
}

}  // namespace

SurfaceMaps illuminance_maps(const RoomScene& scene, const RoomIlluminance& method, int threads) {
  const auto& surfaces = scene.surfaces();
  SurfaceMaps maps(surfaces.size());
  // One work item per texel row of a surface; each texel's key is its running index over all surfaces.
  std::vector<std::pair<std::size_t, int>> rows;
  std::vector<std::uint64_t> first_key(surfaces.size());
  std::uint64_t key = 0;
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    maps[s].assign(surfaces[s].texel_count(), 0.0);
    first_key[s] = key;
    key += surfaces[s].texel_count();
    for (int iv = 0; iv < surfaces[s].texels_v; ++iv) rows.push_back({s, iv});
  }
  parallel_rows(threads, rows.size(), [&](std::size_t r) {
    const auto [s, iv] = rows[r];
    const RoomSurface& f = surfaces[s];
    for (int iu = 0; iu < f.texels_u; ++iu) {
      const glm::dvec2 uv = f.texel_centre(iu, iv);
      const std::size_t t = std::size_t(iv) * std::size_t(f.texels_u) + std::size_t(iu);
      maps[s][t] = method.at(int(s), f.point(uv.x, uv.y), f.normal, uv.x, uv.y, first_key[s] + t);
    }
  });
  return maps;
}

Image render_room_view(const RoomScene& scene, const PinholeCamera& camera, const RoomIlluminance& method,
                       int threads) {
  if (const std::string why = camera.invalid_reason(); !why.empty()) throw std::invalid_argument("camera: " + why);
  Image image(camera.width, camera.height, {"Y", "E", "surface"});
  const double rho_over_pi = scene.room().albedo / kPi;
  const std::uint64_t key0 = total_texels(scene);
  parallel_rows(threads, std::size_t(camera.height), [&](std::size_t row) {
    const int y = int(row);
    for (int x = 0; x < camera.width; ++x) {
      const CameraRay ray = camera.ray(x + 0.5, y + 0.5);
      const RoomHit hit = scene.intersect(ray.origin, ray.direction);
      image.at(x, y, 2) = float(hit.surface);
      if (hit.surface < 0 || !hit.front) continue;
      const RoomSurface& f = scene.surfaces()[std::size_t(hit.surface)];
      const std::uint64_t key = key0 + std::uint64_t(y) * std::uint64_t(camera.width) + std::uint64_t(x);
      const double e = method.at(hit.surface, hit.point, f.normal, hit.u, hit.v, key);
      image.at(x, y, 0) = float(rho_over_pi * e);
      image.at(x, y, 1) = float(e);
    }
  });
  return image;
}

double relative_rmse(const RoomScene& scene, const SurfaceMaps& maps, const SurfaceMaps& reference) {
  check_shape(scene, maps, "method");
  check_shape(scene, reference, "reference");
  double num = 0, den = 0;
  for (std::size_t s = 0; s < maps.size(); ++s) {
    const double a = scene.surfaces()[s].texel_area_m2();
    for (std::size_t t = 0; t < maps[s].size(); ++t) {
      const double d = maps[s][t] - reference[s][t];
      num += a * d * d;
      den += a * reference[s][t] * reference[s][t];
    }
  }
  return den > 0 ? std::sqrt(num / den) : 0.0;
}

double half_noise(const RoomScene& scene, const SurfaceMaps& half_a, const SurfaceMaps& half_b,
                  const SurfaceMaps& reference) {
  check_shape(scene, half_a, "half a");
  check_shape(scene, half_b, "half b");
  check_shape(scene, reference, "reference");
  double num = 0, den = 0;
  for (std::size_t s = 0; s < reference.size(); ++s) {
    const double a = scene.surfaces()[s].texel_area_m2();
    for (std::size_t t = 0; t < reference[s].size(); ++t) {
      const double d = half_a[s][t] - half_b[s][t];
      num += a * d * d / 4.0;  // Var(E_a − E_b) = 2 · 2 Var(E)
      den += a * reference[s][t] * reference[s][t];
    }
  }
  return den > 0 ? std::sqrt(num / den) : 0.0;
}

}  // namespace render
LUMX_NAMESPACE_END
