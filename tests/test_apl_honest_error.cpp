// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The held-out, point-query error estimate of lumx/apl/error.h against the truth: analytic emitters whose
// irradiance is computed without rays (tests/analytic_emitters.h).
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/far_field.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/rays/far_field.h>
#include <lumx/rays/holdout.h>

#include <gtest/gtest.h>

#include "analytic_emitters.h"

#include <cstdio>
#include <cstdlib>
#include <memory>

using namespace lumx;
using namespace lumx_test;

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr std::uint64_t kSuiteRays = 200000;  // the sanitizer build checks agreement on fewer rays
#else
constexpr std::uint64_t kSuiteRays = 1000000;  // the targets are stated for 1 M rays
#endif

PlanarEmitter lambertian_disk() { return {"Lambertian disk r = 0.1 m", PlanarEmitter::Shape::disk, 0.1, 0, 1, 1000}; }
PlanarEmitter lambertian_rectangle() {
  return {"Lambertian rectangle 1.2 x 0.3 m", PlanarEmitter::Shape::rectangle, 0.6, 0.15, 1, 4000};
}
PlanarEmitter spot(double m) {
  return {"cos^" + std::to_string(int(m)) + " spot r = 2 cm", PlanarEmitter::Shape::disk, 0.02, 0, m, 800};
}
PinholeBox pinhole_box() {
  using H = PinholeBox::Hole;
  return {"two point sources in a 10 cm box with four holes", 0.05,
          {H{2, 1, -0.03, 0.01, -0.02, 0.03}, H{2, -1, 0.0, 0.03, -0.03, 0.0}, H{0, 1, -0.04, -0.01, -0.01, 0.03},
           H{1, -1, -0.02, 0.02, -0.045, -0.02}},
          {{{-0.02, 0.01, 0.0}, 500}, {{0.015, -0.01, 0.01}, 500}}};
}

/// The exact irradiance at every evaluation point (k = 1: the patch centres) and its mean over each patch
/// (k×k sub-points), per sphere.
struct ExactOnSpheres {
  std::vector<std::vector<double>> at_centre, patch_mean;
};
ExactOnSpheres exact_on_spheres(const AnalyticEmitter& em, const MeasurementSpheres& ms, int k) {
  ExactOnSpheres out;
  const std::vector<glm::dvec3> centres = ms.evaluation_directions(1), sub = ms.evaluation_directions(k);
  const std::size_t k2 = std::size_t(k * k);
  for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
    auto at = [&](const glm::dvec3& u) { return em.irradiance(glm::dvec3(glm::vec3(ms.centre() + ms.radius(s) * u)), -u); };
    std::vector<double> c(centres.size()), m(centres.size(), 0.0);
    for (std::size_t p = 0; p < centres.size(); ++p) {
      c[p] = at(centres[p]);
      for (std::size_t j = 0; j < k2; ++j) m[p] += at(sub[p * k2 + j]) / double(k2);
    }
    out.at_centre.push_back(std::move(c));
    out.patch_mean.push_back(std::move(m));
  }
  return out;
}

/// Relative RMSE of a row's point values against exact values, per sphere.
std::vector<double> true_errors(const std::vector<std::vector<double>>& exact, const LevelErrors& row) {
  std::vector<double> out;
  for (std::size_t s = 0; s < exact.size(); ++s) out.push_back(compare_irradiance(exact[s], row.irradiance[s]).relative_rmse);
  return out;
}

}  // namespace

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

std::unique_ptr<AnalyticEmitter> suite_emitter(int i) {
  switch (i) {
    case 0: return std::make_unique<PlanarEmitter>(lambertian_disk());
    case 1: return std::make_unique<PlanarEmitter>(lambertian_rectangle());
    case 2: return std::make_unique<PlanarEmitter>(spot(20));
    case 3: return std::make_unique<PlanarEmitter>(spot(50));
    default: return std::make_unique<PinholeBox>(pinhole_box());
  }
}

bool smooth_at_patch_scale(int i) { return i <= 1; }

// Printed per level and distance: the error against the exact irradiance at the patch centres / against
// the exact patch means / the held-out estimate with the noise removed ('<': an upper bound).
TEST_P(HonestErrorSuite, HeldOutEstimateAgreesWithTheTrueError) {
#if defined(__SANITIZE_ADDRESS__)
  // Under the sanitizer (about 10× slower) the box with holes exercises every code path (holes, shadows,
  // every level); the other emitters' agreement is checked by the release build.
  if (GetParam() != 4) GTEST_SKIP() << "release build only (sanitizer build: the box with holes)";
#endif
  const std::unique_ptr<AnalyticEmitter> em = suite_emitter(GetParam() % 5);
  auto rays = em->source(kSuiteRays, 11 + std::uint64_t(GetParam()));
  AplBuildOptions bo;
  bo.threads = 2;
  AplErrorOptions eo;
  const bool fit = GetParam() < 5;
  ResolutionChoice choice;
  const AplErrorReport r =
      fit ? evaluate_held_out_fitted(*rays, [&](RaySource& train) { return build_apl_set(train, half_rays_build_options(bo, rays->info().ray_count)); },
                                     eo, &choice)
          : evaluate_held_out(*rays, [&](RaySource& train) { return build_apl_set(train, bo); }, eo);
  const ExactOnSpheres exact = exact_on_spheres(*em, r.reference.spheres, GetParam() % 5 >= 2 ? 8 : 5);  // lobes narrower than a patch: 8 x 8
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
      // The reference measures patch means, so the estimate is of the point error against the exact
      // patch mean: within ±25 % of it where resolved, else an upper bound of it. To the 25 % is added
      // three standard errors of the estimate itself (u on ε̂², so 3u/(ε̂ + ε) on ε̂): with 1 M rays it
      // is a few tenths of a percent, with the sanitizer build's 200 k rays up to 1.5 points.
      const double slack = [&](double truth_value) {
        return 0.25 * truth_value + 3 * e.noise_removed_standard_error /
                                        std::max(1e-12, e.relative_rmse_noise_removed + truth_value);
      }(truth_mean[s]);
      if (e.resolved) {
        EXPECT_NEAR(e.relative_rmse_noise_removed, truth_mean[s], slack) << where;
      } else {
        // An upper bound (two standard errors) holds the truth but for the issue's ±25 % agreement: one
        // of the ~200 comparisons here is 1 % over its bound (rectangle, 8 APLs, d = 1: 3.16 against 3.13).
        EXPECT_LE(0.75 * truth_mean[s], e.noise_removed_upper) << where;
      }
      // Where the irradiance is smooth across a patch (the Lambertian emitters) the patch mean is the
      // centre's value to second order, and the estimate is that of the point error itself.
      if (!fit && smooth_at_patch_scale(GetParam() % 5) && e.resolved) {
        EXPECT_NEAR(e.relative_rmse_noise_removed, truth[s],
                    0.25 * truth[s] + 3 * e.noise_removed_standard_error /
                                          std::max(1e-12, e.relative_rmse_noise_removed + truth[s])) << where;
      }
    }
    std::printf("\n");
  }
  std::printf("  noise floor        :");
  for (const auto& s : r.reference.sphere) std::printf("  %5.2f      ", 100 * s.noise_floor);
  std::printf("\n");
}

// 0–4: maps at the resolution fitted on held-out rays (the default of lumx build); 5, 6: the disk and the
// rectangle at the builder's resolution, finer than the patches.
INSTANTIATE_TEST_SUITE_P(Emitters, HonestErrorSuite, ::testing::Range(0, 7));

// What lumx build ships (every ray, resolutions fitted on held-out rays) against the exact irradiance at
// the patch centres, per level and distance: the figures the targets are stated for.
class ShippedSetSuite : public ::testing::TestWithParam<int> {};

TEST_P(ShippedSetSuite, AgainstExactIrradiance) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "release build only (the sanitizer build runs the held-out suite's disk and box)";
#endif
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
    std::printf("  %4zu APLs R %3d σ %4.1f°%s:", set.levels[k].size(), set.levels[k].map_resolution,
                choice.kappa.at(k) > 0 ? 180.0 / kPi / std::sqrt(choice.kappa.at(k)) : 0.0,
                choice.sharpened.at(k) ? " sharpened" : "");
    for (double e : levels.back()) std::printf(" %6.2f", 100 * e);
    std::printf("\n");
  }
  const std::vector<double> far = row_errors([&](const glm::vec3& x, const glm::vec3& n) { return far_field_irradiance(set, x, n); });
  std::printf("  far field       :");
  for (double e : far) std::printf(" %6.2f", 100 * e);
  std::printf("\n");
  // The far field attached as IES: level 0's fitted maps on the Type C grid against the rays binned on
  // that grid (2.5° × 1°), as irradiance at the d ≥ 2 points from the bounding-sphere centre.
  {
    AplSet far_set = set;
    far_set.levels[0] = fitted_level(built_level0, choice.far_field_resolution, choice.far_field_kappa,
                                     choice.far_field_sharpened);
    std::printf("  far field maps fitted at d = 5, 10: R %d, kernel κ %.0f%s\n", choice.far_field_resolution,
                choice.far_field_kappa, choice.far_field_sharpened ? " sharpened" : "");
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
  // The finest level at d ≥ 1, as the sharpened, fitted maps reach it (docs/apl_sets.md): the disk
  // 1.89-1.96 % (the target, 2 %), the rectangle 1.95-2.07 %, the cos^20 spot 1.93-4.32 %, the
  // cos^50 spot 3.0-11.3 % (what 1 M rays allow a lobe of 0.12 sr at single points: see the docs).
  // The box with holes: 37.0-41.3 % (49.3-53.1 % when the half set's maps were one step coarser than the
  // shipped set's, so the fit could not choose the resolution the shipped set is built at).
  const double guard[] = {0.02, 0.022, 0.05, 0.125, 0.45};
  {
    for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
      if (ms.relative_distances()[s] >= 1) {
        EXPECT_LT(levels.back()[s], guard[GetParam()]) << ms.relative_distances()[s];
      }
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

TEST(ResolutionFit, FitPatchesFollowTheRays) {
  // Twice the grading resolution at least, finer while ≥ 32 rays fall in a patch on average, ≤ 64.
  EXPECT_EQ(fit_patch_resolution(16, 0), 32);
  EXPECT_EQ(fit_patch_resolution(16, 250000), 32);   // 2·64²·32 = 262 144 > 250 000
  EXPECT_EQ(fit_patch_resolution(16, 262144), 64);
  EXPECT_EQ(fit_patch_resolution(16, 100000000), 64);
  EXPECT_EQ(fit_patch_resolution(64, 100000000), 128);  // never below twice the grading resolution
}

INSTANTIATE_TEST_SUITE_P(Emitters, ShippedSetSuite, ::testing::Range(0, 5));

namespace {
// What limits the box with holes (docs/apl_sets.md): its finest level's point error with plain maps at R 64,
// 128 and 256, from 1 M and from 10 M emitted rays (112 k and 1.12 M leave the holes), against the exact
// irradiance. Ten times the rays lower the per-texel noise √10 times, yet R 128 stays at 24–31 %: the
// beams' sharp borders, read through interpolated texels from APLs that are not at the two sources, are
// the limit, not the noise. Printed, and checked against the documented 512-APL rows (to 0.01 points).
// Off by default (about 20 s):
//   build/tests/lumx_tests --gtest_also_run_disabled_tests --gtest_filter='*BordersNotRays*'
TEST(PinholeBoxStudy, DISABLED_BordersNotRaysLimitTheFinestLevel) {
  const std::unique_ptr<AnalyticEmitter> em = suite_emitter(4);
  const AplErrorOptions eo;
  // 512-APL level, d = 0.5 … 10, % (docs/apl_sets.md).
  const double documented[2][3][6] = {
      {{44.92, 46.94, 38.67, 39.99, 33.90, 37.75}, {0, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0}},
      {{41.72, 42.93, 34.63, 37.12, 32.79, 35.54}, {31.58, 31.12, 24.07, 26.59, 24.96, 25.78},
       {33.12, 34.37, 28.65, 28.53, 28.26, 23.62}}};
  int n_index = 0;
  for (const std::uint64_t n : {std::uint64_t(1000000), std::uint64_t(10000000)}) {
    auto rays = em->source(n, 15);
    int r_index = 0;
    for (const int R : {64, 128, 256}) {
      AplBuildOptions bo;
      bo.threads = 2;
      bo.map_resolution = R;
      bo.max_resolution = R;
      bo.level_counts = {2, 8, 512};
      const AplSet set = build_apl_set(*rays, bo);
      const MeasurementSpheres ms(set.bounds, eo);
      const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
      const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
      for (std::size_t k = 0; k < set.levels.size(); ++k) {
        std::printf("%8llu rays (%7llu leave), R %3d, %3zu APLs:", (unsigned long long)n,
                    (unsigned long long)rays->info().ray_count, R, set.levels[k].size());
        for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
          std::vector<double> model(dirs.size());
          for (std::size_t p = 0; p < dirs.size(); ++p)
            model[p] = luminance_of(set.channels, irradiance(set, k, glm::vec3(ms.centre() + ms.radius(s) * dirs[p]),
                                                             glm::vec3(-dirs[p])).irradiance);
          const double e = 100 * compare_irradiance(exact.at_centre[s], model).relative_rmse;
          std::printf(" %6.2f", e);
          const double doc = documented[n_index][r_index][s];
          if (k + 1 == set.levels.size() && doc > 0) {
            EXPECT_NEAR(e, doc, 0.01) << n << " rays, R " << R << ", sphere " << s;
          }
        }
        std::printf("\n");
      }
      ++r_index;
      if (n == 1000000 && R == 64) break;  // coarser rays: R 64 is what the rule gives them
    }
    ++n_index;
  }
}
}  // namespace
