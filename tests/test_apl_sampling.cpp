// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Sampling an APL level: emission samples carry the right flux and their pdfs agree exactly; light
// selection at a shading point is normalised, consistent and gives an unbiased irradiance estimator.
#include <lumx/apl/evaluation.h>
#include <lumx/apl/sampling.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace lumx;

namespace {

AplSet lobes(int n, ChannelLayout channels, unsigned seed, const MapFrame& frame = {}) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  AplSet set;
  set.channels = channels;
  set.bounds.radius = 0.5;
  AplLevel level;
  level.map_resolution = 16;
  level.frame = frame;
  const int nc = channel_count(channels);
  for (int i = 0; i < n; ++i) {
    Apl a;
    a.position = {u(rng) - 0.5f, u(rng) - 0.5f, 0.2f * u(rng)};
    a.map = SphereMap(16, nc);
    const glm::vec3 axis = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, -1.0f));
    const float scale = 1.0f + 50.0f * u(rng);
    for (int y = 0; y < a.map.height(); ++y)
      for (int x = 0; x < a.map.width(); ++x) {
        const glm::vec3 w = sphere_map::uv_to_direction({(x + 0.5f) / a.map.width(), (y + 0.5f) / a.map.height()});
        const float v = scale * std::pow(std::max(0.0f, glm::dot(w, axis)), 3.0f);
        for (int c = 0; c < nc; ++c) a.map.at(x, y, c) = v * (1.0f + 0.2f * float(c));
      }
    a.flux = a.map.integral();
    level.apls.push_back(std::move(a));
  }
  set.levels.push_back(std::move(level));
  return set;
}

}  // namespace

namespace {
/// ∫ lookup(ω) dω over every map of the level (the emission the samples estimate), by midpoint
/// quadrature on a grid 8× finer than the maps: the bilinear interpolant's integral differs from the
/// texel sum by O(1/R²), which this resolves.
glm::dvec3 bilinear_flux(const AplLevel& level) {
  glm::dvec3 total(0.0);
  for (const Apl& a : level.apls) {
    SphereMap fine(8 * a.map.resolution(), 1);
    glm::dvec3 sum(0.0);
    for (int y = 0; y < fine.height(); ++y)
      for (int x = 0; x < fine.width(); ++x)
        sum += glm::dvec3(a.map.lookup(sphere_map::uv_to_direction({(x + 0.5f) / fine.width(), (y + 0.5f) / fine.height()})));
    total += sum * fine.texel_solid_angle();
  }
  return total;
}
}  // namespace

TEST(AplSampling, EmissionSamplesAreUnbiasedAndTheirPdfsConsistent) {
  // In the photometric frame and in a turned one (the builder's, for a beam): the samples are turned to
  // photometric directions, and pdf() of that direction is the sample's density bit for bit.
  const MapFrame turned = map_frame_for(glm::dvec3(-0.1, 0.2, -1.0));
  for (const MapFrame& frame : {MapFrame{}, turned})
  for (ChannelLayout layout : {ChannelLayout::luminance, ChannelLayout::rgb}) {
    const AplSet set = lobes(12, layout, 1, frame);
    const AplEmissionSampler sampler(set, 0);
    const glm::dvec3 expected = bilinear_flux(set.levels[0]);
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<int> chosen(12, 0);
    const int N = 200000;
    glm::dvec3 sum(0.0), sq(0.0);
    for (int i = 0; i < N; ++i) {
      const EmissionSample s = sampler.sample(u(rng), u(rng), u(rng));
      ASSERT_TRUE(s.valid());
      ASSERT_EQ(sampler.pdf(s.apl, s.direction), s.pdf_apl * s.pdf_direction);
      ASSERT_EQ(s.position, set.levels[0].apls[s.apl].position);
      sum += glm::dvec3(s.flux);
      sq += glm::dvec3(s.flux) * glm::dvec3(s.flux);
      ++chosen[s.apl];
    }
    for (int c = 0; c < 3; ++c) {
      const double mean = sum[c] / N, sigma = std::sqrt((sq[c] / N - mean * mean) / N);
      EXPECT_NEAR(mean, expected[c], 5 * sigma) << "channel " << c;  // 5σ of the sample mean
    }
    const double total = luminance_of(layout, set.levels[0].flux());
    for (std::size_t i = 0; i < 12; ++i) {
      const double p = luminance_of(layout, set.levels[0].apls[i].flux) / total;
      EXPECT_NEAR(double(chosen[i]) / N, p, 5 * std::sqrt(p * (1 - p) / N)) << i;  // 5σ binomial
    }
  }
}

TEST(AplSampling, EveryDirectionWithIntensityCanBeSampled) {
  // A single bright texel: the bilinear intensity spreads into its neighbours, and so must the pdf.
  AplSet set;
  AplLevel level;
  level.map_resolution = 8;
  Apl a;
  a.map = SphereMap(8, 1);
  a.map.at(0, 3, 0) = 100.0f;  // on the upper square's left edge: its neighbours include the other square
  a.flux = a.map.integral();
  level.apls.push_back(a);
  set.levels.push_back(level);
  const AplEmissionSampler sampler(set, 0);
  std::mt19937 rng(3);
  std::normal_distribution<float> g;
  int lit = 0;
  for (int i = 0; i < 200000; ++i) {
    const glm::vec3 w = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
    if (intensity(set.levels[0], a, w).x > 0) {
      ++lit;
      ASSERT_GT(sampler.pdf(0, w), 0.0f);
    }
  }
  EXPECT_GT(lit, 100);
}

TEST(AplSampling, DarkLevelGivesInvalidSamples) {
  AplSet set = lobes(3, ChannelLayout::luminance, 5);
  for (Apl& a : set.levels[0].apls) {
    std::fill(a.map.values().begin(), a.map.values().end(), 0.0f);
    a.flux = glm::dvec3(0.0);
  }
  const AplEmissionSampler sampler(set, 0);
  EXPECT_TRUE(sampler.is_zero());
  EXPECT_FALSE(sampler.sample(0.3f, 0.5f, 0.5f).valid());
  EXPECT_FALSE(choose_light(set, 0, {0, 0, -2}, {0, 0, 1}, 0.5f).valid());
}

TEST(AplSampling, LightChoiceIsNormalisedConsistentAndUnbiased) {
  const AplSet set = lobes(40, ChannelLayout::luminance, 6);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int trial = 0; trial < 20; ++trial) {
    const glm::vec3 x(2.0f * u(rng) - 1.0f, 2.0f * u(rng) - 1.0f, -0.3f - 2.0f * u(rng));
    const glm::vec3 n = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, 1.0f));
    double sum_p = 0;
    for (std::size_t i = 0; i < 40; ++i) sum_p += light_choice_probability(set, 0, x, n, i);
    ASSERT_NEAR(sum_p, 1.0, 1e-5);
    // One-sample estimator E ≈ I_i cos θ_i / r_i² / p_i, against the exact sum over all APLs.
    const double exact = irradiance(set, 0, x, n).irradiance.x;
    const int N = 20000;
    double mean = 0, sq = 0;
    for (int k = 0; k < N; ++k) {
      const LightChoice c = choose_light(set, 0, x, n, u(rng));
      ASSERT_TRUE(c.valid());
      ASSERT_EQ(c.probability, light_choice_probability(set, 0, x, n, c.apl));
      const Apl& a = set.levels[0].apls[c.apl];
      const glm::vec3 d = x - a.position;
      const float r2 = glm::dot(d, d);
      const glm::vec3 w = d / std::sqrt(r2);
      const double e = std::max(0.0f, -glm::dot(n, w)) * intensity(set.levels[0], a, w).x / r2 / c.probability;
      mean += e;
      sq += e * e;
    }
    mean /= N;
    const double sigma = std::sqrt(std::max(0.0, sq / N - mean * mean) / N);
    EXPECT_NEAR(mean, exact, 5 * sigma + 1e-6 * exact) << "trial " << trial;
  }
  // An APL behind the receiver's surface is never chosen.
  const glm::vec3 x(0, 0, 5), up(0, 0, 1);  // above every APL, facing away
  EXPECT_FALSE(choose_light(set, 0, x, up, 0.5f).valid());
  EXPECT_EQ(light_choice_probability(set, 0, x, up, 3), 0.0f);
}
