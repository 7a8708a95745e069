// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Baked luminaires against exact irradiance: particles traced through a luminaire with a closed-form near field
// become APL levels exactly as `lumx bake` makes them (held-out fit, then every exit), and the finest level's
// irradiance at single points of the measurement spheres is compared with the exact value there.
//   * a Lambertian emissive disk: the exact field by quadrature over the disk (analytic_emitters.h);
//   * a point light in a smooth absorbing glass ball: every exit leaves radially, so outside the ball the
//     field is exactly a point source's at the centre with the exit flux, Φ cos θ / (4π r²);
//   * a point light at the centre of a white Lambertian integrating sphere with a port: outside, the
//     light through the port is the point source (in the port's cone) plus the port opening as a
//     Lambertian disk of the wall's uniform radiance;
//   * two point lights in a black box with holes: each light's inverse-square field where a hole lets it out;
//   * a point light at the focus of a paraboloid mirror: the baked far field stays inside its cone.
#include "analytic_emitters.h"
#include "luminaire_test_scenes.h"
#include "test_support.h"

#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/map_fit.h>
#include <lumx/apl/evaluation.h>
#include <lumx/bake/bake.h>
#include <lumx/bake/gltf_writer.h>
#include <lumx/bake/tracer.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/intensity_table.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <functional>

namespace {

using namespace lumx_test;

#if defined(__SANITIZE_ADDRESS__)
constexpr std::uint64_t kParticles = 100000;
constexpr std::uint64_t kSphereParticles = kParticles;  // the sanitizers check the code, not the figure
#else
constexpr std::uint64_t kParticles = 1000000;
constexpr std::uint64_t kSphereParticles = 4 * kParticles;  // 28 % leave: 1.1 M exits
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
                                       double* exit_flux, std::vector<double>* distances,
                                       std::uint64_t particles = kParticles, std::vector<double>* radii = nullptr,
                                       glm::dvec3* centre = nullptr) {
  const lumx::bake::Tracer tracer(scene);
  lumx::bake::TraceOptions o;
  o.particles = particles;
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
  const lumx::AplBuildOptions half = lumx::half_rays_build_options(bo, rays.info().ray_count);
  const auto build_half = [&](lumx::RaySource& r) { return lumx::build_apl_set(r, half); };
  const lumx::AplErrorReport held_out = lumx::evaluate_held_out_fitted(rays, build_half, eo, &choice);
  lumx::AplSet set = build(rays);
  EXPECT_TRUE(lumx::apply_held_out_fit(set, held_out, &choice));
  const lumx::MeasurementSpheres ms(set.bounds, eo);
  const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
  *distances = ms.relative_distances();
  if (radii)
    for (std::size_t s = 0; s < ms.sphere_count(); ++s) radii->push_back(ms.radius(s));
  if (centre) *centre = ms.centre();
  std::vector<double> finest;
  std::printf("%s: %llu particles, %zu exits, %.4g lm; point error against the exact irradiance, %%, at d =", scene.name.c_str(),
              (unsigned long long)particles, exits.rays.size(), flux);
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
    // 1 M particles, 512 APLs: measured 0.97-0.98 % at d ≥ 1 at the rotated patches' centres (R 64 maps,
    // the fitted σ 6.7° kernel, local linear), as for 1 M rays drawn from the analytic disk (0.90-1.00 %,
    // docs/apl_sets.md); the target is 3 %. The sharpened kernel, which leaks light across the disk's
    // horizon, gave 1.89-2.00 %: the guard is 1.5 %.
    if (d[s] >= 1) {
      EXPECT_LT(e[s], 0.015) << "d = " << d[s];
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

// An integrating sphere whose white Lambertian wall (radius R, reflectance ρ, port of solid-angle fraction f)
// itself glows with uniform luminance L_e: from any wall point, a wall element dA subtends the form factor
// dA / (4π R²), so a uniform exitance M gives the uniform irradiance E = M (1 − f), and M = π L_e + ρ E
// solves to M = π L_e / (1 − ρ (1 − f)). Seen from outside, the port is a Lambertian disk (radius R sin α
// at height R cos α) of radiance M / π. (A point light inside would also shine straight through the port: a
// cone with a sharp edge in the far field, which no map of finite resolution resolves at single points.)
TEST(BakeExactIrradiance, IntegratingSphere) {
  SceneBuilder b("baked integrating sphere");
  const double rho = 0.8, cos_port = 0.9, R = 0.1, Le = 100.0;
  Material wall = lambertian(rho);
  wall.emissive = Rgb{1.0};
  wall.emissive_strength = Le;
  wall.double_sided = false;  // glows and scatters on the inside only
  b.begin_part("wall", b.add_material(wall));
  add_sphere(b, R, 48, 128, std::acos(cos_port), /*outward=*/false);
  const double f = 0.5 * (1 - cos_port), M = lumx::kPi * Le / (1 - rho * (1 - f));
  const double port_radius = R * std::sqrt(1 - cos_port * cos_port), port_height = R * cos_port;
  const double port_flux = M * lumx::kPi * port_radius * port_radius;
  const PlanarEmitter port("port", PlanarEmitter::Shape::disk, port_radius, 0.0, 1.0, port_flux);
  double exit_flux = 0.0;
  std::vector<double> d;
  const std::vector<double> e = baked_point_errors(
      b.scene(),
      [&](const glm::dvec3& x, const glm::dvec3& n) { return port.irradiance(x - glm::dvec3(0, 0, port_height), n); },
      &exit_flux, &d, kSphereParticles);
  // Monte Carlo: ~28 % of the particles leave, each with ~Φ/N: a standard error near 0.1 %; the polygonal
  // wall and port differ from the sphere by < 5·10⁻⁴ in area. 4 M particles give 1.1 M exits, the ray
  // budget of the other luminaires and of the analytic suite.
  EXPECT_NEAR(exit_flux, port_flux, 0.01 * port_flux);
  for (std::size_t s = 0; s < d.size(); ++s) {
    if (d[s] < 1) continue;  // spheres of d < 1 cut through the luminaire, whose wall the formula ignores
#if !defined(__SANITIZE_ADDRESS__)
    // 4 M particles, 1.1 M exits: measured 1.54, 1.30, 1.20, 1.24 % at d = 1, 2, 5, 10 (R 64, local
    // linear kernel); the target is 3 %. (Sharpened: 2.70-2.30 %; 1 M particles, 279 000 exits: 4.2-5.2 %
    // with R 32 maps.) The guard is 2 %.
    EXPECT_LT(e[s], 0.02) << "d = " << d[s];
#endif
    EXPECT_LT(e[s], 0.25) << "d = " << d[s];
  }
}

// Two isotropic point lights (500 lm each) inside a black 10 cm box with four rectangular holes — the
// analytic suite's box (tests/test_apl_honest_error.cpp) as geometry: outside, the exact irradiance is each
// light's inverse-square field where the straight line to it passes through a hole (PinholeBox), with sharp
// shadow borders no map of finite resolution resolves at every point.
TEST(BakeExactIrradiance, PointLightsInABoxWithHoles) {
  SceneBuilder b("baked box with holes");
  const double half = 0.05, flux = 500.0;
  const std::vector<RectHole> holes = {{2, 1, -0.03, 0.01, -0.02, 0.03},
                                       {2, -1, 0.0, 0.03, -0.03, 0.0},
                                       {0, 1, -0.04, -0.01, -0.01, 0.03},
                                       {1, -1, -0.02, 0.02, -0.045, -0.02}};
  b.begin_part("box", b.add_material(black()));
  add_box_with_holes(b, half, 20, holes);  // 5 mm cells: every hole edge lies on the grid
  const std::vector<glm::dvec3> lights = {{-0.02, 0.01, 0.0}, {0.015, -0.01, 0.01}};
  for (const glm::dvec3& p : lights) b.point_light(p, flux / (4 * lumx::kPi));
  std::vector<PinholeBox::Hole> exact_holes;
  for (const RectHole& h : holes) exact_holes.push_back({h.axis, h.side, h.u0, h.u1, h.v0, h.v1});
  const PinholeBox exact("box", half, exact_holes, {{lights[0], flux}, {lights[1], flux}});
  double exit_flux = 0.0;
  std::vector<double> d, radius;
  glm::dvec3 centre(0.0);
  const std::vector<double> e = baked_point_errors(
      b.scene(), [&](const glm::dvec3& x, const glm::dvec3& n) { return exact.irradiance(x, n); }, &exit_flux, &d,
      kParticles, &radius, &centre);
  // The particles leave from the lights (the black walls scatter nothing), so the set's bounding sphere is
  // the lights' (radius 2.1 cm) and its spheres up to d ≈ 4 pass through the box, where the exact field
  // is 0 and the APLs know no wall: only spheres wholly outside the box are graded.
  const double box_reach = glm::length(glm::abs(centre) + glm::dvec3(half));
  int graded = 0;
  for (std::size_t s = 0; s < d.size(); ++s) {
    if (radius[s] <= box_reach) continue;
    ++graded;
#if !defined(__SANITIZE_ADDRESS__)
    // 1 M particles, 112 000 exits, every one leaving a light: the two lights as masked APLs
    // (apl/point_sources.h), measured 1.49 and 1.48 % at d = 5 and 10 (R 4 maps), as the same box from rays
    // drawn analytically (1.36-1.74 %, docs/apl_sets.md). Before, clustered plain maps were 52.2 and
    // 47.1 %: the beams' sharp borders needed borders as geometry, not a finer density estimate.
    EXPECT_LT(e[s], 0.05) << "d = " << d[s];
#endif
    EXPECT_LT(e[s], 1.0) << "d = " << d[s];
  }
  EXPECT_GE(graded, 2);
}

// A point light at the focus of a paraboloid mirror (rim at cos θ = 0.6 from +z), baked: every particle leaves
// inside the 53.1° cone about +z — 80 % reflected into a collimated beam along +z (within 1°,
// test_bake_tracer.cpp), 20 % straight past the rim — so the bundle's far field (IES attachment) must hold
// its flux inside that cone, up to the maps' blur, with the reflected beam a spike on the axis.
TEST(BakeExactIrradiance, BakedParaboloidBeamStaysInItsCone) {
  namespace fs = std::filesystem;
  const fs::path dir = lumx_test::unique_temp_path("lumx_bake_paraboloid");
  fs::create_directories(dir);
  SceneBuilder b("paraboloid");
  b.begin_part("mirror", b.add_material(mirror()));
  add_paraboloid(b, 0.02, 0.08, 64, 256);
  b.point_light({0, 0, 0}, 1.0);
  lumx::bake::write_gltf_luminaire(b.scene(), (dir / "paraboloid.glb").string());
  lumx::bake::BakeOptions o;
  o.particles = kParticles / 4;
  o.volume_voxels = 0;
  o.bundle.apl.level_counts = {1, 8};
  const auto r = lumx::bake::bake_luminaire((dir / "paraboloid.glb").string(), (dir / "b").string(), o);
  ASSERT_TRUE(r.bundle.far_field_attached);
  const lumx::BundleReader bundle((dir / "b").string());
  std::string ies;
  for (std::size_t i = 0; i < bundle.manifest().attachments.size(); ++i)
    if (bundle.manifest().attachments[i].first.name == "far_field.ies") ies = bundle.read_attachment(i);
  const lumx::IntensityTable t(lumx::read_ies(ies, "far_field.ies"));
  // Type C: γ = 180° is +z. Outside the cone widened by two map texels of level 0 (R ≥ 16: ≤ 6.4° each).
  const double outside = t.flux_lm(0.0, 180.0 - 53.13 - 2 * 6.4) / t.flux_lm();
  const double axis = t.intensity({0, 0, 1}), off_axis = t.intensity({0.5, 0, std::sqrt(0.75)});
  std::printf("baked paraboloid: far field %.4f lm, %.3f %% outside the widened cone, %.1f cd on the axis, %.3f cd "
              "at 30 deg (1 cd direct), maps R %d\n",
              t.flux_lm(), 100 * outside, axis, off_axis, r.bundle.far_field_resolution);
  EXPECT_LT(outside, 0.01);
  // Every particle leaves (4π lm); measured +3.9 %: the axis spike, 10 lm in about one texel of the R 64
  // maps (2.2°), tabulated on the 2.5° × 1° Type C grid and integrated bilinearly, so its integral depends
  // on where the texel falls between the grid's rings (+1.6 % with the maps drawn in the photometric
  // frame, the spike at the map's pole; the builder's MapFrame puts it mid-wedge).
  EXPECT_NEAR(t.flux_lm(), 4 * lumx::kPi, 0.05 * 4 * lumx::kPi);
  // 10 lm reflected into the axis texel (4π / 2R² sr) against the point's own 1 cd beside it.
  EXPECT_GT(axis, 50 * off_axis);
  EXPECT_NEAR(off_axis, 1.0, 0.3);  // the direct light: 1 cd, within the maps' noise at ~1 000 rays a texel
  fs::remove_all(dir);
}

}  // namespace
