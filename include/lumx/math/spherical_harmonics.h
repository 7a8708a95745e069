// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/spherical_harmonics.h — real orthonormal spherical harmonics: evaluation, projection, windowing.
//
// Convention (Sloan, "Stupid Spherical Harmonics (SH) Tricks", GDC 2008; pbrt-v2 sh.cpp). With
// x = sinθ cosφ, y = sinθ sinφ, z = cosθ, K_lm = sqrt((2l+1)/(4π) · (l-|m|)!/(l+|m|)!) and P_l^m the
// associated Legendre function *with* the Condon–Shortley phase (-1)^m,
//   Y_lm = sqrt(2) K_lm P_l^m(z) cos(mφ)     m > 0
//   Y_l0 =         K_l0 P_l^0(z)
//   Y_lm = sqrt(2) K_lm P_l^|m|(z) sin(|m|φ)  m < 0
// so that Y_00 = 1/(2 sqrt(π)), Y_1-1 = -c y, Y_10 = c z, Y_11 = -c x with c = sqrt(3/(4π)), and
// ∫ Y_lm Y_l'm' dω = δ_ll' δ_mm'. Coefficient (l, m) is stored at index l(l+1)+m; `bands` = L+1 bands
// hold bands² coefficients (bands = 4 -> 16).
//
// Evaluation follows Sloan, "Efficient Spherical Harmonic Evaluation", JCGT 2(2), 2013: no trigonometry.
// The azimuthal factors come from the complex power (x + iy)^m = sin^mθ (cos mφ + i sin mφ), i.e.
//   C_m = x C_{m-1} - y S_{m-1},   S_m = x S_{m-1} + y C_{m-1},   C_0 = 1, S_0 = 0,
// which absorbs the sin^mθ of P_l^m, leaving polynomials in z. Normalised, these obey
//   P̄_mm     = -sqrt((2m+1)/(2m)) P̄_{m-1,m-1},  P̄_00 = 1/(2 sqrt(π))
//   P̄_{m+1,m} = sqrt(2m+3) z P̄_mm
//   P̄_lm     = A_lm z P̄_{l-1,m} - B_lm P̄_{l-2,m},
//   A_lm = sqrt((4l²-1)/(l²-m²)),  B_lm = sqrt((2l+1)((l-1)²-m²) / ((2l-3)(l²-m²))),
// the standard fully normalised recurrences, with the constants tabulated at compile time.
//
// Ringing: a truncated expansion of a peaked function goes negative. Per-band windows σ_l multiply the
// coefficients of band l, i.e. convolve with the zonal kernel k(t) = Σ σ_l (2l+1)/(4π) P_l(t), t = cos γ;
// the windowed reconstruction of every non-negative function is non-negative iff k >= 0, and the delta
// (whose reconstruction is k itself) is the worst case. See Window for which windows achieve that.
#pragma once

#include <lumx/math/constants.h>

#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

LUMX_NAMESPACE_BEGIN

namespace sh {

/// Largest number of bands evaluate() and the helpers accept (L = 15, 256 coefficients).
inline constexpr int kMaxBands = 16;
inline constexpr int kMaxCoefficients = kMaxBands * kMaxBands;
/// Largest degree of exactness project() accepts (8193 x 16385 quadrature points).
inline constexpr int kMaxQuadratureOrder = 16384;

constexpr int coefficient_count(int bands) {
  return bands * bands;
}
constexpr int index(int l, int m) {
  return l * (l + 1) + m;
}

/// Throws std::invalid_argument unless 1 <= bands <= kMaxBands.
inline void check_bands(int bands) {
  if (bands < 1 || bands > kMaxBands)
    throw std::invalid_argument("sh: bands must be in [1, " + std::to_string(kMaxBands) + "], got " +
                                std::to_string(bands));
}

namespace detail {

// sqrt usable in constant expressions (std::sqrt is not constexpr in C++17): Newton's iteration
// x <- (x + a/x)/2 from x >= sqrt(a), which decreases monotonically to within an ulp.
constexpr double constexpr_sqrt(double a) {
  if (!(a > 0.0)) return 0.0;
  double x = a > 1.0 ? a : 1.0;
  for (int i = 0; i < 2000; ++i) {
    const double next = 0.5 * (x + a / x);
    if (!(next < x)) break;
    x = next;
  }
  return x;
}

// Recurrence constants, indexed [l][m] for 0 <= m < l < kMaxBands (a = sqrt(2m+3), b = 0 at l = m+1).
// Compile-time constants, so that with the bands count known the compiler folds them into the code.
struct RecurrenceTables {
  double a[kMaxBands][kMaxBands] = {};
  double b[kMaxBands][kMaxBands] = {};
  double diagonal[kMaxBands] = {};  // P̄_mm (sin^m removed), times sqrt(2) for m > 0
};

constexpr RecurrenceTables make_recurrence_tables() {
  RecurrenceTables t;
  double pmm = 0.5 / constexpr_sqrt(kPi);
  for (int m = 0; m < kMaxBands; ++m) {
    if (m > 0) pmm *= -constexpr_sqrt((2.0 * m + 1.0) / (2.0 * m));
    t.diagonal[m] = m > 0 ? constexpr_sqrt(2.0) * pmm : pmm;
    if (m + 1 < kMaxBands) t.a[m + 1][m] = constexpr_sqrt(2.0 * m + 3.0);  // b = 0: P̄_{m-1,m} = 0
    for (int l = m + 2; l < kMaxBands; ++l) {
      const double l2 = double(l) * l, m2 = double(m) * m;
      t.a[l][m] = constexpr_sqrt((4.0 * l2 - 1.0) / (l2 - m2));
      t.b[l][m] = constexpr_sqrt((2.0 * l + 1.0) * ((l - 1.0) * (l - 1.0) - m2) / ((2.0 * l - 3.0) * (l2 - m2)));
    }
  }
  return t;
}

inline constexpr RecurrenceTables kRecurrence = make_recurrence_tables();

// Column m (all l = m .. n-1) of the recurrences. (c, s) enter as (C_{m-1}, S_{m-1}) and leave as
// (C_m, S_m). sqrt(2) for m > 0 is folded into the diagonal.
template <class Real>
inline void evaluate_column(int m, int n, double x, double y, double z, double& c, double& s, Real* out) {
  const RecurrenceTables& t = kRecurrence;
  if (m > 0) {
    const double c_next = x * c - y * s;
    s = x * s + y * c;
    c = c_next;
  }
  double p2 = 0.0, p1 = t.diagonal[m];
  for (int l = m;;) {
    if (m == 0) {
      out[index(l, 0)] = Real(p1);
    } else {
      out[index(l, m)] = Real(p1 * c);
      out[index(l, -m)] = Real(p1 * s);
    }
    if (++l >= n) break;
    const double p = t.a[l][m] * z * p1 - t.b[l][m] * p2;
    p2 = p1;
    p1 = p;
  }
}

// Bands known at compile time: the columns are expanded by a fold, so every loop has constant bounds
// and the compiler unrolls them, folds the constants and interleaves the independent columns.
template <int Bands, class Real, int... M>
inline void evaluate_unrolled(const glm::dvec3& d, Real* out, std::integer_sequence<int, M...>) {
  double c = 1.0, s = 0.0;
  (evaluate_column(M, Bands, d.x, d.y, d.z, c, s, out), ...);
}

}  // namespace detail

/// All bands² basis functions at a *unit* direction (not normalised here: the caller owns that; other
/// lengths give the polynomial extension). `out` must hold coefficient_count(bands) values.
/// Bands 1..8 run fully unrolled (about 10 ns for bands = 4), 9..16 by the same recurrences in loops.
/// Throws std::invalid_argument for bands outside [1, kMaxBands].
template <class Real>
void evaluate(const glm::dvec3& unit_direction, int bands, Real* out) {
  static_assert(std::is_floating_point_v<Real>, "sh::evaluate writes float or double");
  using detail::evaluate_unrolled;
  switch (bands) {
    case 1:
      return evaluate_unrolled<1>(unit_direction, out, std::make_integer_sequence<int, 1>());
    case 2:
      return evaluate_unrolled<2>(unit_direction, out, std::make_integer_sequence<int, 2>());
    case 3:
      return evaluate_unrolled<3>(unit_direction, out, std::make_integer_sequence<int, 3>());
    case 4:
      return evaluate_unrolled<4>(unit_direction, out, std::make_integer_sequence<int, 4>());
    case 5:
      return evaluate_unrolled<5>(unit_direction, out, std::make_integer_sequence<int, 5>());
    case 6:
      return evaluate_unrolled<6>(unit_direction, out, std::make_integer_sequence<int, 6>());
    case 7:
      return evaluate_unrolled<7>(unit_direction, out, std::make_integer_sequence<int, 7>());
    case 8:
      return evaluate_unrolled<8>(unit_direction, out, std::make_integer_sequence<int, 8>());
    default:
      break;
  }
  check_bands(bands);
  const int n = std::min(bands, kMaxBands);  // (checked above; stated for the optimiser's bounds analysis)
  double c = 1.0, s = 0.0;
  for (int m = 0; m < n; ++m)
    detail::evaluate_column(m, n, unit_direction.x, unit_direction.y, unit_direction.z, c, s, out);
}

/// Σ coeffs[i] Y_i(dir) for a unit direction.
inline double evaluate_sum(const double* coeffs, int bands, const glm::dvec3& unit_direction) {
  std::array<double, kMaxCoefficients> y;
  evaluate(unit_direction, bands, y.data());
  double sum = 0.0;
  for (int i = 0; i < coefficient_count(bands); ++i) sum += coeffs[i] * y[i];
  return sum;
}

/// Gauss–Legendre rule on [-1, 1]: n nodes (ascending) and weights, exact for polynomials of degree
/// 2n - 1. Nodes are the roots of P_n found by Newton's method from x ≈ cos(π(i + 3/4)/(n + 1/2)) with
/// P_n by Bonnet's recurrence k P_k = (2k-1) x P_{k-1} - (k-1) P_{k-2} and
/// P_n' = n (x P_n - P_{n-1}) / (x² - 1); weights w = 2 / ((1 - x²) P_n'(x)²) (Abramowitz & Stegun 25.4.29).
struct GaussLegendreRule {
  std::vector<double> nodes;
  std::vector<double> weights;
};

inline GaussLegendreRule gauss_legendre(int n) {
  if (n < 1) throw std::invalid_argument("gauss_legendre: n must be >= 1");
  GaussLegendreRule rule;
  rule.nodes.assign(n, 0.0);
  rule.weights.assign(n, 0.0);
  auto legendre_and_derivative = [n](double x, double& p, double& dp) {
    double p_prev = 1.0;
    p = x;
    for (int k = 2; k <= n; ++k) {
      const double p_next = ((2.0 * k - 1.0) * x * p - (k - 1.0) * p_prev) / k;
      p_prev = p;
      p = p_next;
    }
    dp = n * (x * p - p_prev) / (x * x - 1.0);
  };
  for (int i = 0; i < (n + 1) / 2; ++i) {
    const bool middle = (n % 2 == 1) && i == n / 2;  // the root at exactly 0
    double x = middle ? 0.0 : std::cos(kPi * (i + 0.75) / (n + 0.5));
    double p = 0.0, dp = 0.0;
    for (int iteration = 0; iteration < 100 && !middle; ++iteration) {
      legendre_and_derivative(x, p, dp);
      const double dx = p / dp;
      x -= dx;
      if (std::abs(dx) <= 1e-16) break;
    }
    legendre_and_derivative(x, p, dp);
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    rule.nodes[i] = -x;
    rule.nodes[n - 1 - i] = x;
    rule.weights[i] = rule.weights[n - 1 - i] = w;
  }
  return rule;
}

/// Coefficients c_lm = ∫ f(ω) Y_lm(ω) dω by a tensor rule: Gauss–Legendre in z (quadrature_order/2 + 1
/// nodes) times the uniform rule in φ (quadrature_order + 1 nodes, each 2π/n). It integrates every
/// polynomial in (x, y, z) of total degree <= quadrature_order exactly, so the projection is exact when
/// f is a polynomial of degree d and quadrature_order >= d + bands - 1; for other f it converges as the
/// order grows (slowly, O(n^-2), across a kink such as max(0, z) at z = 0).
/// Throws std::invalid_argument for bands outside [1, kMaxBands] or quadrature_order outside
/// [0, kMaxQuadratureOrder].
inline std::vector<double> project(const std::function<double(const glm::dvec3&)>& f, int bands, int quadrature_order) {
  check_bands(bands);
  if (quadrature_order < 0 || quadrature_order > kMaxQuadratureOrder)
    throw std::invalid_argument("sh::project: quadrature_order must be in [0, " + std::to_string(kMaxQuadratureOrder) +
                                "]");
  const GaussLegendreRule gl = gauss_legendre(quadrature_order / 2 + 1);
  const int n_phi = quadrature_order + 1;
  std::vector<double> cos_phi(n_phi), sin_phi(n_phi);
  for (int j = 0; j < n_phi; ++j) {
    const double phi = 2.0 * kPi * (j + 0.5) / n_phi;
    cos_phi[j] = std::cos(phi);
    sin_phi[j] = std::sin(phi);
  }
  const int n = coefficient_count(bands);
  std::vector<double> coeffs(n, 0.0);
  std::array<double, kMaxCoefficients> y;
  for (std::size_t i = 0; i < gl.nodes.size(); ++i) {
    const double z = gl.nodes[i];
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double w = gl.weights[i] * 2.0 * kPi / n_phi;
    for (int j = 0; j < n_phi; ++j) {
      const glm::dvec3 d(r * cos_phi[j], r * sin_phi[j], z);
      const double wf = w * f(d);
      evaluate(d, bands, y.data());
      for (int k = 0; k < n; ++k) coeffs[k] += wf * y[k];
    }
  }
  return coeffs;
}

/// Per-band windows against ringing; σ_0 = 1 for all, so the DC term (the integral, i.e. the flux) is
/// kept exactly. Each is a function of l only, hence commutes with rotation.
///
/// Finding (tests/test_spherical_harmonics.cpp, NarrowLobe*): for a delta or a narrow cap at bands = 4,
/// min/max of the reconstruction over the sphere is -25 % unwindowed, -6.9 % with Lanczos and -4.6 %
/// with Hann (both of width L+1); widths L and L+2 are no better (Hann: -6.7 %, -9.1 %), and no width
/// of either reaches -1e-4 until it has effectively cut everything above l = 1 (σ_1 <= 1/3). Neither
/// kernel is non-negative, so neither can guarantee positivity. `vallee_poussin` can: its kernel is the
/// spherical de la Vallée Poussin kernel k(t) ∝ ((1+t)/2)^L (Schaeben 1997), non-negative by
/// construction, with σ_1 = L/(L+2) (0.6 at bands = 4, against 0.53 for the best Gaussian that stays
/// non-negative). It is the default of RadianceVolume. Its price is more blur than Hann.
enum class Window {
  none,            ///< σ_l = 1
  lanczos,         ///< σ_l = sinc(π l / (L+1)), sinc(x) = sin(x)/x (Sloan 2008)
  hann,            ///< σ_l = (1 + cos(π l / (L+1))) / 2
  vallee_poussin,  ///< σ_l = L! (L+1)! / ((L-l)! (L+l+1)!) = Π_{k=1..l} (L-k+1)/(L+k+1); kernel >= 0
};

/// σ_0 .. σ_L for `bands` = L + 1 bands.
inline std::vector<double> window_weights(int bands, Window w) {
  check_bands(bands);
  const int big_l = bands - 1;
  std::vector<double> sigma(bands, 1.0);
  for (int l = 1; l < bands; ++l) {
    const double x = kPi * l / (big_l + 1.0);
    double& s = sigma[l];
    switch (w) {
      case Window::none:
        s = 1.0;
        break;
      case Window::lanczos:
        s = std::sin(x) / x;
        break;
      case Window::hann:
        s = 0.5 * (1.0 + std::cos(x));
        break;
      case Window::vallee_poussin:
        s = sigma[l - 1] * (big_l - l + 1.0) / (big_l + l + 1.0);
        break;
    }
  }
  return sigma;
}

/// Multiplies band l of `coeffs` (bands² values) by σ_l.
inline void apply_window(double* coeffs, int bands, Window w) {
  const std::vector<double> sigma = window_weights(bands, w);
  for (int l = 0; l < bands; ++l)
    for (int m = -l; m <= l; ++m) coeffs[index(l, m)] *= sigma[l];
}

/// Energy Σ_m c_lm² of each band; invariant under rotation of the function.
inline std::vector<double> band_energies(const double* coeffs, int bands) {
  check_bands(bands);
  std::vector<double> e(bands, 0.0);
  for (int l = 0; l < bands; ++l)
    for (int m = -l; m <= l; ++m) e[l] += coeffs[index(l, m)] * coeffs[index(l, m)];
  return e;
}

/// A_l of the clamped cosine max(0, cos γ) (Ramamoorthi & Hanrahan, "An Efficient Representation for
/// Irradiance Environment Maps", SIGGRAPH 2001): A_0 = π, A_1 = 2π/3, A_l = 0 for odd l > 1 and
///   A_l = 2π (-1)^(l/2 - 1) / ((l+2)(l-1)) · l! / (2^l ((l/2)!)²)   for even l
/// (A_2 = π/4, A_4 = -π/24). Irradiance from radiance is E_lm = A_l L_lm.
inline double clamped_cosine_band_factor(int l) {
  if (l < 0) throw std::invalid_argument("clamped_cosine_band_factor: l must be >= 0");
  if (l == 0) return kPi;
  if (l == 1) return 2.0 * kPi / 3.0;
  if (l % 2 == 1) return 0.0;
  double central = 1.0;  // l! / (2^l ((l/2)!)²) = C(l, l/2) / 2^l
  for (int k = 1; k <= l / 2; ++k) central *= (l / 2.0 + k) / (4.0 * k);
  const double sign = (l / 2 - 1) % 2 == 0 ? 1.0 : -1.0;
  return 2.0 * kPi * sign / ((l + 2.0) * (l - 1.0)) * central;
}

/// Zonal coefficient c_l0 of max(0, z) (axis +z): A_l · sqrt((2l+1)/(4π)), i.e. sqrt(π)/2, sqrt(π/3),
/// sqrt(5π)/8, 0, ... ; all c_lm with m != 0 vanish.
inline double clamped_cosine_coefficient(int l) {
  return clamped_cosine_band_factor(l) * std::sqrt((2.0 * l + 1.0) / (4.0 * kPi));
}

}  // namespace sh

LUMX_NAMESPACE_END
