// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Tests of lumx/math/piecewise_constant_2d.h and lumx/math/sphere_map_sampler.h.
//
// The sampler is checked the way pbrt-v4's and Mitsuba's warp tests check theirs: many samples are
// binned into a (cos θ, φ) histogram, the expected count of each bin is the sampler's own pdf()
// integrated over the bin numerically, bins expecting fewer than 5 samples are pooled, and Pearson's χ²
// gives a p-value (regularised incomplete gamma function, below). Each goodness-of-fit test rejects at
// significance 0.01 after a Šidák correction for the kGoodnessOfFitTests tests in this file. Exactness
// properties (pdf of a sample equals pdf of its direction, no sample in a zero texel, the pdf
// integrates to 1) are checked directly. All random inputs come from fixed seeds.
#include <lumx/math/piecewise_constant_2d.h>
#include <lumx/math/sphere_map_sampler.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace lumx;

namespace {

// ---- statistics --------------------------------------------------------------------------------------

/// Q(a, x) = Γ(a, x) / Γ(a), the regularised upper incomplete gamma function: the series for P = 1 − Q
/// below x = a + 1, Legendre's continued fraction for Q (evaluated by Lentz's method) above it.
double regularized_gamma_q(double a, double x) {
  if (!(x > 0)) return 1.0;
  const double log_prefactor = -x + a * std::log(x) - std::lgamma(a);  // log(xᵃ e⁻ˣ / Γ(a))
  if (x < a + 1) {
    // P(a, x) = xᵃ e⁻ˣ / Γ(a) · Σₙ xⁿ / (a (a+1) … (a+n)).
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 100000 && term > sum * 1e-17; ++n) {
      term *= x / (a + n);
      sum += term;
    }
    return std::max(0.0, 1.0 - sum * std::exp(log_prefactor));
  }
  // Q(a, x) = xᵃ e⁻ˣ / Γ(a) · 1/(x+1−a− 1·(1−a)/(x+3−a− 2·(2−a)/(x+5−a− …))).
  constexpr double kTiny = 1e-300;
  double b = x + 1 - a, c = 1 / kTiny, d = 1 / b, h = d;
  for (int n = 1; n < 100000; ++n) {
    const double an = -n * (n - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1) < 1e-16) break;
  }
  return std::exp(log_prefactor) * h;
}

struct ChiSquare {
  double statistic = 0;
  int dof = 0;
  double p_value = 1;
};

/// Pearson's χ² of observed counts against expected counts; bins expecting < 5 are pooled into one bin
/// (merged into the smallest regular bin if the pool itself expects < 5).
ChiSquare chi_square(const std::vector<double>& observed, const std::vector<double>& expected) {
  std::vector<std::pair<double, double>> terms;  // (observed, expected)
  double pooled_obs = 0, pooled_exp = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    if (expected[i] < 5) {
      pooled_obs += observed[i];
      pooled_exp += expected[i];
    } else {
      terms.push_back({observed[i], expected[i]});
    }
  }
  if (pooled_exp >= 5 || terms.empty()) {
    terms.push_back({pooled_obs, pooled_exp});
  } else if (pooled_exp > 0 || pooled_obs > 0) {
    auto smallest = std::min_element(terms.begin(), terms.end(), [](auto& l, auto& r) { return l.second < r.second; });
    smallest->first += pooled_obs;
    smallest->second += pooled_exp;
  }
  ChiSquare r;
  for (const auto& [o, e] : terms) r.statistic += e > 0 ? (o - e) * (o - e) / e : (o > 0 ? 1e300 : 0.0);
  r.dof = int(terms.size()) - 1;
  r.p_value = r.dof > 0 ? regularized_gamma_q(0.5 * r.dof, 0.5 * r.statistic) : 1.0;
  return r;
}

/// Number of goodness-of-fit tests below that are expected to pass (the Šidák family).
constexpr int kGoodnessOfFitTests = 13;
/// Per-test significance: 1 − (1 − 0.01)^(1/m), so the family rejects a correct sampler with p = 0.01.
const double kSignificance = 1.0 - std::pow(1.0 - 0.01, 1.0 / kGoodnessOfFitTests);

// ---- random numbers ----------------------------------------------------------------------------------

/// A float in [0, 1) with 24 random bits.
float uniform_float(std::mt19937& rng) {
  return float(rng() >> 8) * 0x1p-24f;
}

// ---- maps --------------------------------------------------------------------------------------------

/// Direction of the centre of texel (x, y); the lower square's centres are never on u = 0.5.
glm::vec3 texel_centre(const SphereMap& m, int x, int y) {
  return sphere_map::uv_to_direction({(x + 0.5f) / m.width(), (y + 0.5f) / m.height()});
}

SphereMap map_of(int R, int channels, const std::function<glm::vec3(const glm::vec3&)>& f) {
  SphereMap m(R, channels);
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x) {
      const glm::vec3 v = f(texel_centre(m, x, y));
      for (int c = 0; c < channels; ++c) m.at(x, y, c) = v[c];
    }
  return m;
}

/// 1 + 0.5x + 0.3y + 0.2z: smooth, positive, asymmetric in x, y and z.
SphereMap smooth_map(int R, int channels = 1) {
  return map_of(R, channels, [](const glm::vec3& w) {
    const float f = 1.0f + 0.5f * w.x + 0.3f * w.y + 0.2f * w.z;
    return glm::vec3(f, 0.5f + 0.5f * w.z * w.z, 0.1f + 0.2f * std::abs(w.x));
  });
}

/// A lobe around (0.3, −0.5, 0.81) with a floor: ratio ~50 between peak and floor.
SphereMap peaked_map(int R, int channels = 1) {
  const glm::vec3 axis = glm::normalize(glm::vec3(0.3f, -0.5f, 0.81f));
  return map_of(R, channels, [axis](const glm::vec3& w) {
    const float f = std::exp(4.0f * (glm::dot(w, axis) - 1.0f)) + 0.02f;
    return glm::vec3(f, 2.0f * f, 0.5f);
  });
}

/// Texels with even x + y hold 1 + 0.5·((7x + 3y) mod 5); odd ones are zero.
SphereMap checkerboard_map(int R) {
  SphereMap m(R, 1);
  for (int y = 0; y < R; ++y)
    for (int x = 0; x < 2 * R; ++x) m.at(x, y, 0) = (x + y) % 2 ? 0.0f : 1.0f + 0.5f * float((7 * x + 3 * y) % 5);
  return m;
}

/// All texels `floor`, texel (bx, by) `peak`.
SphereMap spike_map(int R, int bx, int by, float peak, float floor) {
  SphereMap m(R, 1);
  std::fill(m.values().begin(), m.values().end(), floor);
  m.at(bx, by, 0) = peak;
  return m;
}

double importance(const SphereMap& m, int x, int y) {
  const glm::vec3 v = m.texel(x, y);
  return m.channels() == 1 ? double(v.x) : (double(v.x) + double(v.y) + double(v.z)) / 3.0;
}

// ---- the (cos θ, φ) histogram and its expected counts --------------------------------------------------

struct Histogram {
  int n_cos, n_phi;
  int bin_of(const glm::vec3& w) const {
    const int i = std::clamp(int((double(w.z) + 1.0) * 0.5 * n_cos), 0, n_cos - 1);
    double phi = std::atan2(double(w.y), double(w.x));
    if (phi < 0) phi += 2 * kPi;
    const int j = std::clamp(int(phi / (2 * kPi) * n_phi), 0, n_phi - 1);
    return i * n_phi + j;
  }
};

/// Integrates a sampler's pdf over each histogram bin. Bins are parametrised by Lambert's disk radius
/// ρ (|z| = 1 − ρ², dω = d(ρ²) dφ) and φ, where texels have comparable extents in both coordinates.
/// Each bin starts as cells smaller than half a texel; a cell whose four corners and centre lie in one
/// texel of `geometry` (SphereMap::texel_of, the rule pdf() uses) contributes area × pdf exactly; other
/// cells are split, `depth` times at most, then take their centre's pdf. Deciding by texel identity
/// rather than pdf value matters: two equal-valued texels meeting at a corner can hide a zero texel
/// between five points. Cells whose texels and their neighbours are all zero in `geometry` are not
/// split (they cannot hold mass). Measured quadrature error, as χ² inflation at 10⁶ samples against a
/// depth-9 reference: smooth R = 64 at depth 2: 0.16; checkerboard R = 8/16 at depth 6: 0.2; single
/// texel R = 8 at depth 6: 0.18 — each small against the statistic's spread √(2·dof) (2.8 to 128).
class BinIntegrator {
 public:
  BinIntegrator(const SphereMapSampler& sampler, const SphereMap& geometry, int depth)
      : sampler_(sampler), map_(geometry), depth_(depth), R_(geometry.resolution()) {
    near_mass_.assign(geometry.texel_count(), 0);
    for (int y = 0; y < R_; ++y)
      for (int x = 0; x < 2 * R_; ++x) {
        if (!(importance(geometry, x, y) > 0)) continue;
        // Mark the texel and every texel within one step, on either square (generous at the seams).
        for (int h = 0; h < 2; ++h)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int lx = std::clamp(x % R_ + dx, 0, R_ - 1), ly = std::clamp(y + dy, 0, R_ - 1);
              const bool same_square = h == x / R_;
              const bool at_border = x % R_ + dx < 0 || x % R_ + dx >= R_ || y + dy < 0 || y + dy >= R_;
              if (same_square || at_border) near_mass_[std::size_t(ly) * 2 * R_ + h * R_ + lx] = 1;
            }
      }
  }

  std::vector<double> bin_probabilities(const Histogram& hist) {
    std::vector<double> p(std::size_t(hist.n_cos) * hist.n_phi, 0.0);
    for (int i = 0; i < hist.n_cos; ++i) {
      const double c0 = -1.0 + 2.0 * i / hist.n_cos, c1 = -1.0 + 2.0 * (i + 1) / hist.n_cos;
      sign_ = c0 >= 0 ? 1.0 : -1.0;
      const double q0 = 1 - std::max(std::abs(c0), std::abs(c1)), q1 = 1 - std::min(std::abs(c0), std::abs(c1));
      const double r0 = std::sqrt(q0), r1 = std::sqrt(q1);
      const int n_r = std::max(1, int(std::ceil((r1 - r0) * R_)));  // texels are 2/R wide in ρ
      for (int j = 0; j < hist.n_phi; ++j) {
        const double p0 = 2 * kPi * j / hist.n_phi, p1 = 2 * kPi * (j + 1) / hist.n_phi;
        const int n_p = std::max(1, int(std::ceil((p1 - p0) / (kPi / (4 * R_)))));  // ~π/(2R) wide at the rim
        double sum = 0;
        for (int a = 0; a < n_r; ++a)
          for (int b = 0; b < n_p; ++b) {
            const double ra = std::sqrt(q0 + (q1 - q0) * a / n_r), rb = std::sqrt(q0 + (q1 - q0) * (a + 1) / n_r);
            const double pa = p0 + (p1 - p0) * b / n_p, pb = p0 + (p1 - p0) * (b + 1) / n_p;
            sum += cell(ra, rb, pa, pb, texel(ra, pa), texel(rb, pa), texel(ra, pb), texel(rb, pb), depth_);
          }
        p[std::size_t(i) * hist.n_phi + j] = sum;
      }
    }
    return p;
  }

 private:
  glm::vec3 direction(double rho, double phi) const {
    rho = std::min(rho, 1.0 - 1e-9);  // keep lower-hemisphere points off z = 0 (the upper square's)
    const double z = 1 - rho * rho, s = rho * std::sqrt(2 - rho * rho);
    return glm::vec3(glm::normalize(glm::dvec3(s * std::cos(phi), s * std::sin(phi), sign_ * z)));
  }
  int texel(double rho, double phi) const {
    int x, y;
    map_.texel_of(direction(rho, phi), x, y);
    return y * 2 * R_ + x;
  }
  double cell(double r0, double r1, double p0, double p1, int t00, int t10, int t01, int t11, int depth) {
    const double rm = std::sqrt(0.5 * (r0 * r0 + r1 * r1)), pm = 0.5 * (p0 + p1);  // splits the area in half
    const double area = (r1 * r1 - r0 * r0) * (p1 - p0);
    const int tc = texel(rm, pm);
    const bool one_texel = t00 == tc && t10 == tc && t01 == tc && t11 == tc;
    const bool no_mass =
        !near_mass_[t00] && !near_mass_[t10] && !near_mass_[t01] && !near_mass_[t11] && !near_mass_[tc];
    if (one_texel || no_mass || depth == 0) return area * double(sampler_.pdf(direction(rm, pm)));
    const int m0 = texel(rm, p0), m1 = texel(rm, p1), n0 = texel(r0, pm), n1 = texel(r1, pm);
    return cell(r0, rm, p0, pm, t00, m0, n0, tc, depth - 1) + cell(rm, r1, p0, pm, m0, t10, tc, n1, depth - 1) +
           cell(r0, rm, pm, p1, n0, tc, t01, m1, depth - 1) + cell(rm, r1, pm, p1, tc, n1, m1, t11, depth - 1);
  }

  const SphereMapSampler& sampler_;
  const SphereMap& map_;
  int depth_, R_;
  double sign_ = 1;
  std::vector<char> near_mass_;
};

/// Histogram of `n` samples of `sampler` (directions optionally altered by `warp`).
std::vector<double> sample_histogram(const SphereMapSampler& sampler, const Histogram& hist, long n, std::uint32_t seed,
                                     const std::function<glm::vec3(const glm::vec3&)>& warp = nullptr) {
  std::vector<double> counts(std::size_t(hist.n_cos) * hist.n_phi, 0.0);
  std::mt19937 rng(seed);
  for (long i = 0; i < n; ++i) {
    const float u1 = uniform_float(rng), u2 = uniform_float(rng);
    const DirectionSample s = sampler.sample(u1, u2);
    if (!(s.pdf > 0)) continue;  // counted as missing mass by the test
    counts[std::size_t(hist.bin_of(warp ? warp(s.direction) : s.direction))] += 1;
  }
  return counts;
}

/// χ² of `n` samples drawn from `drawn` against the pdf of `claimed` (built from `claimed_map`).
ChiSquare goodness_of_fit(const SphereMapSampler& drawn, const SphereMapSampler& claimed, const SphereMap& claimed_map,
                          const Histogram& hist, int depth, long n, std::uint32_t seed,
                          const std::function<glm::vec3(const glm::vec3&)>& warp = nullptr) {
  const std::vector<double> observed = sample_histogram(drawn, hist, n, seed, warp);
  std::vector<double> expected = BinIntegrator(claimed, claimed_map, depth).bin_probabilities(hist);
  double total = 0;
  for (double& e : expected) {
    total += e;
    e *= double(n);
  }
  EXPECT_NEAR(total, 1.0, 2e-4) << "the quadrature of the claimed pdf does not integrate to 1";
  return chi_square(observed, expected);
}

/// The goodness-of-fit test proper: the sampler of `map` against its own pdf.
void expect_fits(const SphereMap& map, const char* name, Histogram hist, int depth, long n = 1000000,
                 std::uint32_t seed = 12345) {
  const SphereMapSampler sampler(map);
  const ChiSquare r = goodness_of_fit(sampler, sampler, map, hist, depth, n, seed);
  std::printf("  %s (R %d, %d ch): chi2 %.1f, dof %d, p %.3g\n", name, map.resolution(), map.channels(), r.statistic,
              r.dof, r.p_value);
  EXPECT_GT(r.dof, 0) << name;
  EXPECT_GT(r.p_value, kSignificance) << name << ": chi2 " << r.statistic << " with " << r.dof << " dof";
}

const Histogram kHistogram{32, 64};
const Histogram kFineHistogram{64, 128};

/// Bit pattern of a float (pdf equality "bit for bit").
std::uint32_t bits(float f) {
  std::uint32_t b;
  std::memcpy(&b, &f, sizeof b);
  return b;
}

}  // namespace

// ---- the statistics themselves -------------------------------------------------------------------------

TEST(ChiSquareHelpers, IncompleteGammaMatchesClosedForms) {
  for (double x : {0.01, 0.5, 1.0, 2.0, 7.5, 30.0, 200.0}) {
    EXPECT_NEAR(regularized_gamma_q(1.0, x), std::exp(-x), 1e-12 + 1e-10 * std::exp(-x));  // Q(1, x) = e⁻ˣ
    EXPECT_NEAR(regularized_gamma_q(0.5, x), std::erfc(std::sqrt(x)), 1e-12);              // Q(½, x) = erfc √x
    EXPECT_NEAR(regularized_gamma_q(2.0, x), (1 + x) * std::exp(-x), 1e-12);               // Q(2, x) = (1+x)e⁻ˣ
  }
  // χ² tail probabilities at the sizes used below (references from mpmath.gammainc, 30 digits).
  EXPECT_NEAR(regularized_gamma_q(0.5 * 8191, 0.5 * 8191), 0.4979220459737523, 1e-12);
  EXPECT_NEAR(regularized_gamma_q(0.5 * 2047, 0.5 * 2200), 0.009527355933091104, 1e-14);
  EXPECT_NEAR(regularized_gamma_q(0.5 * 100, 0.5 * 200), 1.17845007209794e-8, 1e-18);
  EXPECT_GT(kSignificance, 0.0007);  // 1 − 0.99^(1/13) = 7.73e-4
  EXPECT_LT(kSignificance, 0.0008);
}

// ---- PiecewiseConstant1D / 2D --------------------------------------------------------------------------

TEST(PiecewiseConstant1D, ProbabilitiesFollowTheWeights) {
  const std::vector<float> w = {0.5f, 0.0f, 2.0f, 1.5f, 0.0f, 4.0f};
  const PiecewiseConstant1D d(w);
  EXPECT_EQ(d.size(), 6u);
  EXPECT_DOUBLE_EQ(d.integral(), 8.0 / 6.0);
  double total = 0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    EXPECT_NEAR(d.probability(i), w[i] / 8.0, 1e-9);
    total += d.probability(i);
    EXPECT_FLOAT_EQ(d.pdf((float(i) + 0.5f) / 6.0f), float(d.probability(i) * 6.0));
  }
  EXPECT_DOUBLE_EQ(total, 1.0);
  EXPECT_EQ(d.pdf(-0.1f), 0.0f);
  EXPECT_EQ(d.pdf(1.1f), 0.0f);
  EXPECT_EQ(d.pdf(std::nanf("")), 0.0f);
  EXPECT_EQ(d.pdf(1.0f), d.pdf(0.99f));  // x = 1 belongs to the last cell
  EXPECT_EQ(d.bytes(), 7 * sizeof(std::uint32_t));
}

TEST(PiecewiseConstant1D, NeverSamplesAZeroCellEvenOnPlateausAndAtTheEnds) {
  const std::vector<float> w = {0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 3.0f, 0.0f, 1e-30f, 0.0f};
  const PiecewiseConstant1D d(w);
  std::vector<float> us = {0.0f,
                           1e-30f,
                           0x1p-24f,
                           0.2f,
                           0.25f,
                           0.5f,
                           0.75f,
                           piecewise_constant::kOneMinusEpsilon,
                           1.0f,
                           2.0f,
                           -1.0f,
                           std::nanf(""),
                           std::numeric_limits<float>::infinity()};
  for (int k = 0; k < 200000; ++k) us.push_back(float(k) / 200000.0f);
  // u exactly at every stored CDF step (the plateau edges), and one float either side.
  for (std::size_t i = 0; i <= w.size(); ++i) {
    double c = 0;
    for (std::size_t j = 0; j < i; ++j) c += d.probability(j);
    for (float u : {std::nextafter(float(c), 0.0f), float(c), std::nextafter(float(c), 1.0f)}) us.push_back(u);
  }
  for (float u : us) {
    const PiecewiseConstant1D::Sample s = d.sample(u);
    ASSERT_GE(s.cell, 0) << "u = " << u;
    EXPECT_GT(w[std::size_t(s.cell)], 0.0f) << "u = " << u << " gave zero cell " << s.cell;
    EXPECT_GE(double(s.x) * 9, double(s.cell)) << "u = " << u;
    EXPECT_LT(double(s.x) * 9, double(s.cell + 1)) << "u = " << u;
    EXPECT_EQ(bits(s.pdf), bits(d.pdf(s.x))) << "u = " << u;
    EXPECT_GT(s.pdf, 0.0f);
  }
  // A weight 1e-30 of the total keeps one quantum and stays reachable (from the bottom of the CDF).
  const PiecewiseConstant1D tiny(std::vector<float>{1e-30f, 1.0f});
  EXPECT_GT(tiny.probability(0), 0.0);
  EXPECT_EQ(tiny.sample(0.0f).cell, 0);
  EXPECT_EQ(tiny.sample(1e-9f).cell, 1);  // ⌊u·(2³² − 1)⌋ = 4 ≥ one quantum
}

TEST(PiecewiseConstant1D, AllZeroAndInvalidWeights) {
  const PiecewiseConstant1D zero(std::vector<float>(5, 0.0f));
  EXPECT_TRUE(zero.is_zero());
  EXPECT_EQ(zero.integral(), 0.0);
  for (float u : {0.0f, 0.5f, 0.99f}) {
    const PiecewiseConstant1D::Sample s = zero.sample(u);
    EXPECT_EQ(s.pdf, 0.0f);
    EXPECT_EQ(s.cell, -1);
  }
  EXPECT_EQ(zero.pdf(0.3f), 0.0f);
  EXPECT_EQ(zero.probability(2), 0.0);
  EXPECT_TRUE(PiecewiseConstant1D().is_zero());
  EXPECT_EQ(PiecewiseConstant1D().sample(0.5f).pdf, 0.0f);
  EXPECT_THROW(PiecewiseConstant1D(std::vector<float>{}), std::invalid_argument);
  for (float bad : {-1.0f, -1e-30f, std::nanf(""), std::numeric_limits<float>::infinity()})
    EXPECT_THROW(PiecewiseConstant1D(std::vector<float>{1.0f, bad}), std::invalid_argument) << bad;
  EXPECT_THROW(PiecewiseConstant1D(std::vector<double>{1.0, -2.0}), std::invalid_argument);
  // Finite weights whose sum overflows float are fine: sums are in double.
  const PiecewiseConstant1D big(std::vector<float>{3e38f, 3e38f});
  EXPECT_NEAR(big.probability(0), 0.5, 1e-9);
}

TEST(PiecewiseConstant2D, SamplesFollowTheWeights) {
  // 4 × 3 cells with a zero row, a zero column and zero cells; 10⁶ samples against the probabilities.
  const std::vector<float> w = {1, 0, 2,   3,  //
                                0, 0, 0,   0,  //
                                4, 0, 0.5, 7};
  const PiecewiseConstant2D d(w, 4, 3);
  EXPECT_DOUBLE_EQ(d.integral(), 17.5 / 12.0);
  EXPECT_EQ(d.bytes(), (3 * 5 + 4) * sizeof(std::uint32_t));
  std::vector<double> observed(12, 0), expected(12, 0);
  std::mt19937 rng(99);
  const long n = 1000000;
  for (long i = 0; i < n; ++i) {
    const PiecewiseConstant2D::Sample s = d.sample(uniform_float(rng), uniform_float(rng));
    ASSERT_GT(s.pdf, 0.0f);
    ASSERT_GT(w[std::size_t(s.cell_y) * 4 + s.cell_x], 0.0f);
    ASSERT_EQ(bits(s.pdf), bits(d.pdf(s.point)));
    ASSERT_EQ(int(double(s.point.x) * 4), s.cell_x);
    ASSERT_EQ(int(double(s.point.y) * 3), s.cell_y);
    observed[std::size_t(s.cell_y) * 4 + s.cell_x] += 1;
  }
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) {
      EXPECT_NEAR(d.probability(x, y), w[std::size_t(y) * 4 + x] / 17.5, 1e-9);
      EXPECT_FLOAT_EQ(d.pdf({(x + 0.5f) / 4, (y + 0.5f) / 3}), float(d.probability(x, y) * 12));
      expected[std::size_t(y) * 4 + x] = d.probability(x, y) * n;
    }
  const ChiSquare r = chi_square(observed, expected);  // goodness-of-fit test 13 of the family
  std::printf("  2D cells: chi2 %.2f, dof %d, p %.3g\n", r.statistic, r.dof, r.p_value);
  EXPECT_GT(r.p_value, kSignificance);
}

TEST(PiecewiseConstant2D, EdgeInputsAndZeroFunction) {
  const std::vector<float> w = {0, 0, 0, 5};  // only the last cell of the last row
  const PiecewiseConstant2D d(w, 2, 2);
  for (float u1 : {0.0f, 0.5f, piecewise_constant::kOneMinusEpsilon, 1.0f, -3.0f, std::nanf("")})
    for (float u2 : {0.0f, 0.5f, piecewise_constant::kOneMinusEpsilon, 1.0f, 7.0f, std::nanf("")}) {
      const PiecewiseConstant2D::Sample s = d.sample(u1, u2);
      EXPECT_EQ(s.cell_x, 1);
      EXPECT_EQ(s.cell_y, 1);
      EXPECT_GE(s.point.x, 0.5f);
      EXPECT_LT(s.point.x, 1.0f);
      EXPECT_GE(s.point.y, 0.5f);
      EXPECT_LT(s.point.y, 1.0f);
      EXPECT_EQ(s.pdf, 4.0f);
    }
  EXPECT_EQ(d.pdf({0.25f, 0.25f}), 0.0f);
  EXPECT_EQ(d.pdf({1.0f, 1.0f}), 4.0f);
  EXPECT_EQ(d.pdf({1.5f, 0.75f}), 0.0f);
  const PiecewiseConstant2D zero(std::vector<float>(6, 0.0f), 3, 2);
  EXPECT_TRUE(zero.is_zero());
  EXPECT_EQ(zero.integral(), 0.0);
  EXPECT_EQ(zero.sample(0.3f, 0.3f).pdf, 0.0f);
  EXPECT_EQ(zero.sample(0.3f, 0.3f).cell_x, -1);
  EXPECT_EQ(zero.pdf({0.5f, 0.5f}), 0.0f);
  EXPECT_THROW(PiecewiseConstant2D(std::vector<float>(5, 1.0f), 3, 2), std::invalid_argument);
  EXPECT_THROW(PiecewiseConstant2D(std::vector<float>{}, 0, 0), std::invalid_argument);
  EXPECT_THROW(PiecewiseConstant2D(std::vector<float>{1, 2, -1, 4}, 2, 2), std::invalid_argument);
  EXPECT_THROW(PiecewiseConstant2D(std::vector<float>{1, 2, std::nanf(""), 4}, 2, 2), std::invalid_argument);
}

// ---- SphereMapSampler: goodness of fit (the Šidák family, kGoodnessOfFitTests members) -------------------

TEST(SphereMapSamplerFit, SmoothMapAtResolutions1And8And64) {
  expect_fits(smooth_map(1), "smooth", kHistogram, 6);       // 1
  expect_fits(smooth_map(8), "smooth", kHistogram, 4);       // 2
  expect_fits(smooth_map(64), "smooth", kFineHistogram, 2);  // 3 (small pdf jumps: shallow is exact enough)
}

TEST(SphereMapSamplerFit, ThreeChannelMaps) {
  expect_fits(smooth_map(8, 3), "smooth rgb", kHistogram, 4);   // 4
  expect_fits(peaked_map(16, 3), "peaked rgb", kHistogram, 6);  // 5
}

TEST(SphereMapSamplerFit, CheckerboardOfValuesAndZeros) {
  expect_fits(checkerboard_map(8), "checkerboard", kHistogram, 6);   // 6
  expect_fits(checkerboard_map(16), "checkerboard", kHistogram, 6);  // 7
}

TEST(SphereMapSamplerFit, NearDeltaAndSingleTexelMaps) {
  expect_fits(spike_map(8, 5, 2, 1.0f, 1e-3f), "one bright texel", kHistogram, 6);               // 8 (~89 % in it)
  expect_fits(spike_map(8, 15, 7, 1.0f, 0.0f), "single texel at a corner", kHistogram, 7);       // 9
  expect_fits(spike_map(64, 64, 10, 1.0f, 0.0f), "single texel on u = 0.5", kFineHistogram, 7);  // 10
  expect_fits(spike_map(1, 1, 0, 1.0f, 0.0f), "lower hemisphere only", kHistogram, 6);           // 11
  expect_fits(spike_map(8, 4, 4, 1.0f, 0.0f), "single texel at the pole", kHistogram, 7);        // 12
}

TEST(SphereMapSamplerFit, TheTestRejectsWrongDistributions) {
  // Not part of the family: each of these must be rejected at the per-test significance.
  const SphereMap smooth = smooth_map(8), peaked = peaked_map(8);
  const SphereMapSampler smooth_sampler(smooth), peaked_sampler(peaked);
  // Samples of one map against the pdf of another.
  const ChiSquare other = goodness_of_fit(peaked_sampler, smooth_sampler, smooth, kHistogram, 4, 1000000, 1);
  // A pdf that differs in one texel of 128 (weight × 1.5): 0.4 % of the mass moves.
  SphereMap bumped = smooth;
  bumped.at(11, 3, 0) *= 1.5f;
  const SphereMapSampler bumped_sampler(bumped);
  const ChiSquare one_texel = goodness_of_fit(smooth_sampler, bumped_sampler, bumped, kHistogram, 4, 1000000, 2);
  // The right texel probabilities but directions mirrored (x → −x) in the lower hemisphere.
  const ChiSquare mirrored =
      goodness_of_fit(smooth_sampler, smooth_sampler, smooth, kHistogram, 4, 1000000, 3,
                      [](const glm::vec3& w) { return w.z < 0 ? glm::vec3(-w.x, w.y, w.z) : w; });
  std::printf("  wrong pdfs: other map p %.3g, one texel x1.5 p %.3g (chi2 %.0f, dof %d), mirrored p %.3g\n",
              other.p_value, one_texel.p_value, one_texel.statistic, one_texel.dof, mirrored.p_value);
  EXPECT_LT(other.p_value, kSignificance);
  EXPECT_LT(one_texel.p_value, kSignificance);
  EXPECT_LT(mirrored.p_value, kSignificance);
}

// ---- SphereMapSampler: exact properties --------------------------------------------------------------------

TEST(SphereMapSampler, SamplePdfEqualsPdfOfItsDirectionBitForBit) {
  const std::vector<SphereMap> maps = {smooth_map(1),     smooth_map(8),       smooth_map(64),
                                       peaked_map(16, 3), checkerboard_map(8), spike_map(64, 64, 10, 1.0f, 0.0f)};
  std::mt19937 rng(5);
  for (const SphereMap& m : maps) {
    const SphereMapSampler sampler(m);
    for (int i = 0; i < 100000; ++i) {
      const DirectionSample s = sampler.sample(uniform_float(rng), uniform_float(rng));
      ASSERT_GT(s.pdf, 0.0f);
      ASSERT_EQ(bits(s.pdf), bits(sampler.pdf(s.direction))) << "R " << m.resolution() << " sample " << i;
      ASSERT_NEAR(glm::length(s.direction), 1.0f, 1e-6f);
    }
  }
}

TEST(SphereMapSampler, PdfIntegratesToOne) {
  // Σ over texels of pdf(texel centre) × texel solid angle = Σ P(texel) = 1 (probabilities are stored
  // as integers summing to 2³² − 1; the float pdfs round each term by < 6e-8 relative).
  for (const SphereMap& m : {smooth_map(1), smooth_map(8), smooth_map(64), peaked_map(16, 3), checkerboard_map(8),
                             spike_map(8, 5, 2, 1.0f, 1e-3f), spike_map(64, 64, 10, 1.0f, 0.0f)}) {
    const SphereMapSampler sampler(m);
    double sum = 0;
    for (int y = 0; y < m.height(); ++y)
      for (int x = 0; x < m.width(); ++x) sum += double(sampler.pdf(texel_centre(m, x, y))) * m.texel_solid_angle();
    EXPECT_NEAR(sum, 1.0, 1e-5) << "R " << m.resolution();
  }
}

TEST(SphereMapSampler, PdfIsTheNearestTexelValueOverTheIntegral) {
  // pdf(ω) = importance(lookup_nearest(ω)) / Σ importance·Ω, including on the seam, the u = 0.5 edges,
  // the corners and the poles; the stored probabilities round shares by ~2e-10 absolute.
  for (const SphereMap& m : {peaked_map(16, 1), peaked_map(16, 3), checkerboard_map(8)}) {
    const SphereMapSampler sampler(m);
    double total = 0;
    for (int y = 0; y < m.height(); ++y)
      for (int x = 0; x < m.width(); ++x) total += importance(m, x, y) * m.texel_solid_angle();
    std::vector<glm::vec3> dirs = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, -0.0f}, {0, -1, 0}};
    for (float u : {0.0f, 0.25f, 0.5f, std::nextafter(0.5f, 1.0f), 0.75f, 1.0f})
      for (float v : {0.0f, 0.3f, 0.5f, 1.0f}) dirs.push_back(sphere_map::uv_to_direction({u, v}));
    std::mt19937 rng(8);
    for (int i = 0; i < 20000; ++i)
      dirs.push_back(sphere_map::uv_to_direction({uniform_float(rng), uniform_float(rng)}));
    for (const glm::vec3& w : dirs) {
      const glm::vec3 v = m.lookup_nearest(w);
      const double value = m.channels() == 1 ? double(v.x) : (double(v.x) + double(v.y) + double(v.z)) / 3.0;
      EXPECT_NEAR(sampler.pdf(w), value / total, 1e-6 * value / total + 1e-9)
          << "w = (" << w.x << ", " << w.y << ", " << w.z << ")";
    }
  }
}

TEST(SphereMapSampler, UsesTheSameTexelAsSphereMapTexelOf) {
  // Every texel gets a distinct value, so equal pdfs mean equal texels.
  SphereMap m(16, 1);
  for (std::size_t i = 0; i < m.values().size(); ++i) m.values()[i] = 1.0f + float(i);
  const SphereMapSampler sampler(m);
  std::vector<float> texel_pdf(m.texel_count());
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x) texel_pdf[std::size_t(y) * 32 + x] = sampler.pdf(texel_centre(m, x, y));
  std::mt19937 rng(77);
  std::vector<glm::vec3> dirs = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, -0.0f}, {0.6f, 0.8f, 0}};
  for (int i = 0; i < 200000; ++i) {
    // Random directions, and points exactly on texel edges.
    dirs.push_back(sphere_map::uv_to_direction({uniform_float(rng), uniform_float(rng)}));
    dirs.push_back(sphere_map::uv_to_direction({float(rng() % 33) / 32, float(rng() % 17) / 16}));
  }
  for (const glm::vec3& w : dirs) {
    int x, y;
    m.texel_of(w, x, y);
    ASSERT_EQ(sampler.pdf(w), texel_pdf[std::size_t(y) * 32 + x])
        << "w = (" << w.x << ", " << w.y << ", " << w.z << ")";
  }
}

TEST(SphereMapSampler, NoSampleLandsInAZeroTexel) {
  struct Case {
    SphereMap map;
    long n;
  };
  std::vector<Case> cases = {{checkerboard_map(8), 1000000}, {checkerboard_map(64), 1000000}};
  // Single texels: the four columns next to u = 0 / 0.5 / 1, the pole texels, corner texels, R = 1.
  for (int R : {1, 8, 64})
    for (int x : {0, R - 1, R, 2 * R - 1, R / 2, R + R / 2})
      for (int y : {0, R / 2, R - 1})
        if (x < 2 * R) cases.push_back({spike_map(R, x, y, 1.0f, 0.0f), 20000});
  std::mt19937 rng(31);
  for (const Case& c : cases) {
    const SphereMapSampler sampler(c.map);
    long zero = 0;
    for (long i = 0; i < c.n; ++i) {
      const DirectionSample s = sampler.sample(uniform_float(rng), uniform_float(rng));
      ASSERT_GT(s.pdf, 0.0f);
      zero += c.map.lookup_nearest(s.direction).x > 0.0f ? 0 : 1;
    }
    EXPECT_EQ(zero, 0) << "R " << c.map.resolution();
  }
}

TEST(SphereMapSampler, ExtremeUsAndTheSharedEdgeStayInTheirTexel) {
  // Only one column of the image is non-zero, so the column sample is at its left edge for u1 = 0 and
  // at its right edge for u1 → 1. Column R starts at u = 0.5 exactly: that point must go to the lower
  // square's left edge, not to the upper square's right edge (which is also u = 0.5).
  const std::vector<float> extremes = {0.0f, 1e-30f, 0x1p-24f, 0.5f, piecewise_constant::kOneMinusEpsilon, 1.0f};
  for (int R : {1, 2, 8, 64}) {
    for (int column : {0, R - 1, R, 2 * R - 1}) {
      SphereMap m(R, 1);
      for (int y = 0; y < R; ++y) m.at(column, y, 0) = 1.0f + float(y);
      const SphereMapSampler sampler(m);
      for (float u1 : extremes)
        for (float u2 : extremes) {
          const DirectionSample s = sampler.sample(u1, u2);
          ASSERT_GT(s.pdf, 0.0f);
          EXPECT_EQ(bits(s.pdf), bits(sampler.pdf(s.direction)));
          int x, y;
          m.texel_of(s.direction, x, y);
          EXPECT_EQ(x, column) << "R " << R << " u1 " << u1 << " u2 " << u2;
          EXPECT_EQ(s.direction.z < 0, column >= R) << "R " << R << " u1 " << u1 << " u2 " << u2;
        }
    }
  }
}

TEST(SphereMapSampler, AllZeroMapAndDefaultSampler) {
  const SphereMapSampler zero(SphereMap(8, 3));
  EXPECT_TRUE(zero.is_zero());
  for (float u : {0.0f, 0.3f, 0.99f}) {
    const DirectionSample s = zero.sample(u, 1.0f - u);
    EXPECT_EQ(s.pdf, 0.0f);
    EXPECT_EQ(s.direction, glm::vec3(0.0f));
  }
  EXPECT_EQ(zero.pdf({0, 0, 1}), 0.0f);
  EXPECT_EQ(zero.pdf({0.6f, 0.0f, -0.8f}), 0.0f);
  const SphereMapSampler none;
  EXPECT_TRUE(none.is_zero());
  EXPECT_EQ(none.sample(0.5f, 0.5f).pdf, 0.0f);
  EXPECT_EQ(none.pdf({0, 0, 1}), 0.0f);
  EXPECT_EQ(none.bytes(), 0u);
}

TEST(SphereMapSampler, InvalidMapsThrow) {
  EXPECT_THROW(SphereMapSampler{SphereMap()}, std::invalid_argument);
  for (float bad : {-1.0f, std::nanf(""), std::numeric_limits<float>::infinity()}) {
    SphereMap m(4, 3);
    m.at(5, 2, 1) = bad;
    EXPECT_THROW(SphereMapSampler{m}, std::invalid_argument) << bad;
  }
  const SphereMapSampler ok(smooth_map(4));
  EXPECT_EQ(ok.pdf({std::nanf(""), 0, 1}), 0.0f);
}

TEST(SphereMapSampler, ThreeChannelMapSamplesItsChannelMean) {
  // A 3-channel map and the 1-channel map of its channel means give identical samplers.
  const SphereMap rgb = peaked_map(16, 3);
  SphereMap mean(16, 1);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x)
      mean.at(x, y, 0) = SphereMapSampler::texel_importance(&rgb.values()[(std::size_t(y) * 32 + x) * 3]);
  const SphereMapSampler a(rgb), b(mean);
  std::mt19937 rng(4);
  for (int i = 0; i < 10000; ++i) {
    const float u1 = uniform_float(rng), u2 = uniform_float(rng);
    const DirectionSample sa = a.sample(u1, u2), sb = b.sample(u1, u2);
    ASSERT_EQ(sa.direction, sb.direction);
    ASSERT_EQ(bits(sa.pdf), bits(sb.pdf));
  }
  EXPECT_EQ(a.bytes(), b.bytes());
}

TEST(SphereMapSampler, SizesAndResolutions) {
  for (int R : {1, 8, 64}) {
    const SphereMapSampler s(smooth_map(R));
    EXPECT_EQ(s.resolution(), R);
    EXPECT_FALSE(s.is_zero());
    // A CDF of 2R + 1 entries per row and one of R + 1 entries over rows, 4 bytes each.
    EXPECT_EQ(s.bytes(), (std::size_t(R) * (2 * R + 1) + (R + 1)) * sizeof(std::uint32_t));
  }
}
