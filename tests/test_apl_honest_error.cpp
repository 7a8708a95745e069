// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The held-out, point-query error estimate of lumx/apl/error.h against the truth: analytic emitters whose
// irradiance is computed without rays (tests/analytic_emitters.h).
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/far_field.h>
#include <lumx/math/direction_mask.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/rays/far_field.h>
#include <lumx/rays/holdout.h>

#include <gtest/gtest.h>

#include "analytic_emitters.h"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <cstdlib>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <random>

using namespace lumx;
using namespace lumx_test;

namespace {

constexpr std::uint64_t kSuiteRays = 1000000;  // the targets (docs/apl_sets.md) are stated for 1 M rays

PlanarEmitter lambertian_disk() { return {"Lambertian disk r = 0.1 m", PlanarEmitter::Shape::disk, 0.1, 0, 1, 1000}; }
PlanarEmitter lambertian_rectangle() {
  return {"Lambertian rectangle 1.2 x 0.3 m", PlanarEmitter::Shape::rectangle, 0.6, 0.15, 1, 4000};
}
PlanarEmitter spot(double m) {
  return {"cos^" + std::to_string(int(m)) + " spot r = 2 cm", PlanarEmitter::Shape::disk, 0.02, 0, m, 800};
}
PinholeBox pinhole_box() { return suite_pinhole_box(); }

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

/// The set lumx build ships from `rays` (two threads): fitted on held-out rays, then built from every ray
/// with the fit applied; `choice` receives the fit.
AplSet shipped_set(RaySource& rays, ResolutionChoice& choice, bool orient_maps = true) {
  AplBuildOptions bo;
  bo.threads = 2;
  bo.orient_maps = orient_maps;
  const AplBuildOptions half_bo = half_rays_build_options(bo, rays.info().ray_count);
  const AplErrorReport held_out =
      evaluate_held_out_fitted(rays, [&](RaySource& r) { return build_apl_set(r, half_bo); }, AplErrorOptions{}, &choice);
  AplSet set = build_apl_set(rays, bo);
  if (!apply_held_out_fit(set, held_out, &choice)) throw std::runtime_error("shipped_set: the fit does not apply");
  return set;
}

/// Level k's irradiance at the evaluation points `dirs` of sphere s, each queried alone as a renderer does.
std::vector<double> level_at_points(const AplSet& set, std::size_t k, const MeasurementSpheres& ms, std::size_t s,
                                    const std::vector<glm::dvec3>& dirs) {
  std::vector<double> model(dirs.size());
  for (std::size_t p = 0; p < dirs.size(); ++p)
    model[p] = luminance_of(set.channels, irradiance(set, k, glm::vec3(ms.centre() + ms.radius(s) * dirs[p]),
                                                     glm::vec3(-dirs[p])).irradiance);
  return model;
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

// Printed per level and distance: the error against the exact irradiance at the patch centres / against
// the exact patch means / the held-out estimate with the noise removed ('<': an upper bound).
TEST_P(HonestErrorSuite, HeldOutEstimateAgreesWithTheTrueError) {
#if defined(__SANITIZE_ADDRESS__)
  // An accuracy check, about ten times slower under the sanitizers (the box with holes: 137 s from 200 k
  // rays); the held-out fit and grading it runs are run there by CliBuild.EvalOnTheBundlesOwnRays…,
  // BakePasses.StopsAsSoonAs… and the ResolutionFit tests.
  GTEST_SKIP() << "release build only";
#endif
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
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "release build only (as the held-out suite)";
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
  // patch means: SpotStudy.DISABLED_WhatMoreRaysBuy). The spots' guards are the 2 % target, which the
  // per-degree pilot missed (2.09 and 2.87 % at d = 10), so losing the per-order candidate fails them.
  // The box with holes: its two point sources as masked APLs (apl/point_sources.h), the target 10 %
  // (clustered plain maps were 37.0-41.3 %, and exact maps at R 64 at the sources are 33-36 % off there:
  // PinholeBoxStudy.DISABLED_ExactBeamsAtTheSourcesBoundWhatMapsCanDo).
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
      bo.point_sources.enabled = false;  // the clustered set, as built before point sources
      const AplSet set = build_apl_set(*rays, bo);
      const MeasurementSpheres ms(set.bounds, eo);
      const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
      const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
      for (std::size_t k = 0; k < set.levels.size(); ++k) {
        std::printf("%8llu rays (%7llu leave), R %3d, %3zu APLs:", (unsigned long long)n,
                    (unsigned long long)rays->info().ray_count, R, set.levels[k].size());
        for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
          const std::vector<double> model = level_at_points(set, k, ms, s, dirs);
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

namespace {
// The representation's own floor on the box with holes: two APLs placed exactly at the two sources, each
// map the exact intensity of its source averaged over every texel (4 × 4 equal-area sub-directions per
// texel; no rays, so no noise), read as a renderer reads it (bilinear). Whatever a builder does with rays,
// a map at resolution R cannot beat this row. Printed, and checked against docs/apl_sets.md.
// Off by default (about 30 s):
//   build/tests/lumx_tests --gtest_also_run_disabled_tests --gtest_filter='*ExactBeams*'
TEST(PinholeBoxStudy, DISABLED_ExactBeamsAtTheSourcesBoundWhatMapsCanDo) {
  const PinholeBox box = pinhole_box();
  const std::unique_ptr<AnalyticEmitter> em = suite_emitter(4);
  const AplErrorOptions eo;
  // The measurement spheres of the set the builder makes from the suite's rays (the same bounds).
  AplBuildOptions bo;
  bo.threads = 2;
  bo.level_counts = {2};
  const AplSet built = build_apl_set(*em->source(kSuiteRays, 15), bo);
  const MeasurementSpheres ms(built.bounds, eo);
  const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
  const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
  const std::vector<PinholeBox::Source> sources = {{{-0.02, 0.01, 0.0}, 500}, {{0.015, -0.01, 0.01}, 500}};
  // docs/apl_sets.md, d = 0.5 … 10, %: bilinear at R 64 … 1024, then nearest texel at R 1024.
  const double documented[6][6] = {{40.96, 42.09, 33.00, 35.92, 32.63, 34.96}, {29.88, 29.05, 20.97, 23.33, 23.45, 23.71},
                                   {22.90, 22.28, 15.16, 16.17, 18.51, 14.59}, {15.57, 19.16, 11.26, 10.39, 17.28, 11.74},
                                   {11.47, 14.57, 3.54, 10.78, 16.34, 8.99},   {14.76, 7.09, 0.94, 9.50, 16.35, 0.00}};
  int row = 0;
  for (const int R : {64, 128, 256, 512, 1024}) {
    AplSet set;
    set.bounds = built.bounds;
    set.levels.resize(1);
    set.levels[0].map_resolution = R;
    for (const PinholeBox::Source& s : sources) {
      // One source alone behind the same holes: visible in w iff its far irradiance along w is non-zero.
      const PinholeBox one("one source", 0.05, box.holes(), {s});
      Apl a;
      a.position = glm::vec3(s.p);
      a.map = SphereMap(R, 1);
      constexpr int kSub = 4;
      for (int y = 0; y < R; ++y)
        for (int x = 0; x < 2 * R; ++x) {
          int lit = 0;
          for (int j = 0; j < kSub; ++j)
            for (int i = 0; i < kSub; ++i) {
              const glm::vec2 uv((float(x) + (float(i) + 0.5f) / kSub) / float(2 * R),
                                 (float(y) + (float(j) + 0.5f) / kSub) / float(R));
              const glm::dvec3 w = glm::normalize(glm::dvec3(sphere_map::uv_to_direction(uv)));
              lit += one.irradiance(s.p + 100.0 * w, -w) > 0;
            }
          a.map.at(x, y, 0) = float(s.flux / (4 * kPi) * lit / (kSub * kSub));
        }
      a.flux = a.map.integral();
      set.levels[0].apls.push_back(std::move(a));
    }
    std::printf("exact beams at the sources, R %4d:", R);
    for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
      const std::vector<double> model = level_at_points(set, 0, ms, s, dirs);
      const double e = 100 * compare_irradiance(exact.at_centre[s], model).relative_rmse;
      std::printf(" %6.2f", e);
      EXPECT_NEAR(e, documented[row][s], 0.01) << "R " << R << ", sphere " << s;
      // How few points carry the error: the fewest whose squared errors make 90 % of the sum; and the
      // lit points' mean irradiance over the sphere's mean.
      std::vector<double> sq(dirs.size());
      double total = 0, lit_sum = 0, all_sum = 0;
      std::size_t lit = 0;
      for (std::size_t p = 0; p < dirs.size(); ++p) {
        sq[p] = (model[p] - exact.at_centre[s][p]) * (model[p] - exact.at_centre[s][p]);
        total += sq[p];
        all_sum += exact.at_centre[s][p];
        if (exact.at_centre[s][p] > 0) lit_sum += exact.at_centre[s][p], ++lit;
      }
      std::sort(sq.begin(), sq.end(), std::greater<double>());
      std::size_t carriers = 0;
      for (double acc = 0; carriers < sq.size() && acc < 0.9 * total; ++carriers) acc += sq[carriers];
      std::printf(" [%zu pts, lit %zu, %.1f×]", carriers, lit, (lit_sum / double(lit)) / (all_sum / double(dirs.size())));
    }
    std::printf("   (%zu points per sphere)\n", dirs.size());
    // The same maps read at the nearest texel (a staircase border instead of a one-texel ramp).
    std::printf("                 nearest texel:");
    for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
      std::vector<double> model(dirs.size(), 0.0);
      for (std::size_t p = 0; p < dirs.size(); ++p) {
        const glm::dvec3 x = ms.centre() + ms.radius(s) * dirs[p];
        for (const Apl& a : set.levels[0].apls) {
          const glm::dvec3 d = x - glm::dvec3(a.position);
          const double r = glm::length(d);
          const glm::dvec3 w = d / r;
          const double cosine = glm::dot(dirs[p], w);
          if (cosine > 0) model[p] += a.map.lookup_nearest(glm::vec3(w)).x * cosine / (r * r);
        }
      }
      const double e = 100 * compare_irradiance(exact.at_centre[s], model).relative_rmse;
      std::printf(" %6.2f", e);
      if (R == 1024) {
        EXPECT_NEAR(e, documented[5][s], 0.01) << "nearest texel, sphere " << s;
      }
    }
    std::printf("\n");
    ++row;
  }
}
}  // namespace

namespace {
/// m: the distance from point c to the line through o along unit w (double: the study's tolerances reach
/// 10⁻⁷ m, below a float's resolution of these coordinates).
double distance_to_line(const glm::dvec3& c, const glm::dvec3& o, const glm::dvec3& w) {
  const glm::dvec3 v = c - o;
  return glm::length(v - glm::dot(v, w) * w);
}

// Borders as geometry on the box with holes (docs/apl_sets.md, "Beam masks"): each APL's map read inside a
// DirectionMask (lumx/math/direction_mask.h), the hull of the directions of every ray whose line passes
// through the APL's position, normalised by the mask's coverage of its texels. Three sets, against the
// exact irradiance at the same 512 points per sphere:
//   * two APLs at the two sources, maps binned from the suite's rays (no kernel), R 16, 32, 64, plain
//     and masked: what masks do once the APLs sit where the light comes from;
//   * the builder's 512-APL level with plain maps at R 16, 32, 64 (R 64: the maps of BordersNotRays),
//     each APL masked by the lines through it within 1/1000 of the bounding radius when at least 500 pass;
//   * the same level with every ray moved to the APL its line passes nearest, maps binned again: a
//     placement step the builder does not have. Its rows equal the two-at-the-sources rows: every ray
//     then belongs to an APL on its source, and APLs at one point with one mask add up to one light.
// Printed, and checked against the documented rows (to 0.01 points). Off by default (about 10 s):
//   build/tests/lumx_tests --gtest_also_run_disabled_tests --gtest_filter='*BeamMasks*'
TEST(PinholeBoxStudy, DISABLED_BeamMasksDrawTheBordersTheMapsCannot) {
  const std::unique_ptr<AnalyticEmitter> em = suite_emitter(4);
  const PinholeBox box = pinhole_box();
  const AplErrorOptions eo;
  auto rays = em->source(kSuiteRays, 15);
  AplBuildOptions bo;
  bo.threads = 2;
  bo.map_resolution = 64;
  bo.max_resolution = 64;
  bo.level_counts = {2, 8, 512};
  bo.point_sources.enabled = false;  // the clustered set the study masks by hand
  const AplSet set = build_apl_set(*rays, bo);
  const MeasurementSpheres ms(set.bounds, eo);
  const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
  const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
  std::vector<glm::dvec3> origin, direction;
  double ray_flux = 0;
  {
    RayChunk c;
    rays->rewind();
    while (rays->next(c, 1 << 16))
      for (std::size_t i = 0; i < c.size(); ++i) {
        origin.emplace_back(c.position(i));
        direction.emplace_back(c.direction(i));
        ray_flux = c.flux[i];
      }
  }
  // One light: a position, its map in the frame map_to_world turns to the photometric one, and maybe a mask.
  struct Light {
    glm::dvec3 position;
    const SphereMap* map;
    glm::mat3 to_map;
    const DirectionMask* mask = nullptr;
    const SphereMap* coverage = nullptr;  // the mask's, at the map's resolution
  };
  const auto errors = [&](const std::vector<Light>& lights) {
    std::vector<double> out;
    for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
      std::vector<double> model(dirs.size(), 0.0);
      for (std::size_t p = 0; p < dirs.size(); ++p) {
        const glm::dvec3 x = glm::dvec3(glm::vec3(ms.centre() + ms.radius(s) * dirs[p]));
        for (const Light& l : lights) {
          const glm::dvec3 d = x - l.position;
          const double r = glm::length(d);
          const glm::dvec3 w = d / r;
          const double cosine = glm::dot(dirs[p], w);
          if (cosine <= 0) continue;
          const glm::vec3 m = l.to_map * glm::vec3(w);
          const double i = l.mask ? l.mask->normalised_lookup(*l.map, *l.coverage, m, w).x : l.map->lookup(m).x;
          model[p] += i * cosine / (r * r);
        }
      }
      out.push_back(100 * compare_irradiance(exact.at_centre[s], model).relative_rmse);
    }
    return out;
  };
  const auto print_and_check = [&](const char* what, const std::vector<double>& e, const double* doc) {
    std::printf("%-34s", what);
    for (const double v : e) std::printf(" %6.2f", v);
    std::printf("\n");
    for (std::size_t s = 0; s < e.size(); ++s) EXPECT_NEAR(e[s], doc[s], 0.01) << what << ", sphere " << s;
  };
  // docs/apl_sets.md, d = 0.5 … 10, %.
  const double at_sources[3][2][6] = {{{86.04, 78.92, 75.79, 74.01, 73.47, 76.76}, {5.58, 4.96, 4.83, 6.01, 5.76, 5.85}},
                                      {{59.89, 56.27, 51.25, 52.66, 49.24, 52.79}, {10.08, 10.92, 10.46, 9.15, 9.01, 8.92}},
                                      {{42.97, 45.08, 37.67, 39.93, 33.91, 37.76}, {17.98, 18.28, 18.73, 21.28, 18.86, 17.58}}};
  const double builder_level[3][3][6] = {
      {{86.79, 79.06, 76.12, 73.99, 73.39, 76.72}, {33.17, 32.99, 30.18, 29.67, 29.99, 30.76}, {5.58, 4.96, 4.83, 6.01, 5.76, 5.85}},
      {{60.90, 56.34, 51.56, 52.82, 49.28, 52.81}, {26.59, 23.31, 20.38, 20.20, 22.84, 23.54}, {10.08, 10.92, 10.46, 9.15, 9.01, 8.92}},
      {{44.92, 46.94, 38.67, 39.99, 33.90, 37.75}, {25.22, 26.81, 25.25, 24.15, 23.65, 23.06}, {17.98, 18.28, 18.73, 21.28, 18.86, 17.58}}};
  // Two APLs at the sources: each ray belongs to the source its line passes through.
  const std::vector<glm::dvec3> sources = {{-0.02, 0.01, 0.0}, {0.015, -0.01, 0.01}};
  std::vector<std::vector<glm::dvec3>> from(2);
  for (std::size_t j = 0; j < origin.size(); ++j)
    for (std::size_t t = 0; t < 2; ++t) {
      if (distance_to_line(sources[t], origin[j], direction[j]) < 1e-5) {
        from[t].push_back(direction[j]);
        break;
      }
    }
  ASSERT_EQ(from[0].size() + from[1].size(), origin.size());
  std::vector<DirectionMask> source_masks;
  for (std::size_t t = 0; t < 2; ++t) {
    std::string why;
    const auto m = DirectionMask::from_directions(from[t], {}, &why);
    ASSERT_TRUE(m) << why;
    EXPECT_EQ(m->caps().size(), 4u);  // every hole lets each source out
    source_masks.push_back(*m);
  }
  int row = 0;
  for (const int R : {16, 32, 64}) {
    std::vector<SphereMap> maps(2, SphereMap(R, 1));
    for (std::size_t t = 0; t < 2; ++t)
      for (const glm::dvec3& w : from[t]) {
        int x, y;
        maps[t].texel_of(glm::vec3(w), x, y);
        maps[t].at(x, y, 0) += float(ray_flux / maps[t].texel_solid_angle());
      }
    const std::vector<SphereMap> covers = {source_masks[0].coverage(R, glm::mat3(1.0f), 8),
                                           source_masks[1].coverage(R, glm::mat3(1.0f), 8)};
    for (const bool masked : {false, true}) {
      std::vector<Light> lights(2);
      for (std::size_t t = 0; t < 2; ++t)
        lights[t] = {sources[t], &maps[t], glm::mat3(1.0f), masked ? &source_masks[t] : nullptr, masked ? &covers[t] : nullptr};
      const std::string what = "two at the sources, R " + std::to_string(R) + (masked ? ", masked" : ", plain");
      print_and_check(what.c_str(), errors(lights), at_sources[row][masked]);
    }
    ++row;
  }
  // The builder's finest level at R 16, 32, 64: a mask per position through which at least 500 lines pass.
  row = 0;
  for (const int R : {16, 32, 64}) {
    AplBuildOptions rb = bo;
    rb.map_resolution = R;
    rb.max_resolution = R;
    const AplSet built = R == 64 ? AplSet{} : build_apl_set(*rays, rb);
    const AplLevel& level = (R == 64 ? set : built).levels.back();
    const double eps = 1e-3 * set.bounds.radius;
    std::deque<DirectionMask> masks;  // the lights point into these: they must not move
    std::deque<SphereMap> covers;
    std::vector<glm::dvec3> mask_at;
    std::vector<double> off_source;  // mm, from each unmasked APL to the nearer source
    std::vector<Light> plain, masked;
    std::size_t masked_apls = 0;
    double masked_flux = 0, flux = 0;
    for (const Apl& a : level.apls) {
      const glm::dvec3 c(a.position);
      plain.push_back({c, &a.map, level.frame.to_map, nullptr, nullptr});
      flux += a.flux.y;
      std::size_t which = masks.size();
      for (std::size_t q = 0; q < mask_at.size(); ++q)
        if (glm::length(mask_at[q] - c) < eps) which = q;
      if (which == masks.size()) {
        std::vector<glm::dvec3> through;
        for (std::size_t j = 0; j < origin.size(); ++j)  // lines that pass c before they start
          if (glm::dot(c - origin[j], direction[j]) <= 0 && distance_to_line(c, origin[j], direction[j]) < eps)
            through.push_back(direction[j]);
        const auto m = through.size() >= 500 ? DirectionMask::from_directions(through) : std::nullopt;
        if (m) {
          masks.push_back(*m), mask_at.push_back(c);
          covers.push_back(m->coverage(level.map_resolution, glm::transpose(level.frame.to_map), 8));
        }
      }
      masked.push_back(plain.back());
      if (which < masks.size()) {
        masked.back().mask = &masks[which];
        masked.back().coverage = &covers[which];
        ++masked_apls, masked_flux += a.flux.y;
      } else {
        off_source.push_back(1e3 * std::min(glm::length(c - sources[0]), glm::length(c - sources[1])));
      }
    }
    std::sort(off_source.begin(), off_source.end());
    std::printf("512-APL level: %zu masks, %zu APLs masked holding %.1f %% of the flux; the others %.2f/%.2f/%.2f mm "
                "(least/median/most) from the nearer source, %.1f mm apart\n",
                masks.size(), masked_apls, 100 * masked_flux / flux, off_source.empty() ? 0.0 : off_source.front(),
                off_source.empty() ? 0.0 : off_source[off_source.size() / 2], off_source.empty() ? 0.0 : off_source.back(),
                1e3 * glm::length(sources[0] - sources[1]));
    if (R == 64) {
      EXPECT_EQ(masked_apls, 406u);
      EXPECT_NEAR(100 * masked_flux / flux, 85.0, 0.05);
    }
    const std::string what = "builder's 512 APLs, R " + std::to_string(R);
    print_and_check((what + ", plain").c_str(), errors(plain), builder_level[row][0]);
    print_and_check((what + ", masked").c_str(), errors(masked), builder_level[row][1]);
    // Placement: every ray moved to the APL its line passes nearest; among APLs within 10⁻⁶ of the
    // bounding radius of that (all those at one source), to the one whose map is brightest along the
    // ray. The maps are binned again from the rays so assigned, and read masked where a mask was made.
    std::vector<SphereMap> moved(level.apls.size(), SphereMap(R, 1));
    std::vector<double> line_distance(level.apls.size());
    std::size_t emptied = level.apls.size();
    std::vector<bool> used(level.apls.size(), false);
    for (std::size_t j = 0; j < origin.size(); ++j) {
      double best = INFINITY;
      for (std::size_t a = 0; a < level.apls.size(); ++a) {
        line_distance[a] = distance_to_line(glm::dvec3(level.apls[a].position), origin[j], direction[j]);
        best = std::min(best, line_distance[a]);
      }
      const glm::vec3 m = level.frame.map_direction(glm::vec3(direction[j]));
      std::size_t pick = 0;
      float brightest = -1;
      for (std::size_t a = 0; a < level.apls.size(); ++a) {
        if (line_distance[a] > best + 1e-6 * set.bounds.radius) continue;
        const float b = level.apls[a].map.lookup(m).x;
        if (b > brightest) brightest = b, pick = a;
      }
      int x, y;
      moved[pick].texel_of(m, x, y);
      moved[pick].at(x, y, 0) += float(ray_flux / moved[pick].texel_solid_angle());
      if (!used[pick]) used[pick] = true, --emptied;
    }
    std::vector<Light> placed = masked;
    double placed_masked = 0;
    for (std::size_t a = 0; a < placed.size(); ++a) {
      placed[a].map = &moved[a];
      if (placed[a].mask) placed_masked += moved[a].integral().x;
    }
    double placed_total = 0;
    for (const SphereMap& m : moved) placed_total += m.integral().x;
    std::printf("moved to the APL each line passes nearest: %zu of 512 APLs left empty, %.1f %% of the flux masked\n",
                emptied, 100 * placed_masked / placed_total);
    print_and_check((what + ", placed, masked").c_str(), errors(placed), builder_level[row][2]);
    ++row;
  }
}
}  // namespace

namespace {
// The IES far field of the Lambertian emitters (docs/apl_sets.md): level 0's maps at R 64 and each kernel
// against the exact irradiance at d = 2, 5, 10 from the bounding-sphere centre, beside the floor of a point
// at that centre with the exact intensity (I(ω) = r² E(c + r ω) at r = 10⁴ m), and the share of the
// squared error at d = 10 within 15° of the emitters' horizon (z = 0; they emit into z > 0). Printed, and
// checked against the documented rows. Off by default (about 15 s):
//   build/tests/lumx_tests --gtest_also_run_disabled_tests --gtest_filter='*WiderKernels*'
TEST(FarFieldStudy, DISABLED_WiderKernelsForTheLambertianFarField) {
  // Per emitter: the floor, then R 64 with σ = 0, 3.4 (plain), 6.7 (sharpened), 13.5 (plain), 13.5° (sharpened):
  // d = 5 and 10, %.
  // Then local linear at σ 6.7°.
  const double documented[2][7][2] = {
      {{0.46, 0.11}, {5.44, 5.48}, {2.21, 2.22}, {2.05, 2.02}, {13.24, 13.35}, {5.50, 5.49}, {1.03, 0.98}},
      {{0.89, 0.22}, {4.78, 4.72}, {2.44, 2.31}, {2.33, 2.13}, {13.12, 13.25}, {5.52, 5.46}, {1.42, 1.10}}};
  for (int which : {0, 1}) {
    const std::unique_ptr<AnalyticEmitter> em = suite_emitter(which);
    auto rays = em->source(kSuiteRays, 11 + std::uint64_t(which));
    AplBuildOptions bo;
    bo.threads = 2;
    const AplSet set = build_apl_set(*rays, bo);
    AplErrorOptions eo;
    eo.relative_distances = {2, 5, 10};
    const MeasurementSpheres ms(set.bounds, eo);
    const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
    const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
    const double near_horizon = std::sin(15.0 * kDegToRad);
    double horizon_share = 0;
    const auto ies_errors = [&](auto&& intensity) {
      std::vector<double> out;
      for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
        std::vector<double> model(dirs.size());
        double all = 0, band = 0;
        for (std::size_t p = 0; p < dirs.size(); ++p) {
          const glm::dvec3 x = ms.centre() + ms.radius(s) * dirs[p];
          const glm::dvec3 d = x - set.bounds.center;
          const double r = glm::length(d);
          const glm::dvec3 w = d / r;
          model[p] = intensity(w) * std::max(0.0, glm::dot(dirs[p], w)) / (r * r);
          const double sq = (model[p] - exact.at_centre[s][p]) * (model[p] - exact.at_centre[s][p]);
          all += sq;
          if (std::abs(w.z) < near_horizon) band += sq;
        }
        horizon_share = all > 0 ? band / all : 0;
        out.push_back(100 * compare_irradiance(exact.at_centre[s], model).relative_rmse);
      }
      return out;
    };
    std::printf("%s (level 0: %zu APLs, R %d), d = 2, 5, 10\n", em->name().c_str(), set.levels[0].size(),
                set.levels[0].map_resolution);
    const std::vector<double> floor = ies_errors([&](const glm::dvec3& w) {
      const double r = 1e4;
      return r * r * em->irradiance(set.bounds.center + r * w, -w);
    });
    std::printf("  exact intensity at the centre : %6.2f %6.2f %6.2f\n", floor[0], floor[1], floor[2]);
    EXPECT_NEAR(floor[1], documented[which][0][0], 0.01);
    EXPECT_NEAR(floor[2], documented[which][0][1], 0.01);
    const int R = 64;
    const double texel = std::sqrt(4.0 * kPi / (2.0 * double(R) * double(R)));
    const std::pair<double, bool> kernels[] = {{0.0, false}, {1.5, false}, {3.0, true}, {6.0, false}, {6.0, true}};
    int row = 1;
    for (const auto& [widths, sharpened] : kernels) {
      const double kappa = widths > 0 ? 1.0 / ((widths * texel) * (widths * texel)) : 0.0;
      AplSet far_set = set;
      far_set.levels.resize(1);
      far_set.levels[0] = fitted_level(set.levels[0], R, kappa, sharpened ? KernelMode::sharpened : KernelMode::plain);
      const IntensityTable t(far_field_photometry(far_set, 0));
      const std::vector<double> e = ies_errors([&](const glm::dvec3& w) { return t.intensity(w); });
      std::printf("  R %2d σ %5.1f°%s: %6.2f %6.2f %6.2f   (%2.0f %% of the squared error at d = 10 within 15° of the horizon)\n",
                  R, widths * texel * 180 / kPi, sharpened ? " sharpened" : "          ", e[0], e[1], e[2], 100 * horizon_share);
      EXPECT_NEAR(e[1], documented[which][row][0], 0.01) << row;
      EXPECT_NEAR(e[2], documented[which][row][1], 0.01) << row;
      ++row;
    }
    // Local linear (SphereMapKernel::local_linear_gain): no leak across the horizon.
    for (const double widths : {1.5, 3.0, 4.5}) {
      const double kappa = 1.0 / ((widths * texel) * (widths * texel));
      AplSet far_set = set;
      far_set.levels.resize(1);
      far_set.levels[0] = fitted_level(set.levels[0], R, kappa, KernelMode::local_linear);
      const IntensityTable t(far_field_photometry(far_set, 0));
      const std::vector<double> e = ies_errors([&](const glm::dvec3& w) { return t.intensity(w); });
      std::printf("  R %2d σ %5.1f° local linear: %6.2f %6.2f %6.2f   (%2.0f %% within 15° of the horizon)\n", R,
                  widths * texel * 180 / kPi, e[0], e[1], e[2], 100 * horizon_share);
      if (widths == 3.0) {
        EXPECT_NEAR(e[1], documented[which][6][0], 0.01);
        EXPECT_NEAR(e[2], documented[which][6][1], 0.01);
      }
    }
  }
}
}  // namespace

namespace {
// What limits the spots (docs/apl_sets.md): the shipped finest level (fitted on held-out rays as lumx build
// does) from 1 M and 4 M rays, against the exact irradiance. Noise falls as 1/√N and, the kernel
// narrowing as the rays allow, the error falls at least that fast where noise limits it (both spots at
// σ 5.0°, spectral in the photometric frame, spectral per order turned: 4 M rays take the finest level,
// turned, to at most 1.2 % at every d ≥ 1). Then, from the 1 M rays, the finest level at R 128 with σ = 1.5 texel
// widths, sharpened, set by hand (the fit's choice for the cos^50 spot before the extrapolated and
// two-scale kernels). Then the floor of maps at the spot's centre: one APL whose map is the exact
// intensity averaged over each texel, at R 64 and 128. The built rows twice: with the maps in the
// photometric frame (as measured before MapFrame) and turned, as lumx build now draws a beam's maps.
// Printed, and checked against the documented rows. Off by default (about 6 min):
//   build/tests/lumx_tests --gtest_also_run_disabled_tests --gtest_filter='*WhatMoreRaysBuy*'
TEST(SpotStudy, DISABLED_WhatMoreRaysBuy) {
  // [maps in the photometric frame, turned (MapFrame, as shipped)][cos^20, cos^50][1 M rays, 4 M rays,
  // 1 M rays with R 128's kernel by hand][d = 1, 2, 5, 10], %; then the exact maps, which do not depend
  // on the builder: [cos^20, cos^50][R 64, R 128][d].
  const double documented[2][2][3][4] = {
      {{{1.24, 1.73, 2.21, 2.29}, {0.77, 0.95, 1.18, 1.23}, {3.25, 3.55, 3.44, 4.28}},
       {{1.12, 1.61, 2.65, 3.12}, {0.69, 0.83, 1.96, 2.65}, {2.90, 3.62, 4.04, 4.40}}},
      {{{1.24, 1.23, 1.05, 1.08}, {0.76, 0.65, 0.44, 0.40}, {3.25, 3.49, 3.31, 4.41}},
       {{1.11, 1.24, 1.52, 1.58}, {0.74, 0.81, 1.10, 1.20}, {3.02, 3.08, 3.93, 4.03}}}};
  const double documented_exact[2][2][4] = {{{165.38, 50.51, 7.76, 4.00}, {167.12, 52.14, 8.47, 1.92}},
                                            {{425.44, 160.05, 26.62, 10.39}, {429.46, 163.93, 28.75, 6.68}}};
  for (int which : {2, 3}) {
    const std::unique_ptr<AnalyticEmitter> em = suite_emitter(which);
    for (const bool turned : {false, true}) {
      int n_index = 0;
      for (const std::uint64_t n : {std::uint64_t(1000000), std::uint64_t(4000000)}) {
        auto rays = em->source(n, 11 + std::uint64_t(which));
        AplBuildOptions bo;
        bo.threads = 2;
        bo.orient_maps = turned;
        AplErrorOptions eo;
        ResolutionChoice choice;
        const AplSet set = shipped_set(*rays, choice, turned);
        const MeasurementSpheres ms(set.bounds, eo);
        const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
        const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
        const std::size_t k = set.levels.size() - 1;
        const char* frame = turned ? "turned" : "photometric";
        std::printf("%s, %s frame, %llu rays, %zu APLs R %d σ %.1f° %s:", em->name().c_str(), frame,
                    (unsigned long long)n, set.levels[k].size(), set.levels[k].map_resolution,
                    choice.kappa.at(k) > 0 ? 180.0 / kPi / std::sqrt(choice.kappa.at(k)) : 0.0,
                    kernel_mode_name(choice.mode.at(k)));
        int col = 0;
        for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
          if (ms.relative_distances()[s] < 1) continue;
          const std::vector<double> model = level_at_points(set, k, ms, s, dirs);
          const double e = 100 * compare_irradiance(exact.at_centre[s], model).relative_rmse;
          std::printf(" %6.2f", e);
          EXPECT_NEAR(e, documented[turned][which - 2][n_index][col++], 0.01) << frame << ", " << n << " rays, sphere " << s;
        }
        std::printf("\n");
        if (n == 1000000) {
          AplSet by_hand = build_apl_set(*rays, bo);
          const int R = 128;
          const double texel = std::sqrt(4.0 * kPi / (2.0 * R * R));
          by_hand.levels[k] = fitted_level(by_hand.levels[k], R, 1.0 / ((1.5 * texel) * (1.5 * texel)), KernelMode::sharpened);
          std::printf("%s, %s frame, %llu rays, %zu APLs R %d σ %.1f° sharpened, by hand:", em->name().c_str(), frame,
                      (unsigned long long)n, by_hand.levels[k].size(), R, 1.5 * texel * 180.0 / kPi);
          col = 0;
          for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
            if (ms.relative_distances()[s] < 1) continue;
            const double e = 100 * compare_irradiance(exact.at_centre[s], level_at_points(by_hand, k, ms, s, dirs)).relative_rmse;
            std::printf(" %6.2f", e);
            EXPECT_NEAR(e, documented[turned][which - 2][2][col++], 0.01) << frame << ", R 128 by hand, sphere " << s;
          }
          std::printf("\n");
        }
        ++n_index;
      }
    }
    // The floor of maps: one APL at the spot's centre, its map the exact intensity averaged over each texel
    // (I(ω) = r² E(r ω) at r = 10⁴ m, 4 × 4 sub-directions), read bilinearly.
    AplBuildOptions bo;
    bo.threads = 2;
    bo.level_counts = {1};
    const AplSet built = build_apl_set(*em->source(200000, 3), bo);
    AplErrorOptions eo;
    const MeasurementSpheres ms(built.bounds, eo);
    const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
    const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
    for (const int R : {64, 128}) {
      int col = 0;
      AplSet set;
      set.bounds = built.bounds;
      set.levels.resize(1);
      set.levels[0].map_resolution = R;
      Apl a;
      a.map = SphereMap(R, 1);
      for (int y = 0; y < R; ++y)
        for (int x = 0; x < 2 * R; ++x) {
          double sum = 0;
          for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
              const glm::dvec3 w = glm::normalize(glm::dvec3(sphere_map::uv_to_direction(
                  {(float(x) + (float(i) + 0.5f) / 4) / float(2 * R), (float(y) + (float(j) + 0.5f) / 4) / float(R)})));
              sum += 1e8 * em->irradiance(1e4 * w, -w);
            }
          a.map.at(x, y, 0) = float(sum / 16);
        }
      a.flux = a.map.integral();
      set.levels[0].apls.push_back(std::move(a));
      std::printf("%s, exact map at the centre, R %d:", em->name().c_str(), R);
      for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
        if (ms.relative_distances()[s] < 1) continue;
        const std::vector<double> model = level_at_points(set, 0, ms, s, dirs);
        const double e = 100 * compare_irradiance(exact.at_centre[s], model).relative_rmse;
        std::printf(" %6.2f", e);
        EXPECT_NEAR(e, documented_exact[which - 2][R == 64 ? 0 : 1][col++], 0.01) << "exact map, R " << R << ", sphere " << s;
      }
      std::printf("\n");
    }
  }
}
}  // namespace

namespace {
// Bias against noise in the shipped spots (docs/apl_sets.md): K sets built as lumx build builds them, each
// from 1 M rays of its own seed. With e_k the k-th set's point errors against the exact irradiance,
// E|ē|² = |b|² + σ²/K and E|e_k|² = |b|² + σ², so |b|² = (K|ē|² − mean |e_k|²)/(K − 1) and σ² the rest
// (both normalised as eq. 5.1, by the exact mean over the sphere). The same for the spots turned 45° about
// y, where their lobes fall inside one wedge of the maps rather than on the pole where four meet. Off by
// default (about 4 min):
//   build/tests/lumx_tests --gtest_also_run_disabled_tests --gtest_filter='*SpotBiasAndNoise*'
TEST(SpotStudy, DISABLED_SpotBiasAndNoise) {
  constexpr int K = 4;
  // [turned][cos^20, cos^50][RMS of a set, bias, noise][d = 0.5 … 10], % (docs/apl_sets.md).
  const double documented[2][2][3][6] = {
      {{{1.34, 1.30, 1.27, 1.20, 1.27, 1.26}, {0.38, 0.45, 0.38, 0.00, 0.00, 0.04}, {1.28, 1.22, 1.21, 1.20, 1.27, 1.26}},
       {{1.39, 1.35, 1.38, 1.39, 2.91, 3.71}, {0.57, 0.46, 0.45, 0.52, 1.80, 2.59}, {1.27, 1.27, 1.30, 1.29, 2.29, 2.65}}},
      {{{1.31, 1.25, 1.28, 1.10, 0.96, 0.92}, {0.34, 0.51, 0.45, 0.00, 0.00, 0.00}, {1.26, 1.15, 1.20, 1.10, 0.96, 0.92}},
       {{1.40, 1.32, 1.35, 1.32, 1.44, 1.51}, {0.59, 0.42, 0.48, 0.33, 0.00, 0.00}, {1.27, 1.25, 1.26, 1.28, 1.44, 1.51}}}};
  for (const double turn : {0.0, 45.0}) {
    for (int which : {2, 3}) {
      std::unique_ptr<AnalyticEmitter> em = suite_emitter(which);
      if (turn != 0) em = std::make_unique<RotatedEmitter>(std::move(em), turn);
      std::vector<std::vector<std::vector<double>>> err(K);  // [seed][sphere][point], model − exact
      std::vector<double> mean_exact, distances;
      std::unique_ptr<MeasurementSpheres> spheres;
      for (int k = 0; k < K; ++k) {
        auto rays = em->source(1000000, 101 + std::uint64_t(k));
        ResolutionChoice choice;
        const AplSet set = shipped_set(*rays, choice, false);  // as documented: before MapFrame
        // The first seed's spheres for every seed: the same points, so the errors can be averaged.
        if (k == 0) spheres = std::make_unique<MeasurementSpheres>(set.bounds, AplErrorOptions{});
        const MeasurementSpheres& ms = *spheres;
        const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
        const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
        const std::size_t top = set.levels.size() - 1;
        std::printf("%s, seed %d: %zu APLs R %d σ %.1f° %s\n", em->name().c_str(), k, set.levels[top].size(),
                    set.levels[top].map_resolution,
                    choice.kappa.at(top) > 0 ? 180.0 / kPi / std::sqrt(choice.kappa.at(top)) : 0.0,
                    kernel_mode_name(choice.mode.at(top)));
        err[k].resize(ms.sphere_count());
        if (k == 0) {
          mean_exact.resize(ms.sphere_count());
          distances = ms.relative_distances();
        }
        for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
          const std::vector<double> model = level_at_points(set, top, ms, s, dirs);
          double m = 0;
          for (std::size_t p = 0; p < dirs.size(); ++p) {
            err[k][s].push_back(model[p] - exact.at_centre[s][p]);
            m += exact.at_centre[s][p] / double(dirs.size());
          }
          if (k == 0) mean_exact[s] = m;
        }
      }
      std::printf("%s, finest level, %d seeds of 1 M rays, %% (eq. 5.1):\n  d       :", em->name().c_str(), K);
      for (double d : distances) std::printf(" %6.2f", d);
      std::vector<double> total(distances.size()), bias(distances.size()), noise(distances.size());
      for (std::size_t s = 0; s < distances.size(); ++s) {
        const std::size_t P = err[0][s].size();
        double each = 0, of_mean = 0;
        for (std::size_t p = 0; p < P; ++p) {
          double mean = 0;
          for (int k = 0; k < K; ++k) {
            each += err[k][s][p] * err[k][s][p] / (K * double(P));
            mean += err[k][s][p] / K;
          }
          of_mean += mean * mean / double(P);
        }
        const double b2 = std::max(0.0, (K * of_mean - each) / (K - 1)), norm = mean_exact[s];
        total[s] = 100 * std::sqrt(each) / norm;
        bias[s] = 100 * std::sqrt(b2) / norm;
        noise[s] = 100 * std::sqrt(std::max(0.0, each - b2)) / norm;
      }
      for (const auto& [label, row] : {std::pair<const char*, const std::vector<double>*>{"  RMS of a set", &total},
                                       {"  bias        ", &bias}, {"  noise       ", &noise}}) {
        std::printf("\n%s:", label);
        for (double v : *row) std::printf(" %6.2f", v);
      }
      std::printf("\n");
      const auto& doc = documented[turn != 0][which - 2];
      for (std::size_t s = 0; s < distances.size() && s < 6; ++s) {
        EXPECT_NEAR(total[s], doc[0][s], 0.01) << "d = " << distances[s];
        EXPECT_NEAR(bias[s], doc[1][s], 0.01) << "d = " << distances[s];
        EXPECT_NEAR(noise[s], doc[2][s], 0.01) << "d = " << distances[s];
      }
    }
  }
}
}  // namespace

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


namespace {
// Why the fit tries two-scale at 4.5 texel widths (docs/apl_sets.md): a cos^20 spot's 512-APL level, built
// from 1 M rays of two seeds without the held-out fit, its maps at R 128 smoothed two-scale at σ 5.0° (4.5
// texel widths: each map's ~2 000 rays want it, the sum's 1 M rays afford the 2.5° pilot) and extrapolated
// at σ 3.4° (the candidate the fit chose before), against the exact irradiance at d = 0.5 … 10, %. Off by
// default (about 1 min):
//   build/tests/lumx_tests --gtest_also_run_disabled_tests --gtest_filter='*WideTwoScale*'
TEST(SpotStudy, DISABLED_WideTwoScaleForSparseMaps) {
  // [seed 101, 102][two-scale 4.5, extrapolated 3][d]
  const double documented[2][2][6] = {{{1.32, 1.07, 1.12, 1.61, 3.12, 3.66}, {2.02, 1.58, 1.55, 2.01, 3.08, 3.35}},
                                      {{1.37, 1.36, 1.19, 1.24, 1.50, 1.79}, {1.94, 1.99, 1.89, 1.63, 1.56, 1.68}}};
  const std::unique_ptr<AnalyticEmitter> em = suite_emitter(2);
  const int R = 128;
  const double texel = std::sqrt(4.0 * kPi / (2.0 * R * R));
  const FitKernel kernels[2] = {{1.0 / ((4.5 * texel) * (4.5 * texel)), KernelMode::two_scale},
                                {1.0 / ((3.0 * texel) * (3.0 * texel)), KernelMode::extrapolated}};
  for (int si = 0; si < 2; ++si) {
    auto rays = em->source(1000000, 101 + std::uint64_t(si));
    AplBuildOptions bo;
    bo.threads = 2;
    bo.orient_maps = false;  // as documented: measured before MapFrame
    const AplSet built = build_apl_set(*rays, bo);
    const MeasurementSpheres ms(built.bounds, AplErrorOptions{});
    const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
    const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
    const std::size_t k = built.levels.size() - 1;
    ASSERT_EQ(built.levels[k].map_resolution, R);
    for (int ki = 0; ki < 2; ++ki) {
      AplSet set = built;
      set.levels[k] = fitted_level(built.levels[k], R, kernels[ki].kappa, kernels[ki].mode);
      std::printf("%s, seed %d, %zu APLs R %d σ %.2f° %s:", em->name().c_str(), 101 + si, set.levels[k].size(), R,
                  180 / kPi / std::sqrt(kernels[ki].kappa), kernel_mode_name(kernels[ki].mode));
      for (std::size_t s = 0; s < ms.sphere_count() && s < 6; ++s) {
        const double e = 100 * compare_irradiance(exact.at_centre[s], level_at_points(set, k, ms, s, dirs)).relative_rmse;
        std::printf(" %6.2f", e);
        EXPECT_NEAR(e, documented[si][ki][s], 0.01) << "seed " << 101 + si << ", d = " << ms.relative_distances()[s];
      }
      std::printf("\n");
    }
  }
}
}  // namespace

namespace {
/// The held-out estimate of the box's masked level on the rays of each seed: per seed, the level
/// evaluate_held_out_fitted grades (built from the even rays, point sources as masked APLs) against the
/// exact irradiance at the patch centres, beside the estimate with the noise removed ('<': unresolved)
/// and its upper bound, %, and the border allowance of each sphere (SphereReference::border_share).
/// Counted: spheres whose truth is above 10 % (a patch centre in a sliver one mask misses), where the
/// upper bound is below 3/4 of the truth (the estimate flatters), and resolved more than 25 % from it.
struct MaskedEstimateCounts {
  int spheres = 0, spikes = 0, flatters = 0, resolved_off = 0;
};
MaskedEstimateCounts masked_level_estimates(const std::vector<std::uint64_t>& seeds) {
  const PinholeBox box = pinhole_box();
  MaskedEstimateCounts n;
  for (std::uint64_t seed : seeds) {
    auto rays = box.source(kSuiteRays, seed);
    AplBuildOptions bo;
    bo.threads = 2;
    ResolutionChoice choice;
    const AplErrorReport r = evaluate_held_out_fitted(
        *rays, [&](RaySource& train) { return build_apl_set(train, half_rays_build_options(bo, rays->info().ray_count)); },
        AplErrorOptions{}, &choice);
    const LevelErrors& row = r.levels.back();
    EXPECT_TRUE(row.masked) << seed;
    const ExactOnSpheres exact = exact_on_spheres(box, r.reference.spheres, 1);
    const std::vector<double> truth = true_errors(exact.at_centre, row);
    std::printf("seed %2d, R %d:", int(seed), row.map_resolution);
    for (std::size_t s = 0; s < truth.size(); ++s) {
      const IrradianceErrors& e = row.errors[s];
      std::printf(" %4.1f/%4.1f%s/%4.1f", 100 * truth[s], 100 * e.relative_rmse_noise_removed, e.resolved ? " " : "<",
                  100 * e.noise_removed_upper);
      ++n.spheres;
      n.spikes += truth[s] > 0.1;
      n.flatters += e.noise_removed_upper < 0.75 * truth[s];
      n.resolved_off += e.resolved && std::abs(e.relative_rmse_noise_removed - truth[s]) > 0.25 * truth[s];
    }
    std::printf("\n    border allowance, %% of the mean:");
    for (const SphereReference& sr : r.reference.sphere) std::printf(" %.1f", 100 * sr.border_share);
    std::printf("\n");
  }
  std::printf("%d spheres, %d with the truth above 10 %%: the upper bound below 3/4 of the truth at %d, resolved and "
              "more than 25 %% off at %d\n", n.spheres, n.spikes, n.flatters, n.resolved_off);
  return n;
}
}  // namespace

// The box's masked level on the rays of five seeds, four of them (16, 18, 19, 23) with a patch centre in
// a sliver of the graded level's beams that no mask holds (its truth 17-19 %): the upper bound holds
// each truth but for the ±25 % of HonestErrorSuite only with the border allowance (in a trial without
// it, an upper bound of 8.8-12.0 % at five of those spheres). About 20 s.
TEST(PinholeBoxStudy, TheUpperBoundHoldsABorderNoMaskResolves) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "release build only (as the held-out suite)";
#endif
  const MaskedEstimateCounts n = masked_level_estimates({15, 16, 18, 19, 23});
  EXPECT_EQ(n.spikes, 5);
  EXPECT_EQ(n.flatters, 0);
}

// The same over 20 seeds (docs/apl_sets.md, "What the table stores"), checked against the documented
// counts. Off by default (about 80 s):
//   build/tests/lumx_tests --gtest_also_run_disabled_tests --gtest_filter='*HeldOutEstimateOfTheMaskedLevel*'
TEST(PinholeBoxStudy, DISABLED_HeldOutEstimateOfTheMaskedLevel) {
  std::vector<std::uint64_t> seeds;
  for (std::uint64_t s = 11; s < 31; ++s) seeds.push_back(s);
  const MaskedEstimateCounts n = masked_level_estimates(seeds);
  EXPECT_EQ(n.spikes, 12);
  EXPECT_EQ(n.flatters, 0);
  EXPECT_EQ(n.resolved_off, 2);
}
