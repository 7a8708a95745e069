// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Flux-exact pull-push smoothing of sparse sphere-map histograms (math/sphere_map_smoothing.h).
#include <lumx/math/sphere_map.h>
#include <lumx/math/sphere_map_smoothing.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

using namespace lumx;

namespace {

double sum(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

/// A histogram of n rays of unit flux drawn from I(ω) ∝ 1 + 0.9·ω_z (rejection from the uniform sphere),
/// and the expected flux per texel (the density at the texel centre × its solid angle, renormalised).
struct Histogram {
  std::vector<double> flux, expected;
  std::vector<std::uint32_t> rays;
};
Histogram dipole_histogram(int R, int n, unsigned seed) {
  Histogram h;
  const std::size_t T = std::size_t(2 * R) * std::size_t(R);
  h.flux.assign(T, 0.0);
  h.rays.assign(T, 0);
  h.expected.assign(T, 0.0);
  std::mt19937 rng(seed);
  std::normal_distribution<float> g;
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < n;) {
    const glm::vec3 w = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
    if (u(rng) * 1.9f > 1.0f + 0.9f * w.z) continue;
    int x, y;
    sphere_map::texel_of(w, R, x, y);
    h.flux[std::size_t(y) * std::size_t(2 * R) + std::size_t(x)] += 1.0;
    ++h.rays[std::size_t(y) * std::size_t(2 * R) + std::size_t(x)];
    ++i;
  }
  for (int y = 0; y < R; ++y)
    for (int x = 0; x < 2 * R; ++x) {
      const glm::vec3 w = sphere_map::uv_to_direction({(float(x) + 0.5f) / float(2 * R), (float(y) + 0.5f) / float(R)});
      h.expected[std::size_t(y) * std::size_t(2 * R) + std::size_t(x)] = 1.0 + 0.9 * double(w.z);
    }
  const double scale = double(n) / sum(h.expected);
  for (double& e : h.expected) e *= scale;
  return h;
}

double relative_rms(const std::vector<double>& a, const std::vector<double>& truth) {
  double se = 0, st = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    se += (a[i] - truth[i]) * (a[i] - truth[i]);
    st += truth[i] * truth[i];
  }
  return std::sqrt(se / st);
}

}  // namespace

TEST(SphereMapSmoothing, KeepsTheFluxExactly) {
  for (int R : {1, 2, 8, 32}) {
    for (double t : {0.5, 1.0, 4.0, 50.0}) {
      const Histogram h = dipole_histogram(R, 3 * R * R, unsigned(R));
      const std::vector<double> out = smooth_sparse_map(h.flux, h.rays, R, t);
      EXPECT_NEAR(sum(out), sum(h.flux), 1e-12 * sum(h.flux)) << R << " " << t;
      for (double v : out) EXPECT_GE(v, 0.0);
      const std::vector<double> with_prior = smooth_sparse_map(h.flux, h.rays, R, t, &h.expected);
      EXPECT_NEAR(sum(with_prior), sum(h.flux), 1e-12 * sum(h.flux)) << R << " " << t;
    }
  }
}

TEST(SphereMapSmoothing, LeavesADenseMapAloneAndKeepsDarkTexelsDark) {
  const int R = 16;
  Histogram h = dipole_histogram(R, 400000, 5);  // ≥ ~700 rays per texel
  // Darken one quadrant of the upper square: zero rays there, under parents with many.
  for (int y = 0; y < R / 2; ++y)
    for (int x = 0; x < R / 2; ++x) {
      h.flux[std::size_t(y) * std::size_t(2 * R) + std::size_t(x)] = 0;
      h.rays[std::size_t(y) * std::size_t(2 * R) + std::size_t(x)] = 0;
    }
  const std::vector<double> out = smooth_sparse_map(h.flux, h.rays, R, 16);
  for (std::size_t i = 0; i < out.size(); ++i) EXPECT_NEAR(out[i], h.flux[i], 1e-9 * h.flux[i] + 1e-12) << i;
  // min_rays ≤ 0: the input, unchanged.
  EXPECT_EQ(smooth_sparse_map(h.flux, h.rays, R, 0), h.flux);
}

TEST(SphereMapSmoothing, ReducesTheNoiseOfASparseHistogram) {
  // Two rays per texel on average: the raw histogram is off by ~64 % per texel. Smoothed with 8 rays per
  // child, nodes split by the data down to ~8 rays (noise 1/√8 ≈ 35 %) and take a smooth shape below:
  // measured 30 %.
  const int R = 32;
  const Histogram h = dipole_histogram(R, 2 * 2 * R * R, 11);
  const double raw = relative_rms(h.flux, h.expected);
  const double smooth = relative_rms(smooth_sparse_map(h.flux, h.rays, R, 8), h.expected);
  EXPECT_GT(raw, 0.5);
  EXPECT_LT(smooth, 0.6 * raw) << raw << " " << smooth;
  EXPECT_LT(smooth, 1.0 / std::sqrt(8.0)) << smooth;
  // With the true shape as the prior, sparse nodes take it: closer still.
  const double with_prior = relative_rms(smooth_sparse_map(h.flux, h.rays, R, 8, &h.expected), h.expected);
  EXPECT_LT(with_prior, smooth) << with_prior;
}

TEST(SphereMapSmoothing, TooFewRaysTakeThePriorsShapeWithinEachHemisphere) {
  // 5 rays over 2 · 8² texels, threshold 4: no node below the top is dense, so each hemisphere keeps the
  // flux its rays brought (the data decide the hemispheres) shaped exactly like the prior inside it.
  const int R = 8;
  const Histogram h = dipole_histogram(R, 5, 3);
  std::vector<double> prior(h.flux.size());
  for (std::size_t i = 0; i < prior.size(); ++i) prior[i] = 1.0 + double(i % 7);
  const std::vector<double> out = smooth_sparse_map(h.flux, h.rays, R, 4, &prior);
  for (int half = 0; half < 2; ++half) {
    double data = 0, shape = 0;
    for (int y = 0; y < R; ++y)
      for (int x = half * R; x < (half + 1) * R; ++x) {
        data += h.flux[std::size_t(y) * std::size_t(2 * R) + std::size_t(x)];
        shape += prior[std::size_t(y) * std::size_t(2 * R) + std::size_t(x)];
      }
    for (int y = 0; y < R; ++y)
      for (int x = half * R; x < (half + 1) * R; ++x) {
        const std::size_t t = std::size_t(y) * std::size_t(2 * R) + std::size_t(x);
        EXPECT_NEAR(out[t], data / shape * prior[t], 1e-12) << x << " " << y;
      }
  }
}

TEST(SphereMapSmoothing, AFewDownwardRaysStayDownward) {
  // A downlight's 10 rays, all below the horizon (right square), threshold far above: no light may
  // reach the upper hemisphere, with or without a prior that has light there.
  const int R = 8;
  const std::size_t T = std::size_t(2 * R * R);
  std::vector<double> flux(T, 0.0);
  std::vector<std::uint32_t> rays(T, 0);
  for (int i = 0; i < 10; ++i) {
    const std::size_t t = std::size_t(i % R) * std::size_t(2 * R) + std::size_t(R + (3 * i) % R);
    flux[t] += 1.0;
    ++rays[t];
  }
  const std::vector<double> uniform(T, 1.0);
  for (const std::vector<double>* prior : {static_cast<const std::vector<double>*>(nullptr), &uniform}) {
    const std::vector<double> out = smooth_sparse_map(flux, rays, R, 1000, prior);
    double up = 0, down = 0;
    for (int y = 0; y < R; ++y)
      for (int x = 0; x < 2 * R; ++x) (x < R ? up : down) += out[std::size_t(y) * std::size_t(2 * R) + std::size_t(x)];
    EXPECT_EQ(up, 0.0);
    EXPECT_NEAR(down, 10.0, 1e-12);
  }
}

TEST(SphereMapSmoothing, WithoutAPriorTheShapeIsTheBilinearUpsampling) {
  // R = 8; rays only in the upper square's left half (x < 4), one per texel: 32 rays. Threshold 4, so a
  // node splits by the data from 16 rays up. The square (32) and its 4 × 4 quadrants (16, 0) split by the
  // data: the right half stays exactly dark. The 2 × 2 nodes (4 rays) are sparse: their texels take the
  // bilinear upsampling of the 2 × 2 level, flat (4, 4) away from the dark edge and ramping down next to
  // it: texel columns 0 and 1 equal, column 3 darker than column 2.
  const int R = 8;
  const std::size_t T = std::size_t(2 * R * R), W = std::size_t(2 * R);
  std::vector<double> flux(T, 0.0);
  std::vector<std::uint32_t> rays(T, 0);
  for (int y = 0; y < R; ++y)
    for (int x = 0; x < R / 2; ++x) {
      flux[std::size_t(y) * W + std::size_t(x)] = 1.0;
      rays[std::size_t(y) * W + std::size_t(x)] = 1;
    }
  const std::vector<double> out = smooth_sparse_map(flux, rays, R, 4);
  double sum = 0;
  for (int y = 0; y < R; ++y) {
    for (int x = 0; x < R; ++x) sum += out[std::size_t(y) * W + std::size_t(x)];
    for (int x = R / 2; x < R; ++x) EXPECT_EQ(out[std::size_t(y) * W + std::size_t(x)], 0.0) << x << " " << y;
    const double* row = out.data() + std::size_t(y) * W;
    EXPECT_NEAR(row[0], row[1], 1e-12) << y;
    EXPECT_GT(row[2], row[3] + 0.05) << y;
    EXPECT_GT(row[3], 0.0) << y;
  }
  EXPECT_NEAR(sum, 32.0, 1e-12);
}

TEST(SphereMapSmoothing, ADarkPriorFallsBackToTheSmoothShape) {
  // A prior with no light in the upper square, sparse data there: the upper square's flux must still be
  // placed (by the bilinear shape), not lost or left to a 0/0.
  const int R = 8;
  const Histogram h = dipole_histogram(R, 40, 9);
  std::vector<double> prior(h.flux.size(), 0.0);
  for (int y = 0; y < R; ++y)
    for (int x = R; x < 2 * R; ++x) prior[std::size_t(y) * std::size_t(2 * R) + std::size_t(x)] = 1.0;
  const std::vector<double> out = smooth_sparse_map(h.flux, h.rays, R, 100, &prior);
  double up_in = 0, up_out = 0;
  for (int y = 0; y < R; ++y)
    for (int x = 0; x < R; ++x) {
      up_in += h.flux[std::size_t(y) * std::size_t(2 * R) + std::size_t(x)];
      up_out += out[std::size_t(y) * std::size_t(2 * R) + std::size_t(x)];
      EXPECT_TRUE(std::isfinite(out[std::size_t(y) * std::size_t(2 * R) + std::size_t(x)]));
    }
  EXPECT_GT(up_in, 0.0);
  EXPECT_NEAR(up_out, up_in, 1e-12);
  // And the fallback has a shape: upper-square quadrants (0,0) and (1,1) hold 12 rays each, (1,0) and
  // (0,1) none; threshold 4, so the square splits by the data (24 ≥ 16) and the quadrants (12 < 16) by
  // the shape. With the prior dark there, texels next to the dark quadrants get less than those far
  // from them (an equal split would make the quadrant flat).
  {
    const std::size_t W = std::size_t(2 * R);
    std::vector<double> f(h.flux.size(), 0.0);
    std::vector<std::uint32_t> c(h.flux.size(), 0);
    for (int i = 0; i < 12; ++i) {
      const int x = i % 4, y = (i / 4) % 4;
      f[std::size_t(y) * W + std::size_t(x)] += 1;
      ++c[std::size_t(y) * W + std::size_t(x)];
      f[std::size_t(y + 4) * W + std::size_t(x + 4)] += 1;
      ++c[std::size_t(y + 4) * W + std::size_t(x + 4)];
    }
    const std::vector<double> o = smooth_sparse_map(f, c, R, 4, &prior);
    EXPECT_GT(o[0], o[3] + 0.01);           // (0,0) far from the dark quadrant (1,0); (3,0) next to it
    EXPECT_GT(o[0], o[3 * W] + 0.01);       // likewise (0,3) next to the dark quadrant (0,1)
    EXPECT_EQ(o[4], 0.0);                   // the dark quadrants stay dark
  }
  // Non-finite and negative prior values count as dark.
  std::vector<double> bad = prior;
  bad[0] = INFINITY;
  bad[1] = -5;
  bad[2] = NAN;
  for (double v : smooth_sparse_map(h.flux, h.rays, R, 100, &bad)) EXPECT_TRUE(std::isfinite(v));
}

TEST(SphereMapSmoothing, RefusesBadArguments) {
  const std::vector<double> f(2 * 3 * 3, 1.0);
  const std::vector<std::uint32_t> c(2 * 3 * 3, 1);
  EXPECT_THROW(smooth_sparse_map(f, c, 3, 1), std::invalid_argument);  // R not a power of two
  const std::vector<double> f4(2 * 4 * 4, 1.0);
  EXPECT_THROW(smooth_sparse_map(f4, c, 4, 1), std::invalid_argument);  // sizes disagree
  const std::vector<double> short_prior(5, 1.0);
  const std::vector<std::uint32_t> c4(2 * 4 * 4, 1);
  EXPECT_THROW(smooth_sparse_map(f4, c4, 4, 1, &short_prior), std::invalid_argument);
}
