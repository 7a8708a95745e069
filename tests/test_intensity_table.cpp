// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Analytic checks of the full-sphere table: flux integral, interpolation, seams and poles.
#include <lumx/photometry/intensity_table.h>
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/metrics.h>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

using namespace lumx;

namespace {

/// Type C photometry sampled from f(C, gamma) on a regular grid with the given symmetry's range.
Photometry sampled(const std::function<double(double, double)>& f, Symmetry sym, double dc, double dg,
                   double g_last = 180.0) {
  Photometry p;
  p.type = PhotometricType::C;
  p.symmetry = sym;
  double c0 = 0, c1 = 360;
  stored_range(sym, c0, c1);
  if (sym == Symmetry::none) c0 = 0, c1 = 360;
  for (double c = c0; c <= c1 + 1e-9; c += dc) {
    p.horizontal_deg.push_back(c);
    if (sym == Symmetry::rotational) break;
  }
  for (double g = 0; g <= g_last + 1e-9; g += dg) p.vertical_deg.push_back(g);
  for (double c : p.horizontal_deg)
    for (double g : p.vertical_deg) p.candela.push_back(f(c, g));
  p.absolute = true;
  return p;
}

}  // namespace

TEST(IntensityTable, IsotropicIntegratesToFourPiI) {
  for (Symmetry s : {Symmetry::none, Symmetry::rotational, Symmetry::quadrant, Symmetry::plane_c0_c180,
                     Symmetry::plane_c90_c270}) {
    const Photometry p = sampled([](double, double) { return 100.0; }, s, 15, 5);
    // A constant is reproduced exactly by the interpolant, and the sin-weighted polar integral is exact.
    EXPECT_NEAR(IntensityTable(p).flux_lm(), 4 * kPi * 100.0, 1e-9 * 4 * kPi * 100.0) << to_string(s);
  }
}

TEST(IntensityTable, CosineLowerHemisphereIntegratesToPiI0) {
  // Linear interpolation of cos(g) between nodes h apart lies below it by cos(g)(g-a)(b-g)/2 (to first
  // order), so the flux is low by about 2pi * h^2/12 * int_0^{pi/2} cos g sin g dg = pi h^2 / 12:
  // relative deficit h^2/12 (6.3e-4 for h = 5 degrees).
  for (double step : {5.0, 2.5, 1.0}) {
    const Photometry p = sampled(
        [](double, double g) { return g <= 90 ? 1000.0 * std::cos(g * kDegToRad) : 0.0; }, Symmetry::quadrant, 15,
        step, 90.0);
    const double phi = IntensityTable(p).flux_lm();
    const double exact = kPi * 1000.0, h = step * kDegToRad;
    EXPECT_LT(phi, exact);
    EXPECT_NEAR((exact - phi) / exact, h * h / 12, 0.05 * h * h / 12) << "step " << step;
  }
}

TEST(IntensityTable, InterpolationExactOnBilinearData) {
  // f = a + b C + c g + d C g is bilinear in the angles, so bilinear interpolation reproduces it
  // everywhere inside the grid; the first and last cells in each angle are excluded because the pole
  // rows are replaced by their mean over C, and C0 and C360 by their mean (one direction, one value).
  auto f = [](double c, double g) { return 10 + 0.5 * c + 2 * g + 0.01 * c * g; };
  const Photometry p = sampled(f, Symmetry::none, 10, 5);
  const IntensityTable t(p);
  for (double c = 11.3; c < 349; c += 17.1)
    for (double g = 6.2; g < 174; g += 11.3) EXPECT_NEAR(t.at_angles(c, g), f(c, g), 1e-9 * f(c, g)) << c << " " << g;
}

TEST(IntensityTable, ContinuousAcrossSeamAndPoles) {
  // Different values in every plane, including at the poles (as measurement noise gives).
  auto f = [](double c, double g) { return 100 + 40 * std::sin(c * kDegToRad) + g; };
  const Photometry p = sampled(f, Symmetry::none, 15, 5);
  const IntensityTable t(p);
  // Seam: C -> 360 from below and C -> 0 from above agree.
  for (double g : {10.0, 47.5, 133.0}) {
    EXPECT_NEAR(t.at_angles(360.0 - 1e-7, g), t.at_angles(1e-7, g), 1e-4);
    EXPECT_NEAR(t.at_angles(-30.0, g), t.at_angles(330.0, g), 1e-9);
  }
  // Poles: every plane gives the same value at gamma 0 and 180, and nearby values approach it.
  const double south = t.at_angles(0, 0), north = t.at_angles(0, 180);
  for (double c = 0; c < 360; c += 7) {
    EXPECT_NEAR(t.at_angles(c, 0), south, 1e-9);
    EXPECT_NEAR(t.at_angles(c, 180), north, 1e-9);
    EXPECT_NEAR(t.at_angles(c, 1e-6), south, 1e-3);
  }
  // Directions exactly at the poles (x = y = 0) and the zero vector do not produce NaN.
  EXPECT_NEAR(t.intensity({0, 0, -1}), south, 1e-9);
  EXPECT_NEAR(t.intensity({0, 0, 1}), north, 1e-9);
  EXPECT_TRUE(std::isfinite(t.intensity({0, 0, 0})));
}

TEST(IntensityTable, ZeroOutsideMeasuredVerticalRange) {
  const Photometry p = sampled([](double, double) { return 50.0; }, Symmetry::rotational, 0, 10, 90.0);
  const IntensityTable t(p);
  EXPECT_DOUBLE_EQ(t.at_angles(0, 90), 50.0);
  EXPECT_DOUBLE_EQ(t.at_angles(0, 90.5), 0.0);
  EXPECT_DOUBLE_EQ(t.at_angles(0, std::nan("")), 0.0);
  EXPECT_NEAR(t.flux_lm(), 2 * kPi * 50.0, 1e-9);              // hemisphere
  EXPECT_NEAR(downward_flux_fraction(t), 1.0, 1e-12);
}

TEST(IntensityTable, DownwardFractionSplitsAtNinety) {
  // Isotropic over the whole sphere: half the flux goes down, for Type C exactly (split integral).
  const Photometry p = sampled([](double, double) { return 7.0; }, Symmetry::rotational, 0, 15);
  EXPECT_NEAR(downward_flux_fraction(IntensityTable(p)), 0.5, 1e-12);
  // A grid whose cell straddles 90 degrees (gamma step 40) is split inside the cell.
  const Photometry q = sampled([](double, double g) { return g < 100 ? 10.0 : 0.0; }, Symmetry::rotational, 0, 40, 160);
  const IntensityTable tq(q);
  // Integrand 10 on [0,80], linear 10->0 on [80,120], 0 beyond; down part = [0,90].
  EXPECT_NEAR(tq.flux_lm(0, 90) + tq.flux_lm(90, 180), tq.flux_lm(), 1e-9 * tq.flux_lm());
  EXPECT_GT(tq.flux_lm(90, 180), 0.0);
}

TEST(IntensityTable, RejectsMalformedTables) {
  Photometry p;
  p.vertical_deg = {0};
  p.horizontal_deg = {0};
  p.candela = {1};
  EXPECT_THROW(IntensityTable{p}, std::invalid_argument);
  p.vertical_deg = {0, 10};
  EXPECT_THROW(IntensityTable{p}, std::invalid_argument);  // 1 value for 2 angles
  p.candela = {1, 2};
  p.vertical_deg = {10, 0};
  EXPECT_THROW(IntensityTable{p}, std::invalid_argument);
}

TEST(Metrics, BeamAndFieldAnglesOfACosinePowerBeam) {
  // I = cos^n(g): I/I0 = 1/2 at g = acos(2^{-1/n}), = 1/10 at acos(10^{-1/n}); full angles are twice those.
  const double n = 8;
  const Photometry p = sampled([n](double, double g) { return g < 90 ? 1000 * std::pow(std::cos(g * kDegToRad), n) : 0.0; },
                               Symmetry::rotational, 0, 0.5, 90);
  const IntensityTable t(p);
  const Spread s = spread(t, SpreadPlane::c0_c180);
  const double beam = 2 * std::acos(std::pow(0.5, 1 / n)) * kRadToDeg;
  const double field = 2 * std::acos(std::pow(0.1, 1 / n)) * kRadToDeg;
  // Tabulated every 0.5 degree, sampled every 0.05: the crossing is located to within ~0.05 degree.
  EXPECT_NEAR(s.beam_deg, beam, 0.1);
  EXPECT_NEAR(s.field_deg, field, 0.1);
  EXPECT_NEAR(s.peak_cd, 1000, 1e-9);
  EXPECT_NEAR(s.peak_angle_deg, 0, 1e-9);
  const Spread s90 = spread(t, SpreadPlane::c90_c270);
  EXPECT_NEAR(s90.beam_deg, s.beam_deg, 1e-9);
}

TEST(Metrics, SummaryLightOutputRatioAndEfficacy) {
  Photometry p = sampled([](double, double) { return 100.0; }, Symmetry::rotational, 0, 5);
  p.absolute = false;
  p.lamp_sets = {LampSet{1, "LED", 2000.0, "", "", 20.0}};
  p.input_watts = 25;
  const PhotometricSummary s = summarize(p);
  ASSERT_TRUE(s.light_output_ratio.has_value());
  EXPECT_NEAR(*s.light_output_ratio, 4 * kPi * 100 / 2000, 1e-9);
  EXPECT_NEAR(s.efficacy_lm_per_w, 4 * kPi * 100 / 25, 1e-9);
  p.absolute = true;
  EXPECT_FALSE(summarize(p).light_output_ratio.has_value());
}

namespace {

// The downward fraction by a midpoint rule on a 0.25° × 0.25° (C, gamma) grid through intensity(): the
// reference for the exact split of Types A and B.
double downward_fraction_by_quadrature(const IntensityTable& t) {
  constexpr int nc = 1440, ng = 720;
  double down = 0, all = 0;
  for (int jg = 0; jg < ng; ++jg) {
    const double g = (jg + 0.5) * 180.0 / ng, w = std::sin(g * kDegToRad);
    double ring = 0;
    for (int ic = 0; ic < nc; ++ic) ring += t.intensity(direction_from_angles(PhotometricType::C, (ic + 0.5) * 360.0 / nc, g));
    all += ring * w;
    if (g < 90.0) down += ring * w;
  }
  return down / all;
}

// An IES file of Type A (3) or B (2) with the given horizontal and vertical angles and candela per plane
// from f(H, V).
std::string type_ab_ies(int type, const std::vector<double>& h, const std::vector<double>& v,
                        const std::function<double(double, double)>& f) {
  std::string s = "IESNA:LM-63-2002\n[TEST] lumx\nTILT=NONE\n1 -1 1 " + std::to_string(v.size()) + " " +
                  std::to_string(h.size()) + " " + std::to_string(type) + " 2 0 0 0\n1 1 25\n";
  for (double x : v) s += std::to_string(x) + " ";
  s += "\n";
  for (double x : h) s += std::to_string(x) + " ";
  s += "\n";
  for (double a : h) {
    for (double b : v) s += std::to_string(f(a, b)) + " ";
    s += "\n";
  }
  return s;
}

}  // namespace

TEST(IntensityTable, DownwardFractionOfTypesAAndBIsTheExactHorizontalSplit) {
  // Types A and B have a horizontal polar axis: the lower hemisphere is H in [−90, 90] for every V. The
  // exact split of the interpolant agrees with a fine quadrature of it (whose own error is ~1e-4 here).
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1000.0);
  const std::vector<double> v = {-90, -60, -30, -10, 0, 10, 30, 60, 90};
  const std::vector<std::vector<double>> ranges = {{0, 30, 60, 90}, {-90, -45, 0, 20, 45, 90},
                                                   {-180, -135, -90, -30, 0, 30, 90, 135, 180}};
  for (int type : {2, 3})
    for (const std::vector<double>& h : ranges) {
      std::vector<double> values;
      for (std::size_t i = 0; i < h.size() * v.size(); ++i) values.push_back(u(rng));
      std::size_t next = 0;
      const IntensityTable t(read_ies(type_ab_ies(type, h, v, [&](double, double) { return values[next++]; }), "ab.ies"));
      const double exact = downward_flux_fraction(t), reference = downward_fraction_by_quadrature(t);
      EXPECT_NEAR(exact, reference, 1e-3) << "type " << type << ", " << h.size() << " planes";
      EXPECT_GT(exact, 0.0);
      EXPECT_LE(exact, 1.0);  // planes within H in [−90, 90] only: all of it (zero outside the planes)
    }
  // One plane (no azimuthal variation about the horizontal axis): exactly half goes down.
  const IntensityTable one(read_ies(type_ab_ies(3, {0}, v, [](double, double b) { return 100 + b; }), "one.ies"));
  EXPECT_NEAR(downward_flux_fraction(one), 0.5, 1e-12);
  // Light only towards H in [−60, 60] (zero from |H| = 90 on), V within ±80° (pole rows would be averaged
  // over every H): all of it goes down.
  const IntensityTable down(read_ies(type_ab_ies(2, {-180, -90, -60, 0, 60, 90, 180}, {-80, -40, 0, 40, 80},
                                                 [](double a, double) { return std::abs(a) <= 60 ? 500.0 : 0.0; }),
                                     "down.ies"));
  EXPECT_NEAR(downward_flux_fraction(down), 1.0, 1e-12);
  // The span is capped at one turn, and a bad range gives 0.
  EXPECT_NEAR(down.flux_lm_horizontal(-180, 180), down.flux_lm(), 1e-9 * down.flux_lm());
  EXPECT_NEAR(down.flux_lm_horizontal(-180, 900), down.flux_lm(), 1e-9 * down.flux_lm());
  EXPECT_NEAR(down.flux_lm_horizontal(270, 450), down.flux_lm_horizontal(-90, 90), 1e-9 * down.flux_lm());
  EXPECT_EQ(down.flux_lm_horizontal(10, 10), 0.0);
  EXPECT_EQ(down.flux_lm_horizontal(NAN, 10), 0.0);
}
