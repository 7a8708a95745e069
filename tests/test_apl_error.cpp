// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Reference evaluators (apl/error.h): the metrics on hand-computed examples, the gathering of rays on
// measurement spheres (exits, rays starting outside, halves), the noise floor against an exact model and
// its 1/√rays scaling, errors of built APL sets against their rays (decrease with level near the
// luminaire, agreement far away, a point source, the measured OSRAM sample), determinism, and error tables
// through a bundle.
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/map_fit.h>
#include <lumx/apl/lod.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/rayset_io.h>

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "apl/error_detail.h"
#include "rayset_test_support.h"

#include <filesystem>
#include <random>

#include <unistd.h>

using namespace lumx;
namespace fs = std::filesystem;

namespace {

/// Unit vector of a cos^k lobe around `axis` (k = 0: uniform hemisphere), by inverting the lobe's CDF.
glm::vec3 lobe_direction(const glm::vec3& axis, float k, float u1, float u2) {
  const glm::vec3 helper = std::abs(axis.z) < 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
  const glm::vec3 t1 = glm::normalize(glm::cross(axis, helper)), t2 = glm::cross(axis, t1);
  const float cos_t = std::pow(u1, 1.0f / (k + 1.0f)), sin_t = std::sqrt(std::max(0.0f, 1.0f - cos_t * cos_t));
  const float az = float(2 * kPi) * u2;
  return glm::normalize(sin_t * std::cos(az) * t1 + sin_t * std::sin(az) * t2 + cos_t * axis);
}

/// A ring luminaire: `n` rays starting on a circle of radius 0.2 m in the z = 0 plane, each from a
/// cos^k lobe whose axis points down and tilts outward (tilt 0.5), so that near the ring the pattern
/// depends on where the light starts. Flux per ray varies around the ring (1 ± 0.5 cos).
MemoryRaySource ring_rays(int n, unsigned seed, float k = 1.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  RayChunk rays;
  rays.reserve(std::size_t(n));
  for (int i = 0; i < n; ++i) {
    const float angle = float(2 * kPi) * u(rng);
    const glm::vec3 p(0.2f * std::cos(angle), 0.2f * std::sin(angle), 0.0f);
    const glm::vec3 axis = glm::normalize(glm::vec3(0.5f * std::cos(angle), 0.5f * std::sin(angle), -1.0f));
    const float u1 = u(rng), u2 = u(rng);
    rays.push_back(p, lobe_direction(axis, k, u1, u2), (1.0f + 0.5f * std::cos(angle)) * 1e-3f);
  }
  RaysetInfo info;
  info.file = "ring";
  info.format = "memory";
  return MemoryRaySource(std::move(rays), info);
}

/// `n` rays of equal flux from one point, a downward cos lobe.
MemoryRaySource point_rays(int n, unsigned seed, const glm::vec3& at) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  RayChunk rays;
  for (int i = 0; i < n; ++i) {
    const float u1 = u(rng), u2 = u(rng);
    rays.push_back(at, lobe_direction({0, 0, -1}, 1.0f, u1, u2), 0.01f);
  }
  RaysetInfo info;
  info.file = "point";
  return MemoryRaySource(std::move(rays), info);
}

MemoryRaySource rays_of(RayChunk c) {
  RaysetInfo info;
  info.file = "hand";
  return MemoryRaySource(std::move(c), info);
}

/// The standard test set: ring rays built into levels 1, 8, 64 (and 256) with one map resolution.
/// The resolution is fixed rather than left to the builder's rule: the rule gives 4×4-texel maps to the
/// 256-APL level of a 400 k-ray set, whose bilinear blur (≈ 24 % here) would hide what these tests
/// measure (docs/apl_sets.md, "Error against distance, time and bytes").
AplSet build_fixed(RaySource& rays, int resolution, std::vector<std::size_t> counts = {1, 8, 64, 256}) {
  AplBuildOptions o;
  o.level_counts = std::move(counts);
  o.map_resolution = resolution;
  o.place_at_convergence = false;  // the dissertation's placement: these tests chart the hierarchy itself
  return build_apl_set(rays, o);
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// Metrics on exact examples

TEST(AplErrorMetrics, HandComputedValues) {
  // ref (1, 3), model (2, 2): RMSE √((1 + 1)/2) = 1, mean 2 → 0.5. p = (¼, ¾), q = (½, ½):
  // l² = √(2 · ¼²) = √⅛; Hellinger = √(½((½ − √½)² + (√¾ − √½)²)).
  const IrradianceErrors e = compare_irradiance({1, 3}, {2, 2});
  EXPECT_DOUBLE_EQ(e.relative_rmse, 0.5);
  EXPECT_DOUBLE_EQ(e.l2, std::sqrt(0.125));
  const double h = std::sqrt(0.5 * (std::pow(0.5 - std::sqrt(0.5), 2) + std::pow(std::sqrt(0.75) - std::sqrt(0.5), 2)));
  EXPECT_DOUBLE_EQ(e.hellinger, h);
  EXPECT_NEAR(e.hellinger, 0.18459191, 1e-8);

  // Identical → 0; a scaled copy has the same shape (l², H = 0) but relative RMSE = |scale − 1|.
  const IrradianceErrors same = compare_irradiance({1, 2, 3, 4}, {1, 2, 3, 4});
  EXPECT_EQ(same.relative_rmse, 0.0);
  EXPECT_EQ(same.l2, 0.0);
  EXPECT_EQ(same.hellinger, 0.0);
  const IrradianceErrors twice = compare_irradiance({1, 2, 3, 4}, {2, 4, 6, 8});
  EXPECT_DOUBLE_EQ(twice.relative_rmse, std::sqrt((1 + 4 + 9 + 16) / 4.0) / 2.5);
  EXPECT_NEAR(twice.l2, 0.0, 1e-17);
  EXPECT_NEAR(twice.hellinger, 0.0, 1e-8);

  // Disjoint supports: the maxima, l² = √2 and H = 1; relative RMSE √((1 + 1)/2) / ½ = 2.
  const IrradianceErrors disjoint = compare_irradiance({1, 0}, {0, 1});
  EXPECT_DOUBLE_EQ(disjoint.relative_rmse, 2.0);
  EXPECT_DOUBLE_EQ(disjoint.l2, std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(disjoint.hellinger, 1.0);

  // Undefined cases are NaN, not 0; sizes must match.
  EXPECT_TRUE(std::isnan(compare_irradiance({}, {}).relative_rmse));
  const IrradianceErrors dark = compare_irradiance({0, 0}, {1, 1});
  EXPECT_TRUE(std::isnan(dark.relative_rmse) && std::isnan(dark.l2) && std::isnan(dark.hellinger));
  const IrradianceErrors model_dark = compare_irradiance({1, 1}, {0, 0});
  EXPECT_DOUBLE_EQ(model_dark.relative_rmse, 1.0);
  EXPECT_TRUE(std::isnan(model_dark.l2) && std::isnan(model_dark.hellinger));
  EXPECT_THROW(compare_irradiance({1}, {1, 2}), std::invalid_argument);
}

TEST(AplErrorMetrics, NoiseFloorOfHalves) {
  // Halves (1, 3) and (3, 1): RMSE of the difference √((4 + 4)/2) = 2, mean of the whole 2 → 2/2/2 = 0.5.
  EXPECT_DOUBLE_EQ(noise_floor({1, 3}, {3, 1}), 0.5);
  EXPECT_EQ(noise_floor({2, 2}, {2, 2}), 0.0);
  EXPECT_TRUE(std::isnan(noise_floor({0, 0}, {0, 0})));
  EXPECT_THROW(noise_floor({1}, {}), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------------------
// Gathering

TEST(AplErrorGather, ExitPointsRaysFromOutsideAndHalves) {
  // Bounds: centre (1, 2, 3), radius 0.5 → D = 1; one sphere at d = 2 (ρ = 2), R_patch = 4 (32 patches).
  BoundingSphere b;
  b.center = {1, 2, 3};
  b.radius = 0.5;
  AplErrorOptions o;
  o.relative_distances = {2.0};
  o.patch_resolution = 4;
  const glm::vec3 c(1, 2, 3);
  RayChunk rays;
  rays.push_back(c, {0, 0, 1}, 3.0f);                     // 0 (even): from the centre, up
  rays.push_back(c + glm::vec3(1.5f, 0, 0), {0, 0, 1}, 5.0f);  // 1 (odd): inside, off-centre, up
  rays.push_back(c + glm::vec3(4, 0, 0), {-1, 0, 0}, 7.0f); // 2 (even): outside, crosses: exits at −x
  rays.push_back(c + glm::vec3(4, 0, 0), {1, 0, 0}, 11.0f); // 3 (odd): outside, moving away: missed
  rays.push_back(c + glm::vec3(0, 4, 0), {-1, 0, 0}, 13.0f);// 4 (even): outside, line misses the sphere
  rays.push_back(c, {0, 1, 0}, 0.0f);                     // 5: no flux (counted, not gathered)
  MemoryRaySource src = rays_of(rays);
  const ReferenceIrradiance ref = gather_reference(src, b, o);
  ASSERT_EQ(ref.sphere.size(), 1u);
  const SphereReference& s = ref.sphere[0];
  EXPECT_EQ(ref.rays, 6u);
  EXPECT_EQ(ref.zero_flux_rays, 1u);
  EXPECT_DOUBLE_EQ(ref.flux, 3.0 + 5 + 7 + 11 + 13);
  EXPECT_DOUBLE_EQ(s.radius, 2.0);
  EXPECT_DOUBLE_EQ(s.patch_area, 4 * kPi * 4 / 32);
  EXPECT_EQ(s.rays, 3u);
  EXPECT_EQ(s.started_outside, 3u);
  EXPECT_EQ(s.missed, 2u);
  EXPECT_DOUBLE_EQ(s.flux, 15.0);
  // Exit points: (0, 0, 2) and (1.5, 0, √1.75) from the centre (the second ray leaves at z = √(4 − 1.5²)),
  // and (−2, 0, 0) for the ray that came from outside.
  const MeasurementSpheres& ms = ref.spheres;
  const std::size_t up = ms.patch_of({0, 0, 1}), tilted = ms.patch_of(glm::normalize(glm::vec3(1.5f, 0, std::sqrt(1.75f))));
  const std::size_t minus_x = ms.patch_of({-1, 0, 0});
  ASSERT_NE(up, tilted);
  const double A = s.patch_area;
  std::vector<double> expect(32, 0.0), even(32, 0.0), odd(32, 0.0);
  expect[up] += 3 / A, expect[tilted] += 5 / A, expect[minus_x] += 7 / A;
  even[up] += 6 / A, even[minus_x] += 14 / A, odd[tilted] += 10 / A;
  for (std::size_t p = 0; p < 32; ++p) {
    EXPECT_DOUBLE_EQ(s.irradiance[p], expect[p]) << p;
    EXPECT_DOUBLE_EQ(s.half_even[p], even[p]) << p;
    EXPECT_DOUBLE_EQ(s.half_odd[p], odd[p]) << p;
    // v_i = (Σ Φ² − (Σ Φ)²/M)/A² with M = 3 rays on the sphere, one per lit patch: (2/3) Φ²/A².
    EXPECT_NEAR(s.variance[p], 2.0 / 3.0 * (expect[p] * expect[p]), 1e-12 * expect[p] * expect[p]) << p;
  }
  // σ = √(Σ v_i / N) / mean E = √(2/3 · Σ E_i² / 32) / (Σ E_i / 32).
  const double sum = (3 + 5 + 7) / A, sum2 = (9 + 25 + 49) / (A * A);
  EXPECT_NEAR(s.noise_floor, std::sqrt(2.0 / 3.0 * sum2 / 32) / (sum / 32), 1e-12);
  EXPECT_DOUBLE_EQ(s.split_noise_floor, noise_floor(even, odd));
}

TEST(AplErrorGather, PatchesAreTheSphereMapTexelsAndOptionsAreChecked) {
  BoundingSphere b;
  b.radius = 0.25;
  AplErrorOptions o;
  o.patch_resolution = 16;
  o.patch_subsamples = 3;
  const MeasurementSpheres ms(b, o);
  EXPECT_EQ(ms.patch_count(), 512u);
  EXPECT_DOUBLE_EQ(ms.diameter(), 0.5);
  EXPECT_DOUBLE_EQ(ms.radius(0), 0.25);  // d = 0.5 is the bounding sphere
  EXPECT_DOUBLE_EQ(ms.radius(5), 5.0);
  const std::vector<glm::dvec3> dirs = ms.evaluation_directions(3);
  ASSERT_EQ(dirs.size(), 512u * 9u);
  // Every evaluation point lies in its own patch; the patch areas add up to the sphere.
  for (std::size_t e = 0; e < dirs.size(); ++e) ASSERT_EQ(ms.patch_of(glm::vec3(dirs[e])), e / 9) << e;
  EXPECT_EQ(ms.subsamples_for(256, 512), 3);  // fixed by the option
  // Automatic k: ⌈R_map / R_patch⌉ in [1, 16], lowered to keep APLs · k² · N · spheres ≤ 2e8.
  AplErrorOptions automatic;
  EXPECT_EQ(automatic.patch_subsamples, 1);  // the default: one point per patch, as a renderer queries
  automatic.patch_subsamples = 0;
  const MeasurementSpheres ma(b, automatic);
  EXPECT_EQ(ma.patch_subsamples(), 0);
  EXPECT_EQ(ma.subsamples_for(64, 1), 4);
  EXPECT_EQ(ma.subsamples_for(24, 1), 2);
  EXPECT_EQ(ma.subsamples_for(8, 64), 1);
  EXPECT_EQ(ma.subsamples_for(4096, 1), 16);
  EXPECT_EQ(ma.subsamples_for(256, 512), 11);  // 512 · 121 · 512 · 6 = 1.9e8
  EXPECT_NEAR(ms.patch_area(2) * 512, 4 * kPi * 0.5 * 0.5, 1e-12);

  // A point source (D = 0) gets min_diameter.
  EXPECT_DOUBLE_EQ(MeasurementSpheres(BoundingSphere{}, AplErrorOptions{}).diameter(), 1e-3);
  AplErrorOptions bad = o;
  bad.relative_distances = {1, 1};
  EXPECT_THROW(MeasurementSpheres(b, bad), std::invalid_argument);
  bad.relative_distances = {0, 1};
  EXPECT_THROW(MeasurementSpheres(b, bad), std::invalid_argument);
  bad.relative_distances = {};
  EXPECT_THROW(MeasurementSpheres(b, bad), std::invalid_argument);
  bad = o;
  bad.patch_resolution = 0;
  EXPECT_THROW(MeasurementSpheres(b, bad), std::invalid_argument);
  bad = o;
  bad.patch_subsamples = 17;
  EXPECT_THROW(MeasurementSpheres(b, bad), std::invalid_argument);
  // Unsorted distances are sorted.
  bad = o;
  bad.relative_distances = {10, 0.5, 2};
  EXPECT_EQ(MeasurementSpheres(b, bad).relative_distances(), (std::vector<double>{0.5, 2, 10}));

  RayChunk broken;
  broken.push_back({0, 0, 0}, {0, 0, 1}, -1.0f);
  MemoryRaySource src = rays_of(broken);
  EXPECT_THROW(gather_reference(src, b, o), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------------------
// Noise floor

TEST(AplErrorNoise, ExactModelMeasuresTheNoiseFloor) {
  // An isotropic point source and its exact model (one APL with a constant map): the model has no noise,
  // so its relative RMSE against the reference is the reference's own noise, which the halves estimate.
  // Both are RMS values over N = 512 patches: each has a relative standard error ≈ 1/√(2N) ≈ 3 %, so
  // their ratio is 1 within ±12 % (about 3σ).
  const int n = 200000;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  RayChunk rays;
  for (int i = 0; i < n; ++i) {
    const float z = 1 - 2 * u(rng), phi = float(2 * kPi) * u(rng), s = std::sqrt(std::max(0.0f, 1 - z * z));
    rays.push_back({0.5f, 0, 0}, {s * std::cos(phi), s * std::sin(phi), z}, 2e-5f);
  }
  MemoryRaySource src = rays_of(rays);
  AplSet set;
  set.bounds.center = {0.5, 0, 0};
  set.bounds.radius = 0.1;
  AplLevel level;
  level.map_resolution = 8;
  Apl a;
  a.position = {0.5f, 0, 0};
  a.map = SphereMap(8, 1);
  const double flux = double(n) * double(2e-5f);
  for (float& v : a.map.values()) v = float(flux / (4 * kPi));
  a.flux = a.map.integral();
  level.apls.push_back(a);
  set.levels.push_back(level);
  AplErrorOptions o;
  o.min_timing_seconds = 0;
  const AplErrorReport r = evaluate_apl_errors(set, src, o);
  for (std::size_t s = 0; s < r.reference.sphere.size(); ++s) {
    const double noise = r.reference.sphere[s].noise_floor;
    // Poisson: N patches of n/N rays each → relative noise √(N/n) = 0.0506.
    EXPECT_NEAR(noise, std::sqrt(512.0 / n), 0.12 * std::sqrt(512.0 / n)) << s;
    EXPECT_NEAR(r.levels[0].errors[s].relative_rmse / noise, 1.0, 0.12) << s;
    EXPECT_NEAR(r.far_field.errors[s].relative_rmse / noise, 1.0, 0.12) << s;
  }
}

TEST(AplErrorNoise, ScalesAsOneOverSquareRootOfRays) {
  // 4× the rays → half the noise. Each noise floor is an RMS over 512 patches (±3 % each, so ±4.4 % for
  // the ratio); averaged over the six spheres the ratio is within ±10 % of 2 (≥ 3σ even if the spheres
  // were fully correlated).
  AplErrorOptions o;
  BoundingSphere b;
  b.radius = 0.2;
  MemoryRaySource few = ring_rays(50000, 11), many = ring_rays(200000, 12);
  const ReferenceIrradiance r1 = gather_reference(few, b, o), r2 = gather_reference(many, b, o);
  double ratio = 0;
  for (std::size_t s = 0; s < r1.sphere.size(); ++s) ratio += r1.sphere[s].noise_floor / r2.sphere[s].noise_floor;
  ratio /= double(r1.sphere.size());
  EXPECT_NEAR(ratio, 2.0, 0.2);
}

// ---------------------------------------------------------------------------------------------------------
// Built sets against their rays

TEST(AplErrorLevels, ErrorDecreasesWithLevelNearAndAgreesFarAway) {
  MemoryRaySource rays = ring_rays(400000, 5);
  const AplSet set = build_fixed(rays, 16);
  ASSERT_EQ(set.levels.size(), 4u);
  AplErrorOptions o;
  o.min_timing_seconds = 0;
  o.threads = 1;  // the points on one thread: that pass is timed
  const AplErrorReport r = evaluate_apl_errors(set, rays, o);
  ASSERT_EQ(r.levels.size(), 4u);
  const auto& spheres = r.reference.sphere;
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    const double d = spheres[s].relative_distance, noise = spheres[s].noise_floor;
    ASSERT_GT(noise, 0.02);
    ASSERT_LT(noise, 0.08);
    EXPECT_EQ(spheres[s].missed, 0u);
    if (d <= 1) {
      // 1 → 8 → 64 APLs: each step lowers the error, the first at least by half (one point for a 0.4 m
      // ring is off by 40–200 %); from 64 to 256 the error is at the noise floor and may only stay there.
      EXPECT_LT(r.levels[1].errors[s].relative_rmse, 0.5 * r.levels[0].errors[s].relative_rmse) << d;
      EXPECT_LT(r.levels[2].errors[s].relative_rmse, r.levels[1].errors[s].relative_rmse) << d;
      EXPECT_LT(r.levels[3].errors[s].relative_rmse, r.levels[2].errors[s].relative_rmse + noise) << d;
      EXPECT_GT(r.levels[0].errors[s].relative_rmse, 5 * noise) << d;  // the far field is visibly wrong
      // The shape metrics agree on the ordering.
      EXPECT_LT(r.levels[2].errors[s].hellinger, r.levels[0].errors[s].hellinger) << d;
      EXPECT_LT(r.levels[2].errors[s].l2, r.levels[0].errors[s].l2) << d;
    }
    if (d >= 10) {
      // Far away every level is the same point source: within 3 × the noise floor (measured ≤ 1×; the
      // maps share the reference's rays, so the difference can be below the floor).
      for (const LevelErrors& l : r.levels) EXPECT_LT(l.errors[s].relative_rmse, 3 * noise) << l.apls;
    }
  }
  // The far-field row is level 0 (one APL at the bounding-sphere centre).
  for (std::size_t s = 0; s < spheres.size(); ++s)
    EXPECT_NEAR(r.far_field.errors[s].relative_rmse, r.levels[0].errors[s].relative_rmse,
                1e-4 * r.levels[0].errors[s].relative_rmse);
  // Cost: more APLs take longer per evaluation; bytes are the maps'.
  for (std::size_t k = 0; k < r.levels.size(); ++k) {
    EXPECT_EQ(r.levels[k].bytes, set.levels[k].map_bytes());
    EXPECT_GT(r.levels[k].ns_per_evaluation, 0);
  }
  EXPECT_GT(r.levels[3].ns_per_evaluation, r.levels[0].ns_per_evaluation);
}

TEST(AplErrorLevels, LevelZeroFarAwayIsNearTheNoiseFloorWithTheBuilderRule) {
  // The builder's own resolution rule (level 0: R = 64 for 200 k rays). Its patch-centre lookups read
  // the 2×2 central texels of the 4×4 under a patch, an estimate from a quarter of the patch's rays: for
  // a point source that alone gives √3 × the noise floor (Var(4X − (X + Y)) = 3n for Poisson counts X of
  // n/4 and Y of 3n/4 rays). At d = 10 the ring adds a 2° parallax; allow 2.5×.
  MemoryRaySource rays = ring_rays(200000, 9);
  AplBuildOptions bo;
  bo.level_counts = {1, 8};
  const AplSet set = build_apl_set(rays, bo);
  ASSERT_EQ(set.levels[0].map_resolution, 64);
  AplErrorOptions o;
  o.relative_distances = {10};
  o.min_timing_seconds = 0;
  o.patch_subsamples = 1;
  const AplErrorReport r = evaluate_apl_errors(set, rays, o);
  const double noise = r.reference.sphere[0].noise_floor;
  EXPECT_LT(r.levels[0].errors[0].relative_rmse, 2.5 * noise);
  EXPECT_GT(r.levels[0].errors[0].relative_rmse, 1.2 * noise);
  // The automatic k = 64/16 = 4 samples every texel under a patch: the level then reproduces the patch
  // sums up to the 2° parallax, below the noise floor (it shares the reference's rays).
  o.patch_subsamples = 0;
  const AplErrorReport ra = evaluate_apl_errors(set, rays, o);
  EXPECT_EQ(ra.levels[0].subsamples, 4);
  EXPECT_LT(ra.levels[0].errors[0].relative_rmse, noise);
}

TEST(AplErrorSpheres, RotatedPatchCentresFallAtGenericPlacesOfTheMaps) {
  // A bilinear lookup at a texel centre returns the texel's mean and hides the interpolation error a
  // renderer's shading point sees. In the photometric frame every R 16 patch centre is an R 16 map's
  // texel centre; in the rotated patch frame (the default) few are near any texel centre of any map.
  BoundingSphere b;
  AplErrorOptions o;
  const auto near_texel_centres = [&](bool rotated, int R) {
    o.rotated_patches = rotated;
    const MeasurementSpheres ms(b, o);
    std::size_t near = 0;
    const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
    for (const glm::dvec3& d : dirs) {
      int half;
      const glm::vec2 q = sphere_map::direction_to_square(glm::vec3(d), half);
      const double fx = double(q.x) * R - std::floor(double(q.x) * R), fy = double(q.y) * R - std::floor(double(q.y) * R);
      if (std::abs(fx - 0.5) < 0.05 && std::abs(fy - 0.5) < 0.05) ++near;  // within 5 % of a texel of its centre
    }
    return double(near) / double(dirs.size());
  };
  EXPECT_GT(near_texel_centres(false, 16), 0.99);
  for (int R : {8, 16, 32, 64}) EXPECT_LT(near_texel_centres(true, R), 0.05) << R;  // a uniform spread: ~1 %
  // The frame is a rotation (orthonormal, determinant 1).
  const glm::dmat3 Q = MeasurementSpheres::patch_frame();
  const glm::dmat3 I = glm::transpose(Q) * Q;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(I[i][j], i == j ? 1.0 : 0.0, 1e-12);
  EXPECT_NEAR(glm::determinant(Q), 1.0, 1e-12);
}

TEST(AplErrorLevels, RaysFromOnePointGiveNoiseForEveryLevel) {
  // Every ray from one point: the builder's bound has radius 0 (min_diameter is used) and its centre is
  // the point, so the spheres are centred on the source. Then E_ref ∝ 1/ρ² on every sphere, and so is
  // every level's irradiance: the relative errors are the same at every d. All levels sum the same
  // rays into maps of one resolution R = 64 = 4 R_patch, so each shows the √3 × noise of the test above.
  MemoryRaySource rays = point_rays(200000, 4, {0.1f, -0.2f, 0.3f});
  AplBuildOptions bo;
  bo.level_counts = {1, 8, 64};
  bo.map_resolution = 64;
  bo.orient_maps = false;  // the maps' texels must be the patches' (below), so no turned frame
  const AplSet set = build_apl_set(rays, bo);
  AplErrorOptions o;
  o.min_timing_seconds = 0;
  o.patch_subsamples = 1;
  // Patches in the photometric frame, as the maps are: their centres are texel centres of the R 64 maps' 2×2 blocks, where
  // the lookup is the texels' mean, so the level reproduces the patch sums and only the noise is measured.
  o.rotated_patches = false;
  const AplErrorReport r = evaluate_apl_errors(set, rays, o);
  EXPECT_DOUBLE_EQ(r.reference.spheres.diameter(), 1e-3);
  const double noise = r.reference.sphere[0].noise_floor;
  for (const SphereReference& s : r.reference.sphere) EXPECT_NEAR(s.noise_floor, noise, 1e-9 * noise);
  for (const LevelErrors& l : r.levels)
    for (std::size_t s = 0; s < r.reference.sphere.size(); ++s) {
      EXPECT_NEAR(l.errors[s].relative_rmse, r.levels[0].errors[0].relative_rmse, 1e-4) << l.apls << " " << s;
      EXPECT_GT(l.errors[s].relative_rmse, 1.3 * noise) << l.apls;
      EXPECT_LT(l.errors[s].relative_rmse, 2.2 * noise) << l.apls;
    }

  // With k = R_map / R_patch = 4 subsamples per patch (the automatic choice) the lookups land on the
  // centres of the 16 texels
  // under each patch, so the model's patch mean is the reference up to float rounding (a ray within an
  // ulp of a texel edge may fall on the other side in the two computations: ~1e-5 here, against the
  // √3 × 5 % above).
  o.patch_subsamples = 0;
  o.relative_distances = {0.5, 10};
  const AplErrorReport exact = evaluate_apl_errors(set, rays, o);
  for (const LevelErrors& l : exact.levels)
    for (const IrradianceErrors& e : l.errors) {
      EXPECT_EQ(l.subsamples, 4);
      EXPECT_LT(e.relative_rmse, 1e-4) << l.apls;
      EXPECT_LT(e.hellinger, 1e-3) << l.apls;
    }
}

TEST(AplErrorLevels, DeterministicWhateverTheChunkSizeAndThreadCount) {
  MemoryRaySource rays = ring_rays(60000, 21);
  const AplSet set = build_fixed(rays, 16, {1, 8, 64});
  AplErrorOptions a, b;
  a.min_timing_seconds = b.min_timing_seconds = 0;
  a.chunk_rays = 65536;
  b.chunk_rays = 777;
  a.threads = 1;
  b.threads = 3;  // more threads than cores: the split, not the machine, is what must not matter
  const AplErrorReport ra = evaluate_apl_errors(set, rays, a), rb = evaluate_apl_errors(set, rays, b);
  for (std::size_t s = 0; s < ra.reference.sphere.size(); ++s) {
    EXPECT_EQ(ra.reference.sphere[s].irradiance, rb.reference.sphere[s].irradiance);
    EXPECT_EQ(ra.reference.sphere[s].noise_floor, rb.reference.sphere[s].noise_floor);
    for (std::size_t k = 0; k < ra.levels.size(); ++k) {
      EXPECT_EQ(ra.levels[k].irradiance[s], rb.levels[k].irradiance[s]);
      EXPECT_EQ(ra.levels[k].errors[s].relative_rmse, rb.levels[k].errors[s].relative_rmse);
      EXPECT_EQ(ra.levels[k].errors[s].hellinger, rb.levels[k].errors[s].hellinger);
    }
  }
  for (std::size_t k = 0; k < ra.levels.size(); ++k) {
    EXPECT_EQ(ra.levels[k].clamped, rb.levels[k].clamped);
    // Timed on one thread only: one untimed pass over three threads reports no time.
    EXPECT_GT(ra.levels[k].ns_per_evaluation, 0);
    EXPECT_TRUE(std::isnan(rb.levels[k].ns_per_evaluation));
  }
  // With a timing asked for, the points run on three threads and the timing repeats on one.
  b.min_timing_seconds = 1e-6;
  const LevelErrors timed = evaluate_level(set, 2, rb.reference, b);
  EXPECT_EQ(timed.irradiance, rb.levels[2].irradiance);
  EXPECT_GT(timed.ns_per_evaluation, 0);
}

// The fit grades every candidate at one resolution through the lookups of the first: the same bits as
// evaluate_level, for maps of other values, in a turned frame, with clamped distances, and with the
// lookups of a third of the points (a memory budget); another layout, other irradiance options or another
// reference are refused.
TEST(AplErrorLevels, LookupsKeptForALayoutGiveEvaluateLevelsBits) {
  MemoryRaySource rays = ring_rays(60000, 23);
  AplSet set = build_fixed(rays, 16, {1, 8, 64});
  AplErrorOptions o;
  o.min_timing_seconds = 0;
  o.irradiance.min_distance = 0.5 * set.bounds.radius;  // points at d = 0.5 come that close to APLs
  const ReferenceIrradiance ref = gather_reference(rays, set.bounds, o);
  for (const bool turned : {false, true}) {
    if (turned) set.levels[2].frame.to_map = glm::mat3(glm::rotate(glm::mat4(1.0f), 0.7f, glm::normalize(glm::vec3(1, 2, 3))));
    ASSERT_EQ(set.levels[2].frame.is_identity(), !turned);
    const lumx::detail::LevelLookups lookups(set, 2, ref, o);
    const double all_bytes = lumx::detail::LevelLookups::bytes_for(set, 2, ref);
    const lumx::detail::LevelLookups third(set, 2, ref, o, all_bytes / 3);
    ASSERT_GT(third.points_looked_up(), 0u);
    ASSERT_LT(3 * third.points_looked_up(), lookups.points_looked_up() + 3);
    EXPECT_EQ(lumx::detail::LevelLookups(set, 2, ref, o, all_bytes).points_looked_up(), lookups.points_looked_up());
    for (int candidate = 0; candidate < 2; ++candidate) {
      if (candidate == 1)  // other values in the same layout, as a smoothing gives
        for (Apl& a : set.levels[2].apls)
          for (std::size_t t = 0; t < a.map.texel_count() * std::size_t(a.map.channels()); ++t)
            a.map.data()[t] *= 1.0f + 0.5f * std::sin(float(t));
      for (const unsigned threads : {1u, 2u}) {
        o.threads = threads;
        const LevelErrors direct = evaluate_level(set, 2, ref, o), kept = lookups.evaluate(set, 2, ref, o);
        EXPECT_EQ(kept.irradiance, direct.irradiance) << turned << candidate << threads;
        EXPECT_EQ(kept.clamped, direct.clamped);
        const LevelErrors part = third.evaluate(set, 2, ref, o);
        EXPECT_EQ(part.irradiance, direct.irradiance) << turned << candidate << threads;
        EXPECT_EQ(part.clamped, direct.clamped);
        EXPECT_GT(kept.clamped, 0u);
        for (std::size_t s = 0; s < ref.sphere.size(); ++s)
          EXPECT_EQ(kept.errors[s].relative_rmse, direct.errors[s].relative_rmse);
      }
    }
    AplSet moved = set;
    moved.levels[2].apls[0].position.x += 1e-3f;
    EXPECT_THROW(lookups.evaluate(moved, 2, ref, o), std::invalid_argument);
    AplSet coarser = set;
    coarser.levels[2] = downsampled_level(set.levels[2], 8);
    EXPECT_THROW(lookups.evaluate(coarser, 2, ref, o), std::invalid_argument);
    AplErrorOptions closer = o, facing = o;
    closer.irradiance.min_distance *= 0.5;
    facing.irradiance.ignore_normal = true;
    EXPECT_THROW(lookups.evaluate(set, 2, ref, closer), std::invalid_argument);
    EXPECT_THROW(lookups.evaluate(set, 2, ref, facing), std::invalid_argument);
    AplErrorOptions other = o;
    other.relative_distances = {1, 2};
    const ReferenceIrradiance other_ref = gather_reference(rays, set.bounds, other);
    EXPECT_THROW(lookups.evaluate(set, 2, other_ref, o), std::invalid_argument);
  }
}

// ---------------------------------------------------------------------------------------------------------
// Error tables

TEST(AplErrorTables, FilledTablesRoundTripThroughABundle) {
  MemoryRaySource rays = ring_rays(60000, 31);
  AplSet set = build_fixed(rays, 16, {1, 8, 64});
  AplErrorOptions o;
  o.min_timing_seconds = 0;
  const AplErrorReport r = evaluate_apl_errors(set, rays, o);
  store_error_tables(set, r);
  EXPECT_TRUE(check_apl_set(set).empty());
  for (std::size_t k = 0; k < set.levels.size(); ++k) {
    const ErrorTable& t = set.levels[k].error;
    ASSERT_EQ(t.relative_distance, (std::vector<double>{0.5, 0.75, 1, 2, 5, 10}));
    // Stored: the noise-removed point error where the rays resolve it, else its upper bound.
    for (std::size_t s = 0; s < t.relative_rmse.size(); ++s) {
      const IrradianceErrors& e = r.levels[k].errors[s];
      EXPECT_EQ(t.relative_rmse[s], e.resolved ? e.relative_rmse_noise_removed : e.noise_removed_upper);
      EXPECT_GE(t.relative_rmse[s], e.relative_rmse_noise_removed);
    }
  }
  const fs::path dir = fs::temp_directory_path() / ("lumx_apl_error_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  write_bundle(dir.string(), set);
  const BundleReader reader(dir.string());
  const AplSet loaded = reader.load();
  ASSERT_EQ(loaded.levels.size(), set.levels.size());
  for (std::size_t k = 0; k < set.levels.size(); ++k) {
    EXPECT_EQ(reader.manifest().levels[k].error.relative_distance, set.levels[k].error.relative_distance);
    EXPECT_EQ(reader.manifest().levels[k].error.relative_rmse, set.levels[k].error.relative_rmse);
    EXPECT_EQ(loaded.levels[k].error.relative_rmse, set.levels[k].error.relative_rmse);
  }
  // The error-target rule reads them: near the ring 1 APL misses 10 %, 64 APLs meet it.
  EXPECT_GT(interpolated_error(loaded.levels[0].error, 0.5), 0.1);
  const double between = 0.5 * (r.levels[1].errors[0].relative_rmse + r.levels[2].errors[0].relative_rmse);
  EXPECT_EQ(choose_level_for_error(loaded, 0.5, between), 2u);
  EXPECT_EQ(choose_level_for_error(loaded, 10, 1.0), 0u);
  fs::remove_all(dir);

  // A report of another set is refused.
  AplSet other = set;
  other.levels.pop_back();
  EXPECT_THROW(store_error_tables(other, r), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------------------
// A measured rayset

namespace {

/// Honest targets for one measured rayset, built with the defaults at 1, 8, 64 and 512 APLs from the
/// even rays (resolutions fitted on rays 1, 5, 9, …) and graded at points against rays 3, 7, 11, …:
///  - no level is reported below the rays' noise floor: the raw error of a model independent of the
///    reference is √(ε̂² + σ²) ≥ σ; 0.9 σ allows the floor's own estimation error (its relative standard
///    error is about 1/√(2N) = 3 % for N = 512 patches, the rest is the model's);
///  - near the luminaire (d ≤ 1) the finest level is no worse than one APL, within `step_tolerance` × σ
///    (the model's own noise from half the rays differs between levels).
/// Prints the table; returns the report.
AplErrorReport expect_noise_floor_targets(RaySource& rays, double step_tolerance) {
  AplBuildOptions bo;
  bo.level_counts = {1, 8, 64, 512};
  bo.threads = 2;
  AplErrorOptions o;
  o.min_timing_seconds = 0;
  const AplErrorReport r =
      evaluate_held_out_fitted(rays, [&](RaySource& train) { return build_apl_set(train, half_rays_build_options(bo, rays.info().ray_count)); }, o);
  EXPECT_EQ(r.levels.size(), 4u);
  if (r.levels.size() != 4) return r;
  std::printf("%s\n", rays.info().file.c_str());
  for (const LevelErrors& l : r.levels) {
    std::printf("  %4zu APLs R %3d:", l.apls, l.map_resolution);
    for (const IrradianceErrors& e : l.errors)
      std::printf(" %6.2f%s", 100 * (e.resolved ? e.relative_rmse_noise_removed : e.noise_removed_upper), e.resolved ? " " : "<");
    std::printf("\n");
  }
  std::printf("  noise floor    :");
  for (const SphereReference& sr : r.reference.sphere) std::printf(" %6.2f ", 100 * sr.noise_floor);
  std::printf("\n  reference      :");
  for (const SphereReference& sr : r.reference.sphere) std::printf(" %7s", sr.centred ? "centre" : "mean");
  std::printf("\n");
  for (std::size_t s = 0; s < r.reference.sphere.size(); ++s) {
    const double d = r.reference.sphere[s].relative_distance, noise = r.reference.sphere[s].noise_floor;
    for (const LevelErrors& l : r.levels) EXPECT_GE(l.errors[s].relative_rmse, 0.9 * noise) << l.apls << " " << d;
    // Compared raw: both against the same reference, so its noise adds the same σ² to both.
    const auto err = [&](std::size_t k) { return r.levels[k].errors[s].relative_rmse; };
    if (d <= 1) {
      EXPECT_LE(err(3), err(0) + step_tolerance * noise) << d;
    }
  }
  return r;
}

}  // namespace

TEST(AplErrorMeasured, OsramBlueLedMeetsTheNoiseFloor) {
  // The measured OSRAM LERTDUW blue LED (100 k rays, ../shared/data/raysets, read in place; the test
  // below covers every real file): the error falls strictly with the level near the LED, and 512 APLs
  // stay within 1.5 × the noise floor at d ≥ 1 (measured ≤ 0.51×). With the dissertation's placement the
  // far-field row is level 0 exactly (one APL at the bounding-sphere centre).
  fs::path file;
  for (const fs::path& f : lumx_rays::real_ray_files())
    if (f.filename().string().find("LERTDUW_S2WP_blue_100k") != std::string::npos) file = f;
  if (file.empty()) LUMX_SKIP_WITHOUT_SHARED("data/raysets");
  const auto rays = open_rayset(file.string());
  const AplErrorReport r = expect_noise_floor_targets(*rays, 0.1);
  // 25 k rays grade (rays 3, 7, 11, …): the floor is about 2× the 4–9 % of all 100 k.
  for (const SphereReference& sphere : r.reference.sphere) {
    EXPECT_GT(sphere.noise_floor, 0.08) << sphere.relative_distance;
    EXPECT_LT(sphere.noise_floor, 0.18) << sphere.relative_distance;
  }
  AplBuildOptions bo;
  bo.level_counts = {1, 8};
  bo.place_at_convergence = false;
  AplErrorOptions o;
  o.min_timing_seconds = 0;
  const AplErrorReport classic = evaluate_apl_errors(build_apl_set(*rays, bo), *rays, o);
  for (std::size_t s = 0; s < classic.reference.sphere.size(); ++s)
    EXPECT_NEAR(classic.far_field.errors[s].relative_rmse, classic.levels[0].errors[s].relative_rmse,
                1e-4 * classic.levels[0].errors[s].relative_rmse) << s;
}

TEST(AplErrorMeasured, RealTm25FilesMeetTheNoiseFloor) {
  // The same targets on every real TM-25 file of ../shared/data/raysets. A step up of a tenth of the
  // floor is allowed (measured at most +0.38 % on the green LED at d = 0.75, floor 7.2 %).
  std::vector<fs::path> files;
  for (const fs::path& f : lumx_rays::real_ray_files()) {
    std::string ext = f.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".tm25ray") files.push_back(f);
  }
  if (files.empty()) LUMX_SKIP_WITHOUT_SHARED("data/raysets");
  EXPECT_GE(files.size(), 6u);
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.filename().string());
    const auto rays = open_rayset(file.string());
    expect_noise_floor_targets(*rays, 0.1);
  }
}
