// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Analytic checks of lumx/photometry/polar_diagram.h on hand-built photometry.
//
// Interpolation bound used throughout: the curves are sampled from IntensityTable's bilinear interpolant.
// Along a plane that coincides with stored planes (C0, C90, C180, C270 here) the azimuth weight is 0 or 1,
// so the value is the linear interpolant of one stored column in gamma. For a twice-differentiable
// f(gamma) tabulated every h radians, linear interpolation is off by at most h^2/8 * max|f''|
// (the classic bound (x - a)(b - x)/2 * |f''| <= h^2/8 |f''|). For f = I0 cos g, |f''| <= I0; for
// f = I0 cos^3 g, f'' = 6 cos g - 9 cos^3 g, so |f''| <= 3 I0 on [0, 90] degrees.
#include <lumx/photometry/polar_diagram.h>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace {

using lumx::Photometry;
using lumx::PhotometricType;
using lumx::PolarDiagram;
using lumx::Symmetry;

constexpr double kDeg = 3.14159265358979323846 / 180.0;

std::vector<double> angles(double first, double last, double step) {
  std::vector<double> v;
  const int n = static_cast<int>(std::lround((last - first) / step));
  for (int i = 0; i <= n; ++i) v.push_back(first + i * step);
  return v;
}

Photometry make(PhotometricType type, Symmetry sym, std::vector<double> h, std::vector<double> v,
                const std::function<double(double, double)>& f) {
  Photometry p;
  p.type = type;
  p.symmetry = sym;
  p.horizontal_deg = std::move(h);
  p.vertical_deg = std::move(v);
  for (double hh : p.horizontal_deg)
    for (double vv : p.vertical_deg) p.candela.push_back(f(hh, vv));
  p.absolute = true;  // values stay in cd unless a test sets lamp flux
  return p;
}

void set_relative(Photometry& p, std::vector<double> lamp_flux) {
  p.absolute = false;
  p.lamp_sets.clear();
  for (double lm : lamp_flux) {
    lumx::LampSet l;
    l.flux_lm = lm;
    p.lamp_sets.push_back(l);
  }
}

// Value of a curve at a signed angle (must be a sample angle).
double at(const lumx::PolarCurve& c, double theta) {
  for (const auto& pt : c.points)
    if (std::abs(pt.angle_deg - theta) < 1e-9) return pt.value;
  ADD_FAILURE() << "no sample at " << theta;
  return NAN;
}

TEST(PolarDiagram, SamplesEveryHalfDegreeFromMinus180To180) {
  const Photometry p = make(PhotometricType::C, Symmetry::rotational, {0}, angles(0, 180, 10),
                            [](double, double) { return 100.0; });
  const PolarDiagram dg = lumx::make_polar_diagram(p);
  for (const auto* c : {&dg.c0_c180, &dg.c90_c270}) {
    ASSERT_EQ(c->points.size(), 721u);
    for (std::size_t i = 0; i < c->points.size(); ++i)
      EXPECT_DOUBLE_EQ(c->points[i].angle_deg, -180.0 + 0.5 * static_cast<double>(i));
  }
  EXPECT_EQ(dg.c0_c180.plane, lumx::SpreadPlane::c0_c180);
  EXPECT_EQ(dg.c90_c270.plane, lumx::SpreadPlane::c90_c270);
  EXPECT_EQ(dg.c0_c180.positive_side, "C0");
  EXPECT_EQ(dg.c0_c180.negative_side, "C180");
  EXPECT_EQ(dg.c90_c270.positive_side, "C90");
  EXPECT_EQ(dg.c90_c270.negative_side, "C270");
}

TEST(PolarDiagram, IsotropicSourceGivesConstantCurves) {
  // A constant table interpolates to the same constant everywhere (the bilinear weights sum to 1).
  const Photometry p = make(PhotometricType::C, Symmetry::rotational, {0}, angles(0, 180, 10),
                            [](double, double) { return 123.25; });
  const PolarDiagram dg = lumx::make_polar_diagram(p);
  EXPECT_EQ(dg.unit, "cd");
  EXPECT_FALSE(dg.relative);
  EXPECT_EQ(dg.scale, 1.0);
  for (const auto* c : {&dg.c0_c180, &dg.c90_c270}) {
    for (const auto& pt : c->points) EXPECT_NEAR(pt.value, 123.25, 1e-9) << pt.angle_deg;
    EXPECT_NEAR(c->max_value, 123.25, 1e-9);
  }
  // Also when the same source is stored as a full 0..345 table (periodic azimuth interpolation).
  const Photometry full = make(PhotometricType::C, Symmetry::none, angles(0, 345, 15), angles(0, 180, 5),
                               [](double, double) { return 50.0; });
  const PolarDiagram dg2 = lumx::make_polar_diagram(full);
  for (const auto* c : {&dg2.c0_c180, &dg2.c90_c270})
    for (const auto& pt : c->points) EXPECT_NEAR(pt.value, 50.0, 1e-9) << pt.angle_deg;
}

void expect_cosine_downlight(const Photometry& p, double I0, double h_deg) {
  const double tol = I0 * (h_deg * kDeg) * (h_deg * kDeg) / 8.0 + 1e-9;
  const PolarDiagram dg = lumx::make_polar_diagram(p);
  double worst = 0;
  for (const auto* c : {&dg.c0_c180, &dg.c90_c270}) {
    for (const auto& pt : c->points) {
      const double a = std::abs(pt.angle_deg);
      if (a <= 90.0) {
        const double want = I0 * std::cos(a * kDeg);
        EXPECT_NEAR(pt.value, want, tol) << pt.angle_deg;
        worst = std::max(worst, std::abs(pt.value - want));
      } else {
        EXPECT_EQ(pt.value, 0.0) << pt.angle_deg;  // nothing emitted above the horizon
      }
    }
    EXPECT_NEAR(at(*c, 0), I0, 1e-9);  // nadir is a stored value
  }
  // The test is not vacuous: between the 5-degree samples the chord really is below the cosine.
  EXPECT_GT(worst, 0.2 * tol);
}

TEST(PolarDiagram, CosineDownlightStoredToNinetyDegrees) {
  const double I0 = 1000;
  expect_cosine_downlight(make(PhotometricType::C, Symmetry::rotational, {0}, angles(0, 90, 5),
                               [&](double, double g) { return I0 * std::cos(g * kDeg); }),
                          I0, 5);
}

TEST(PolarDiagram, CosineDownlightStoredToOneEightyWithZerosAbove) {
  const double I0 = 1000;
  expect_cosine_downlight(
      make(PhotometricType::C, Symmetry::rotational, {0}, angles(0, 180, 5),
           [&](double, double g) { return g < 90 ? I0 * std::cos(g * kDeg) : 0.0; }),  // as files store it
      I0, 5);
}

TEST(PolarDiagram, QuadrantSymmetricFileGivesEachPlaneItsOwnCurve) {
  // C0: I0 cos g, C90: I0 cos^3 g, in between a blend; both planes agree at nadir (as they must).
  const double I0 = 800, h = 2.5;
  auto f = [&](double c, double g) {
    const double w = std::cos(c * kDeg) * std::cos(c * kDeg);
    const double cg = std::max(0.0, std::cos(g * kDeg));
    return I0 * (w * cg + (1 - w) * cg * cg * cg);
  };
  const Photometry p = make(PhotometricType::C, Symmetry::quadrant, angles(0, 90, 15), angles(0, 90, h), f);
  const PolarDiagram dg = lumx::make_polar_diagram(p);
  const double h2 = (h * kDeg) * (h * kDeg) / 8.0;
  for (const auto& pt : dg.c0_c180.points) {
    const double a = std::abs(pt.angle_deg);
    const double want = a <= 90 ? I0 * std::cos(a * kDeg) : 0.0;
    EXPECT_NEAR(pt.value, want, I0 * h2 + 1e-9) << "C0-C180 at " << pt.angle_deg;
  }
  for (const auto& pt : dg.c90_c270.points) {
    const double a = std::abs(pt.angle_deg);
    const double want = a <= 90 ? I0 * std::pow(std::cos(a * kDeg), 3) : 0.0;
    EXPECT_NEAR(pt.value, want, 3 * I0 * h2 + 1e-9) << "C90-C270 at " << pt.angle_deg;
  }
  // C180 mirrors C0 and C270 mirrors C90 exactly (symmetry expansion copies the stored columns).
  for (double t = 0; t <= 180; t += 0.5) {
    EXPECT_DOUBLE_EQ(at(dg.c0_c180, -t), at(dg.c0_c180, t)) << t;
    EXPECT_DOUBLE_EQ(at(dg.c90_c270, -t), at(dg.c90_c270, t)) << t;
  }
  // The planes really differ: cos 45 = 0.707 against cos^3 45 = 0.354.
  EXPECT_GT(at(dg.c0_c180, 45) - at(dg.c90_c270, 45), 0.3 * I0);
}

TEST(PolarDiagram, PositiveAnglesAreC0AndC90NegativeAreC180AndC270) {
  // No symmetry: C0 is 1.5x, C180 0.5x, C90 1.25x, C270 0.75x a cosine distribution.
  const double I0 = 400;
  auto f = [&](double c, double g) {
    const double k = 1 + 0.5 * std::cos(c * kDeg) + 0.25 * std::sin(c * kDeg);
    return I0 * k * std::max(0.0, std::cos(g * kDeg));
  };
  const Photometry p = make(PhotometricType::C, Symmetry::none, angles(0, 345, 15), angles(0, 90, 5), f);
  const PolarDiagram dg = lumx::make_polar_diagram(p);
  const double tol = 1.5 * I0 * (5 * kDeg) * (5 * kDeg) / 8.0 + 1e-9;
  for (double t : {10.0, 30.0, 60.0}) {  // stored gammas: only the max factor matters
    const double cg = I0 * std::cos(t * kDeg);
    EXPECT_NEAR(at(dg.c0_c180, t), 1.5 * cg, tol) << t;
    EXPECT_NEAR(at(dg.c0_c180, -t), 0.5 * cg, tol) << t;
    EXPECT_NEAR(at(dg.c90_c270, t), 1.25 * cg, tol) << t;
    EXPECT_NEAR(at(dg.c90_c270, -t), 0.75 * cg, tol) << t;
  }
}

TEST(PolarDiagram, TypeBUsesTheSameDirectionSampling) {
  // I = I0 cos V cos H is I0 cos(angle from the photometric zero): both planes are I0 cos(theta).
  // Along V = 0 (the X-Z plane) only H is interpolated, along H = 0 (Y-Z) only V: the same h^2/8 bound.
  const double I0 = 5000, h = 5;
  const Photometry p = make(PhotometricType::B, Symmetry::lateral, angles(0, 90, h), angles(-90, 90, h),
                            [&](double hh, double v) { return I0 * std::cos(hh * kDeg) * std::cos(v * kDeg); });
  const PolarDiagram dg = lumx::make_polar_diagram(p);
  const double tol = I0 * (h * kDeg) * (h * kDeg) / 8.0 + 1e-6;
  for (const auto* c : {&dg.c0_c180, &dg.c90_c270})
    for (const auto& pt : c->points) {
      const double a = std::abs(pt.angle_deg);
      EXPECT_NEAR(pt.value, a <= 90 ? I0 * std::cos(a * kDeg) : 0.0, tol) << pt.angle_deg;
    }
  EXPECT_EQ(dg.c0_c180.name, "V = 0° plane");
  EXPECT_EQ(dg.c90_c270.name, "H = 0° plane");
}

TEST(PolarDiagram, NiceRingStepCoversTheMaximumWithFourToSixRings) {
  auto is_nice = [](double step) {
    const double k = std::floor(std::log10(step) + 1e-12);
    const double m = step / std::pow(10.0, k);
    for (double n : {1.0, 2.0, 2.5, 5.0})
      if (std::abs(m - n) < 1e-9) return true;
    return false;
  };
  for (double e = -3; e <= 7; e += 0.01) {
    const double max = std::pow(10.0, e);
    const lumx::PolarRingScale s = lumx::nice_ring_scale(max);
    EXPECT_TRUE(is_nice(s.ring_step)) << max << " -> " << s.ring_step;
    EXPECT_GE(s.ring_count, 4) << max;
    EXPECT_LE(s.ring_count, 6) << max;
    EXPECT_DOUBLE_EQ(s.outer_radius, s.ring_count * s.ring_step);
    EXPECT_GE(s.outer_radius, max) << max;
    EXPECT_LT((s.ring_count - 1) * s.ring_step, max) << max;  // no empty outer ring
  }
  // Exact multiples take the ring they land on.
  EXPECT_EQ(lumx::nice_ring_scale(1000).ring_step, 200);
  EXPECT_EQ(lumx::nice_ring_scale(1000).ring_count, 5);
  EXPECT_EQ(lumx::nice_ring_scale(600).ring_step, 100);
  EXPECT_EQ(lumx::nice_ring_scale(600).ring_count, 6);
  EXPECT_EQ(lumx::nice_ring_scale(601).ring_step, 200);
  EXPECT_EQ(lumx::nice_ring_scale(601).ring_count, 4);
  EXPECT_EQ(lumx::nice_ring_scale(12.5).ring_step, 2.5);
  // Nothing to show: 4 rings of 1.
  EXPECT_EQ(lumx::nice_ring_scale(0).ring_step, 1);
  EXPECT_EQ(lumx::nice_ring_scale(0).ring_count, 4);
  EXPECT_EQ(lumx::nice_ring_scale(NAN).ring_count, 4);
}

TEST(PolarDiagram, DiagramRingsCoverBothCurves) {
  const Photometry p = make(PhotometricType::C, Symmetry::rotational, {0}, angles(0, 90, 5),
                            [](double, double g) { return 1800 * std::pow(std::cos(g * kDeg), 6); });
  const PolarDiagram dg = lumx::make_polar_diagram(p);
  const double m = std::max(dg.c0_c180.max_value, dg.c90_c270.max_value);
  EXPECT_NEAR(m, 1800, 1e-9);
  EXPECT_GE(dg.rings.outer_radius, lumx::kPolarRingHeadroom * m);
  EXPECT_EQ(dg.rings.ring_step, 500);
  EXPECT_EQ(dg.rings.ring_count, 4);
  EXPECT_EQ(dg.max_cd, 1800);
  EXPECT_EQ(dg.max_vertical_deg, 0);
}

TEST(PolarDiagram, RelativePhotometryIsInCdPerKlmExactly) {
  Photometry p = make(PhotometricType::C, Symmetry::quadrant, angles(0, 90, 30), angles(0, 180, 10),
                      [](double c, double g) { return 300 + 2 * c + std::max(0.0, 700 * std::cos(g * kDeg)); });
  set_relative(p, {1000, 500});  // 1500 lm rated
  lumx::PolarDiagramOptions cd_opts;
  cd_opts.force_cd = true;
  const PolarDiagram rel = lumx::make_polar_diagram(p);
  const PolarDiagram abs = lumx::make_polar_diagram(p, cd_opts);
  EXPECT_TRUE(rel.relative);
  EXPECT_EQ(rel.unit, "cd/klm");
  EXPECT_EQ(rel.scale, 1000.0 / 1500.0);
  EXPECT_FALSE(abs.relative);
  EXPECT_EQ(abs.unit, "cd");
  EXPECT_EQ(abs.scale, 1.0);
  EXPECT_EQ(rel.rated_lamp_flux_lm, 1500);
  for (std::size_t i = 0; i < rel.c0_c180.points.size(); ++i) {
    EXPECT_DOUBLE_EQ(rel.c0_c180.points[i].value, abs.c0_c180.points[i].value * 1000.0 / 1500.0);
    EXPECT_DOUBLE_EQ(rel.c90_c270.points[i].value, abs.c90_c270.points[i].value * 1000.0 / 1500.0);
  }
  EXPECT_DOUBLE_EQ(rel.c0_c180.max_value, abs.c0_c180.max_value * 1000.0 / 1500.0);
  // The stored maximum and the flux stay in cd and lm.
  EXPECT_EQ(rel.max_cd, abs.max_cd);
  EXPECT_EQ(rel.luminaire_flux_lm, abs.luminaire_flux_lm);

  // Absolute photometry is in cd even with a lamp flux on file; so is relative without a lamp flux.
  Photometry a = p;
  a.absolute = true;
  EXPECT_EQ(lumx::make_polar_diagram(a).unit, "cd");
  Photometry z = p;
  set_relative(z, {0});
  EXPECT_EQ(lumx::make_polar_diagram(z).unit, "cd");
}

TEST(PolarDiagram, TitleComesFromTheLuminaireNameElseTheFileName) {
  Photometry p = make(PhotometricType::C, Symmetry::rotational, {0}, angles(0, 90, 45),
                      [](double, double) { return 1.0; });
  p.source.file = "/some/dir/fixture.ies";
  EXPECT_EQ(lumx::make_polar_diagram(p).title, "fixture.ies");
  EXPECT_EQ(lumx::make_polar_diagram(p).file_name, "fixture.ies");
  p.ldt.luminaire_name = "LDT name";
  EXPECT_EQ(lumx::polar_default_title(p), "LDT name");
  p.keywords.push_back({"LUMINAIRE", "  Recessed downlight 3000K\nsecond line"});
  EXPECT_EQ(lumx::polar_default_title(p), "Recessed downlight 3000K");
  Photometry q;
  EXPECT_EQ(lumx::polar_default_title(q), "Photometry");
}

TEST(PolarDiagram, RingLabelsUseTheDecimalsOfTheStep) {
  EXPECT_EQ(lumx::format_ring_value(500, 100), "500");
  EXPECT_EQ(lumx::format_ring_value(7.5, 2.5), "7.5");
  EXPECT_EQ(lumx::format_ring_value(10, 2.5), "10.0");
  EXPECT_EQ(lumx::format_ring_value(0.75, 0.25), "0.75");
  EXPECT_EQ(lumx::format_ring_value(0.002, 0.001), "0.002");
}

TEST(PolarDiagram, UnusableTableIsALumxError) {
  Photometry p;  // no angles at all
  p.source.file = "broken.ies";
  try {
    (void)lumx::make_polar_diagram(p);
    FAIL() << "expected lumx::Error";
  } catch (const lumx::Error& e) {
    EXPECT_EQ(e.diagnostic().field, "intensity table");
    EXPECT_EQ(e.diagnostic().file, "broken.ies");
  }
  lumx::PolarDiagramOptions bad;
  bad.step_deg = 0;
  const Photometry ok = make(PhotometricType::C, Symmetry::rotational, {0}, angles(0, 90, 45),
                             [](double, double) { return 1.0; });
  EXPECT_THROW((void)lumx::make_polar_diagram(ok, bad), lumx::Error);
}

}  // namespace
