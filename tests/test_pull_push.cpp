// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Pull-push preview filtering (lumx/math/pull_push.h, seed 002 §5) and the rayset intensity preview
// (lumx/rays/intensity_preview.h): stable texels untouched, noise cut where particles are few, light kept
// out of shadow better than by bilinear upsampling, flux kept, bad input refused.
#include <lumx/math/pull_push.h>
#include <lumx/rays/intensity_preview.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace {

using namespace lumx;

/// A histogram of `rays` directions drawn uniformly on the sphere (flux 1 each) or, with `cone_deg` > 0,
/// uniformly within that angle of +Z.
void histogram(int R, std::size_t rays, double cone_deg, std::uint32_t seed, std::vector<double>& flux,
               std::vector<double>& count) {
  flux.assign(std::size_t(2) * R * R, 0.0);
  count.assign(flux.size(), 0.0);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double zmin = cone_deg > 0 ? std::cos(cone_deg * M_PI / 180) : -1.0;
  for (std::size_t i = 0; i < rays; ++i) {
    const double z = zmin + (1 - zmin) * u(rng), phi = 2 * M_PI * u(rng), s = std::sqrt(std::max(0.0, 1 - z * z));
    int x, y;
    sphere_map::texel_of(glm::vec3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(z)), R, x, y);
    const std::size_t t = std::size_t(y) * std::size_t(2 * R) + std::size_t(x);
    flux[t] += 1;
    count[t] += 1;
  }
}

double relative_rmse(const std::vector<double>& v, double truth) {
  double sq = 0;
  for (double x : v) sq += (x - truth) * (x - truth);
  return std::sqrt(sq / double(v.size())) / truth;
}

double sum(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s;
}

TEST(PullPush, StableTexelsAreKeptExactly) {
  std::vector<double> flux, count;
  histogram(16, 512 * 400, 0, 1, flux, count);  // ~400 per texel, none below 32 (Poisson: 17 σ)
  const PullPushResult r = pull_push(flux, count, 16);
  EXPECT_EQ(r.levels, 5);
  for (std::size_t i = 0; i < flux.size(); ++i) {
    ASSERT_EQ(r.kind[i], PullPushTexel::stable) << i;
    EXPECT_NEAR(r.flux[i], flux[i], 1e-9 * flux[i]) << i;
  }
}

TEST(PullPush, SparseUniformHistogramBecomesNearlyFlat) {
  // 4 particles per texel: the histogram is off by 1/√4 = 50 % (Poisson). Every texel is unstable
  // (threshold 32), so values come from level 3 (64× the particles: ~1/√256 = 6 %) through bilateral
  // upsampling; allow 15 % for the interpolation across the squares' seams and corners.
  const int R = 64;
  std::vector<double> flux, count;
  histogram(R, std::size_t(2) * R * R * 4, 0, 2, flux, count);
  const double truth = 4.0;
  const double raw = relative_rmse(flux, truth);
  const PullPushResult r = pull_push(flux, count, R);
  const double filtered = relative_rmse(r.flux, truth);
  EXPECT_NEAR(raw, 0.5, 0.02);
  EXPECT_LT(filtered, 0.15) << "raw " << raw;
  EXPECT_NEAR(sum(r.flux), sum(flux), 1e-9 * sum(flux));  // the flux is kept
}

TEST(PullPush, BilateralUpsamplingLeaksLessLightIntoShadowThanBilinear) {
  // A 40° cone of light, few particles: flux that the filter puts into texels wholly outside the cone is
  // a leak. Bilateral weights (σ_r = 0.5 f̃) must leak less than the same push with σ_r huge (bilinear).
  const int R = 64;
  std::vector<double> flux, count;
  histogram(R, 60000, 40, 3, flux, count);
  const double zcut = std::cos(44 * M_PI / 180);  // texel centres beyond 44°: wholly outside (texel ~2.5°)
  const auto leak = [&](const PullPushResult& r) {
    double outside = 0;
    for (int y = 0; y < R; ++y)
      for (int x = 0; x < 2 * R; ++x) {
        const glm::vec3 w = sphere_map::uv_to_direction({(x + 0.5f) / float(2 * R), (y + 0.5f) / float(R)});
        if (w.z < zcut) outside += r.flux[std::size_t(y) * std::size_t(2 * R) + std::size_t(x)];
      }
    return outside / sum(r.flux);
  };
  PullPushOptions bilinear;
  bilinear.sigma_range = 1e12;
  const double leak_bilateral = leak(pull_push(flux, count, R)), leak_bilinear = leak(pull_push(flux, count, R, bilinear));
  EXPECT_LT(leak_bilateral, leak_bilinear);
  EXPECT_LT(leak_bilateral, 0.05);
  // Shadow borders are recognised on coarse levels only; level 0 marks no texel as border.
  const PullPushResult r = pull_push(flux, count, R);
  for (PullPushTexel k : r.kind) EXPECT_NE(k, PullPushTexel::border);
}

TEST(PullPush, BadInputIsRefused) {
  std::vector<double> flux(2 * 4 * 4, 1.0), count(flux.size(), 1.0);
  EXPECT_THROW(pull_push(flux, count, 3), std::invalid_argument);  // not a power of two
  EXPECT_THROW(pull_push(flux, count, 8), std::invalid_argument);  // wrong size
  flux[5] = std::nan("");
  EXPECT_THROW(pull_push(flux, count, 4), std::invalid_argument);
  flux[5] = 1;
  count[7] = -1;
  EXPECT_THROW(pull_push(flux, count, 4), std::invalid_argument);
}

TEST(IntensityPreview, BinsRaysAsIntensityAndKeepsTheirFlux) {
  RayChunk rays;
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  double total = 0;
  for (int i = 0; i < 20000; ++i) {
    glm::vec3 d(u(rng), u(rng), u(rng));
    if (glm::length(d) < 1e-3f) continue;
    const float f = 0.5f + 0.5f * std::abs(u(rng));
    rays.push_back({0, 0, 0}, d, f);
    total += f;
  }
  MemoryRaySource source(rays, {});
  const IntensityPreview p = intensity_preview(source, 16);
  EXPECT_EQ(p.rays, rays.size());
  EXPECT_NEAR(p.histogram.integral().x, total, 1e-5 * total);  // Σ I Ω = Σ flux
  EXPECT_NEAR(p.filtered.integral().x, total, 1e-5 * total);
  RayChunk bad;
  bad.push_back({0, 0, 0}, {0, 0, 0}, 1.0f);
  MemoryRaySource zero(bad, {});
  EXPECT_THROW(intensity_preview(zero, 16), std::invalid_argument);
}

}  // namespace
