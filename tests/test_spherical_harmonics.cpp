// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Real spherical harmonics against independent oracles: hand-written polynomials, orthonormality by exact
// quadrature, the clamped-cosine coefficients of Ramamoorthi & Hanrahan, rotation invariance of band
// energy, and the positivity of windowed narrow lobes.
#include <lumx/math/spherical_harmonics.h>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace lumx;

namespace {

constexpr double kSqrtPi = 1.7724538509055160273;

glm::dvec3 random_unit(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (;;) {
    const glm::dvec3 v(u(rng), u(rng), u(rng));
    const double n = glm::length(v);
    if (n > 1e-3 && n <= 1.0) return v / n;
  }
}

// Y_lm for l <= 3 written out by hand (Sloan 2008, "Stupid SH Tricks", appendix; x² + y² + z² = 1).
std::vector<double> hand_written(const glm::dvec3& d) {
  const double x = d.x, y = d.y, z = d.z, pi = kPi;
  return {
      0.5 * std::sqrt(1 / pi),
      -std::sqrt(3 / (4 * pi)) * y,
      std::sqrt(3 / (4 * pi)) * z,
      -std::sqrt(3 / (4 * pi)) * x,
      0.5 * std::sqrt(15 / pi) * x * y,
      -0.5 * std::sqrt(15 / pi) * y * z,
      0.25 * std::sqrt(5 / pi) * (3 * z * z - 1),
      -0.5 * std::sqrt(15 / pi) * x * z,
      0.25 * std::sqrt(15 / pi) * (x * x - y * y),
      -0.25 * std::sqrt(35 / (2 * pi)) * y * (3 * x * x - y * y),
      0.5 * std::sqrt(105 / pi) * x * y * z,
      -0.25 * std::sqrt(21 / (2 * pi)) * y * (5 * z * z - 1),
      0.25 * std::sqrt(7 / pi) * z * (5 * z * z - 3),
      -0.25 * std::sqrt(21 / (2 * pi)) * x * (5 * z * z - 1),
      0.25 * std::sqrt(105 / pi) * z * (x * x - y * y),
      -0.25 * std::sqrt(35 / (2 * pi)) * x * (x * x - 3 * y * y),
  };
}

// Legendre polynomial P_n(x) by Bonnet's recurrence.
double legendre(int n, double x) {
  double p0 = 1, p1 = x;
  if (n == 0) return p0;
  for (int k = 2; k <= n; ++k) {
    const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
    p0 = p1;
    p1 = p2;
  }
  return p1;
}

// Rotation by `angle` about the unit `axis` (Rodrigues).
glm::dmat3 rotation(const glm::dvec3& axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
  const double x = axis.x, y = axis.y, z = axis.z;
  // Columns of the matrix (GLM is column-major).
  return glm::dmat3(glm::dvec3(t * x * x + c, t * x * y + s * z, t * x * z - s * y),
                    glm::dvec3(t * x * y - s * z, t * y * y + c, t * y * z + s * x),
                    glm::dvec3(t * x * z + s * y, t * y * z - s * x, t * z * z + c));
}

// min / max of Σ c Y over a dense (θ, φ) grid that includes both poles.
double min_over_max(const std::vector<double>& coeffs, int bands) {
  double lo = INFINITY, hi = -INFINITY;
  const int nt = 360, np = 720;
  for (int i = 0; i <= nt; ++i) {
    const double theta = kPi * i / nt;
    for (int j = 0; j < (i == 0 || i == nt ? 1 : np); ++j) {
      const double phi = 2 * kPi * j / np;
      const glm::dvec3 d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      const double v = sh::evaluate_sum(coeffs.data(), bands, d);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  return lo / hi;
}

}  // namespace

TEST(SphericalHarmonics, IndexAndCount) {
  static_assert(sh::coefficient_count(4) == 16);
  static_assert(sh::index(0, 0) == 0 && sh::index(1, -1) == 1 && sh::index(1, 1) == 3);
  static_assert(sh::index(2, -2) == 4 && sh::index(3, 3) == 15 && sh::index(4, -4) == 16);
}

TEST(SphericalHarmonics, MatchesHandWrittenPolynomialsUpToL3) {
  std::mt19937 rng(7);
  std::vector<glm::dvec3> dirs = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, -1, 0}};
  for (int n = 0; n < 500; ++n) dirs.push_back(random_unit(rng));
  for (const glm::dvec3& d : dirs) {
    const std::vector<double> expected = hand_written(d);
    double y[16];
    float yf[16];
    sh::evaluate(d, 4, y);
    sh::evaluate(d, 4, yf);
    for (int i = 0; i < 16; ++i) {
      EXPECT_NEAR(y[i], expected[i], 1e-14) << "index " << i;
      EXPECT_NEAR(yf[i], expected[i], 1e-6) << "index " << i;
    }
    // Fewer bands give the same leading values.
    double y2[4];
    sh::evaluate(d, 2, y2);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(y2[i], y[i]);
  }
}

TEST(SphericalHarmonics, RejectsUnsupportedBands) {
  double y[sh::kMaxCoefficients];
  EXPECT_THROW(sh::evaluate(glm::dvec3(0, 0, 1), 0, y), std::invalid_argument);
  EXPECT_THROW(sh::evaluate(glm::dvec3(0, 0, 1), sh::kMaxBands + 1, y), std::invalid_argument);
  EXPECT_NO_THROW(sh::evaluate(glm::dvec3(0, 0, 1), sh::kMaxBands, y));
  EXPECT_THROW(sh::project([](const glm::dvec3&) { return 1.0; }, 4, -1), std::invalid_argument);
  EXPECT_THROW(sh::window_weights(0, sh::Window::hann), std::invalid_argument);
}

TEST(SphericalHarmonics, GaussLegendreIsExactToDegree2nMinus1) {
  for (int n : {1, 2, 3, 7, 16, 33}) {
    const sh::GaussLegendreRule rule = sh::gauss_legendre(n);
    for (int k = 0; k <= 2 * n - 1; ++k) {
      double sum = 0;
      for (int i = 0; i < n; ++i) sum += rule.weights[i] * std::pow(rule.nodes[i], k);
      EXPECT_NEAR(sum, k % 2 == 1 ? 0.0 : 2.0 / (k + 1), 1e-14) << "n " << n << " degree " << k;
    }
    // Degree 2n fails: P_n² vanishes at every node but integrates to 2/(2n+1).
    double sum = 0;
    for (int i = 0; i < n; ++i) sum += rule.weights[i] * std::pow(legendre(n, rule.nodes[i]), 2);
    EXPECT_NEAR(sum, 0.0, 1e-20);
    EXPECT_LT(sum, 2.0 / (2 * n + 1) - 1e-3);
    EXPECT_TRUE(std::is_sorted(rule.nodes.begin(), rule.nodes.end()));
  }
}

TEST(SphericalHarmonics, OrthonormalByExactQuadrature) {
  for (int bands = 1; bands <= 6; ++bands) {
    const int n = sh::coefficient_count(bands);
    const int order = 2 * (bands - 1);  // Y_i Y_j has degree <= 2L
    const sh::GaussLegendreRule gl = sh::gauss_legendre(order / 2 + 1);
    const int n_phi = order + 1;
    std::vector<double> gram(n * n, 0.0);
    std::vector<double> y(n);
    for (std::size_t i = 0; i < gl.nodes.size(); ++i) {
      const double z = gl.nodes[i], r = std::sqrt(1 - z * z);
      for (int j = 0; j < n_phi; ++j) {
        const double phi = 2 * kPi * (j + 0.25) / n_phi;
        sh::evaluate(glm::dvec3(r * std::cos(phi), r * std::sin(phi), z), bands, y.data());
        const double w = gl.weights[i] * 2 * kPi / n_phi;
        for (int p = 0; p < n; ++p)
          for (int q = 0; q < n; ++q) gram[p * n + q] += w * y[p] * y[q];
      }
    }
    for (int p = 0; p < n; ++p)
      for (int q = 0; q < n; ++q)
        EXPECT_NEAR(gram[p * n + q], p == q ? 1.0 : 0.0, 1e-12) << "bands " << bands << " (" << p << "," << q << ")";
  }
}

TEST(SphericalHarmonics, OrthonormalAtMaxBands) {
  // The same through project(): projecting Y_i itself must give the unit vector e_i.
  const int bands = sh::kMaxBands;
  for (int i : {0, 5, 100, 200, 255}) {
    const auto f = [i](const glm::dvec3& d) {
      double y[sh::kMaxCoefficients];
      sh::evaluate(d, sh::kMaxBands, y);
      return y[i];
    };
    const std::vector<double> c = sh::project(f, bands, 2 * (bands - 1));
    for (int k = 0; k < sh::coefficient_count(bands); ++k)
      EXPECT_NEAR(c[k], k == i ? 1.0 : 0.0, 1e-11) << "Y_" << i << " coefficient " << k;
  }
}

TEST(SphericalHarmonics, ProjectionOfAPolynomialIsExact) {
  // f = 1 + x - 2yz + z³ has degree 3; bands 4 needs order 3 + 3.
  const auto f = [](const glm::dvec3& d) { return 1 + d.x - 2 * d.y * d.z + d.z * d.z * d.z; };
  const std::vector<double> c = sh::project(f, 4, 6);
  std::mt19937 rng(3);
  for (int n = 0; n < 100; ++n) {
    const glm::dvec3 d = random_unit(rng);
    EXPECT_NEAR(sh::evaluate_sum(c.data(), 4, d), f(d), 1e-13);
  }
  // Degree 3 holds nothing above band 3.
  const std::vector<double> c6 = sh::project(f, 6, 8);
  for (int k = 16; k < 36; ++k) EXPECT_NEAR(c6[k], 0.0, 1e-14);
}

TEST(SphericalHarmonics, ClampedCosineKnownValues) {
  // Ramamoorthi & Hanrahan 2001: A_0 = π, A_1 = 2π/3, A_2 = π/4, A_3 = 0, A_4 = -π/24.
  EXPECT_DOUBLE_EQ(sh::clamped_cosine_band_factor(0), kPi);
  EXPECT_DOUBLE_EQ(sh::clamped_cosine_band_factor(1), 2 * kPi / 3);
  EXPECT_DOUBLE_EQ(sh::clamped_cosine_band_factor(2), kPi / 4);
  EXPECT_EQ(sh::clamped_cosine_band_factor(3), 0.0);
  EXPECT_DOUBLE_EQ(sh::clamped_cosine_band_factor(4), -kPi / 24);
  // c_l0 = A_l sqrt((2l+1)/(4π)): sqrt(π)/2, sqrt(π/3), sqrt(5π)/8.
  EXPECT_DOUBLE_EQ(sh::clamped_cosine_coefficient(0), kSqrtPi / 2);
  EXPECT_DOUBLE_EQ(sh::clamped_cosine_coefficient(1), std::sqrt(kPi / 3));
  EXPECT_DOUBLE_EQ(sh::clamped_cosine_coefficient(2), std::sqrt(5 * kPi) / 8);
}

TEST(SphericalHarmonics, ProjectionOfClampedCosine) {
  // Independent check of the closed forms: ∫_0^1 z Y_l0(z) 2π dz with Y_l0 from the hand-written table.
  // c00 = 2π · 1/(2√π) · 1/2, c10 = 2π √(3/4π) · 1/3, c20 = 2π √(5/16π) · (3/4 - 1/2).
  EXPECT_NEAR(kSqrtPi / 2, 2 * kPi * 0.5 / kSqrtPi * 0.5, 1e-15);
  EXPECT_NEAR(std::sqrt(kPi / 3), 2 * kPi * std::sqrt(3 / (4 * kPi)) / 3, 1e-15);
  EXPECT_NEAR(std::sqrt(5 * kPi) / 8, 2 * kPi * std::sqrt(5 / (16 * kPi)) * 0.25, 1e-15);

  const int bands = 6;
  // The kink at z = 0 limits Gauss–Legendre to O(n^-2): about 5e-6 with 601 nodes in z.
  const std::vector<double> c = sh::project([](const glm::dvec3& d) { return std::max(0.0, d.z); }, bands, 1200);
  for (int l = 0; l < bands; ++l)
    for (int m = -l; m <= l; ++m) {
      const double expected = m == 0 ? sh::clamped_cosine_coefficient(l) : 0.0;
      EXPECT_NEAR(c[sh::index(l, m)], expected, 1e-5) << "l " << l << " m " << m;
    }
  EXPECT_NEAR(c[0], kSqrtPi / 2, 1e-5);
  EXPECT_NEAR(c[2], std::sqrt(kPi / 3), 1e-5);
  EXPECT_NEAR(c[6], std::sqrt(5 * kPi) / 8, 1e-5);
}

TEST(SphericalHarmonics, BandEnergyIsRotationInvariant) {
  const glm::dmat3 r = rotation(glm::normalize(glm::dvec3(1, -2, 0.5)), 1.1);
  // A degree-4 polynomial (exact at bands 5, order 4 + 4) and a smooth non-polynomial function.
  const auto poly = [](const glm::dvec3& d) { return d.x * d.x * d.y - 3 * d.z * d.x + d.y * d.y * d.z * d.z + 0.2; };
  const auto lobe = [](const glm::dvec3& d) { return std::exp(3 * glm::dot(d, glm::normalize(glm::dvec3(1, 1, 2)))); };
  struct Case {
    std::function<double(const glm::dvec3&)> f;
    int bands, order;
    double tol;
  };
  for (const Case& k : {Case{poly, 5, 8, 1e-13}, Case{lobe, 4, 60, 1e-11}}) {
    const auto rotated = [&](const glm::dvec3& d) { return k.f(glm::transpose(r) * d); };
    const std::vector<double> a = sh::project(k.f, k.bands, k.order);
    const std::vector<double> b = sh::project(rotated, k.bands, k.order);
    const std::vector<double> ea = sh::band_energies(a.data(), k.bands), eb = sh::band_energies(b.data(), k.bands);
    bool coefficients_moved = false;
    for (int l = 0; l < k.bands; ++l) {
      EXPECT_NEAR(ea[l], eb[l], k.tol * std::max(1.0, ea[l])) << "band " << l;
      for (int m = -l; m <= l; ++m) coefficients_moved |= std::abs(a[sh::index(l, m)] - b[sh::index(l, m)]) > 1e-3;
    }
    EXPECT_TRUE(coefficients_moved);  // the rotation really changed the function
  }
}

TEST(SphericalHarmonics, WindowWeights) {
  for (int bands = 1; bands <= sh::kMaxBands; ++bands)
    for (sh::Window w : {sh::Window::none, sh::Window::lanczos, sh::Window::hann, sh::Window::vallee_poussin}) {
      const std::vector<double> s = sh::window_weights(bands, w);
      ASSERT_EQ(s.size(), std::size_t(bands));
      EXPECT_EQ(s[0], 1.0);
      for (int l = 1; l < bands; ++l) {
        EXPECT_LE(s[l], s[l - 1]);
        EXPECT_GT(s[l], 0.0);
      }
    }
  const std::vector<double> lanczos = sh::window_weights(4, sh::Window::lanczos);
  EXPECT_NEAR(lanczos[1], std::sin(kPi / 4) / (kPi / 4), 1e-15);
  const std::vector<double> hann = sh::window_weights(4, sh::Window::hann);
  EXPECT_NEAR(hann[2], 0.5, 1e-15);
  // de la Vallée Poussin, L = 3: 3!4!/((3-l)!(4+l)!) = 1, 3/5, 1/5, 1/35.
  const std::vector<double> vp = sh::window_weights(4, sh::Window::vallee_poussin);
  EXPECT_NEAR(vp[1], 0.6, 1e-15);
  EXPECT_NEAR(vp[2], 0.2, 1e-15);
  EXPECT_NEAR(vp[3], 1.0 / 35, 1e-15);
}

TEST(SphericalHarmonics, WindowKeepsTheDcTermExactly) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g;
  for (sh::Window w : {sh::Window::lanczos, sh::Window::hann, sh::Window::vallee_poussin}) {
    std::vector<double> c(16);
    for (double& v : c) v = g(rng);
    const std::vector<double> before = c;
    sh::apply_window(c.data(), 4, w);
    EXPECT_EQ(c[0], before[0]);
    // Per band: every coefficient of band l scaled by the same σ_l.
    const std::vector<double> s = sh::window_weights(4, w);
    for (int l = 0; l < 4; ++l)
      for (int m = -l; m <= l; ++m) EXPECT_DOUBLE_EQ(c[sh::index(l, m)], before[sh::index(l, m)] * s[l]);
  }
}

TEST(SphericalHarmonics, NarrowLobeDeltaPositivityByWindow) {
  // The projection of a delta at ω0 is Y_lm(ω0); its windowed reconstruction is the window's kernel,
  // the worst case for positivity. Tilted so that the grid does not line up with it.
  const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, -0.5, 0.8));
  std::vector<double> delta(16);
  sh::evaluate(axis, 4, delta.data());
  auto windowed = [&](sh::Window w) {
    std::vector<double> c = delta;
    sh::apply_window(c.data(), 4, w);
    return min_over_max(c, 4);
  };
  // The finding documented at sh::Window (min/max of the kernel, bands = 4).
  EXPECT_NEAR(windowed(sh::Window::none), -0.25, 1e-3);
  EXPECT_NEAR(windowed(sh::Window::lanczos), -0.0689, 1e-3);
  EXPECT_NEAR(windowed(sh::Window::hann), -0.0463, 1e-3);
  EXPECT_GE(windowed(sh::Window::vallee_poussin), -1e-4);
  // The windowed delta is the kernel (L+1)/(4π) · ((1+t)/2)^L, t = cos γ (unit integral, zero only at the
  // antipode), checked pointwise.
  std::vector<double> vp = delta;
  sh::apply_window(vp.data(), 4, sh::Window::vallee_poussin);
  std::mt19937 rng(5);
  for (int n = 0; n < 200; ++n) {
    const glm::dvec3 d = n == 0 ? -axis : (n == 1 ? axis : random_unit(rng));
    const double t = glm::dot(d, axis);
    EXPECT_NEAR(sh::evaluate_sum(vp.data(), 4, d), 4 / (4 * kPi) * std::pow((1 + t) / 2, 3), 1e-14);
  }
}

TEST(SphericalHarmonics, NarrowCapPositivityByWindow) {
  // A 5° cap (indicator of the cone around a tilted axis), projected numerically.
  const glm::dvec3 axis = glm::normalize(glm::dvec3(-0.2, 0.7, 0.4));
  const double cos_half_angle = std::cos(5 * kDegToRad);
  const std::vector<double> cap =
      sh::project([&](const glm::dvec3& d) { return glm::dot(d, axis) >= cos_half_angle ? 1.0 : 0.0; }, 4, 600);
  EXPECT_NEAR(cap[0] * 2 * kSqrtPi, 2 * kPi * (1 - cos_half_angle), 2e-3 * 2 * kPi * (1 - cos_half_angle));
  auto windowed = [&](sh::Window w) {
    std::vector<double> c = cap;
    sh::apply_window(c.data(), 4, w);
    return min_over_max(c, 4);
  };
  EXPECT_LT(windowed(sh::Window::none), -0.2);  // clearly negative: the test can fail
  EXPECT_LT(windowed(sh::Window::lanczos), -0.05);
  EXPECT_LT(windowed(sh::Window::hann), -0.03);
  EXPECT_GE(windowed(sh::Window::vallee_poussin), -1e-4);
}
