// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Checks of lumx/math/direction_mask.h against exact geometry: a point source behind rectangular holes,
// whose lit directions and solid angles are known in closed form. Random inputs come from fixed seeds.
#include <lumx/math/direction_mask.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace lumx;

namespace {

/// A rectangular hole [x0, x1] × [y0, y1] in the plane z = h > 0, seen from the origin.
struct Hole {
  double x0, x1, y0, y1, h;
  bool lets_through(const glm::dvec3& w) const {
    if (w.z <= 0) return false;
    const double t = h / w.z, x = t * w.x, y = t * w.y;
    return x >= x0 && x <= x1 && y >= y0 && y <= y1;
  }
  /// sr, exact: Σ over the corners of ± atan(x·y / (h·√(x² + y² + h²))).
  double solid_angle() const {
    auto f = [&](double x, double y) { return std::atan(x * y / (h * std::sqrt(x * x + y * y + h * h))); };
    return f(x1, y1) - f(x0, y1) - f(x1, y0) + f(x0, y0);
  }
};

glm::dvec3 isotropic(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double z = 1 - 2 * u(rng), r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * kPi * u(rng);
  return {r * std::cos(phi), r * std::sin(phi), z};
}

/// The directions, among `emitted` isotropic ones, that leave through one of the holes.
std::vector<glm::dvec3> rays_through(const std::vector<Hole>& holes, std::size_t emitted, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<glm::dvec3> out;
  for (std::size_t i = 0; i < emitted; ++i) {
    const glm::dvec3 w = isotropic(rng);
    for (const Hole& h : holes)
      if (h.lets_through(w)) {
        out.push_back(w);
        break;
      }
  }
  return out;
}

const Hole kHole{-0.01, 0.03, -0.02, 0.02, 0.03};  // off-centre, 1.159 sr

}  // namespace

TEST(DirectionMask, HullOfTheRaysThroughAHoleApproachesItFromInside) {
  // The hull of points inside a convex region lies inside it: the mask never lights a dark direction.
  // For n points in a k-gon the expected missing area is about (2k/3)·ln n / n of the area (Rényi &
  // Sulanke 1963); the gnomonic chart is a projective image of the hole's plane, which keeps hulls, so the
  // same holds for the solid angle up to the variation over the hole of the rays' density in the chart
  // (cos³ θ about the mean direction: a factor 2.6 here), which the factor 4 below covers.
  const double exact = kHole.solid_angle();
  double last_missing = 1;
  for (const std::size_t emitted : {std::size_t(40000), std::size_t(400000)}) {
    const std::vector<glm::dvec3> w = rays_through({kHole}, emitted, 7);
    std::string why;
    const auto mask = DirectionMask::from_directions(w, {}, &why);
    ASSERT_TRUE(mask) << why;
    ASSERT_EQ(mask->caps().size(), 1u);
    const double missing = (exact - mask->solid_angle()) / exact;
    const double n = double(w.size()), expected = (2.0 * 4 / 3) * std::log(n) / n;
    std::printf("%zu rays through the hole: %.3f of %.3f sr, missing %.2e (Rényi–Sulanke %.2e)\n", w.size(),
                mask->solid_angle(), exact, missing, expected);
    EXPECT_GT(missing, 0);
    EXPECT_LT(missing, 4 * expected);
    EXPECT_LT(missing, last_missing);
    last_missing = missing;
    // Classified directions: none lit that the hole blocks; the unlit lit ones are the missing sliver.
    std::mt19937_64 rng(99);
    std::size_t false_lit = 0, false_dark = 0, lit = 0;
    for (int i = 0; i < 200000; ++i) {
      const glm::dvec3 q = isotropic(rng);
      const bool truth = kHole.lets_through(q), got = mask->contains(q);
      lit += truth;
      false_lit += got && !truth;
      false_dark += truth && !got;
    }
    EXPECT_EQ(false_lit, 0u);
    EXPECT_LE(double(false_dark), 4 * expected * double(lit) + 3) << lit;
  }
}

TEST(DirectionMask, BeamsApartStayApartAndTheGapBetweenThemStaysDark) {
  // Two holes 1 cm apart in one face, 3 cm from the source: the gap is 0.3 rad wide, ten link angles.
  const Hole a{-0.03, -0.005, -0.02, 0.02, 0.03}, b{0.005, 0.03, -0.02, 0.02, 0.03};
  const std::vector<glm::dvec3> w = rays_through({a, b}, 200000, 3);
  const auto mask = DirectionMask::from_directions(w);
  ASSERT_TRUE(mask);
  ASSERT_EQ(mask->caps().size(), 2u);
  EXPECT_FALSE(mask->contains(glm::normalize(glm::dvec3(0, 0, 1))));   // the middle of the gap
  EXPECT_TRUE(mask->contains(glm::normalize(glm::dvec3(-0.015, 0, 0.03))));
  EXPECT_TRUE(mask->contains(glm::normalize(glm::dvec3(0.015, 0, 0.03))));
  const double exact = a.solid_angle() + b.solid_angle();
  EXPECT_LT(mask->solid_angle(), exact);
  EXPECT_GT(mask->solid_angle(), 0.99 * exact);
}

TEST(DirectionMask, CoverageIntegratesToTheMasksSolidAngleInAnyFrame) {
  const std::vector<glm::dvec3> w = rays_through({kHole}, 100000, 5);
  const auto mask = DirectionMask::from_directions(w);
  ASSERT_TRUE(mask);
  // A map frame turned 40° about x: map direction m is mask direction turn · m.
  const double c = std::cos(0.7), s = std::sin(0.7);
  const glm::mat3 turn(glm::vec3(1, 0, 0), glm::vec3(0, float(c), float(s)), glm::vec3(0, float(-s), float(c)));
  for (const glm::mat3& frame : {glm::mat3(1.0f), turn})
    for (const int R : {16, 64}) {
      const SphereMap cov = mask->coverage(R, frame, 4);
      double sum = 0;
      std::size_t partial = 0;
      for (int y = 0; y < R; ++y)
        for (int x = 0; x < 2 * R; ++x) {
          const float f = cov.at(x, y, 0);
          EXPECT_GE(f, 0.0f);
          EXPECT_LE(f, 1.0f);
          sum += f;
          partial += f > 0 && f < 1;
        }
      sum *= cov.texel_solid_angle();
      // 4 × 4 midpoint samples misjudge a straight border's share of a texel by at most a quarter of it.
      const double bound = 0.25 * double(partial) * cov.texel_solid_angle();
      std::printf("R %d: coverage %.4f sr, mask %.4f sr, %zu border texels (bound %.4f sr)\n", R, sum, mask->solid_angle(),
                  partial, bound);
      EXPECT_NEAR(sum, mask->solid_angle(), bound);
      EXPECT_GT(partial, 0u);
      // The texels coverage() skips as far from every cap hold no lit sub-direction: every texel counted
      // without the skip gives the same map, bit for bit.
      std::size_t differ = 0;
      for (int y = 0; y < R; ++y)
        for (int x = 0; x < 2 * R; ++x) {
          int lit = 0;
          for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
              const glm::vec2 uv((float(x) + (float(i) + 0.5f) / 4.0f) / float(2 * R), (float(y) + (float(j) + 0.5f) / 4.0f) / float(R));
              lit += mask->contains(glm::normalize(glm::dvec3(frame * sphere_map::uv_to_direction(uv))));
            }
          differ += cov.at(x, y, 0) != float(lit) * (1.0f / 16);
        }
      EXPECT_EQ(differ, 0u);
    }
}

TEST(DirectionMask, NormalisedLookupKeepsABeamsIntensityUpToItsBorder) {
  // An isotropic source of 1 000 lm behind the hole, its rays binned on an R 16 map (cd, whole-texel flux
  // over the texel's solid angle). Inside the mask the normalised lookup reads the source's intensity
  // 1000 / 4π to within the rays' noise everywhere, border included; the plain bilinear lookup falls to
  // about half at the border.
  const std::size_t emitted = 1000000;
  const std::vector<glm::dvec3> w = rays_through({kHole}, emitted, 11);
  const auto mask = DirectionMask::from_directions(w);
  ASSERT_TRUE(mask);
  const int R = 16;
  SphereMap map(R, 1);
  const double per_ray = 1000.0 / double(emitted), omega = map.texel_solid_angle();
  for (const glm::dvec3& d : w) {
    int x, y;
    map.texel_of(glm::vec3(d), x, y);
    map.at(x, y, 0) += float(per_ray / omega);
  }
  const SphereMap cov = mask->coverage(R, glm::mat3(1.0f), 8);
  const double intensity = 1000 / (4 * kPi);
  // Rays a lit texel holds: its solid angle over 4π of 10⁶; a bilinear value averages about four texels.
  const double rays_per_texel = omega / (4 * kPi) * double(emitted), noise = 1 / std::sqrt(rays_per_texel);
  std::mt19937_64 rng(17);
  double sq_norm = 0, sq_plain = 0, near_border_norm = 0, near_border_plain = 0;
  std::size_t inside = 0, near_border = 0;
  for (int i = 0; i < 400000; ++i) {
    const glm::dvec3 q = isotropic(rng);
    if (!mask->contains(q)) {
      EXPECT_EQ(mask->normalised_lookup(map, cov, glm::vec3(q), q).x, 0.0f);
      continue;
    }
    const double got = mask->normalised_lookup(map, cov, glm::vec3(q), q).x / intensity - 1;
    const double plain = map.lookup(glm::vec3(q)).x / intensity - 1;
    sq_norm += got * got, sq_plain += plain * plain, ++inside;
    if (cov.lookup(glm::vec3(q)).x < 0.75f) near_border_norm += got * got, near_border_plain += plain * plain, ++near_border;
  }
  const double rms = std::sqrt(sq_norm / double(inside)), rms_plain = std::sqrt(sq_plain / double(inside));
  const double border = std::sqrt(near_border_norm / double(near_border)),
               border_plain = std::sqrt(near_border_plain / double(near_border));
  std::printf("inside the mask: normalised %.4f, plain %.4f; near the border (%zu of %zu): %.4f, %.4f; one texel's noise %.4f\n",
              rms, rms_plain, near_border, inside, border, border_plain, noise);
  EXPECT_LT(rms, 1.5 * noise);
  EXPECT_LT(border, 2.5 * noise);
  EXPECT_GT(border_plain, 10 * border);
}

TEST(DirectionMask, RefusesWhatItCannotHoldAndNamesBadDirections) {
  std::mt19937_64 rng(1);
  std::vector<glm::dvec3> all;
  for (int i = 0; i < 50000; ++i) all.push_back(isotropic(rng));  // 0.016 rad apart: linked
  std::string why;
  EXPECT_FALSE(DirectionMask::from_directions(all, {}, &why));  // one group round the whole sphere
  EXPECT_NE(why.find("reaches"), std::string::npos) << why;
  std::vector<glm::dvec3> few(all.begin(), all.begin() + 10);
  EXPECT_FALSE(DirectionMask::from_directions(few, {}, &why));  // ten scattered directions: no beam
  EXPECT_NE(why.find("no group"), std::string::npos) << why;
  why.clear();
  EXPECT_FALSE(DirectionMask::from_directions({}, {}, &why));
  EXPECT_NE(why.find("no group"), std::string::npos) << why;
  std::vector<glm::dvec3> bad = rays_through({kHole}, 2000, 2);
  bad[3] = glm::dvec3(std::nan(""), 0, 1);
  try {
    (void)DirectionMask::from_directions(bad);
    ADD_FAILURE() << "a NaN direction was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("direction 3 "), std::string::npos) << e.what();
  }
  bad[3] = glm::dvec3(0, 0, 2);
  EXPECT_THROW((void)DirectionMask::from_directions(bad), std::invalid_argument);
  DirectionMaskOptions o;
  o.link_angle = 0;
  EXPECT_THROW((void)DirectionMask::from_directions(rays_through({kHole}, 2000, 2), o), std::invalid_argument);
  // 180 rays over 1.16 sr are 0.08 rad apart, beyond the link: scattered groups, no beam.
  why.clear();
  EXPECT_FALSE(DirectionMask::from_directions(rays_through({kHole}, 2000, 2), {}, &why));
  EXPECT_NE(why.find("no group"), std::string::npos) << why;
  const auto mask = DirectionMask::from_directions(rays_through({kHole}, 20000, 2));
  ASSERT_TRUE(mask);
  EXPECT_THROW((void)mask->coverage(8, glm::mat3(1.0f), 0), std::invalid_argument);
  // A coverage of another resolution than the map's is refused, not read out of bounds.
  EXPECT_THROW((void)mask->normalised_lookup(SphereMap(16, 1), mask->coverage(8, glm::mat3(1.0f)), glm::vec3(0, 0, 1),
                                             glm::dvec3(0, 0, 1)),
               std::invalid_argument);
  EXPECT_THROW((void)mask->normalised_lookup(SphereMap(16, 1), SphereMap(), glm::vec3(0, 0, 1), glm::dvec3(0, 0, 1)),
               std::invalid_argument);
}

TEST(DirectionMask, TheSameDirectionsGiveTheSameMaskAndTheGroupsIgnoreOrder) {
  const Hole a{-0.03, -0.005, -0.02, 0.02, 0.03}, b{0.005, 0.03, -0.02, 0.02, 0.03};
  std::vector<glm::dvec3> w = rays_through({a, b}, 50000, 9);
  const auto m1 = DirectionMask::from_directions(w), m2 = DirectionMask::from_directions(w);
  ASSERT_TRUE(m1 && m2);
  ASSERT_EQ(m1->caps().size(), m2->caps().size());
  for (std::size_t i = 0; i < m1->caps().size(); ++i) {
    ASSERT_EQ(m1->caps()[i].hull.size(), m2->caps()[i].hull.size());
    for (std::size_t j = 0; j < m1->caps()[i].hull.size(); ++j) EXPECT_EQ(m1->caps()[i].hull[j], m2->caps()[i].hull[j]);
  }
  // Reversed, the groups are the same (in reverse order: a group's place is its smallest index), so each
  // cap holds the same directions: the same solid angle, and the same verdict on every direction.
  std::reverse(w.begin(), w.end());
  const auto m3 = DirectionMask::from_directions(w);
  ASSERT_TRUE(m3);
  ASSERT_EQ(m3->caps().size(), 2u);
  ASSERT_EQ(m1->caps().size(), 2u);
  EXPECT_NEAR(m1->solid_angle(), m3->solid_angle(), 1e-9);
  std::mt19937_64 rng(5);
  std::size_t disagree = 0;
  for (int i = 0; i < 100000; ++i) {
    const glm::dvec3 q = isotropic(rng);
    disagree += m1->contains(q) != m3->contains(q);
  }
  EXPECT_EQ(disagree, 0u);
}
