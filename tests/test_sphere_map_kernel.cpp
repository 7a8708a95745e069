// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The von Mises–Fisher smoothing of sphere maps (math/sphere_map_kernel.h) and its use by the held-out fit
// (apl/error.h: fitted_level, kernel_peak_change).
#include <lumx/apl/error.h>
#include <lumx/math/sphere_map_kernel.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace lumx;

namespace {

double map_sum(const SphereMap& m) {
  double s = 0;
  for (float v : m.values()) s += double(v);
  return s;
}

glm::dvec3 texel_direction(int R, int x, int y) {
  return glm::normalize(glm::dvec3(
      sphere_map::uv_to_direction({(float(x) + 0.5f) / float(2 * R), (float(y) + 0.5f) / float(R)})));
}

}  // namespace

TEST(SphereMapKernel, KeepsFluxAndSpreadsOneTexelAsTheKernel) {
  const int R = 32;
  const double kappa = 400;  // σ = 2.9°
  const SphereMapKernel k(R, kappa);
  EXPECT_NEAR(k.sigma(), 1.0 / 20.0, 1e-12);
  // One lit texel near the upper pole: the result is the kernel around it, sampled at the texel centres.
  // Its flux is kept, and its angular second moment about the texel's direction is that of the vMF kernel:
  // E[θ²] = 2/κ for large κ (two tangent axes of variance 1/κ each), less 0.8 % for the truncation at
  // 3.7 σ; measured 3.4 % below 2/κ (the 2.9° kernel sampled on a 4.5° grid).
  SphereMap m(R, 1);
  const int x0 = R / 2 + 3, y0 = R / 2 + 2;
  m.at(x0, y0, 0) = 1000.0f;
  const SphereMap s = k.apply(m);
  EXPECT_NEAR(map_sum(s), 1000.0, 1000.0 * 1e-6);
  const glm::dvec3 c = texel_direction(R, x0, y0);
  double second = 0, total = 0;
  for (int y = 0; y < R; ++y)
    for (int x = 0; x < 2 * R; ++x) {
      const double v = s.at(x, y, 0);
      if (v <= 0) continue;
      const double t = std::acos(std::min(1.0, glm::dot(c, texel_direction(R, x, y))));
      second += v * t * t;
      total += v;
    }
  EXPECT_NEAR(second / total, 2.0 / kappa, 0.05 * (2.0 / kappa));
  for (float v : s.values()) EXPECT_GE(v, 0.0f);
}

TEST(SphereMapKernel, CrossesTheEquatorSeamAsTheSphereDoes) {
  // A texel on the upper square's border (next to the equator) hands light to the lower hemisphere as a
  // Gaussian of σ = 1/√κ across the equator would: the fraction Φ(−elevation/σ) of it (the kernel works on
  // directions, not on square coordinates, so the seam does not stop it).
  const int R = 32;
  const SphereMapKernel k(R, 200);
  SphereMap m(R, 1);
  m.at(R - 1, R / 2, 0) = 1.0f;  // upper square, right edge: 3.5° above the equator at +x
  const SphereMap s = k.apply(m);
  double upper = 0, lower = 0;
  for (int y = 0; y < R; ++y)
    for (int x = 0; x < 2 * R; ++x) (x < R ? upper : lower) += s.at(x, y, 0);
  const double elevation = std::asin(texel_direction(R, R - 1, R / 2).z);
  const double expected = 0.5 * std::erfc(elevation * std::sqrt(200.0) / std::sqrt(2.0));
  // Measured 0.152 against 0.192: the nearest lower texels are 7° away, the kernel sampled on 4.5° texels.
  EXPECT_NEAR(lower, expected, 0.25 * expected);
  EXPECT_NEAR(upper + lower, 1.0, 1e-6);
}

TEST(SphereMapKernel, RefusesBadArgumentsAndIsShared) {
  EXPECT_THROW(SphereMapKernel(0, 10), std::invalid_argument);
  EXPECT_THROW(SphereMapKernel(SphereMapKernel::kMaxResolution * 2, 10), std::invalid_argument);
  EXPECT_THROW(SphereMapKernel(16, 0), std::invalid_argument);
  EXPECT_THROW(SphereMapKernel(16, NAN), std::invalid_argument);
  const SphereMapKernel k(16, 50);
  EXPECT_THROW(k.apply(SphereMap(8, 1)), std::invalid_argument);
  EXPECT_EQ(SphereMapKernel::shared(16, 50).get(), SphereMapKernel::shared(16, 50).get());
}

TEST(SphereMapKernel, SmoothedLevelIsTheSameForAnyThreadCount) {
  // Each map is smoothed alone: the level does not depend on how the APLs were split among threads.
  AplLevel level;
  level.map_resolution = 16;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 40; ++i) {
    Apl a;
    a.map = SphereMap(16, i % 2 ? 3 : 1);
    for (float& v : a.map.values()) v = u(rng) < 0.1f ? 10.0f * u(rng) : 0.0f;
    level.apls.push_back(std::move(a));
  }
  const SphereMapKernel k(16, 100);
  const AplLevel one = smoothed_level(level, k, 1), three = smoothed_level(level, k, 3);
  for (std::size_t i = 0; i < level.apls.size(); ++i) {
    EXPECT_EQ(one.apls[i].map.values(), three.apls[i].map.values()) << i;
    EXPECT_NEAR(map_sum(one.apls[i].map), map_sum(level.apls[i].map), 1e-5 * (1 + map_sum(level.apls[i].map)));
  }
}

TEST(SphereMapKernel, PeakGuardRefusesToFlattenANarrowLobeButNotABroadOne) {
  // kernel_peak_change on exact (noise-free) maps of many rays: a cos^50 lobe (σ 1/√50 rad = 8.1°) loses
  // 1.7 % of its brightest 5 % of flux under σ 1.7° sampled on 2.25° texels, far beyond the 0.3 % that
  // 10⁷ rays' noise allows there; a Lambertian cos θ loses ~1/κ (0.1 %).
  const int R = 64;
  const double kappa = 1.0 / ((1.7 * kPi / 180) * (1.7 * kPi / 180));
  const SphereMapKernel k(R, kappa);
  const auto level_of = [&](double m) {
    AplLevel level;
    level.map_resolution = R;
    Apl a;
    a.map = SphereMap(R, 1);
    for (int y = 0; y < R; ++y)
      for (int x = 0; x < 2 * R; ++x) a.map.at(x, y, 0) = float(std::pow(std::max(0.0, texel_direction(R, x, y).z), m));
    level.apls.push_back(std::move(a));
    return level;
  };
  const auto [narrow, narrow_allowed] = kernel_peak_change(level_of(50), k, 10000000);
  EXPECT_GT(narrow, 0.01);
  EXPECT_GT(narrow, narrow_allowed);
  const auto [broad, broad_allowed] = kernel_peak_change(level_of(1), k, 10000000);
  EXPECT_LT(broad, 0.005);
  EXPECT_LT(broad, broad_allowed);
  // Unknown ray count: never allowed.
  const auto [unknown, none] = kernel_peak_change(level_of(1), k, 0);
  EXPECT_GT(unknown, none);
}
