// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Independent checks of lumx/math/sphere_map.h: the concentric + Lambert transform both ways, equal solid
// angle per texel, bilinear lookups across the equator seam, the squares' corners and the poles, and the
// map's integral under splatting and downsampling. All random inputs come from fixed seeds.
//
// The last group of tests guards defects this suite found in a first version (corner seams, exact
// constants, the shared u = 0.5 edge, precision at the poles); each names the fix.
#include <lumx/math/sphere_map.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <random>
#include <vector>

using namespace lumx;

namespace {

/// Angle between two directions (normalised here), 2·asin(|a − b| / 2): accurate for small angles.
double angle_between(const glm::dvec3& a, const glm::dvec3& b) {
  const double d = glm::length(glm::normalize(a) - glm::normalize(b));
  return 2.0 * std::asin(std::min(1.0, 0.5 * d));
}

/// A float unit direction from spherical coordinates computed in double.
glm::vec3 direction_from(double cos_theta, double phi) {
  const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  return glm::vec3(glm::normalize(glm::dvec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta)));
}

/// Uniform direction on the sphere (z uniform in [−1, 1], φ uniform: Archimedes).
glm::vec3 uniform_direction(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double z = 2.0 * u(rng) - 1.0;
  return direction_from(z, 2.0 * kPi * u(rng));
}

/// Direction of point (sx, sy) of square `half` through the public uv transform. u = 0.5 is the upper
/// square's right edge, so the lower square's left edge (sx = 0) is approached from just inside.
glm::dvec3 square_point_direction(int half, double sx, double sy) {
  float u = float(0.5 * sx);
  if (half == 1) u = sx > 0.0 ? float(0.5 + 0.5 * sx) : std::nextafter(0.5f, 1.0f);
  return glm::dvec3(sphere_map::uv_to_direction({u, float(sy)}));
}

/// A lower-hemisphere direction whose u is 0.5, the upper square's right edge (see
/// LowerSquaresLeftEdgeRoundTrips).
bool maps_onto_the_shared_edge(const glm::vec3& w) {
  return w.z < 0.0f && sphere_map::direction_to_uv(w).x == 0.5f;
}

/// Direction of the centre of texel (x, y) of a map of square resolution R.
glm::vec3 texel_centre_direction(int R, int x, int y) {
  const int half = x / R;
  return glm::vec3(square_point_direction(half, (x - half * R + 0.5) / R, (y + 0.5) / R));
}

/// A one-channel map of square resolution R holding f at its texel centres.
SphereMap map_of(int R, const std::function<double(const glm::vec3&)>& f) {
  SphereMap m(R, 1);
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x) m.at(x, y, 0) = float(f(texel_centre_direction(R, x, y)));
  return m;
}

/// The smooth test function 1 + 0.5x + 0.3y + 0.2z (|∇f| ≤ 0.62 per radian, range [0.38, 1.62]).
double smooth(const glm::vec3& w) {
  return 1.0 + 0.5 * w.x + 0.3 * w.y + 0.2 * w.z;
}

SphereMap random_map(int R, int channels, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  SphereMap m(R, channels);
  for (float& v : m.values()) v = u(rng);
  return m;
}

/// Point on the equator at azimuth φ lifted to height ±eps (unit, float).
glm::vec3 near_equator(double phi, double eps) {
  return direction_from(eps, phi);
}

/// Azimuth of a square corner on the equator: π/4 + k·π/2.
double corner_azimuth(int k) {
  return kPi / 4 + k * kPi / 2;
}

/// Distance in azimuth from φ to the nearest square corner on the equator.
double distance_to_corner(double phi) {
  double d = 10.0;
  for (int k = 0; k < 4; ++k) d = std::min(d, std::abs(std::remainder(phi - corner_azimuth(k), 2 * kPi)));
  return d;
}

/// Largest jump |lookup(above) − lookup(below)| across the equator at azimuths from `phis`, the pair
/// at heights ±eps.
double largest_equator_jump(const SphereMap& m, const std::vector<double>& phis, double eps) {
  double jump = 0;
  for (double phi : phis) {
    const glm::vec3 above = m.lookup(near_equator(phi, eps)), below = m.lookup(near_equator(phi, -eps));
    for (int c = 0; c < 3; ++c) jump = std::max(jump, double(std::abs(above[c] - below[c])));
  }
  return jump;
}

/// Azimuths around the equator: `n` evenly spaced, either avoiding (keep_corners = false) or restricted
/// to (true) a band of `band` radians around the four square corners.
std::vector<double> equator_azimuths(int n, double band, bool keep_corners) {
  std::vector<double> phis;
  for (int i = 0; i < n; ++i) {
    const double phi = 2 * kPi * (i + 0.5) / n;
    if ((distance_to_corner(phi) < band) == keep_corners) phis.push_back(phi);
  }
  return phis;
}

/// Azimuths within ±band of the square corners, n per corner, including the corners themselves.
std::vector<double> corner_azimuths(int n, double band) {
  std::vector<double> phis;
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i <= n; ++i) phis.push_back(corner_azimuth(k) + band * (2.0 * i / n - 1.0));
  return phis;
}

/// Signed solid angle of the spherical triangle (a, b, c) (Van Oosterom & Strackee 1983):
/// tan(E/2) = a·(b × c) / (1 + a·b + b·c + c·a).
double triangle_solid_angle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  return 2.0 * std::atan2(glm::dot(a, glm::cross(b, c)), 1.0 + glm::dot(a, b) + glm::dot(b, c) + glm::dot(c, a));
}

/// Solid angle of texel (x, y): its boundary traced with m points per edge through uv_to_direction,
/// fanned from its centre into spherical triangles. Great-circle chords between boundary points make an
/// O(1/m²) error (the texel edges are curves on the sphere).
double texel_solid_angle_polygon(int R, int x, int y, int m) {
  const int half = x / R, lx = x - half * R;
  const glm::dvec3 centre = glm::normalize(square_point_direction(half, (lx + 0.5) / R, (y + 0.5) / R));
  std::vector<glm::dvec3> ring;
  for (int k = 0; k < m; ++k) ring.push_back(square_point_direction(half, (lx + double(k) / m) / R, double(y) / R));
  for (int k = 0; k < m; ++k) ring.push_back(square_point_direction(half, (lx + 1.0) / R, (y + double(k) / m) / R));
  for (int k = 0; k < m; ++k)
    ring.push_back(square_point_direction(half, (lx + 1.0 - double(k) / m) / R, (y + 1.0) / R));
  for (int k = 0; k < m; ++k)
    ring.push_back(square_point_direction(half, double(lx) / R, (y + 1.0 - double(k) / m) / R));
  double sum = 0;
  for (std::size_t i = 0; i < ring.size(); ++i)
    sum += triangle_solid_angle(centre, glm::normalize(ring[i]), glm::normalize(ring[(i + 1) % ring.size()]));
  return std::abs(sum);  // the lower square is mirrored in z, so its boundary runs the other way
}

}  // namespace

// ---- transform ---------------------------------------------------------------------------------------

TEST(SphereMapTransform, ConcentricCentreAndPolesHaveNoNaN) {
  const glm::vec2 d = sphere_map::square_to_disk(0.5f, 0.5f);
  EXPECT_EQ(d.x, 0.0f);
  EXPECT_EQ(d.y, 0.0f);
  for (float phi : {-3.0f, 0.0f, 1.0f, 3.14159f}) {
    const glm::vec2 s = sphere_map::disk_to_square(0.0f, phi);
    EXPECT_EQ(s.x, 0.5f);
    EXPECT_EQ(s.y, 0.5f);
  }
  EXPECT_EQ(sphere_map::direction_to_uv({0, 0, 1}), glm::vec2(0.25f, 0.5f));
  EXPECT_EQ(sphere_map::direction_to_uv({0, 0, -1}), glm::vec2(0.75f, 0.5f));
  EXPECT_EQ(sphere_map::uv_to_direction({0.25f, 0.5f}), glm::vec3(0, 0, 1));
  EXPECT_EQ(sphere_map::uv_to_direction({0.75f, 0.5f}), glm::vec3(0, 0, -1));
}

TEST(SphereMapTransform, DirectionRoundTripOverRandomDirections) {
  // dot > 1 − 1e-6 (angle < 1.4e-3 rad) everywhere; away from the poles (|z| ≤ 0.99) the float
  // transform is good to a few ulps of angle, so the bound there is 2e-6 rad.
  std::mt19937_64 rng(20240611);
  double worst_dot = 1.0, worst_angle_off_pole = 0.0, worst_angle = 0.0;
  for (int i = 0; i < 1000000; ++i) {
    const glm::vec3 w = uniform_direction(rng);
    const glm::vec3 back = sphere_map::uv_to_direction(sphere_map::direction_to_uv(w));
    ASSERT_TRUE(std::isfinite(back.x) && std::isfinite(back.y) && std::isfinite(back.z));
    worst_dot = std::min(worst_dot, glm::dot(glm::dvec3(w), glm::dvec3(back)));
    const double angle = angle_between(w, back);
    worst_angle = std::max(worst_angle, angle);
    if (std::abs(w.z) <= 0.99f) worst_angle_off_pole = std::max(worst_angle_off_pole, angle);
  }
  std::printf("  round trip: worst dot 1 - %.3g, worst angle %.3g rad (%.3g rad for |z| <= 0.99)\n", 1.0 - worst_dot,
              worst_angle, worst_angle_off_pole);
  EXPECT_GT(worst_dot, 1.0 - 1e-6);
  EXPECT_LT(worst_angle_off_pole, 2e-6);
}

TEST(SphereMapTransform, DirectionRoundTripAtPolesEquatorCornersAndAxisPlanes) {
  std::vector<glm::vec3> dirs = {{0, 0, 1},     {0, 0, -1},     {1, 0, 0},           {-1, 0, 0},
                                 {0, 1, 0},     {0, -1, 0},     {0.0f, -0.0f, 1.0f}, {-0.0f, 0.0f, -1.0f},
                                 {1, -0.0f, 0}, {-1, -0.0f, 0}, {-1, 0.0f, -0.0f},   {0, 1, -0.0f}};
  // The directions of both squares' corners and edge midpoints (all on the equator).
  for (float u : {0.0f, 0.25f, 0.5f, std::nextafter(0.5f, 1.0f), 0.75f, 1.0f})
    for (float v : {0.0f, 0.5f, 1.0f}) dirs.push_back(sphere_map::uv_to_direction({u, v}));
  // The equator, including the corners' azimuths kπ/4 exactly; the x = 0 and y = 0 great circles.
  for (int i = 0; i < 4096; ++i) {
    const double a = 2 * kPi * i / 4096;
    dirs.push_back(direction_from(0.0, a));
    dirs.push_back(glm::vec3(glm::normalize(glm::dvec3(0.0, std::sin(a), std::cos(a)))));
    dirs.push_back(glm::vec3(glm::normalize(glm::dvec3(std::sin(a), 0.0, std::cos(a)))));
  }
  // Just off the equator and just off the poles, at the corners' azimuths and between them.
  for (double t = 1e-7; t < 0.1; t *= 3.0)
    for (int k = 0; k < 16; ++k) {
      const double phi = kPi / 8 * k;
      for (double s : {1.0, -1.0}) {
        dirs.push_back(direction_from(s * t, phi));
        dirs.push_back(direction_from(s * std::cos(t), phi));
      }
    }
  // The angle between a direction and its round trip, atan2(|a × b|, a · b) (exact near 0, unlike acos of the
  // dot product, whose resolution there is ~1e-8 rad at best): below 1e-5 rad (hard-cases.md §6 item 44).
  double worst = 0;
  for (const glm::vec3& w : dirs) {
    if (maps_onto_the_shared_edge(w)) continue;  // LowerSquaresLeftEdgeRoundTrips
    const glm::vec3 back = sphere_map::uv_to_direction(sphere_map::direction_to_uv(w));
    EXPECT_NEAR(glm::length(glm::dvec3(back)), 1.0, 1e-6);  // uv_to_direction returns unit vectors
    const glm::dvec3 a = glm::normalize(glm::dvec3(w)), b = glm::normalize(glm::dvec3(back));
    const double angle = std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
    worst = std::max(worst, angle);
    EXPECT_LT(angle, 1e-5) << "w = (" << w.x << ", " << w.y << ", " << w.z << ")";
  }
  std::printf("  special directions: worst round-trip angle %.3g rad over %zu directions\n", worst, dirs.size());
}

TEST(SphereMapTransform, UvRoundTripInsideBothSquares) {
  // Square coordinates survive uv → direction → uv to 3e-5 (the worst case is next to the poles, see
  // PoleRoundTripsKeepFullPrecision; elsewhere it is ~1e-6). The lower square's border is the
  // equator, which belongs to the upper square, so it is checked separately below.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst = 0;
  for (int i = 0; i < 400000; ++i) {
    const int half = i & 1;
    const double sx = 1e-4 + (1 - 2e-4) * u(rng), sy = 1e-4 + (1 - 2e-4) * u(rng);
    const glm::vec2 uv(float(0.5 * (sx + half)), float(sy));
    const glm::vec2 back = sphere_map::direction_to_uv(sphere_map::uv_to_direction(uv));
    worst = std::max(worst, double(std::max(std::abs(back.x - uv.x), std::abs(back.y - uv.y))));
  }
  std::printf("  uv round trip: worst |du|,|dv| %.3g\n", worst);
  EXPECT_LT(worst, 3e-5);
  // The upper square's border, including its corners and u = 0.5, maps back onto itself.
  for (int i = 0; i <= 256; ++i) {
    const float t = float(i) / 256;
    for (glm::vec2 uv :
         {glm::vec2(0.0f, t), glm::vec2(0.5f, t), glm::vec2(0.5f * t, 0.0f), glm::vec2(0.5f * t, 1.0f)}) {
      const glm::vec2 back = sphere_map::direction_to_uv(sphere_map::uv_to_direction(uv));
      EXPECT_NEAR(back.x, uv.x, 2e-6);
      EXPECT_NEAR(back.y, uv.y, 2e-6);
    }
  }
  // A point of the lower square's border is the equator point of the upper square with the same square
  // coordinates.
  for (int i = 0; i <= 256; ++i) {
    const double t = double(i) / 256;
    for (const glm::dvec2 s : {glm::dvec2(0.0, t), glm::dvec2(1.0, t), glm::dvec2(t, 0.0), glm::dvec2(t, 1.0)}) {
      const glm::dvec3 lower = square_point_direction(1, s.x, s.y), upper = square_point_direction(0, s.x, s.y);
      EXPECT_LT(angle_between(lower, upper), 1e-6) << "s = (" << s.x << ", " << s.y << ")";
      EXPECT_NEAR(upper.z, 0.0, 1e-6);
    }
  }
}

TEST(SphereMapTransform, TexelCentresFallInTheirTexel) {
  for (int R : {1, 2, 3, 4, 7, 16, 64}) {
    SphereMap m(R, 1);
    for (int y = 0; y < m.height(); ++y)
      for (int x = 0; x < m.width(); ++x) {
        int tx = -1, ty = -1;
        m.texel_of(texel_centre_direction(R, x, y), tx, ty);
        EXPECT_EQ(tx, x) << "R " << R << " texel (" << x << ", " << y << ")";
        EXPECT_EQ(ty, y) << "R " << R << " texel (" << x << ", " << y << ")";
      }
  }
}

// ---- equal area --------------------------------------------------------------------------------------

TEST(SphereMapGeometry, EveryTexelHasTheSameSolidAngle) {
  // Each texel's solid angle by tracing its boundary (m = 16 and 32 points per edge) and Richardson
  // extrapolation (4·A₃₂ − A₁₆)/3, which removes the O(1/m²) chord error (measured: 4e-4 at m = 16
  // before, < 1.3e-5 after). What is left is float noise of the boundary directions (~1e-7 rad on a
  // texel ~2.5/R rad wide), so the tolerance grows with R: 5e-7·R + 2e-6 relative.
  for (int R : {4, 16, 64}) {
    const double expected = sphere_map::texel_solid_angle(R), tolerance = 5e-7 * R + 2e-6;
    double total = 0, worst = 0;
    for (int y = 0; y < R; ++y)
      for (int x = 0; x < 2 * R; ++x) {
        const double a = (4 * texel_solid_angle_polygon(R, x, y, 32) - texel_solid_angle_polygon(R, x, y, 16)) / 3;
        total += a;
        worst = std::max(worst, std::abs(a / expected - 1));
        EXPECT_NEAR(a / expected, 1.0, tolerance) << "R " << R << " texel (" << x << ", " << y << ")";
      }
    std::printf("  R %d: worst relative texel solid-angle error %.3g (tolerance %.3g)\n", R, worst, tolerance);
    EXPECT_NEAR(total, 4 * kPi, 1e-5);
    EXPECT_DOUBLE_EQ(expected * 2 * R * R, 4 * kPi);
  }
}

TEST(SphereMapGeometry, UniformDirectionsFillTexelsEvenly) {
  // texel_of (the direction → texel side) bins 2·10⁶ uniform directions. Equal solid angles make the
  // counts multinomial with equal cell probabilities, so Σ (n − e)²/e is χ² with k = 2R² − 1 degrees of
  // freedom; Wilson–Hilferty maps it to a standard normal z = ((χ²/k)^⅓ − (1 − 2/9k)) / √(2/9k). z < 5
  // (one-sided p ≈ 3e-7) tolerates chance; a 1 % area error on 1/8 of the texels at R = 16 gives z ≈ 16.
  for (int R : {4, 16, 64}) {
    SphereMap m(R, 1);
    std::vector<long> counts(m.texel_count(), 0);
    std::mt19937_64 rng(1000 + R);
    const long n = 2000000;
    for (long i = 0; i < n; ++i) {
      int x, y;
      m.texel_of(uniform_direction(rng), x, y);
      ASSERT_TRUE(x >= 0 && x < m.width() && y >= 0 && y < m.height());
      ++counts[std::size_t(y) * m.width() + x];
    }
    const double e = double(n) / double(m.texel_count());
    double chi2 = 0;
    for (long c : counts) chi2 += (c - e) * (c - e) / e;
    const double k = double(m.texel_count() - 1);
    const double z = (std::cbrt(chi2 / k) - (1 - 2 / (9 * k))) / std::sqrt(2 / (9 * k));
    std::printf("  R %d: chi2 %.1f for %.0f dof, z %.2f\n", R, chi2, k, z);
    EXPECT_LT(z, 5.0) << "R " << R;
  }
}

// ---- lookups -----------------------------------------------------------------------------------------

TEST(SphereMapLookup, ConstantMapLooksUpWithinOneUlpOfTheConstant) {
  // Exactly constant for constants like 1 and 0.3; see ConstantMapLooksUpExactlyConstant.
  std::mt19937_64 rng(3);
  for (float c : {1.0f, 0.1f, 3.7f, 1e-3f, 12345.678f}) {
    for (int channels : {1, 3}) {
      SphereMap m(8, channels);
      std::fill(m.values().begin(), m.values().end(), c);
      for (int i = 0; i < 20000; ++i) {
        const glm::vec3 v = m.lookup(uniform_direction(rng));
        for (int k = 0; k < 3; ++k) ASSERT_NEAR(v[k], c, 1.2e-7 * c);
      }
      EXPECT_EQ(m.lookup_nearest({0, 0, 1}), glm::vec3(c));
    }
  }
}

TEST(SphereMapLookup, SmoothMapReproducesTheFunctionToOrderTexelSize) {
  // Texel values are f at texel centres. Bilinear weights in square coordinates are not the sphere's,
  // and across the seam the mirror texel stands in for a neighbour; both give O(h) errors with h ≈ 2/R
  // the texel size in radians, so |lookup − f| ≤ C/R. Measured C ≈ 0.5; the bound uses C = 1, and the
  // error must shrink with R (ratio ≥ 2 per factor 4 in R, measured ≈ 4).
  std::mt19937_64 rng(11);
  std::vector<glm::vec3> dirs;
  for (int i = 0; i < 200000; ++i) dirs.push_back(uniform_direction(rng));
  for (double phi : corner_azimuths(64, 0.2))
    for (double z : {1e-6, -1e-6, 0.01, -0.01}) dirs.push_back(near_equator(phi, z));
  for (float s : {1.0f, -1.0f}) dirs.push_back({0, 0, s});
  double previous = 0;
  for (int R : {4, 16, 64}) {
    const SphereMap m = map_of(R, smooth);
    double worst = 0;
    for (const glm::vec3& w : dirs) worst = std::max(worst, std::abs(double(m.lookup(w).x) - smooth(w)));
    std::printf("  R %d: max |lookup - f| = %.3g (= %.2f / R)\n", R, worst, worst * R);
    EXPECT_LT(worst, 1.0 / R) << "R " << R;
    if (previous > 0) {
      EXPECT_LT(worst, previous / 2) << "R " << R;
    }
    previous = worst;
  }
}

TEST(SphereMapLookup, SmoothMapIsContinuousAcrossTheEquatorAwayFromCorners) {
  // A continuous interpolant jumps by O(eps) between directions eps above and below the equator; its
  // slope is about |∇f| ≤ 0.62 /rad times the map's distortion, so 20·eps is a loose bound.
  // (Within one texel of the squares' corners, see SmoothMapIsContinuousAtSquareCorners.)
  const double eps = 1e-5;
  for (int R : {4, 16, 64}) {
    const SphereMap m = map_of(R, smooth);
    const double jump = largest_equator_jump(m, equator_azimuths(20000, kPi / (2 * R), false), eps);
    EXPECT_LT(jump, 20 * eps) << "R " << R;
  }
}

TEST(SphereMapLookup, SmoothMapIsContinuousAtThePoles) {
  // The poles are the squares' centres: lookups eps away in any azimuth approach the pole's value.
  const double eps = 1e-5;
  for (int R : {1, 4, 16, 64}) {
    const SphereMap m = map_of(R, smooth);
    for (double s : {1.0, -1.0}) {
      const float at_pole = m.lookup({0, 0, float(s)}).x;
      for (int k = 0; k < 64; ++k) {
        const glm::vec3 w = direction_from(s * std::cos(eps), 2 * kPi * k / 64);
        EXPECT_NEAR(m.lookup(w).x, at_pole, 20 * eps) << "R " << R << " pole " << s;
      }
    }
  }
}

TEST(SphereMapLookup, RandomMapIsContinuousAcrossTheEquatorAwayFromCorners) {
  // Texels uniform in [0, 1): neighbouring texels differ by O(1), so the bilinear slope is up to ~R per
  // unit of square coordinate, and ±eps in z moves the square coordinates by ~eps/4 each side of the
  // seam. The bound 2·eps·R is about 4× the measured worst jump; a seam that pairs the wrong texels
  // jumps by O(1).
  const double eps = 1e-5;
  for (int R : {1, 4, 16, 64}) {
    for (int channels : {1, 3}) {
      const SphereMap m = random_map(R, channels, 100 + R);
      const double jump = largest_equator_jump(m, equator_azimuths(40000, kPi / (2 * R), false), eps);
      EXPECT_LT(jump, 2 * eps * R) << "R " << R << " channels " << channels;
    }
  }
}

TEST(SphereMapLookup, BilinearLookupAtTexelCentresReturnsTheTexel) {
  const SphereMap m = random_map(16, 3, 5);
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x) {
      const glm::vec3 w = texel_centre_direction(16, x, y), v = m.lookup(w), t = m.texel(x, y);
      EXPECT_EQ(m.lookup_nearest(w), t);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(v[c], t[c], 1e-4) << "texel (" << x << ", " << y << ")";
    }
}

// ---- integral, splatting, downsampling -----------------------------------------------------------------

TEST(SphereMapIntegral, SplattedParticlesIntegrateToTheirFlux) {
  // Splatting adds flux / Ω to one float texel; integral() multiplies back by Ω in double. The only
  // errors are float rounding of 1/Ω and of the texel sums, ~1e-7 relative each, so 1e-5 is loose.
  for (int channels : {1, 3}) {
    for (int R : {1, 16, 64}) {
      SphereMap m(R, channels);
      std::mt19937_64 rng(42 + R);
      std::uniform_real_distribution<float> flux(0.0f, 2.0f);
      glm::dvec3 sum(0.0);
      for (int i = 0; i < 100000; ++i) {
        const glm::vec3 phi(flux(rng), flux(rng), flux(rng));
        m.splat(uniform_direction(rng), phi);
        sum += channels == 1 ? glm::dvec3(double(phi.x)) : glm::dvec3(phi);
      }
      // Exact poles and equator points too.
      for (glm::vec3 w : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::vec3(0, -1, -0.0f)}) {
        m.splat(w, glm::vec3(1.0f, 2.0f, 3.0f));
        sum += channels == 1 ? glm::dvec3(1.0) : glm::dvec3(1.0, 2.0, 3.0);
      }
      const glm::dvec3 integral = m.integral();
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(integral[c] / sum[c], 1.0, 1e-5) << "R " << R << " ch " << channels;
      EXPECT_TRUE(m.all_finite_nonnegative());
    }
  }
}

TEST(SphereMapIntegral, DownsamplingKeepsTheIntegral) {
  for (int channels : {1, 3}) {
    SphereMap m = random_map(64, channels, 9);
    const glm::dvec3 original = m.integral();
    while (m.resolution() > 1) {
      m = m.downsampled();
      const glm::dvec3 now = m.integral();
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(now[c] / original[c], 1.0, 1e-6) << "R " << m.resolution();
    }
    EXPECT_THROW(m.downsampled(), std::invalid_argument);  // R = 1
  }
  EXPECT_THROW(SphereMap(3, 1).downsampled(), std::invalid_argument);
  EXPECT_THROW(SphereMap().downsampled(), std::invalid_argument);
}

// ---- construction ------------------------------------------------------------------------------------

TEST(SphereMap, InvalidConstructorArgumentsThrow) {
  for (int R : {0, -1, -4096, sphere_map::kMaxResolution + 1, 1 << 30})
    EXPECT_THROW(SphereMap(R, 1), std::invalid_argument) << "R " << R;
  for (int c : {0, 2, 4, -1}) EXPECT_THROW(SphereMap(4, c), std::invalid_argument) << "channels " << c;
}

TEST(SphereMap, LayoutSizesAndSolidAngle) {
  const SphereMap m(8, 3);
  EXPECT_EQ(m.width(), 16);
  EXPECT_EQ(m.height(), 8);
  EXPECT_EQ(m.texel_count(), 128u);
  EXPECT_EQ(m.bytes(), 128u * 3 * sizeof(float));
  EXPECT_DOUBLE_EQ(m.texel_solid_angle() * 128, 4 * kPi);
  EXPECT_EQ(m.max_value(), 0.0f);
  EXPECT_TRUE(SphereMap().empty());
  SphereMap bad(2, 3);
  bad.at(3, 1, 2) = -1.0f;
  int x = -1, y = -1, c = -1;
  EXPECT_FALSE(bad.all_finite_nonnegative(&x, &y, &c));
  EXPECT_EQ(x, 3);
  EXPECT_EQ(y, 1);
  EXPECT_EQ(c, 2);
}

// ---- regressions: defects found in the first version of math/sphere_map.h ----------------------------------

// fetch() flips to the other square once even when both coordinates are outside (past a corner). Along
// the equator within half a texel of a corner the two squares then weight the two corner texels U, L
// differently: the upper square returns (1 − t)(U + L)/2 + t·L, the lower (1 − t)(U + L)/2 + t·U, a jump
// of t·|U − L| up to |U − L|/2. Fix: flip once per crossed edge (`half ^= crossed_x ^ crossed_y`), so the
// texel diagonally past a corner is the square's own corner texel.
TEST(SphereMapLookup, SmoothMapIsContinuousAtSquareCorners) {
  const double eps = 1e-5;
  for (int R : {4, 16, 64}) {
    const SphereMap m = map_of(R, smooth);
    const double jump = largest_equator_jump(m, corner_azimuths(200, 2 * kPi / (2 * R)), eps);
    std::printf("  R %d: smooth-map jump at the corners %.3g\n", R, jump);
    EXPECT_LT(jump, 20 * eps) << "R " << R;
  }
}

TEST(SphereMapLookup, RandomMapIsContinuousAtSquareCorners) {
  const double eps = 1e-5;
  for (int R : {1, 4, 16, 64}) {
    const SphereMap m = random_map(R, 1, 100 + R);
    const double jump = largest_equator_jump(m, corner_azimuths(200, 2 * kPi / (2 * R)), eps);
    std::printf("  R %d: random-map jump at the corners %.3g\n", R, jump);
    EXPECT_LT(jump, 2 * eps * R) << "R " << R;
  }
}

// (v0·(1 − t) + v1·t) is not exactly v0 when v1 == v0 (0.1f: half of all lookups are 1 ulp off).
// Fix: interpolate as v0 + t·(v1 − v0), which is exact when v1 == v0.
TEST(SphereMapLookup, ConstantMapLooksUpExactlyConstant) {
  std::mt19937_64 rng(3);
  for (float c : {1.0f, 0.1f, 3.7f, 1e-3f, 12345.678f}) {
    SphereMap m(8, 1);
    std::fill(m.values().begin(), m.values().end(), c);
    long inexact = 0;
    for (int i = 0; i < 20000; ++i) inexact += m.lookup(uniform_direction(rng)).x != c ? 1 : 0;
    EXPECT_EQ(inexact, 0) << "constant " << c;
  }
}

// direction_to_square takes ρ = √(1 − |z|); near the poles 1 − |z| is a multiple of 2⁻²⁴ in float, so
// ρ is quantised to 2⁻¹²·√k: directions within ~2e-4 rad of a pole round-trip with errors up to 2.3e-4
// rad (hard-cases §44 asks < 1e-5), square coordinates within ~1e-4 of the centre collapse onto it, and
// at R ≥ 2048 texel_of puts such directions in the wrong central texel. Fix: for unit w,
// ρ = √((x² + y²) / (1 + |z|)), the same quantity without the cancellation.
TEST(SphereMapTransform, PoleRoundTripsKeepFullPrecision) {
  double worst_angle = 0;
  for (double theta = 1e-6; theta < 1e-2; theta *= 1.1)
    for (int k = 0; k < 16; ++k)
      for (double s : {1.0, -1.0}) {
        const glm::vec3 w = direction_from(s * std::cos(theta), 0.4 * k);
        worst_angle =
            std::max(worst_angle, angle_between(w, sphere_map::uv_to_direction(sphere_map::direction_to_uv(w))));
      }
  std::printf("  worst round-trip angle near the poles %.3g rad\n", worst_angle);
  EXPECT_LT(worst_angle, 1e-5);
  double worst_uv = 0;
  for (double d : {1e-6, 1e-5, 5e-5, 1e-4, 2e-4})
    for (float half : {0.0f, 0.5f}) {
      const glm::vec2 uv(half + float(0.25 - d), float(0.5 + d));
      const glm::vec2 back = sphere_map::direction_to_uv(sphere_map::uv_to_direction(uv));
      worst_uv = std::max(worst_uv, double(std::max(std::abs(back.x - uv.x), std::abs(back.y - uv.y))));
    }
  std::printf("  worst uv round trip near the poles %.3g\n", worst_uv);
  EXPECT_LT(worst_uv, 2e-6);
}

// direction_to_uv gives u = 0.5·(sx + 1) for the lower square; for a direction just below the equator on
// the lower square's left edge (x < 0, −1e-7 ≲ z < 0) sx < 6e-8 and u rounds to 0.5, which
// uv_to_direction reads as the upper square's right edge: the round trip returns the mirror direction
// (x → −x, up to 180° off). Fix: in direction_to_uv, when half == 1 and u == 0.5f return (0, s.y), the
// same equator point seen from the upper square.
TEST(SphereMapTransform, LowerSquaresLeftEdgeRoundTrips) {
  std::vector<glm::vec3> dirs = {sphere_map::uv_to_direction({std::nextafter(0.5f, 1.0f), 0.5f}),
                                 sphere_map::uv_to_direction({std::nextafter(0.5f, 1.0f), 0.1f})};
  for (double z : {-1e-8, -5e-8, -1e-7})
    for (int k = 0; k <= 8; ++k) dirs.push_back(direction_from(z, 3 * kPi / 4 + k * kPi / 16));
  for (const glm::vec3& w : dirs) {
    const glm::vec3 back = sphere_map::uv_to_direction(sphere_map::direction_to_uv(w));
    EXPECT_GT(glm::dot(glm::dvec3(w), glm::dvec3(back)), 1.0 - 1e-6)
        << "w = (" << w.x << ", " << w.y << ", " << w.z << ") came back as (" << back.x << ", " << back.y << ", "
        << back.z << ")";
  }
}
