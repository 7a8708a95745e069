// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Point sources behind apertures as masked APLs (lumx/apl/point_sources.h, the builder's step 7): found
// where every line passes through a few points and nowhere else, placed at the sources, their masks in
// evaluation, sampling and the bundle, and the bundle's refusals of bad masks.
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/map_fit.h>
#include <lumx/apl/evaluation.h>
#include <lumx/apl/sampling.h>
#include <lumx/io/bundle_io.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "analytic_emitters.h"
#include "apl/error_detail.h"
#include "test_support.h"

#include <algorithm>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>

using namespace lumx;
using namespace lumx_test;

namespace {

PinholeBox two_source_box() { return suite_pinhole_box(); }
const glm::dvec3 kSources[2] = {{-0.02, 0.01, 0.0}, {0.015, -0.01, 0.01}};

double ray_flux(RaySource& rays) {
  RayChunk c;
  double f = 0;
  rays.rewind();
  while (rays.next(c, 1 << 16))
    for (float x : c.flux) f += x;
  return f;
}

void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
}

}  // namespace

TEST(PointSources, TheBoxWithHolesBecomesOneMaskedAplPerSource) {
  const PinholeBox box = two_source_box();
  auto rays = box.source(kSanitized ? 200000 : 1000000, 21);
  AplBuildOptions bo;
  bo.threads = 2;
  AplBuildReport rep;
  const AplSet set = build_apl_set(*rays, bo, &rep);
  ASSERT_EQ(rep.point_sources, 2u) << rep.point_source_note;
  // Levels 1, 8, 64, 256, 512 requested; at most one APL per source: 1 and 2.
  ASSERT_EQ(set.levels.size(), 2u);
  EXPECT_EQ(set.levels[0].size(), 1u);
  ASSERT_EQ(set.levels[1].size(), 2u);
  EXPECT_TRUE(check_apl_set(set).empty());
  // Each finest APL sits on a source: the rays' lines pass the sources to float rounding (10⁻⁸ m here),
  // far below the 70 µm tolerance they were gathered with.
  for (const Apl& a : set.levels[1].apls) {
    const double d = std::min(glm::length(glm::dvec3(a.position) - kSources[0]), glm::length(glm::dvec3(a.position) - kSources[1]));
    EXPECT_LT(d, 1e-6) << "APL at " << a.position.x << ", " << a.position.y << ", " << a.position.z;
    ASSERT_TRUE(a.mask);
    EXPECT_EQ(a.mask->caps().size(), 4u);  // four holes let each source out
    EXPECT_EQ(a.coverage.resolution(), a.map.resolution());
    EXPECT_EQ(a.parent, 0);
  }
  EXPECT_NE(glm::length(set.levels[1].apls[0].position - set.levels[1].apls[1].position), 0.0f);
  // Every ray's flux is in every level (the two sources share the flux about equally).
  const double total = ray_flux(*rays);
  for (const AplLevel& l : set.levels) EXPECT_NEAR(l.flux().x, total, 1e-6 * total);
  // Each APL holds the flux of the rays whose lines pass its source (to 10⁻⁵ m here, independently).
  {
    RayChunk c;
    double through[2] = {0, 0};
    rays->rewind();
    while (rays->next(c, 1 << 16))
      for (std::size_t i = 0; i < c.size(); ++i)
        for (const Apl& apl : set.levels[1].apls) {
          const glm::dvec3 v = glm::dvec3(apl.position) - glm::dvec3(c.position(i)), w(c.direction(i));
          if (glm::length(v - glm::dot(v, w) * w) < 1e-5) through[&apl - &set.levels[1].apls[0]] += c.flux[i];
        }
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(set.levels[1].apls[i].flux.x, through[i], 1e-6 * total);
  }
  // A direction through no hole is dark, one through a hole lit, from the source's own position.
  const Apl& a = set.levels[1].apls[0];
  const bool first_is_0 = glm::length(glm::dvec3(a.position) - kSources[0]) < 1e-6;
  const glm::dvec3 src = first_is_0 ? kSources[0] : kSources[1];
  const glm::dvec3 through_top = glm::normalize(glm::dvec3(-0.01, 0.005, 0.05) - src);  // hole on +z
  const glm::dvec3 into_wall = glm::normalize(glm::dvec3(0.0, 0.05, 0.0) - src);         // +y face: no hole
  EXPECT_GT(intensity(set.levels[1], a, glm::vec3(through_top)).x, 0.0f);
  EXPECT_EQ(intensity(set.levels[1], a, glm::vec3(into_wall)).x, 0.0f);
}

TEST(PointSources, ExtendedEmittersKeepTheClusteredSet) {
  const PlanarEmitter disk{"Lambertian disk r = 0.1 m", PlanarEmitter::Shape::disk, 0.1, 0, 1, 1000};
  auto rays = disk.source(20000, 3);
  AplBuildOptions bo;
  bo.level_counts = {1, 8, 64};
  AplBuildReport rep;
  const AplSet set = build_apl_set(*rays, bo, &rep);
  EXPECT_EQ(rep.point_sources, 0u);
  EXPECT_NE(rep.point_source_note.find("passes none"), std::string::npos) << rep.point_source_note;
  ASSERT_EQ(set.levels.size(), 3u);
  for (const AplLevel& l : set.levels) EXPECT_FALSE(l.has_masks());
  // Off by option: the same set as found none.
  bo.point_sources.enabled = false;
  const AplSet off = build_apl_set(*rays, bo);
  ASSERT_EQ(off.levels.size(), set.levels.size());
  for (std::size_t k = 0; k < set.levels.size(); ++k)
    for (std::size_t i = 0; i < set.levels[k].size(); ++i)
      EXPECT_EQ(off.levels[k].apls[i].map.values(), set.levels[k].apls[i].map.values());
}

TEST(PointSources, AFewStrayLinesLeaveTheClusteredSet) {
  // One ray in 10 000 not through a source (a reflection off the box's edge, say): no point-source set,
  // since its light would have no APL to leave from.
  const PinholeBox box = two_source_box();
  RayChunk c = box.rays(200000, 5);
  for (std::size_t i = 0; i < c.size(); i += 10000) c.x[i] += 0.003f;
  RaysetInfo info;
  info.file = "box with stray rays";
  MemoryRaySource rays(std::move(c), info);
  AplBuildReport rep;
  const AplSet set = build_apl_set(rays, AplBuildOptions{}, &rep);
  EXPECT_EQ(rep.point_sources, 0u);
  EXPECT_FALSE(set.levels.back().has_masks());
}

TEST(PointSources, TheSameSetForAnyThreadCount) {
  const PinholeBox box = two_source_box();
  auto rays = box.source(300000, 8);
  AplBuildOptions one, two;
  one.threads = 1, two.threads = 2;
  one.chunk_rays = 5000;  // other chunks too
  const AplSet a = build_apl_set(*rays, one), b = build_apl_set(*rays, two);
  ASSERT_EQ(a.levels.size(), b.levels.size());
  for (std::size_t k = 0; k < a.levels.size(); ++k)
    for (std::size_t i = 0; i < a.levels[k].size(); ++i) {
      EXPECT_EQ(a.levels[k].apls[i].position, b.levels[k].apls[i].position);
      EXPECT_EQ(a.levels[k].apls[i].map.values(), b.levels[k].apls[i].map.values());
      EXPECT_EQ(a.levels[k].apls[i].coverage.values(), b.levels[k].apls[i].coverage.values());
    }
}

TEST(PointSources, MaskedEmissionSamplesAreUnbiased) {
  // E[sample flux] = ∫ I(ω) dω, the masked intensity's integral, computed here by quadrature over 16 × 16
  // sub-directions per texel of R 32 (no sampling). Each sample's flux is I(ω)/pdf: 0 outside the mask.
  const PinholeBox box = two_source_box();
  auto rays = box.source(400000, 9);
  AplBuildOptions bo;
  bo.map_resolution = 16;
  AplBuildReport rep;
  const AplSet set = build_apl_set(*rays, bo, &rep);
  ASSERT_EQ(set.levels.size(), 2u) << rep.point_source_note;
  const AplLevel& level = set.levels[1];
  double exact = 0;
  const int R = 32, sub = 16;
  const double dw = sphere_map::texel_solid_angle(R) / (sub * sub);
  for (std::size_t i = 0; i < level.size(); ++i)
    for (int y = 0; y < R * sub; ++y)
      for (int x = 0; x < 2 * R * sub; ++x) {
        const glm::vec2 uv((float(x) + 0.5f) / float(2 * R * sub), (float(y) + 0.5f) / float(R * sub));
        const glm::vec3 w = level.frame.world_direction(sphere_map::uv_to_direction(uv));
        exact += double(intensity(level, level.apls[i], glm::normalize(w)).x) * dw;
      }
  AplEmissionSampler sampler(set, 1);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int n = 400000;
  double sum = 0, sum2 = 0;
  int outside = 0;
  for (int s = 0; s < n; ++s) {
    const EmissionSample e = sampler.sample(u(rng), u(rng), u(rng));
    ASSERT_TRUE(e.valid());
    EXPECT_FLOAT_EQ(sampler.pdf(e.apl, e.direction), e.pdf_apl * e.pdf_direction);
    sum += e.flux.x, sum2 += double(e.flux.x) * e.flux.x;
    outside += e.flux.x == 0;
  }
  const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
  std::printf("masked emission: mean sample flux %.3f lm ± %.3f, quadrature %.3f lm, %.1f %% of samples outside the masks; "
              "the maps hold %.3f lm\n", mean, se, exact, 100.0 * outside / n, level.flux().x);
  EXPECT_NEAR(mean, exact, 4 * se);
  // The masked intensity keeps the maps' flux to the coverage's sampling: within 1 % here.
  EXPECT_NEAR(exact, level.flux().x, 0.01 * level.flux().x);
}

TEST(PointSources, MasksRoundTripThroughTheBundle) {
  const PinholeBox box = two_source_box();
  auto rays = box.source(200000, 12);
  AplBuildOptions bo;
  bo.map_resolution = 32;
  const AplSet set = build_apl_set(*rays, bo);
  ASSERT_TRUE(set.levels.back().has_masks());
  const auto dir = fresh_temp_dir("point_sources_bundle");
  write_bundle((dir / "b.lumx").string(), set);
  const std::string manifest = read_text(dir / "b.lumx" / "manifest.json");
  const nlohmann::json doc = nlohmann::json::parse(manifest);
  EXPECT_EQ(doc["format_version"], 3);
  EXPECT_EQ(doc["masks"].size(), 2u);  // the two sources' (level 0's one APL stands for both: plain)
  const BundleReader reader((dir / "b.lumx").string());
  const AplSet back = reader.load();
  ASSERT_EQ(back.levels.size(), set.levels.size());
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (std::size_t k = 0; k < set.levels.size(); ++k) {
    for (std::size_t i = 0; i < set.levels[k].size(); ++i) {
      ASSERT_EQ(bool(back.levels[k].apls[i].mask), bool(set.levels[k].apls[i].mask));
      if (!set.levels[k].apls[i].mask) continue;
      const auto& ca = set.levels[k].apls[i].mask->caps();
      const auto& cb = back.levels[k].apls[i].mask->caps();
      ASSERT_EQ(ca.size(), cb.size());
      for (std::size_t c = 0; c < ca.size(); ++c) EXPECT_EQ(ca[c].hull, cb[c].hull);  // doubles round-trip JSON
      EXPECT_EQ(back.levels[k].apls[i].coverage.values(), set.levels[k].apls[i].coverage.values());
    }
    // The same irradiance at points around the box (maps in half floats: to 2^-11 relative).
    for (int p = 0; p < 200; ++p) {
      const glm::vec3 x = 0.3f * glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
      const double e0 = irradiance(set, k, x, -glm::normalize(x)).irradiance.x;
      const double e1 = irradiance(back, k, x, -glm::normalize(x)).irradiance.x;
      EXPECT_NEAR(e1, e0, 1e-3 * e0 + 1e-9);
    }
  }
  // Partial loading at a coarser resolution recomputes the coverage there.
  const AplLevel coarse = reader.load_level(1, 8);
  EXPECT_EQ(coarse.apls[0].coverage.resolution(), 8);
  EXPECT_TRUE(check_bundle((dir / "b.lumx").string()).empty());
  // A set without masks is still format version 2.
  AplBuildOptions plain = bo;
  plain.point_sources.enabled = false;
  write_bundle((dir / "p.lumx").string(), build_apl_set(*rays, plain));
  EXPECT_EQ(nlohmann::json::parse(read_text(dir / "p.lumx" / "manifest.json"))["format_version"], 2);

  // Bad masks are refused with the JSON pointer of the field and what is wrong.
  const auto refused = [&](const std::function<void(nlohmann::json&)>& edit, const std::string& pointer,
                           const std::string& says) {
    nlohmann::json bad = doc;
    edit(bad);
    write_text(dir / "b.lumx" / "manifest.json", bad.dump(1));
    try {
      BundleReader r((dir / "b.lumx").string());
      ADD_FAILURE() << "accepted: " << pointer << " " << says;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(pointer), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  using J = nlohmann::json;
  refused([](J& j) { j["levels"][1]["mask"][0] = 7; }, "/levels/1/mask/0", "exceeds 1");
  refused([](J& j) { j["format_version"] = 2; }, "/masks", "not part of format version 2");
  refused([](J& j) { j["masks"][0]["caps"][0]["hull"][0] = J::array({1.0, 2.0, 3.0}); }, "/masks/0/caps/0/hull/0",
          "expected 2");
  refused([](J& j) { j["masks"][0]["caps"] = J::array(); }, "/masks/0/caps", "0 caps");
  refused([](J& j) { j["masks"][0]["caps"][0]["axis"] = J::array({2.0, 0.0, 0.0}); }, "/masks/0/caps/0", "orthonormal");
  // A level whose masks' coverage would take more than BundleLimits::max_mask_tests (R 4096).
  refused([](J& j) { j["levels"][1]["map_resolution"] = 4096; }, "/levels/1/mask", "max_mask_tests");
  refused([](J& j) { j["masks"][0]["caps"][0]["extra"] = 1; }, "/masks/0/caps/0", "extra");
  refused([](J& j) { j["masks"][0]["caps"][0]["hull"][1][0] = nullptr; }, "/masks/0/caps/0/hull/1/0", "number");
  refused(
      [](J& j) {
        J& h = j["masks"][0]["caps"][0]["hull"];
        std::reverse(h.begin(), h.end());  // clockwise
      },
      "/masks/0/caps/0", "counter-clockwise");
}

TEST(PointSources, AFittedLevelsCoverageIsWhatItsBundleReadsBack) {
  // downsampled_level (the fit) computes the coverage afresh at the new resolution, as a reader loading
  // the level there does: the graded level and the shipped one agree bit for bit.
  const PinholeBox box = two_source_box();
  auto rays = box.source(200000, 13);
  AplBuildOptions bo;
  bo.map_resolution = 32;
  AplSet set = build_apl_set(*rays, bo);
  ASSERT_TRUE(set.levels.back().has_masks());
  const auto dir = fresh_temp_dir("point_sources_fitted");
  write_bundle((dir / "b.lumx").string(), set);
  const AplLevel fitted = downsampled_level(set.levels[1], 8);
  const AplLevel loaded = BundleReader((dir / "b.lumx").string()).load_level(1, 8);
  for (std::size_t i = 0; i < fitted.size(); ++i) {
    ASSERT_EQ(loaded.apls[i].coverage.resolution(), 8);
    EXPECT_EQ(loaded.apls[i].coverage.values(), fitted.apls[i].coverage.values()) << i;
  }
  EXPECT_TRUE(check_apl_set(set).empty());
}

TEST(PointSources, ContainmentByBisectionIsTheTestOfEveryEdge) {
  // DirectionMask::contains bisects each cap's hull; against the plain test of every edge (the point
  // left of or on each), on random points, points on edges and points next to vertex 0 of a hull.
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<glm::dvec3> dirs;
  for (int j = 0; j < 5000; ++j) dirs.push_back(glm::normalize(glm::dvec3(0.3 * u(rng), 0.2 * u(rng), 1.0)));
  const DirectionMask mask = *DirectionMask::from_directions(dirs);
  ASSERT_EQ(mask.caps().size(), 1u);
  const DirectionMask::Cap& c = mask.caps()[0];
  const auto every_edge = [&](const glm::dvec2& q) {
    const std::size_t n = c.hull.size();
    for (std::size_t i = 0; i < n; ++i) {
      const glm::dvec2 &a = c.hull[i], &b = c.hull[(i + 1) % n];
      if ((b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x) < 0) return false;
    }
    return true;
  };
  const auto direction = [&](const glm::dvec2& q) { return glm::normalize(c.axis + q.x * c.e1 + q.y * c.e2); };
  const auto chart = [&](const glm::dvec3& w) {
    const double z = glm::dot(w, c.axis);
    return glm::dvec2(glm::dot(w, c.e1) / z, glm::dot(w, c.e2) / z);
  };
  int disagree = 0, inside = 0, tried = 0;
  const auto check = [&](const glm::dvec2& q) {
    const glm::dvec3 w = direction(q);
    const bool want = every_edge(chart(w));  // the same chart coordinates contains() computes
    disagree += mask.contains(w) != want;
    inside += want;
    ++tried;
  };
  for (int j = 0; j < 20000; ++j) check({0.4 * u(rng), 0.3 * u(rng)});
  for (std::size_t i = 0; i < c.hull.size(); ++i)
    for (int j = 0; j < 50; ++j) {
      const double t = 0.5 * (u(rng) + 1);
      check(c.hull[i] + t * (c.hull[(i + 1) % c.hull.size()] - c.hull[i]));
    }
  for (int j = 0; j < 2000; ++j) check(c.hull[0] + 1e-9 * glm::dvec2(u(rng), u(rng)));
  EXPECT_EQ(disagree, 0) << "of " << tried << " points, " << inside << " inside";
  EXPECT_GT(inside, 1000);
}

TEST(PointSources, FromCapsRefusesWhatIsNoConvexHull) {
  DirectionMask::Cap c;
  c.hull = {{0, 0}, {0.1, 0}, {0.1, 0.1}, {0, 0.1}};
  EXPECT_NO_THROW(DirectionMask::from_caps({c}));
  DirectionMask::Cap twice = c;  // a pentagram: every turn left, yet twice around
  twice.hull = {{1, 0}, {-0.809, 0.588}, {0.309, -0.951}, {0.309, 0.951}, {-0.809, -0.588}};
  for (auto& p : twice.hull) p *= 0.1;
  EXPECT_THROW(DirectionMask::from_caps({twice}), std::invalid_argument);
  // A limaçon r = 1 + 2 cos t: every turn left and once around its vertices' mean, yet its edges turn
  // twice (an inner loop), so it is no convex hull.
  DirectionMask::Cap limacon = c;
  limacon.hull.clear();
  for (int i = 0; i < 139; ++i) {
    const double t = 2 * kPi * i / 139.0, r = 1 + 2 * std::cos(t);
    limacon.hull.push_back(0.25 * glm::dvec2(r * std::cos(t), r * std::sin(t)) - glm::dvec2(0.3, 0));
  }
  EXPECT_THROW(DirectionMask::from_caps({limacon}), std::invalid_argument);
  DirectionMask::Cap skew = c;
  skew.e1 = glm::dvec3(1, 0.01, 0);
  EXPECT_THROW(DirectionMask::from_caps({skew}), std::invalid_argument);
  DirectionMask::Cap nan = c;
  nan.hull[2].x = NAN;
  EXPECT_THROW(DirectionMask::from_caps({nan}), std::invalid_argument);
  DirectionMask::Cap wide = c;
  for (auto& p : wide.hull) p *= 100.0;  // reaches 1.56 rad from its axis
  EXPECT_THROW(DirectionMask::from_caps({wide}), std::invalid_argument);
  EXPECT_THROW(DirectionMask::from_caps({}), std::invalid_argument);
}

TEST(MaskedReference, APilotTakesTheBordersTheGradedSetsRaysProveLit) {
  // pilot_with_known_borders: the pilot of a held-out evaluation, from a quarter of the rays, joins the
  // masks of the graded set (from the even half) at the same sources. Every direction either mask holds
  // is then lit in the pilot, and nothing else; every even ray's direction is in its set's hull, and
  // some of them lie outside the quarter's.
  const PinholeBox box = two_source_box();
  auto rays = box.source(kSanitized ? 300000 : 1000000, 31);
  AplBuildOptions bo;
  bo.threads = 2;
  AplSet graded, from_quarter;
  {
    RayHalf even(*rays, 0);
    graded = build_apl_set(even, bo);
    RayHalf odd(*rays, 1);
    RayHalf quarter(odd, 0);
    from_quarter = build_apl_set(quarter, bo);
  }
  const AplSet pilot = centring_pilot(from_quarter);
  ASSERT_TRUE(pilot.levels.at(0).has_masks());
  ASSERT_TRUE(graded.levels.back().has_masks());
  const AplSet joined = pilot_with_known_borders(pilot, graded);
  const AplLevel &p = pilot.levels[0], &j = joined.levels[0], &g = graded.levels.back();
  ASSERT_EQ(j.size(), p.size());
  auto nearest = [](const AplLevel& l, const glm::vec3& x) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < l.size(); ++i)
      if (glm::length(l.apls[i].position - x) < glm::length(l.apls[best].position - x)) best = i;
    return best;
  };
  // (A few even rays fall outside their own set's mask: hull vertices, rounded between the float rays and
  // the double hull.)
  std::size_t even_rays = 0, lit_by_graded_only = 0, lost = 0;
  RayHalf even(*rays, 0);
  RayChunk c;
  even.rewind();
  while (even.next(c, 1 << 16))
    for (std::size_t r = 0; r < c.size(); ++r) {
      const glm::dvec3 w(c.direction(r)), start(c.position(r));
      // The source whose line this is: the nearer of the two to the ray's line.
      std::size_t s = 0;
      double best = 1e300;
      for (std::size_t q = 0; q < 2; ++q) {
        const glm::dvec3 v = kSources[q] - start;
        const double d = glm::length(v - glm::dot(v, w) * w);
        if (d < best) best = d, s = q;
      }
      const std::size_t pi = nearest(p, glm::vec3(kSources[s]));
      const bool in_g = g.apls[nearest(g, glm::vec3(kSources[s]))].mask->contains(w);
      ++even_rays;
      lit_by_graded_only += in_g && !p.apls[pi].mask->contains(w);
      lost += in_g && !j.apls[pi].mask->contains(w);
    }
  EXPECT_GT(even_rays, kSanitized ? 15000u : 40000u);
  EXPECT_GT(lit_by_graded_only, 0u);  // the quarter's hulls are short of the even rays' borders
  EXPECT_EQ(lost, 0u);                // joined, none is
  // Random directions: the joined mask is the union of the two, nothing more.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n01;
  std::size_t only_graded = 0;
  for (int t = 0; t < 200000; ++t) {
    glm::dvec3 w(n01(rng), n01(rng), n01(rng));
    w = glm::normalize(w);
    for (std::size_t i = 0; i < p.size(); ++i) {
      const bool in_g = g.apls[nearest(g, p.apls[i].position)].mask->contains(w);
      const bool in_p = p.apls[i].mask->contains(w);
      ASSERT_EQ(j.apls[i].mask->contains(w), in_g || in_p) << t;
      only_graded += in_g && !in_p;
    }
  }
  EXPECT_GT(only_graded, 0u);
  // Coverage computed for the joined mask: never below the pilot's own.
  for (std::size_t i = 0; i < p.size(); ++i) {
    ASSERT_EQ(j.apls[i].coverage.resolution(), p.apls[i].coverage.resolution());
    for (std::size_t t = 0; t < p.apls[i].coverage.values().size(); ++t)
      EXPECT_GE(j.apls[i].coverage.values()[t], p.apls[i].coverage.values()[t]) << i << " " << t;
  }
  // Sources elsewhere join nothing; a pilot without masks is left alone.
  AplSet moved = graded;
  for (AplLevel& l : moved.levels)
    for (Apl& a : l.apls) a.position += glm::vec3(0.01f, 0, 0);
  const AplSet apart = pilot_with_known_borders(pilot, moved);
  for (std::size_t i = 0; i < p.size(); ++i) EXPECT_EQ(apart.levels[0].apls[i].mask, p.apls[i].mask);
  AplBuildOptions plain = bo;
  plain.point_sources.enabled = false;
  RayHalf odd(*rays, 1);
  const AplSet clustered = centring_pilot(build_apl_set(odd, plain));
  ASSERT_FALSE(clustered.levels[0].has_masks());
  const AplSet same = pilot_with_known_borders(clustered, graded);
  EXPECT_EQ(same.levels[0].apls.size(), clustered.levels[0].apls.size());
  EXPECT_FALSE(same.levels[0].has_masks());
}

TEST(MaskedReference, AMaskedPilotScalesAPatchAndItsNoise) {
  // detail::centre_patch: a plain pilot adds P(c) − P̄ (floored at 0); a masked one scales by P(c) / P̄,
  // the variance by its square and the halves alike; a patch a masked pilot leaves dark keeps its mean.
  SphereReference sr;
  sr.irradiance = {2, 2, 2, 1};
  sr.variance = {0.5, 0.5, 0.5, 0.5};
  sr.half_even = {1.5, 1.5, 1.5, 1};
  sr.half_odd = {2.5, 2.5, 2.5, 1};
  SphereReference plain = sr;
  detail::centre_patch(sr, 0, 3.0, 1.5, true);
  EXPECT_DOUBLE_EQ(sr.irradiance[0], 4.0);
  EXPECT_DOUBLE_EQ(sr.variance[0], 2.0);
  EXPECT_DOUBLE_EQ(sr.half_even[0], 3.0);
  EXPECT_DOUBLE_EQ(sr.half_odd[0], 5.0);
  detail::centre_patch(sr, 1, 0.0, 0.7, true);  // the pilot's border misses the centre
  EXPECT_DOUBLE_EQ(sr.irradiance[1], 0.0);
  EXPECT_DOUBLE_EQ(sr.variance[1], 0.0);
  detail::centre_patch(sr, 2, 0.0, 0.0, true);  // dark throughout in the pilot: the mean stays
  EXPECT_DOUBLE_EQ(sr.irradiance[2], 2.0);
  EXPECT_DOUBLE_EQ(sr.variance[2], 0.5);
  detail::refresh_noise_floors(sr);
  const double mean = (4.0 + 0.0 + 2.0 + 1.0) / 4, var = (2.0 + 0.0 + 0.5 + 0.5) / 4;
  EXPECT_DOUBLE_EQ(sr.noise_floor, std::sqrt(var) / mean);
  detail::centre_patch(plain, 0, 3.0, 1.5, false);
  detail::centre_patch(plain, 3, 0.0, 1.5, false);
  EXPECT_DOUBLE_EQ(plain.irradiance[0], 3.5);
  EXPECT_DOUBLE_EQ(plain.variance[0], 0.5);
  EXPECT_DOUBLE_EQ(plain.irradiance[3], 0.0);  // 1 + 0 − 1.5, floored
  EXPECT_DOUBLE_EQ(plain.variance[3], 0.5);
}

TEST(MaskedReference, AHullGainsTheSolidAngleOfItsFan) {
  // detail::cap_gain: the solid angle hull(H ∪ w) adds to a cap's hull H, exactly (spherical triangles),
  // however far w lies and however many edges it sees: the difference of the two hulls' solid angles
  // (DirectionMask::solid_angle).
  DirectionMask::Cap c;  // a square of half-width 0.2 in the chart about +z
  c.hull = {{-0.2, -0.2}, {0.2, -0.2}, {0.2, 0.2}, {-0.2, 0.2}};
  const DirectionMask square = DirectionMask::from_caps({c});
  const std::vector<detail::CapVertices> cv = detail::cap_vertices(square);
  DirectionMaskOptions wide;
  wide.max_half_angle = 1.49;  // w up to 84° from the axis
  auto check = [&](const glm::dvec2& q, std::vector<glm::dvec2> grown_hull) {
    DirectionMask::Cap grown = c;
    grown.hull = std::move(grown_hull);
    const double expected = DirectionMask::from_caps({grown}, wide).solid_angle() - square.solid_angle();
    EXPECT_NEAR(detail::cap_gain(cv[0], glm::normalize(glm::dvec3(q, 1.0))), expected, 1e-9 + 1e-6 * expected)
        << q.x << " " << q.y;
  };
  // Beyond the right edge alone: a pentagon.
  for (double qx : {0.2001, 0.21, 0.5, 3.0, 10.0})
    check({qx, 0.05}, {{-0.2, -0.2}, {0.2, -0.2}, {qx, 0.05}, {0.2, 0.2}, {-0.2, 0.2}});
  // Beyond a corner, seeing two edges: the corner (0.2, 0.2) falls inside the grown hull.
  for (double t : {0.5, 4.0}) check({t, t}, {{-0.2, -0.2}, {0.2, -0.2}, {t, t}, {-0.2, 0.2}});
  // Inside: no edge faces w. Behind the chart: infinite.
  EXPECT_EQ(detail::cap_gain(cv[0], glm::normalize(glm::dvec3(0.1, 0.1, 1.0))), 0.0);
  EXPECT_TRUE(std::isinf(detail::cap_gain(cv[0], glm::dvec3(0, 0, -1))));
}
