// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Baked luminaires against exact irradiance: particles traced through a luminaire with a closed-form near field
// become APL levels exactly as `lumx bake` makes them (held-out fit, then every exit), and the finest level's
// irradiance at single points of the measurement spheres is compared with the exact value there.
//   * a Lambertian emissive disk: the exact field by quadrature over the disk (analytic_emitters.h);
//   * a point light in a smooth absorbing glass ball: every exit leaves radially, so outside the ball the
//     field is exactly a point source's at the centre with the exit flux, Φ cos θ / (4π r²).
#include "analytic_emitters.h"
#include "luminaire_test_scenes.h"

#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/evaluation.h>
#include <lumx/bake/tracer.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <functional>

namespace {

using namespace lumx_test;

#if defined(__SANITIZE_ADDRESS__)
constexpr std::uint64_t kParticles = 100000;
#else
constexpr std::uint64_t kParticles = 1000000;
#endif

struct ExitCollector : lumx::bake::ParticleSink {
  lumx::RayChunk rays;
  void consume(const lumx::bake::ParticleChunk& c) override {
    for (const auto& x : c.exits) rays.push_back(x.position, x.direction, float(lumx::bake::luminance(glm::dvec3(x.flux_lm))));
  }
};

/// The finest level's relative RMSE against `exact` on each measurement sphere (patch centres), printed per
/// level for the record.
std::vector<double> baked_point_errors(const LuminaireScene& scene, const std::function<double(const glm::dvec3&, const glm::dvec3&)>& exact,
                                       double* exit_flux, std::vector<double>* distances) {
  const lumx::bake::Tracer tracer(scene);
  lumx::bake::TraceOptions o;
  o.particles = kParticles;
  ExitCollector exits;
  tracer.trace(o, exits);
  double flux = 0.0;
  for (float f : exits.rays.flux) flux += f;
  *exit_flux = flux;
  lumx::RaysetInfo info;
  info.file = scene.name;
  lumx::MemoryRaySource rays(exits.rays, info);

  lumx::AplBuildOptions bo;
  bo.threads = 2;
  lumx::AplErrorOptions eo;
  lumx::ResolutionChoice choice;
  const auto build = [&](lumx::RaySource& r) { return lumx::build_apl_set(r, bo); };
  const lumx::AplErrorReport held_out = lumx::evaluate_held_out_fitted(rays, build, eo, &choice);
  lumx::AplSet set = build(rays);
  EXPECT_TRUE(lumx::apply_held_out_fit(set, held_out, &choice));
  const lumx::MeasurementSpheres ms(set.bounds, eo);
  const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
  *distances = ms.relative_distances();
  std::vector<double> finest;
  std::printf("%s: %llu particles, %zu exits, %.4g lm; point error against the exact irradiance, %%, at d =", scene.name.c_str(),
              (unsigned long long)kParticles, exits.rays.size(), flux);
  for (double d : ms.relative_distances()) std::printf(" %g", d);
  std::printf("\n");
  for (std::size_t k = 0; k < set.levels.size(); ++k) {
    std::printf("  %4zu APLs R %3d:", set.levels[k].size(), set.levels[k].map_resolution);
    std::vector<double> row;
    for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
      std::vector<double> ref(dirs.size()), model(dirs.size());
      for (std::size_t p = 0; p < dirs.size(); ++p) {
        const glm::dvec3 x = ms.centre() + ms.radius(s) * dirs[p], n = -dirs[p];
        ref[p] = exact(x, n);
        model[p] = lumx::luminance_of(set.channels, lumx::irradiance(set, k, glm::vec3(x), glm::vec3(n)).irradiance);
      }
      row.push_back(lumx::compare_irradiance(ref, model).relative_rmse);
      std::printf(" %6.2f", 100 * row.back());
    }
    std::printf("\n");
    if (k + 1 == set.levels.size()) finest = row;
  }
  return finest;
}

TEST(BakeExactIrradiance, LambertianDisk) {
  SceneBuilder b("baked Lambertian disk");
  const double L = 1000.0, radius = 0.1;
  b.begin_part("disk", b.add_material(emissive(L)));
  add_disk(b, radius, 256);
  const double flux = lumx::kPi * L * disk_polygon_area(radius, 256);
  // The exact field of the circle of the same area (the 256-gon differs from it by < 10⁻⁴ relative).
  const PlanarEmitter exact("disk", PlanarEmitter::Shape::disk, radius, 0.0, 1.0, flux);  // intensity ∝ cos θ
  double exit_flux = 0.0;
  std::vector<double> d;
  const std::vector<double> e = baked_point_errors(
      b.scene(), [&](const glm::dvec3& x, const glm::dvec3& n) { return exact.irradiance(x, n); }, &exit_flux, &d);
  EXPECT_NEAR(exit_flux, flux, 1e-5 * flux);  // every particle leaves the bare disk: exact up to float sums
  for (std::size_t s = 0; s < d.size(); ++s) {
#if !defined(__SANITIZE_ADDRESS__)
    // 1 M particles, 512 APLs: measured 3.1-3.2 % at d ≥ 1, as for 1 M rays drawn from the analytic disk
    // (2.6-3.2 %, docs/apl_sets.md): the maps' noise at 2 000 rays per APL.
    if (d[s] >= 1) {
      EXPECT_LT(e[s], 0.035) << "d = " << d[s];
    }
#endif
    EXPECT_LT(e[s], 0.25) << "d = " << d[s];
  }
}

TEST(BakeExactIrradiance, PointLightInAGlassBall) {
  SceneBuilder b("baked glass ball");
  const double radius = 0.05;
  b.begin_part("ball", b.add_material(smooth_glass(1.5, 0.6, radius)));
  add_sphere(b, radius, 64, 128, 0.0, true);
  b.point_light({0, 0, 0}, 10.0);
  double exit_flux = 0.0;
  std::vector<double> d;
  const std::vector<double> e = baked_point_errors(
      b.scene(),
      [&](const glm::dvec3& x, const glm::dvec3& n) {
        const double r2 = glm::dot(x, x);
        return exit_flux * std::max(0.0, -glm::dot(n, x) / std::sqrt(r2)) / (4 * lumx::kPi * r2);
      },
      &exit_flux, &d);
  for (std::size_t s = 0; s < d.size(); ++s) {
#if !defined(__SANITIZE_ADDRESS__)
    // Measured 0.29 % at every d: the exits leave radially, the APLs converge to the centre. This checks the
    // angular shape (the exit flux itself is checked against its closed form in test_bake_tracer.cpp).
    if (d[s] >= 1) {
      EXPECT_LT(e[s], 0.01) << "d = " << d[s];
    }
#endif
    EXPECT_LT(e[s], 0.25) << "d = " << d[s];
  }
}

}  // namespace
