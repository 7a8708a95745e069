// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// APL sets: the model's consistency rules, intensity and irradiance queries, the LOD rules and the far
// field, on hand-made sets whose answers follow from the inverse-square law and from the levels being
// cuts of one tree.
#include <lumx/apl/evaluation.h>
#include <lumx/apl/lod.h>
#include <lumx/apl/far_field.h>
#include <lumx/apl/apl_set.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/io/photometry_io.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <random>

#include "test_support.h"

using namespace lumx;

namespace {

SphereMap map_of(int R, const std::function<float(const glm::vec3&)>& f) {
  SphereMap m(R, 1);
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x)
      m.at(x, y, 0) = f(sphere_map::uv_to_direction({(x + 0.5f) / m.width(), (y + 0.5f) / m.height()}));
  return m;
}

/// Level 0: one APL at the centre, its map the sum of level 1's; level 1: eight APLs at the corners of a
/// cube of half-edge a, each a differently tilted downward lobe. Exactly a two-level cut of one tree.
AplSet two_level_set(int R = 32, float a = 0.1f) {
  AplSet set;
  set.bounds.radius = std::sqrt(3.0) * a;
  AplLevel fine;
  fine.map_resolution = R;
  for (int i = 0; i < 8; ++i) {
    Apl apl;
    apl.position = glm::vec3(i & 1 ? a : -a, i & 2 ? a : -a, i & 4 ? a : -a);
    apl.parent = 0;
    const glm::vec3 axis = glm::normalize(glm::vec3(0.3f * (i & 1 ? 1 : -1), 0.2f * (i & 2 ? 1 : -1), -1.0f));
    apl.map = map_of(R, [&](const glm::vec3& w) { return 100.0f * float(i + 1) * std::pow(std::max(0.0f, glm::dot(w, axis)), 2.0f) + 1.0f; });
    apl.flux = apl.map.integral();
    fine.apls.push_back(std::move(apl));
  }
  AplLevel coarse;
  coarse.map_resolution = R;
  Apl root;
  root.map = SphereMap(R, 1);
  for (const Apl& c : fine.apls)
    for (std::size_t t = 0; t < root.map.values().size(); ++t) root.map.values()[t] += c.map.values()[t];
  root.flux = root.map.integral();
  coarse.apls.push_back(std::move(root));
  set.levels.push_back(std::move(coarse));
  set.levels.push_back(std::move(fine));
  return set;
}

}  // namespace

TEST(AplSet, HandMadeSetIsConsistent) {
  const AplSet set = two_level_set();
  EXPECT_TRUE(check_apl_set(set).empty());
  const double f0 = set.levels[0].flux().x, f1 = set.levels[1].flux().x;
  EXPECT_NEAR(f0, f1, 1e-5 * f0);
}

TEST(AplSet, CheckFindsEveryBrokenRule) {
  AplSet set = two_level_set(8);
  {
    AplSet s = set;
    s.levels[1].apls[3].parent = 5;
    const auto p = check_apl_set(s);
    ASSERT_EQ(p.size(), 2u);  // the bad parent, and parent 0's children no longer sum to it
    EXPECT_NE(p[0].find("levels[1].apls[3].parent"), std::string::npos) << p[0];
  }
  {
    AplSet s = set;
    s.levels[1].apls[2].map.at(3, 2, 0) = NAN;
    const auto p = check_apl_set(s);
    ASSERT_FALSE(p.empty());
    EXPECT_NE(p[0].find("texel (3, 2)"), std::string::npos) << p[0];
  }
  {
    AplSet s = set;
    s.levels[1].apls[0].flux *= 1.01;
    EXPECT_FALSE(check_apl_set(s).empty());
  }
  {
    AplSet s = set;
    s.levels[1].apls[0].map = SphereMap(4, 1);
    EXPECT_FALSE(check_apl_set(s).empty());
  }
  {
    AplSet s = set;
    std::swap(s.levels[0], s.levels[1]);
    EXPECT_FALSE(check_apl_set(s).empty());
  }
}

TEST(AplEvaluation, InverseSquareAndCosineLawsAreExactForAnIsotropicApl) {
  AplSet set;
  AplLevel level;
  level.map_resolution = 4;
  Apl apl;
  apl.position = {1.0f, 2.0f, 3.0f};
  apl.map = map_of(4, [](const glm::vec3&) { return 250.0f; });  // 250 cd everywhere: 1000π lm
  apl.flux = apl.map.integral();
  EXPECT_NEAR(apl.flux.x, 1000.0 * kPi, 1e-3);
  level.apls.push_back(apl);
  set.levels.push_back(level);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    const glm::vec3 d = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
    const float r = 0.5f + 4.0f * (u(rng) + 1.0f);
    const glm::vec3 x = apl.position + r * d;
    const glm::vec3 n = glm::normalize(-d + 0.5f * glm::vec3(u(rng), u(rng), u(rng)));
    const double expected = 250.0 * std::max(0.0f, glm::dot(n, -d)) / (double(r) * r);
    const IrradianceResult e = irradiance(set, 0, x, n);
    EXPECT_NEAR(e.irradiance.x, expected, 1e-5 * 250.0 / (r * r));
    EXPECT_EQ(e.clamped, 0u);
  }
}

TEST(AplEvaluation, IntensityFollowsTheMapWithinItsResolution) {
  const glm::vec3 axis(0, 0, -1);
  auto f = [&](const glm::vec3& w) { return 1000.0f * std::max(0.0f, glm::dot(w, axis)); };
  for (int R : {32, 128}) {
    // Drawn in a turned frame (as the builder draws a beam's maps): the lookup turns w the same way.
    AplLevel level;
    level.frame = map_frame_for(glm::dvec3(0.3, -0.2, -1.0));
    ASSERT_FALSE(level.frame.is_identity());
    Apl apl;
    apl.map = map_of(R, [&](const glm::vec3& m) { return f(level.frame.world_direction(m)); });
    double max_err = 0;
    std::mt19937 rng(3);
    std::normal_distribution<float> g;
    for (int i = 0; i < 20000; ++i) {
      const glm::vec3 w = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
      max_err = std::max(max_err, double(std::abs(intensity(level, apl, w).x - f(w))));
    }
    // Bilinear error of a function with slope ≤ 1000 cd/rad over texels ≲ 2.3/R rad wide (the widest
    // texel of the concentric map), plus the kink of max(0, ·) at the equator.
    EXPECT_LT(max_err, 1000.0 * 2.5 / R) << "R = " << R;
  }
}

TEST(AplEvaluation, FinerLevelConvergesToCoarseLevelFarAway) {
  const AplSet set = two_level_set(64, 0.1f);
  const glm::vec3 n(0, 0, 1);
  double previous = INFINITY;
  for (float distance : {1.0f, 4.0f, 16.0f}) {  // metres below the luminaire; its size is 0.35 m
    const glm::vec3 x(0.3f * distance, 0.2f * distance, -distance);
    const double e0 = irradiance(set, 0, x, n).irradiance.x;
    const double e1 = irradiance(set, 1, x, n).irradiance.x;
    const double rel = std::abs(e1 - e0) / e0;
    EXPECT_LT(rel, previous) << "distance " << distance;
    previous = rel;
  }
  EXPECT_LT(previous, 0.01);  // 16 m ≈ 23 luminaire diameters: the far field holds to 1 %
}

TEST(AplEvaluation, VisibilityCallbackAndPointsAtAnApl) {
  const AplSet set = two_level_set(16);
  const glm::vec3 x(0.0f, 0.0f, -1.0f), n(0, 0, 1);
  const double all = irradiance(set, 1, x, n).irradiance.x;
  // Block the four upper APLs: the result is the sum over the lower four.
  auto lower_only = [&](std::size_t i, const glm::vec3&, const glm::vec3&) { return i & 4 ? 0.0f : 1.0f; };
  const double lower = irradiance(set, 1, x, n, lower_only).irradiance.x;
  double expected = 0;
  for (std::size_t i = 0; i < 8; ++i)
    if (!(i & 4)) {
      AplSet one = set;
      one.levels[1].apls = {set.levels[1].apls[i]};
      expected += irradiance(one, 1, x, n).irradiance.x;
    }
  EXPECT_NEAR(lower, expected, 1e-5 * all);
  EXPECT_LT(lower, all);
  // A shading point exactly at an APL: finite, and the clamp is reported.
  const IrradianceResult at = irradiance(set, 1, set.levels[1].apls[0].position, n);
  EXPECT_TRUE(std::isfinite(at.irradiance.x));
  EXPECT_EQ(at.clamped, 1u);
}

TEST(AplLod, RationalApproximationTracksEquation61) {
  for (double d = 0; d <= 20.0; d += 0.01) {
    const double exact = lod_apl_count_exact(d), approx = lod_apl_count(d);
    EXPECT_LT(std::abs(approx - exact) / exact, d >= 0.5 ? 0.028 : 0.069) << "d = " << d;  // Remez fit, measured
  }
  EXPECT_EQ(lod_apl_count(20.5), 1.0);
  EXPECT_NEAR(lod_apl_count_exact(1.0), 630.31 * std::exp(-0.333), 1e-9);
}

TEST(AplLod, StochasticChoiceHasTheDesiredExpectedCount) {
  AplSet set;
  for (int n : {1, 8, 64, 256, 512}) {
    AplLevel l;
    l.apls.resize(std::size_t(n));
    set.levels.push_back(std::move(l));
  }
  for (double desired : {1.0, 5.0, 8.0, 30.0, 100.0, 300.0, 511.0}) {
    const int N = 100000;
    double sum = 0;
    for (int i = 0; i < N; ++i) sum += double(set.levels[choose_level_stochastic(set, desired, (i + 0.5) / N)].size());
    EXPECT_NEAR(sum / N, desired, 1e-3 * desired + 0.01) << desired;
  }
  EXPECT_EQ(choose_level_stochastic(set, 0.2, 0.5), 0u);
  EXPECT_EQ(choose_level_stochastic(set, 5000.0, 0.5), 4u);
  EXPECT_EQ(choose_level_stochastic(set, NAN, 0.5), 0u);
  // Relative distance from the bounding sphere: d = |x − c| / (2r).
  set.bounds.center = {0, 0, 1};
  set.bounds.radius = 0.25;
  EXPECT_NEAR(set.relative_distance({0, 0, -1}), 4.0, 1e-12);
  EXPECT_EQ(choose_level_by_distance(set, {0, 0, 100}, 0.0), 0u);  // d = 198 > 20: one APL
}

TEST(AplLod, ErrorTargetPicksTheSmallestSufficientLevel) {
  AplSet set;
  const std::vector<double> d = {0.5, 1, 2, 5, 10};
  const std::vector<std::vector<double>> err = {
      {0.9, 0.5, 0.2, 0.05, 0.01}, {0.4, 0.2, 0.08, 0.02, 0.005}, {0.1, 0.05, 0.02, 0.01, 0.004}};
  for (std::size_t k = 0; k < err.size(); ++k) {
    AplLevel l;
    l.apls.resize(std::size_t(1) << (3 * k));
    l.error.relative_distance = d;
    l.error.relative_rmse = err[k];
    set.levels.push_back(std::move(l));
  }
  EXPECT_EQ(choose_level_for_error(set, 10.0, 0.02), 0u);
  EXPECT_EQ(choose_level_for_error(set, 5.0, 0.04), 1u);
  EXPECT_EQ(choose_level_for_error(set, 1.0, 0.05), 2u);
  EXPECT_EQ(choose_level_for_error(set, 0.5, 0.01), 2u);  // unreachable: the finest level
  // Log-linear interpolation: halfway between d = 1 and 2 in log d.
  EXPECT_NEAR(interpolated_error(set.levels[0].error, std::sqrt(2.0)), 0.35, 1e-12);
  EXPECT_EQ(interpolated_error(set.levels[0].error, 100.0), 0.01);
  EXPECT_TRUE(std::isinf(interpolated_error(ErrorTable{}, 1.0)));
}

TEST(AplFarField, OneAplLevelAgreesWithItsExportedFile) {
  // The one-APL level and the IES file exported from it describe the same luminaire: compare them in
  // random directions (off the file's grid), after a write and a read of the file.
  const AplSet set = two_level_set(64);
  const Photometry back = read_ies(format_ies(far_field_photometry(set, 0)), "level0.ies");
  const IntensityTable table(back);
  const Apl& apl = set.levels[0].apls[0];
  const double peak = table.max_cd();
  std::mt19937 rng(8);
  std::normal_distribution<double> g;
  double worst = 0;
  for (int i = 0; i < 20000; ++i) {
    const glm::dvec3 w = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
    worst = std::max(worst, std::abs(table.intensity(w) - double(intensity(set.levels[0], apl, glm::vec3(w)).x)));
  }
  // Both are bilinear interpolants of the same smooth function on grids of ~1–2.5° (file) and
  // ~1.4° (R = 64 map): their difference is second order in the spacing, ≲ 1 % of the peak here.
  EXPECT_LT(worst, 0.01 * peak);
}

// Level 0's map is the sum of level 1's: the far fields agree up to float rounding (the far-field sum
// must not depend on how the light is split into APLs).
TEST(AplFarField, LevelsAgreeAndFluxIsPreserved) {
  const AplSet set = two_level_set(64);
  const Photometry p0 = far_field_photometry(set, 0), p1 = far_field_photometry(set, 1);
  ASSERT_EQ(p0.candela.size(), p1.candela.size());
  double peak = 0;
  for (double c : p0.candela) peak = std::max(peak, c);
  for (std::size_t i = 0; i < p0.candela.size(); ++i) EXPECT_NEAR(p0.candela[i], p1.candela[i], 1e-5 * peak);
  const double map_flux = set.levels[0].flux().x;
  EXPECT_NEAR(IntensityTable(p0).flux_lm(), map_flux, 0.005 * map_flux);
  // Through the IES writer and reader: the flux survives the file.
  const Photometry back = read_ies(format_ies(p0), "far_field.ies");
  EXPECT_NEAR(IntensityTable(back).flux_lm(), map_flux, 0.005 * map_flux);
  // Radiometric sets need an explicit efficacy.
  AplSet radiometric = set;
  radiometric.quantity = PhotometricQuantity::radiometric;
  EXPECT_THROW(far_field_photometry(radiometric, 0), std::invalid_argument);
  FarFieldGrid g;
  g.luminous_efficacy_lm_per_w = 300;
  EXPECT_NEAR(far_field_photometry(radiometric, 0, g).candela[5], 300 * p0.candela[5], 1e-6 * 300 * peak);
}

TEST(AplFarField, RealPhotometryRoundTripsThroughAnApl) {
  // A real file → one-APL set → far field again: flux is exact by construction, and the candela table
  // comes back within what a 128-resolution map resolves.
  const std::vector<std::filesystem::path> files = lumx_test::shared_photometry_files({".ies", ".ldt"});
  if (files.empty()) LUMX_SKIP_WITHOUT_SHARED("data/photometry");
  int tested = 0;
  for (const auto& file : files) {
    const std::string path = file.string();
    Photometry original;
    try {
      original = read_photometry(path);
    } catch (const Error&) {
      continue;  // the folder also holds deliberately broken files
    }
    if (original.type != PhotometricType::C) continue;
    const IntensityTable table(original);
    const double flux = table.flux_lm();
    if (!(flux > 0)) continue;
    const AplSet set = apl_set_from_photometry(original, 128);
    EXPECT_TRUE(check_apl_set(set).empty()) << path;
    EXPECT_NEAR(set.levels[0].flux().x, flux, 1e-5 * flux) << path;
    const Photometry back = far_field_photometry(set, 0);
    const IntensityTable back_table(back);
    EXPECT_NEAR(back_table.flux_lm(), flux, 0.005 * flux) << path;
    // The candela come back too, within what a 128-resolution map resolves: the RMS difference over
    // random directions stays below 2 % of the peak (sharp beams blur by about a texel). A cut-off at
    // the horizon (files that store γ ≤ 90° only, e.g. a uniform hemisphere) is a step of height J along a
    // great circle: bilinear lookups blur it over a band about two texels (2Δ, Δ = sqrt(4π / 2R²) rad)
    // wide, a fraction Δ/2 of the sphere, with a mean squared error ≤ J²/3 there, so such files are
    // allowed J·sqrt(Δ/6) more.
    double horizon_jump = 0;
    for (double c = 0; c < 360; c += 5)
      horizon_jump = std::max(horizon_jump, std::abs(table.at_angles(c, 89.5) - table.at_angles(c, 90.5)));
    const double texel_rad = std::sqrt(4 * kPi / (2.0 * 128 * 128));
    const double allowed = 0.02 * table.max_cd() + horizon_jump * std::sqrt(texel_rad / 6);
    std::mt19937 rng(9);
    std::normal_distribution<double> g;
    double sq = 0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
      const glm::dvec3 w = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
      const double d = back_table.intensity(w) - table.intensity(w);
      sq += d * d;
    }
    EXPECT_LT(std::sqrt(sq / n), allowed) << path << " (horizon step " << horizon_jump << " cd)";
    ++tested;
  }
  EXPECT_GE(tested, 3);
}
