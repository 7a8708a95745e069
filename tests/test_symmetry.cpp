// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Symmetry expansion and compaction, C-plane rotation, photometric frames.
#include <lumx/photometry/photometric_frame.h>
#include <lumx/photometry/resample.h>
#include <lumx/photometry/symmetry.h>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <limits>

using namespace lumx;

namespace {

AngleTable make(const std::vector<double>& h, std::size_t nv) {
  AngleTable t;
  t.horizontal_deg = h;
  for (std::size_t i = 0; i < nv; ++i) t.vertical_deg.push_back(10.0 * static_cast<double>(i));
  for (std::size_t ih = 0; ih < h.size(); ++ih)
    for (std::size_t iv = 0; iv < nv; ++iv) t.candela.push_back(100.0 * static_cast<double>(ih) + static_cast<double>(iv));
  return t;
}

/// Value of plane `c` of an expanded table (first vertical angle), or -1 if the plane is missing.
double plane_value(const AngleTable& t, double c, std::size_t iv = 1) {
  for (std::size_t i = 0; i < t.horizontal_deg.size(); ++i)
    if (std::abs(t.horizontal_deg[i] - c) < 1e-9) return t.at(i, iv);
  return -1;
}

}  // namespace

TEST(Symmetry, QuadrantExpandsToHandBuiltGrid) {
  const AngleTable s = make({0, 30, 60, 90}, 3);
  const AngleTable f = expand(s, Symmetry::quadrant);
  const std::vector<double> want = {0, 30, 60, 90, 120, 150, 180, 210, 240, 270, 300, 330};
  ASSERT_EQ(f.horizontal_deg, want);
  // Plane values: C and 180-C, 180+C, 360-C all equal the stored C.
  const double stored[] = {1, 101, 201, 301};  // iv = 1 of planes 0, 30, 60, 90
  const int src[] = {0, 1, 2, 3, 2, 1, 0, 1, 2, 3, 2, 1};
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_EQ(plane_value(f, want[i]), stored[src[i]]) << want[i];
}

TEST(Symmetry, BilateralPlanesMirrorCorrectly) {
  const AngleTable s0 = make({0, 45, 90, 135, 180}, 2);
  const AngleTable f0 = expand(s0, Symmetry::plane_c0_c180);
  EXPECT_EQ(f0.horizontal_deg.size(), 8u);
  EXPECT_EQ(plane_value(f0, 315), plane_value(f0, 45));  // I(C) = I(360 - C)
  EXPECT_EQ(plane_value(f0, 225), plane_value(f0, 135));

  const AngleTable s9 = make({90, 135, 180, 225, 270}, 2);
  const AngleTable f9 = expand(s9, Symmetry::plane_c90_c270);
  EXPECT_EQ(f9.horizontal_deg.size(), 8u);
  EXPECT_EQ(plane_value(f9, 0), plane_value(f9, 180));   // I(C) = I(180 - C)
  EXPECT_EQ(plane_value(f9, 45), plane_value(f9, 135));
  EXPECT_EQ(plane_value(f9, 315), plane_value(f9, 225));
}

TEST(Symmetry, CompactInvertsExpandExactly) {
  struct Case {
    Symmetry s;
    std::vector<double> h;
  };
  const Case cases[] = {{Symmetry::quadrant, {0, 15, 30, 45, 60, 75, 90}},
                        {Symmetry::plane_c0_c180, {0, 22.5, 45, 90, 135, 157.5, 180}},
                        {Symmetry::plane_c90_c270, {90, 100, 180, 260, 270}},
                        {Symmetry::rotational, {0}},
                        {Symmetry::none, {0, 90, 180, 270, 360}},
                        {Symmetry::lateral, {0, 10, 45, 90}}};
  for (const Case& c : cases) {
    const AngleTable s = make(c.h, 4);
    const auto back = compact(expand(s, c.s), c.s);
    ASSERT_TRUE(back.has_value()) << to_string(c.s);
    EXPECT_EQ(back->horizontal_deg, s.horizontal_deg) << to_string(c.s);
    EXPECT_EQ(back->candela, s.candela) << to_string(c.s);
  }
}

TEST(Symmetry, RangeMismatchAndMissingPlanesAreRefused) {
  EXPECT_THROW(expand(make({0, 45, 90, 135}, 2), Symmetry::plane_c0_c180), std::invalid_argument);
  EXPECT_FALSE(compact(make({10, 20, 350}, 2), Symmetry::quadrant).has_value());
}

TEST(Symmetry, IesRangesMapToSymmetries) {
  EXPECT_EQ(symmetry_from_ies_range(PhotometricType::C, 0, 0, 1), Symmetry::rotational);
  EXPECT_EQ(symmetry_from_ies_range(PhotometricType::C, 0, 90, 7), Symmetry::quadrant);
  EXPECT_EQ(symmetry_from_ies_range(PhotometricType::C, 0, 180, 13), Symmetry::plane_c0_c180);
  EXPECT_EQ(symmetry_from_ies_range(PhotometricType::C, 90, 270, 13), Symmetry::plane_c90_c270);
  EXPECT_EQ(symmetry_from_ies_range(PhotometricType::C, 0, 360, 25), Symmetry::none);
  EXPECT_FALSE(symmetry_from_ies_range(PhotometricType::C, 0, 270, 10).has_value());
  EXPECT_FALSE(symmetry_from_ies_range(PhotometricType::C, 0, 45, 4).has_value());
  EXPECT_EQ(symmetry_from_ies_range(PhotometricType::B, 0, 90, 7), Symmetry::lateral);
  EXPECT_EQ(symmetry_from_ies_range(PhotometricType::B, -90, 90, 13), Symmetry::none);
}

TEST(Rotation, QuarterTurnSwapsBilateralPlanesAndKeepsValues) {
  Photometry p;
  p.symmetry = Symmetry::plane_c0_c180;
  const AngleTable s = make({0, 45, 90, 135, 180}, 3);
  p.horizontal_deg = s.horizontal_deg;
  p.vertical_deg = s.vertical_deg;
  p.candela = s.candela;
  const Photometry r = rotate_c_planes(p, 90);
  EXPECT_EQ(r.symmetry, Symmetry::plane_c90_c270);
  const IntensityTable a(p), b(r);
  for (double c = 0; c < 360; c += 45)
    for (double g : {0.0, 10.0, 20.0}) EXPECT_DOUBLE_EQ(b.at_angles(std::fmod(c + 90, 360), g), a.at_angles(c, g));
  // Four quarter turns give the original back.
  const Photometry back = rotate_c_planes(rotate_c_planes(rotate_c_planes(r, 90), 90), 90);
  EXPECT_EQ(back.symmetry, Symmetry::plane_c0_c180);
  EXPECT_EQ(back.horizontal_deg, p.horizontal_deg);
  EXPECT_EQ(back.candela, p.candela);
}

TEST(Frames, AnglesRoundTripForAllTypes) {
  for (PhotometricType t : {PhotometricType::A, PhotometricType::B, PhotometricType::C}) {
    const double vlo = t == PhotometricType::C ? 1.0 : -89.0, vhi = t == PhotometricType::C ? 179.0 : 89.0;
    for (double v = vlo; v <= vhi; v += 11)
      for (double h = t == PhotometricType::C ? 0.0 : -179.0; h < 180; h += 13) {
        const glm::dvec3 d = direction_from_angles(t, h, v);
        EXPECT_NEAR(glm::dot(d, d), 1.0, 1e-12);
        const PhotometricAngles a = angles_from_direction(t, d);
        EXPECT_NEAR(a.vertical_deg, v, 1e-9);
        EXPECT_NEAR(a.horizontal_deg, h, 1e-9);
      }
  }
  // Type B relation to Type C (formats.md §1.3): tan B = cos C tan g, sin V = sin C sin g.
  const double c = 30 * kDegToRad, g = 40 * kDegToRad;
  const PhotometricAngles b = angles_from_direction(PhotometricType::B, direction_from_angles(PhotometricType::C, 30, 40));
  EXPECT_NEAR(std::tan(b.horizontal_deg * kDegToRad), std::cos(c) * std::tan(g), 1e-12);
  EXPECT_NEAR(std::sin(b.vertical_deg * kDegToRad), std::sin(c) * std::sin(g), 1e-12);
}

// Poles, grazing angles and directions whose length is 1 ± ulp (hard-cases.md §6 item 46): no NaN, and the
// angles within 1e-6 rad of the exact ones, since the inverse uses atan2 of both components, never acos of
// a dot product (whose argument 1 + ulp would be NaN and whose slope is infinite at ±1).
TEST(Frames, PolesGrazingAndNearUnitDirectionsGiveExactAnglesWithoutNaN) {
  const double ulp = std::numeric_limits<double>::epsilon();
  const double tol_deg = 1e-6 * kRadToDeg;
  for (PhotometricType t : {PhotometricType::A, PhotometricType::B, PhotometricType::C}) {
    // The photometric zero (nadir) and its opposite, lengthened and shortened by an ulp.
    for (const double s : {1.0 - ulp, 1.0, 1.0 + ulp, 1.0 + 4 * ulp}) {
      const PhotometricAngles nadir = angles_from_direction(t, s * direction_from_angles(t, 0, 0));
      EXPECT_TRUE(std::isfinite(nadir.vertical_deg) && std::isfinite(nadir.horizontal_deg));
      EXPECT_NEAR(nadir.vertical_deg, 0.0, tol_deg);
      EXPECT_NEAR(nadir.horizontal_deg, 0.0, tol_deg);
    }
  }
  // Type C: the poles γ = 0 and 180 (C is 0 there), grazing 1e-7 rad from each pole and from the horizon.
  const double e = 1e-7;
  struct Case {
    glm::dvec3 d;
    double gamma_rad;
  };
  const Case cases[] = {{{0, 0, -1}, 0},
                        {{0, 0, 1}, M_PI},
                        {{0, 0, -(1 + ulp)}, 0},
                        {{0, 0, 1 + ulp}, M_PI},
                        {{e, 0, -1}, std::atan(e)},
                        {{e, 0, 1}, M_PI - std::atan(e)},
                        {{1, 0, -e}, M_PI / 2 - std::atan(e)},
                        {{1, 0, e}, M_PI / 2 + std::atan(e)},
                        {{1e-300, 0, -1}, 1e-300},
                        {{1, 0, 0}, M_PI / 2},
                        {{-1, 1e-300, 0}, M_PI / 2}};
  for (const Case& c : cases) {
    const PhotometricAngles a = angles_from_direction(PhotometricType::C, c.d);
    ASSERT_TRUE(std::isfinite(a.vertical_deg) && std::isfinite(a.horizontal_deg)) << c.d.x << ' ' << c.d.z;
    EXPECT_NEAR(a.vertical_deg * kDegToRad, c.gamma_rad, 1e-6) << c.d.x << ' ' << c.d.z;
    EXPECT_GE(a.horizontal_deg, 0.0);
    EXPECT_LT(a.horizontal_deg, 360.0);
  }
  // Antiparallel directions: γ of −d is 180° − γ of d, with C turned by 180° (all types round trip).
  for (const double g : {0.0, 1e-7, 30.0, 90.0, 179.9999999, 180.0}) {
    const glm::dvec3 d = direction_from_angles(PhotometricType::C, 40, g);
    const PhotometricAngles back = angles_from_direction(PhotometricType::C, -d);
    EXPECT_NEAR(back.vertical_deg, 180.0 - g, tol_deg) << g;
    if (g > 1e-6 && g < 180 - 1e-6) {
      EXPECT_NEAR(back.horizontal_deg, 220.0, 1e-6) << g;
    }
  }
  // Round trips that reach the poles and the horizon (the test above stops 1° short).
  for (const double v : {0.0, 1e-7, 89.9999999, 90.0, 90.0000001, 179.9999999, 180.0}) {
    const PhotometricAngles a = angles_from_direction(PhotometricType::C, direction_from_angles(PhotometricType::C, 123, v));
    EXPECT_NEAR(a.vertical_deg, v, 1e-9) << v;
    if (v > 1e-6 && v < 180 - 1e-6) {
      EXPECT_NEAR(a.horizontal_deg, 123, 1e-6) << v;
    }
  }
  for (PhotometricType t : {PhotometricType::A, PhotometricType::B})
    for (const double v : {-90.0, -89.9999999, 0.0, 89.9999999, 90.0}) {
      const PhotometricAngles a = angles_from_direction(t, direction_from_angles(t, 45, v));
      EXPECT_NEAR(a.vertical_deg, v, 1e-9) << v;
    }
}
