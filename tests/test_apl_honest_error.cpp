// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The held-out, point-query error estimate of lumx/apl/error.h against the truth: analytic emitters whose
// irradiance is computed without rays (tests/analytic_emitters.h, tests/honest_error_support.h). The studies
// that measure the figures docs/apl_sets.md tabulates are programs in studies/, not tests.
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/far_field.h>
#include <lumx/apl/map_fit.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/rays/far_field.h>
#include <lumx/rays/holdout.h>

#include <gtest/gtest.h>

#include "honest_error_support.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <random>
#include <vector>

using namespace lumx;
using namespace lumx_test;

TEST(AnalyticEmitters, DiskQuadratureMatchesTheClosedFormOnTheAxis) {
  // On the axis of a Lambertian disk of radius a and flux Φ: E = Φ / (π (a² + h²)).
  const PlanarEmitter disk = lambertian_disk();
  for (double h : {0.01, 0.1, 1.0, 10.0}) {
    const double exact = 1000 / (kPi * (0.01 + h * h));
    EXPECT_NEAR(disk.irradiance({0, 0, h}, {0, 0, -1}), exact, 1e-6 * exact) << h;  // 48-point Gauss, peaked at h = a/10
  }
}

TEST(AnalyticEmitters, RaysCarryTheFluxAndTheIrradianceTheyPredict) {
  // The rays' flux through a far patch agrees with the quadrature within 4 binomial σ.
  const PlanarEmitter s = spot(20);
  const lumx::RayChunk rays = s.rays(400000, 7);
  const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, 0.0, 1.0));
  const double cone = 0.1;  // cos-angle window around `axis`
  double inside = 0;
  for (std::size_t i = 0; i < rays.size(); ++i)
    if (glm::dot(glm::dvec3(rays.direction(i)), axis) > std::cos(cone)) inside += rays.flux[i];
  // Far away (R = 1000 m) the flux into the cone is ∫ E dA over the cap, ≈ E(axis) · 2π(1 − cos) R².
  const double R = 1000, e = s.irradiance(R * axis, -axis);
  const double predicted = e * 2 * kPi * (1 - std::cos(cone)) * R * R;
  const double p = predicted / 800, sigma = 800 * std::sqrt(p * (1 - p) / 400000.0);
  EXPECT_NEAR(inside, predicted, 4 * sigma + 0.01 * predicted);  // 1 %: E varies across the 0.1 rad cap
}

TEST(RayHalf, SplitsByIndexAndDoublesTheFlux) {
  lumx::RayChunk c;
  for (int i = 0; i < 7; ++i) c.push_back({float(i), 0, 0}, {0, 0, 1}, 1.0f + float(i));
  lumx::RaysetInfo info;
  info.file = "seven";
  lumx::MemoryRaySource src(c, info);
  for (int part : {0, 1}) {
    RayHalf half(src, part);
    EXPECT_EQ(half.info().ray_count, part == 0 ? 4u : 3u);
    for (int pass = 0; pass < 2; ++pass) {  // rewinding starts again
      half.rewind();
      RayChunk out;
      std::vector<float> xs, fs;
      while (half.next(out, 2))
        for (std::size_t i = 0; i < out.size(); ++i) xs.push_back(out.x[i]), fs.push_back(out.flux[i]);
      ASSERT_EQ(xs.size(), half.info().ray_count);
      for (std::size_t i = 0; i < xs.size(); ++i) {
        EXPECT_EQ(xs[i], float(2 * i + std::size_t(part)));
        EXPECT_EQ(fs[i], 2.0f * (1.0f + xs[i]));
      }
    }
  }
  EXPECT_THROW(RayHalf(src, 2), std::invalid_argument);
}

TEST(HonestError, VarianceNoiseFloorAgreesWithTheHalvesScatter) {
  // Two estimates of the reference's noise: from Σ Φ² per patch, and from the even/odd halves' scatter.
  // The halves' estimate has a relative standard error of about 1/√(2N) (N = 512 patches): 3 %.
  const PlanarEmitter disk = lambertian_disk();
  auto src = disk.source(200000, 3);
  BoundingSphere b;
  b.radius = 0.1;
  const ReferenceIrradiance ref = gather_reference(*src, b);
  for (const SphereReference& s : ref.sphere) EXPECT_NEAR(s.split_noise_floor / s.noise_floor, 1.0, 0.15) << s.relative_distance;
}

class HonestErrorSuite : public ::testing::TestWithParam<int> {};

// Printed per level and distance: the error against the exact irradiance at the patch centres / against
// the exact patch means / the held-out estimate with the noise removed ('<': an upper bound).
TEST_P(HonestErrorSuite, HeldOutEstimateAgreesWithTheTrueError) {
  // 7: the box with holes as clustered APLs (point sources off), on the rays of 4.
  const bool clustered_box = GetParam() == 7;
  const int emitter = clustered_box ? 4 : GetParam() % 5;
  const std::unique_ptr<AnalyticEmitter> em = suite_emitter(emitter);
  auto rays = em->source(kSuiteRays, 11 + std::uint64_t(emitter == 4 ? 4 : GetParam()));
  AplBuildOptions bo;
  bo.threads = 2;
  bo.point_sources.enabled = !clustered_box;
  AplErrorOptions eo;
  const bool fit = GetParam() < 5 || clustered_box;
  ResolutionChoice choice;
  const AplErrorReport r =
      fit ? evaluate_held_out_fitted(*rays, [&](RaySource& train) { return build_apl_set(train, half_rays_build_options(bo, rays->info().ray_count)); },
                                     eo, &choice)
          : evaluate_held_out(*rays, [&](RaySource& train) { return build_apl_set(train, bo); }, eo);
  const ExactOnSpheres exact = exact_on_spheres(*em, r.reference.spheres, emitter >= 2 ? 8 : 5);  // lobes narrower than a patch: 8 x 8
  std::printf("%s, %llu rays, %s\n", em->name().c_str(), (unsigned long long)rays->info().ray_count,
              fit ? "resolutions fitted on rays 1, 5, 9, ..., graded on rays 3, 7, 11, ..." : "built resolutions");
  std::vector<const LevelErrors*> rows;
  for (const LevelErrors& l : r.levels) rows.push_back(&l);
  rows.push_back(&r.far_field);
  for (const LevelErrors* row : rows) {
    const std::vector<double> truth = true_errors(exact.at_centre, *row), truth_mean = true_errors(exact.patch_mean, *row);
    std::printf("  %4zu APLs R %3d:", row->apls, row->map_resolution);
    for (std::size_t s = 0; s < truth.size(); ++s) {
      const IrradianceErrors& e = row->errors[s];
      std::printf(" %5.1f/%5.1f/%5.1f%s", 100 * truth[s], 100 * truth_mean[s], 100 * e.relative_rmse_noise_removed,
                  e.resolved ? " " : "<");
      const std::string where = em->name() + ", " + std::to_string(row->apls) + " APLs, d = " +
                                std::to_string(r.reference.sphere[s].relative_distance);
      // Where the reference is moved to the patch centres (a pilot from other rays whose shape passed the
      // rays' own), the estimate is of the point error itself, what a renderer's shading point sees; where
      // it keeps its patch means, of the point error against the exact patch means. Within ±25 % of that
      // where resolved, else an upper bound of it. To the 25 % is added three standard errors of the
      // estimate itself (u on ε̂², so 3u/(ε̂ + ε) on ε̂): with 1 M rays it is a few tenths of a percent.
      const double t = r.reference.sphere[s].centred ? truth[s] : truth_mean[s];
      const double slack =
          0.25 * t + 3 * e.noise_removed_standard_error / std::max(1e-12, e.relative_rmse_noise_removed + t);
      if (e.resolved) {
        EXPECT_NEAR(e.relative_rmse_noise_removed, t, slack) << where;
      } else {
        // An upper bound (two standard errors) holds the truth but for the ±25 % agreement.
        EXPECT_LE(0.75 * t, e.noise_removed_upper) << where;
      }
    }
    std::printf("\n");
  }
  std::printf("  noise floor        :");
  for (const auto& s : r.reference.sphere) std::printf("  %5.2f      ", 100 * s.noise_floor);
  std::printf("\n  reference (shift / the pilot's shape error, upper bound, %% of the mean):");
  for (const auto& s : r.reference.sphere)
    std::printf(" %s %.1f/%.1f", s.centred ? "centre" : "mean", 100 * s.centring_shift, 100 * s.pilot_shape_error);
  std::printf("\n  border allowance, %% of the mean:");
  for (const auto& s : r.reference.sphere) std::printf(" %.1f", 100 * s.border_share);
  std::printf("\n");
  // What the shape check decides, where it matters: the spots' lobes, a few patches wide, are centred
  // from d = 1 on (their 512-APL levels, 2–7 % off at points, are 13–75 % off the exact patch means
  // there); the box's beams as masked APLs, whose borders the pilot holds as geometry, are centred at
  // every d (its 2-APL level is 55–67 % off the exact patch means); as clustered APLs, whose sharp
  // borders the pilot blurs as the levels do, they keep their patch means at every d.
  for (const SphereReference& s : r.reference.sphere) {
    if (GetParam() == 2 || GetParam() == 3) {
      EXPECT_TRUE(s.relative_distance < 1 || s.centred) << s.relative_distance;
    }
    if (GetParam() == 4) {
      EXPECT_TRUE(r.levels.back().masked);
      EXPECT_TRUE(s.centred) << s.relative_distance;
    }
    if (clustered_box) {
      EXPECT_FALSE(r.levels.back().masked);
      EXPECT_FALSE(s.centred) << s.relative_distance;
    }
  }
}

// 0–4: maps at the resolution fitted on held-out rays (the default of lumx build; 4, the box with holes,
// as point sources behind apertures: masked APLs); 5, 6: the disk and the rectangle at the builder's
// resolution, finer than the patches; 7: the box as clustered APLs (point sources off), fitted.
INSTANTIATE_TEST_SUITE_P(Emitters, HonestErrorSuite, ::testing::Range(0, 8));

// What lumx build ships (every ray, resolutions fitted on held-out rays) against the exact irradiance at
// the patch centres, per level and distance: the figures the targets are stated for.
class ShippedSetSuite : public ::testing::TestWithParam<int> {};

TEST_P(ShippedSetSuite, AgainstExactIrradiance) {
  const std::unique_ptr<AnalyticEmitter> em = suite_emitter(GetParam());
  auto rays = em->source(kSuiteRays, 11 + std::uint64_t(GetParam()));
  AplBuildOptions bo;
  bo.threads = 2;
  AplErrorOptions eo;
  // As lumx build does it: fit on held-out rays, then build from every ray and apply the fit.
  ResolutionChoice choice;
  const auto build = [&](RaySource& r) { return build_apl_set(r, bo); };
  const AplBuildOptions half_bo = half_rays_build_options(bo, rays->info().ray_count);
  const auto build_half = [&](RaySource& r) { return build_apl_set(r, half_bo); };
  const AplErrorReport held_out = evaluate_held_out_fitted(*rays, build_half, eo, &choice);
  AplSet set = build(*rays);
  const AplLevel built_level0 = set.levels.at(0);
  AplSet as_built = set;  // the resolution rule's maps, unfitted: the default before the held-out fit
  as_built.levels.erase(as_built.levels.begin(), as_built.levels.end() - 1);
  ASSERT_TRUE(apply_held_out_fit(set, held_out, &choice));
  // The fit widens two-scale only while widening helped (fit_map_resolutions): at each level and
  // resolution, a two-scale candidate is followed by a wider one only if it graded better than the one
  // before it (on the box, σ 6.7° grades worse than 3.4°, and 10.1° is not tried).
  // So do spectral and spectral per order, and on a one-APL level each tries one width.
  for (std::size_t k = 0; k < choice.tried.size(); ++k)
    for (const KernelMode mode : {KernelMode::two_scale, KernelMode::spectral, KernelMode::spectral_per_order}) {
      std::map<int, std::vector<double>> widths;  // per resolution, the costs in the order tried
      for (const FitCandidate& c : choice.tried[k])
        if (c.mode == mode) widths[c.resolution].push_back(c.cost);
      for (const auto& [R, costs] : widths) {
        for (std::size_t i = 1; i + 1 < costs.size(); ++i)
          EXPECT_LT(costs[i], costs[i - 1]) << "level " << k << ", R " << R << ": widened after a worse width";
        if (set.levels[k].size() <= 1) {
          EXPECT_LE(costs.size(), mode == KernelMode::two_scale ? 0u : 1u) << "level " << k;
        }
      }
    }
  const MeasurementSpheres ms(set.bounds, eo);
  const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
  const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
  std::printf("%s, %llu rays, shipped set: point error against the exact irradiance, %%\n", em->name().c_str(),
              (unsigned long long)rays->info().ray_count);
  const auto row_errors = [&](auto&& value_at) {
    std::vector<double> out;
    for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
      std::vector<double> model(dirs.size());
      for (std::size_t p = 0; p < dirs.size(); ++p)
        model[p] = value_at(glm::vec3(ms.centre() + ms.radius(s) * dirs[p]), glm::vec3(-dirs[p]));
      out.push_back(compare_irradiance(exact.at_centre[s], model).relative_rmse);
    }
    return out;
  };
  std::vector<std::vector<double>> levels;
  for (std::size_t k = 0; k < set.levels.size(); ++k) {
    levels.push_back(row_errors([&](const glm::vec3& x, const glm::vec3& n) {
      return luminance_of(set.channels, irradiance(set, k, x, n).irradiance);
    }));
    std::printf("  %4zu APLs R %3d σ %4.1f° %s:", set.levels[k].size(), set.levels[k].map_resolution,
                choice.kappa.at(k) > 0 ? 180.0 / kPi / std::sqrt(choice.kappa.at(k)) : 0.0,
                kernel_mode_name(choice.mode.at(k)));
    for (double e : levels.back()) std::printf(" %6.2f", 100 * e);
    std::printf("\n");
  }
  const std::vector<double> far = row_errors([&](const glm::vec3& x, const glm::vec3& n) { return far_field_irradiance(set, x, n); });
  std::printf("  far field       :");
  for (double e : far) std::printf(" %6.2f", 100 * e);
  std::printf("\n");
  // The far field attached as IES: level 0's fitted maps on the Type C grid against the rays binned on
  // that grid (2.5° × 1°), as irradiance at the d ≥ 2 points from the bounding-sphere centre.
  std::vector<double> ies_level0;
  {
    AplSet far_set = set;
    far_set.levels[0] = fitted_level(built_level0, choice.far_field_resolution, choice.far_field_kappa,
                                     choice.far_field_mode);
    std::printf("  far field maps fitted at d = 5, 10: R %d, kernel κ %.0f %s\n", choice.far_field_resolution,
                choice.far_field_kappa, kernel_mode_name(choice.far_field_mode));
    const Photometry from_map = far_field_photometry(far_set, 0), from_rays = far_field_from_rays(*rays);
    const IntensityTable tm(from_map), tr(from_rays);
    const auto ies_row = [&](const IntensityTable& t) {
      return row_errors([&](const glm::vec3& x, const glm::vec3& n) {
        const glm::dvec3 d = glm::dvec3(x) - set.bounds.center;
        const double r = glm::length(d);
        const glm::dvec3 w = d / r;
        return t.intensity(w) * std::max(0.0, -glm::dot(glm::dvec3(n), w)) / (r * r);
      });
    };
    const std::vector<double> e_map = ies_row(tm), e_rays = ies_row(tr);
    ies_level0 = e_map;
    std::printf("  IES, level 0  :");
    for (double e : e_map) std::printf(" %6.2f", 100 * e);
    std::printf("\n  IES, rays     :");
    for (double e : e_rays) std::printf(" %6.2f", 100 * e);
    std::printf("\n");
    const std::vector<double> before = row_errors([&](const glm::vec3& x, const glm::vec3& n) {
      return luminance_of(as_built.channels, irradiance(as_built, 0, x, n).irradiance);
    });
    std::printf("  %4zu APLs, the rule's R %d, unfitted (before):", as_built.levels[0].size(), as_built.levels[0].map_resolution);
    for (double e : before) std::printf(" %6.2f", 100 * e);
    std::printf("\n");
    // LUMX_FIGURES_DIR: the rows as CSV for scripts/plot_apl_suite.py (docs/images/apl_suite_error.png).
    if (const char* dir = std::getenv("LUMX_FIGURES_DIR")) {
      const std::string path = std::string(dir) + "/apl_suite_" + std::to_string(GetParam()) + ".csv";
      if (FILE* f = std::fopen(path.c_str(), "w")) {
        std::fprintf(f, "emitter,series,d,relative_rmse\n");
        const auto rows = [&](const char* series, const std::vector<double>& v) {
          for (std::size_t s = 0; s < v.size(); ++s)
            std::fprintf(f, "\"%s\",\"%s\",%g,%.6g\n", em->name().c_str(), series, ms.relative_distances()[s], v[s]);
        };
        rows("finest level, fitted and smoothed (shipped)", levels.back());
        rows("finest level, the rule's R (before the fit)", before);
        rows("far field, one point", far);
        rows("IES attachment from level 0's fitted maps", e_map);
        rows("IES from the rays binned on its grid (before)", e_rays);
        std::fclose(f);
      }
    }
    // For the Lambertian emitters the fitted map is over 3× better than the binned rays at d ≥ 5 (3.3
    // against 11.5 %; at d = 2 the rectangle is still 2.5 m from a 1.2 m source: 6.4 against 12 %); for
    // the spots it is mixed (docs/apl_sets.md), so only the first is asserted.
    for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
      if (GetParam() <= 1 && ms.relative_distances()[s] >= 5) {
        EXPECT_LE(e_map[s], 0.5 * e_rays[s]) << ms.relative_distances()[s];
      }
    }
  }
  // No level of several APLs is worse than the single far-field point by more than a point (its own
  // noise: the finest level's maps each hold 1/512 of the rays, the far field's all of them). The
  // one-APL level sits at its rays' convergence point instead of the bounding-sphere centre and is
  // compared in the docs (up to 0.9 % relative worse on the box at d ≤ 1).
  for (std::size_t s = 0; s < ms.sphere_count(); ++s)
    for (std::size_t k = 1; k < levels.size(); ++k)
      EXPECT_LE(levels[k][s], far[s] + 0.01) << set.levels[k].size() << " APLs, d = " << ms.relative_distances()[s];
  // The finest level at d ≥ 1, as the fitted maps reach it (docs/apl_sets.md): the disk 0.90-1.00 % and
  // the rectangle 1.02-1.08 % (local linear kernels; 1.80-1.87 % when the fit graded against patch means
  // rather than centred references, FitReference above; the target is 2 %), the cos^20 spot
  // 1.05-1.24 % (R 128, σ 5.0° spectral per order; 1.22-2.09 % spectral, 1.21-3.23 % two-scale,
  // 1.87-2.90 % extrapolated at σ 3.4°, 1.87-3.17 % sharpened, 1.93-4.32 % when the kernels stopped at
  // R 64), the cos^50 spot 1.11-1.58 % (R 128, σ 5.0° spectral per order; 1.14-2.87 % spectral,
  // 1.50-3.68 % two-scale at σ 3.4°, 2.90-4.40 % sharpened at σ 1.7°, 3.0-11.3 % with R 64 chosen against
  // patch means: studies/study_spot.cpp, more-rays). The spots' guards are the 2 % target, which the
  // per-degree pilot missed (2.09 and 2.87 % at d = 10), so losing the per-order candidate fails them.
  // The box with holes: its two point sources as masked APLs (apl/point_sources.h), the target 10 %
  // (clustered plain maps were 37.0-41.3 %, and exact maps at R 64 at the sources are 33-36 % off there:
  // studies/study_pinhole_box.cpp, exact-beams).
  const double guard[] = {0.0125, 0.0125, 0.02, 0.02, 0.10};
  for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
    const double d = ms.relative_distances()[s];
    if (d >= 1) {
      EXPECT_LT(levels.back()[s], guard[GetParam()]) << d;
    }
    // The targets for the Lambertian emitters: ≤ 5 % at d = 0.5 (1.05 and 1.84 % measured); the
    // far field, as the one-APL level (1.85/1.91 and 1.97/1.88 %) and as the attached IES (1.03/0.98 and
    // 1.42/1.10 %; sharpened 2.05/2.02 and 2.33/2.13 %), ≤ 2 % at d ≥ 5.
    if (GetParam() <= 1 && d == 0.5) {
      EXPECT_LE(levels.back()[s], 0.05);
    }
    if (GetParam() <= 1 && d >= 5) {
      EXPECT_LE(levels.front()[s], 0.02) << "one APL, d = " << d;
      EXPECT_LE(ies_level0[s], 0.02) << "IES, d = " << d;
    }
  }
}

TEST(ResolutionFit, DownsamplingKeepsEveryAplsFluxAndRefusesOtherResolutions) {
  // Equal-area texels: a box downsample is flux-exact, so each APL's flux (the map's integral) is kept.
  const PlanarEmitter disk = lambertian_disk();
  auto rays = disk.source(20000, 5);
  AplBuildOptions bo;
  bo.level_counts = {1, 8};
  bo.map_resolution = 32;
  const AplSet set = build_apl_set(*rays, bo);
  for (int R : {16, 8, 4}) {
    const AplLevel d = downsampled_level(set.levels[1], R);
    EXPECT_EQ(d.map_resolution, R);
    for (std::size_t i = 0; i < d.size(); ++i) {
      EXPECT_EQ(d.apls[i].map.resolution(), R);
      const double before = set.levels[1].apls[i].map.integral()[0], after = d.apls[i].map.integral()[0];
      EXPECT_NEAR(after, before, 1e-5 * before) << R << " " << i;
    }
  }
  EXPECT_THROW(downsampled_level(set.levels[1], 12), std::invalid_argument);
}

TEST(ResolutionFit, TheHalfSetGetsTheWholeSetsResolutions) {
  // The fit only coarsens, so the half set it grades must have the maps the whole set will have: 112 143 rays
  // give R 64, their even half R 32 by the plain rule. Halving the rays per texel instead is off at the
  // rule's edges: 65 535 rays (8 per texel: 8 191.9 texels) give R 32, their even half of 32 768 rays R 64.
  const PlanarEmitter disk = lambertian_disk();
  for (const std::uint64_t n : {std::uint64_t(65535), std::uint64_t(65536), std::uint64_t(112143)}) {
    auto rays = disk.source(n, 5);
    AplBuildOptions bo;
    bo.level_counts = {1, 8};
    const AplSet whole = build_apl_set(*rays, bo);
    RayHalf even(*rays, 0);
    const AplSet half = build_apl_set(even, half_rays_build_options(bo, n));
    AplBuildOptions halved = bo;
    halved.rays_per_texel /= 2;
    ASSERT_EQ(half.levels.size(), whole.levels.size());
    for (std::size_t k = 0; k < whole.levels.size(); ++k) {
      EXPECT_EQ(half.levels[k].map_resolution, whole.levels[k].map_resolution) << n << " rays, level " << k;
      if (n == 65535) {
        EXPECT_EQ(whole.levels[k].map_resolution, 32);
        EXPECT_EQ(map_resolution_for(double(even.info().ray_count), double(whole.levels[k].size()), halved), 64);
      }
    }
  }
}

TEST(ResolutionFit, CostDifferenceStandardErrorMatchesTheScatterOfTheDifference) {
  // As in the fit: two fixed candidates, off the truth by fixed Gaussian deviations (about 7 and 8 % of the
  // mean), graded against a reference redrawn 400 times with Gaussian noise of 10 % of the mean, the same
  // noise on both spheres (the same rays cross matching patches of every sphere). The difference of the
  // two candidates' Σ_s log ε_s scatters from draw to draw by the standard error
  // cost_difference_standard_error predicts from one draw (mean over the draws, within 10 %: the
  // scatter's own relative standard error is 1/√(2·400) = 3.5 %). Summing the spheres' variances as
  // independent would predict 1/√2 of it. Identical candidates differ by 0 ± 0.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g;
  const std::size_t n = 2048;
  std::vector<double> truth(n);
  for (double& e : truth) e = 1.0 + 0.5 * std::abs(g(rng));
  std::vector<std::vector<double>> a(2, std::vector<double>(n)), b = a;
  for (std::size_t p = 0; p < n; ++p) {
    a[0][p] = a[1][p] = truth[p] + 0.10 * g(rng);
    b[0][p] = b[1][p] = truth[p] + 0.11 * g(rng);
  }
  std::vector<double> differences, predicted;
  for (int draw = 0; draw < 400; ++draw) {
    ReferenceIrradiance ref;
    ref.sphere.resize(2);
    ref.sphere[0].irradiance.resize(n);
    for (std::size_t p = 0; p < n; ++p) ref.sphere[0].irradiance[p] = truth[p] + 0.14 * g(rng);
    ref.sphere[1].irradiance = ref.sphere[0].irradiance;
    double d = 0;
    for (std::size_t s = 0; s < 2; ++s)
      d += std::log(compare_irradiance(ref.sphere[s].irradiance, a[s]).relative_rmse) -
           std::log(compare_irradiance(ref.sphere[s].irradiance, b[s]).relative_rmse);
    differences.push_back(d);
    predicted.push_back(cost_difference_standard_error(ref, a, b));
    if (draw == 0) {
      EXPECT_EQ(cost_difference_standard_error(ref, a, a), 0.0);
    }
  }
  double mean = 0, var = 0, se = 0;
  for (double d : differences) mean += d / double(differences.size());
  for (double d : differences) var += (d - mean) * (d - mean) / double(differences.size() - 1);
  for (double p : predicted) se += p / double(predicted.size());
  std::printf("  scatter of the difference %.5f, predicted standard error %.5f\n", std::sqrt(var), se);
  EXPECT_NEAR(se, std::sqrt(var), 0.10 * std::sqrt(var));
}

TEST(ResolutionFit, FitPatchesFollowTheRays) {
  // Twice the grading resolution at least, finer while ≥ 32 rays fall in a patch on average, ≤ 64.
  EXPECT_EQ(fit_patch_resolution(16, 0), 32);
  EXPECT_EQ(fit_patch_resolution(16, 250000), 32);   // 2·64²·32 = 262 144 > 250 000
  EXPECT_EQ(fit_patch_resolution(16, 262144), 64);
  EXPECT_EQ(fit_patch_resolution(16, 100000000), 64);
  EXPECT_EQ(fit_patch_resolution(64, 100000000), 128);  // never below twice the grading resolution
}

INSTANTIATE_TEST_SUITE_P(Emitters, ShippedSetSuite, ::testing::Range(0, 5));

TEST(FitReference, ThePilotsShapeMovesPatchMeansToPatchCentres) {
  // fit_map_resolutions evaluates candidates at patch centres, the reference is a patch mean. On the fit's
  // R 32 patches a cos^50 spot's patch means are 17-26 % (eq. 5.1) from its values at the centres at d ≥ 2,
  // while their noise (250 k fitting rays) is 9 %: graded against them, candidates blurred like a patch
  // looked best. centred_reference adds a pilot's shape within each patch (centre minus k × k mean), the
  // pilot built from other rays; the result is as far from the exact centre values as the noise allows.
  // Independent errors add in quadrature, so 1.15 × the floor leaves the pilot's shape up to 0.57 × the
  // floor (5 %) of error; measured 8.4-9.4 % against a 9.0 % floor.
  const PlanarEmitter em = spot(50);
  auto rays = em.source(250000, 11), other = em.source(500000, 12);  // as the fit has them from 1 M
  AplErrorOptions eo;
  eo.patch_resolution = 32;
  AplBuildOptions bo;
  bo.level_counts = {1, 8, 64};
  const AplSet pilot_set = build_apl_set(*other, bo);
  const ReferenceIrradiance raw = gather_reference(*rays, pilot_set.bounds, eo);
  const ReferenceIrradiance centred = centred_reference(raw, centring_pilot(pilot_set), eo);
  const ExactOnSpheres exact = exact_on_spheres(em, raw.spheres, 1);
  for (std::size_t s = 0; s < raw.sphere.size(); ++s) {
    const double before = compare_irradiance(exact.at_centre[s], raw.sphere[s].irradiance).relative_rmse;
    const double after = compare_irradiance(exact.at_centre[s], centred.sphere[s].irradiance).relative_rmse;
    const double floor = raw.sphere[s].noise_floor, d = raw.sphere[s].relative_distance;
    std::printf("  d %5.2f: patch means %6.2f %%, centred %6.2f %%, noise floor %5.2f %%\n", d, 100 * before, 100 * after, 100 * floor);
    // Independent noise adds in quadrature: an unbiased reference is at √(floor² + the pilot's small error²).
    EXPECT_LT(after, 1.15 * floor) << d;
    if (d >= 2) {
      EXPECT_GT(before, 1.8 * floor) << d;
    }
  }
}

// The box's masked level on the rays of five seeds, four of them (16, 18, 19, 23) with a patch centre in
// a sliver of the graded level's beams that no mask holds (its truth 17-19 %): the upper bound holds
// each truth but for the ±25 % of HonestErrorSuite only with the border allowance (in a trial without
// it, an upper bound of 8.8-12.0 % at five of those spheres). About 20 s. The same over 20 seeds:
// studies/study_pinhole_box.cpp, masked-estimate.
TEST(PinholeBoxStudy, TheUpperBoundHoldsABorderNoMaskResolves) {
  std::vector<MaskedLevelEstimate> estimates;
  for (const std::uint64_t seed : {15, 16, 18, 19, 23}) {
    estimates.push_back(masked_level_estimate(seed));
    const MaskedLevelEstimate& m = estimates.back();
    EXPECT_TRUE(m.masked) << seed;
    // Per sphere: the truth / the estimate with the noise removed ('<': unresolved) / its upper bound, %.
    std::printf("seed %2d, R %d:", int(seed), m.map_resolution);
    for (std::size_t s = 0; s < m.truth.size(); ++s)
      std::printf(" %4.1f/%4.1f%s/%4.1f", 100 * m.truth[s], 100 * m.estimate[s], m.resolved[s] ? " " : "<", 100 * m.upper[s]);
    std::printf("\n    border allowance, %% of the mean:");
    for (const double b : m.border_share) std::printf(" %.1f", 100 * b);
    std::printf("\n");
  }
  const MaskedEstimateCounts n = count_masked_estimates(estimates);
  std::printf("%d spheres, %d with the truth above 10 %%: the upper bound below 3/4 of the truth at %d, resolved and "
              "more than 25 %% off at %d\n", n.spheres, n.spikes, n.flatters, n.resolved_off);
  EXPECT_EQ(n.spikes, 5);
  EXPECT_EQ(n.flatters, 0);
}
