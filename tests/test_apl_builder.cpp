// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Clustering seeds into a tree (eq. 4.1, PLOC) and building APL sets from raysets: tree invariants,
// quality against exact greedy merging, nested cuts, flux conservation, hard cases (one point, duplicate
// positions, fewer rays than APLs, zero-flux rays, flux spanning 10^6) and determinism.
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/far_field.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/rays/far_field.h>
#include <lumx/io/bundle_io.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "test_support.h"

using namespace lumx;
namespace fs = std::filesystem;

namespace {

void random_seeds(std::size_t n, unsigned seed, std::vector<glm::vec3>& p, std::vector<float>& f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  p.resize(n);
  f.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    p[i] = {u(rng), u(rng), 0.3f * u(rng)};
    f[i] = 0.5f + u(rng);
  }
}

/// Σ merge costs over the tree: the quantity greedy agglomeration minimises step by step.
double total_cost(const ClusterTree& t) {
  double s = 0;
  for (double c : t.cost) s += c;
  return s;
}

/// Exact greedy agglomeration (always merge the globally cheapest pair), O(n³): the reference.
double greedy_total_cost(const std::vector<glm::vec3>& p, const std::vector<float>& f) {
  struct C {
    glm::vec3 lo, hi;
    double flux;
  };
  std::vector<C> cs;
  for (std::size_t i = 0; i < p.size(); ++i) cs.push_back({p[i], p[i], f[i]});
  double total = 0;
  while (cs.size() > 1) {
    double best = INFINITY;
    std::size_t bi = 0, bj = 1;
    for (std::size_t i = 0; i < cs.size(); ++i)
      for (std::size_t j = i + 1; j < cs.size(); ++j) {
        const double c = detail::merge_cost(cs[i].lo, cs[i].hi, cs[i].flux, cs[j].lo, cs[j].hi, cs[j].flux);
        if (c < best) best = c, bi = i, bj = j;
      }
    total += best;
    cs[bi] = {glm::min(cs[bi].lo, cs[bj].lo), glm::max(cs[bi].hi, cs[bj].hi), cs[bi].flux + cs[bj].flux};
    cs.erase(cs.begin() + std::ptrdiff_t(bj));
  }
  return total;
}

/// Rays from `emitters` points (each a tiny disc of radius 1 mm), each emitter with its own flux and a
/// downward cos^m lobe (m = `lobe`); `per_emitter` rays each, all with equal flux within an emitter.
MemoryRaySource emitter_rays(int emitters, int per_emitter, unsigned seed, double spread_m = 0.2, int lobe = 2) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  RayChunk rays;
  for (int e = 0; e < emitters; ++e) {
    const float angle = float(2 * kPi) * float(e) / float(emitters);
    const glm::vec3 centre(float(spread_m) * std::cos(angle), float(spread_m) * std::sin(angle), 0.0f);
    const float emitter_flux = 10.0f * float(e + 1);
    for (int r = 0; r < per_emitter; ++r) {
      const float rho = 0.001f * std::sqrt(u(rng)), phi = float(2 * kPi) * u(rng);
      const glm::vec3 p = centre + glm::vec3(rho * std::cos(phi), rho * std::sin(phi), 0.0f);
      // I ∝ cos^m θ: cos θ has the density ∝ c^m on [0, 1], drawn as u^(1/(m+1)).
      const float cos_t = std::pow(u(rng), 1.0f / float(lobe + 1)), sin_t = std::sqrt(1 - cos_t * cos_t), az = float(2 * kPi) * u(rng);
      rays.push_back(p, {sin_t * std::cos(az), sin_t * std::sin(az), -cos_t}, emitter_flux / float(per_emitter));
    }
  }
  RaysetInfo info;
  info.file = "synthetic";
  info.format = "memory";
  return MemoryRaySource(std::move(rays), info);
}

double ray_flux(RaySource& s) {
  s.rewind();
  RayChunk c;
  double sum = 0;
  while (s.next(c, 4096))
    for (float f : c.flux) sum += f;
  return sum;
}

}  // namespace

TEST(ClusterTree, InvariantsHold) {
  std::vector<glm::vec3> p;
  std::vector<float> f;
  random_seeds(5000, 1, p, f);
  const ClusterTree t = build_cluster_tree(p, f);
  ASSERT_EQ(t.size(), 2 * p.size() - 1);
  double flux = 0;
  for (float v : f) flux += v;
  EXPECT_NEAR(t.flux[std::size_t(t.root)], flux, 1e-9 * flux);
  EXPECT_EQ(t.seeds[std::size_t(t.root)], p.size());
  EXPECT_EQ(t.parent[std::size_t(t.root)], -1);
  for (std::size_t n = 0; n < t.size(); ++n) {
    if (int(n) != t.root) {
      ASSERT_GE(t.parent[n], 0) << n;
      const std::size_t q = std::size_t(t.parent[n]);
      ASSERT_TRUE(t.left[q] == int(n) || t.right[q] == int(n));
      // A parent's box holds its child's, and eq. 4.1 never decreases going up the tree.
      ASSERT_TRUE(glm::all(glm::lessThanEqual(t.lo[q], t.lo[n])) && glm::all(glm::greaterThanEqual(t.hi[q], t.hi[n])));
      ASSERT_GE(t.cost[q], t.cost[n]);
    }
    if (!t.is_seed(int(n))) {
      ASSERT_NEAR(t.flux[n], t.flux[std::size_t(t.left[n])] + t.flux[std::size_t(t.right[n])], 1e-9 * flux);
    }
  }
}

TEST(ClusterTree, QualityIsCloseToExactGreedyMerging) {
  for (unsigned seed : {2u, 3u, 4u}) {
    std::vector<glm::vec3> p;
    std::vector<float> f;
    random_seeds(250, seed, p, f);
    const double ploc = total_cost(build_cluster_tree(p, f));
    const double greedy = greedy_total_cost(p, f);
    // Greedy is not optimal either, but it is the method eq. 4.1 was designed for; PLOC with r = 16
    // stays within a few per cent of it (Meister & Bittner report 1–3 % for SAH).
    std::cout << "seed " << seed << ": PLOC / greedy total eq. 4.1 cost = " << ploc / greedy << "\n";
    EXPECT_LT(ploc, 1.10 * greedy) << "seed " << seed;
    EXPECT_GT(ploc, 0.90 * greedy) << "seed " << seed;
  }
}

TEST(ClusterTree, CutsAreNestedAndHaveTheRequestedSizes) {
  std::vector<glm::vec3> p;
  std::vector<float> f;
  random_seeds(3000, 5, p, f);
  const ClusterTree t = build_cluster_tree(p, f);
  const auto cuts = cut_cluster_tree(t, {1, 8, 64, 256, 512});
  ASSERT_EQ(cuts.size(), 5u);
  const std::size_t sizes[] = {1, 8, 64, 256, 512};
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_EQ(cuts[k].size(), sizes[k]);
    double flux = 0;
    for (int n : cuts[k]) flux += t.flux[std::size_t(n)];
    EXPECT_NEAR(flux, t.flux[std::size_t(t.root)], 1e-9 * flux);  // a cut covers every seed once
    if (k == 0) continue;
    for (int n : cuts[k]) {  // exactly one ancestor (or itself) in the coarser cut
      int hits = 0;
      for (int a = n; a >= 0; a = t.parent[std::size_t(a)])
        hits += int(std::count(cuts[k - 1].begin(), cuts[k - 1].end(), a));
      EXPECT_EQ(hits, 1);
    }
  }
}

TEST(ClusterTree, DegenerateSeedsStillGiveATree) {
  // Every seed at one point (a far-field rayset): all costs are 0, ties are broken by the pair hash.
  std::vector<glm::vec3> p(10000, glm::vec3(0.0f));
  std::vector<float> f(10000, 1.0f);
  const ClusterTree t = build_cluster_tree(p, f);
  EXPECT_EQ(t.seeds[std::size_t(t.root)], 10000u);
  EXPECT_EQ(cut_cluster_tree(t, {512})[0].size(), 512u);
  // One seed; fewer seeds than clusters requested.
  const ClusterTree one = build_cluster_tree({glm::vec3(1.0f)}, {2.0f});
  EXPECT_EQ(one.root, 0);
  const auto cuts = cut_cluster_tree(build_cluster_tree(std::vector<glm::vec3>(5, glm::vec3(0.5f)), std::vector<float>(5, 1.0f)),
                                     {1, 8});
  EXPECT_EQ(cuts[1].size(), 5u);
  EXPECT_THROW(build_cluster_tree({glm::vec3(NAN)}, {1.0f}), std::invalid_argument);
  EXPECT_THROW(build_cluster_tree({}, {}), std::invalid_argument);
}

TEST(AplBuilder, MapResolutionRule) {
  AplBuildOptions o;  // 8 rays per texel over the level's rays (n^0), R in [4, 128]
  EXPECT_EQ(map_resolution_for(100, 1, o), 4);                     // too few rays: the minimum
  EXPECT_EQ(map_resolution_for(8 * 2 * 64 * 64, 1, o), 64);        // exactly 8 rays per texel at R = 64
  EXPECT_EQ(map_resolution_for(8 * 2 * 64 * 64 - 1, 1, o), 32);
  EXPECT_EQ(map_resolution_for(8 * 2 * 64 * 64, 512, o), 64);      // the level's budget: n does not enter
  EXPECT_EQ(map_resolution_for(1e12, 1, o), 128);                  // the maximum
  o.apl_exponent = 0.5;                                            // geometric mean of level and APL budgets
  EXPECT_EQ(map_resolution_for(4 * 8 * 2 * 32 * 32, 16, o), 32);   // √16 = 4 APLs' worth of budget
  EXPECT_EQ(map_resolution_for(4 * 8 * 2 * 32 * 32 - 1, 16, o), 16);
  o.apl_exponent = 1;                                              // one APL's budget
  EXPECT_EQ(map_resolution_for(64 * 8 * 2 * 16 * 16, 64, o), 16);
  // The measured 100 k-ray LED, 1, 8, 64, 256, 512 APLs: 64 everywhere by default; 64, 32, 16, 16, 16 with
  // the geometric mean; 64, 16, 8, 4, 4 per APL.
  const double apls[] = {1, 8, 64, 256, 512};
  const int level[] = {64, 64, 64, 64, 64}, mean[] = {64, 32, 16, 16, 16}, per_apl[] = {64, 16, 8, 4, 4};
  for (int i = 0; i < 5; ++i) {
    o.apl_exponent = 0;
    EXPECT_EQ(map_resolution_for(1e5, apls[i], o), level[i]) << apls[i];
    o.apl_exponent = 0.5;
    EXPECT_EQ(map_resolution_for(1e5, apls[i], o), mean[i]) << apls[i];
    o.apl_exponent = 1;
    EXPECT_EQ(map_resolution_for(1e5, apls[i], o), per_apl[i]) << apls[i];
  }
}

TEST(AplBuilder, EmittersBecomeApls) {
  MemoryRaySource rays = emitter_rays(8, 4000, 7);
  AplBuildOptions o;
  o.level_counts = {1, 8, 64};
  AplBuildReport report;
  const AplSet set = build_apl_set(rays, o, &report);
  ASSERT_EQ(set.levels.size(), 3u);
  EXPECT_TRUE(check_apl_set(set).empty());
  const double flux = ray_flux(rays);
  for (const AplLevel& l : set.levels) EXPECT_NEAR(l.flux().x, flux, 1e-9 * flux);
  // Level 8: one APL per emitter, at the emitter (within its 1 mm disc) with its flux.
  for (const Apl& a : set.levels[1].apls) {
    const float angle = std::atan2(a.position.y, a.position.x);
    const int e = int(std::lround(std::fmod(angle + 2 * kPi, 2 * kPi) / (2 * kPi) * 8)) % 8;
    EXPECT_NEAR(glm::length(glm::vec2(a.position)), 0.2f, 0.002f);
    EXPECT_NEAR(a.flux.x, 10.0 * (e + 1), 1e-6 * flux) << "emitter " << e;
    // Its map is the emitter's cos² lobe: all light goes down. The maps are drawn turned (MapFrame), so
    // "down" is each texel's photometric direction, and a texel the horizon cuts (centre within half a
    // texel diagonal of it) may hold light on either side.
    const SphereMap& m = a.map;
    const float margin = std::sqrt(float(m.texel_solid_angle()));
    double down = 0;
    for (int y = 0; y < m.height(); ++y)
      for (int x = 0; x < m.width(); ++x) {
        const glm::vec3 w = set.levels[1].frame.world_direction(
            sphere_map::uv_to_direction({(float(x) + 0.5f) / float(m.width()), (float(y) + 0.5f) / float(m.height())}));
        if (w.z < margin) down += m.at(x, y, 0);
      }
    EXPECT_NEAR(down * m.texel_solid_angle(), a.flux.x, 1e-6 * a.flux.x);
  }
  EXPECT_EQ(report.rays, 32000u);
  EXPECT_EQ(report.seeds, 32000u);
  // Resolution by the rule: 32 000 rays over 1, 8, 64 APLs at 8 rays per texel.
  EXPECT_EQ(report.map_resolution[0], map_resolution_for(32000.0, 1, o));
  EXPECT_EQ(report.map_resolution[2], map_resolution_for(32000.0, 64, o));
}

TEST(AplBuilder, HardCases) {
  AplBuildOptions o;
  o.level_counts = {1, 8, 64};
  {  // every ray from one point: a far-field rayset
    RayChunk c;
    std::mt19937 rng(1);
    std::normal_distribution<float> g;
    for (int i = 0; i < 5000; ++i) c.push_back(glm::vec3(0.0f), glm::normalize(glm::vec3(g(rng), g(rng), g(rng))), 1.0f);
    MemoryRaySource s(std::move(c), RaysetInfo{});
    const AplSet set = build_apl_set(s, o);
    EXPECT_TRUE(check_apl_set(set).empty());
    for (const Apl& a : set.levels.back().apls) EXPECT_EQ(a.position, glm::vec3(0.0f));
    EXPECT_EQ(set.bounds.radius, 0.0);
    EXPECT_NEAR(set.levels[0].flux().x, 5000.0, 1e-6);
  }
  {  // fewer rays than APLs requested, zero-flux rays, flux spanning 10^6
    RayChunk c;
    for (int i = 0; i < 5; ++i) c.push_back({0.1f * float(i), 0.0f, 0.0f}, {0, 0, -1}, std::pow(10.0f, -float(i) * 1.5f));
    c.push_back({1, 1, 1}, {0, 0, -1}, 0.0f);
    MemoryRaySource s(std::move(c), RaysetInfo{});
    AplBuildReport r;
    const AplSet set = build_apl_set(s, o, &r);
    ASSERT_EQ(set.levels.size(), 2u);  // 1 and 5 APLs: level 64 would repeat level 5
    EXPECT_EQ(set.levels[1].size(), 5u);
    EXPECT_EQ(r.zero_flux_rays, 1u);
    EXPECT_TRUE(check_apl_set(set).empty());
    const double flux = ray_flux(s);  // the float fluxes 1, 10^-1.5, ..., 10^-6 summed in double
    EXPECT_NEAR(set.levels[0].flux().x, flux, 1e-9 * flux);  // fixed point: 2^-40 of the largest ray
    EXPECT_NEAR(set.levels[1].apls[4].flux.x + set.levels[1].apls[0].flux.x, 1 + 1e-6, 1e-9);  // the smallest survives
  }
  {  // duplicate positions
    RayChunk c;
    for (int i = 0; i < 1000; ++i) c.push_back({float(i % 3), 0.0f, 0.0f}, {0, 0, -1}, 1.0f);
    MemoryRaySource s(std::move(c), RaysetInfo{});
    const AplSet set = build_apl_set(s, o);
    EXPECT_TRUE(check_apl_set(set).empty());
  }
  {  // a ray with a NaN direction is refused with its index
    RayChunk c;
    c.push_back({0, 0, 0}, {0, 0, -1}, 1.0f);
    c.push_back({0, 0, 0}, {NAN, 0, 0}, 1.0f);
    MemoryRaySource s(std::move(c), RaysetInfo{});
    try {
      build_apl_set(s, o);
      ADD_FAILURE() << "no error";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("ray 1"), std::string::npos) << e.what();
    }
  }
}

TEST(AplBuilder, SameInputGivesByteIdenticalBundles) {
  const fs::path root = fs::temp_directory_path() / ("lumx_builder_" + std::to_string(::getpid()));
  fs::remove_all(root);
  fs::create_directories(root);
  std::vector<std::string> manifests;
  for (int run = 0; run < 4; ++run) {
    MemoryRaySource rays = emitter_rays(16, 2000, 9);
    AplBuildOptions o;
    o.level_counts = {1, 8, 64};
    o.chunk_rays = run % 2 == 0 ? 65536 : 5000;  // arrival in different chunkings must not matter,
    o.threads = run % 2 == 0 ? 1 : 2;            // nor the thread count,
    o.map_smoothing_rays = run < 2 ? 0 : 4;      // with the smoothing too
    const fs::path dir = root / ("b" + std::to_string(run) + ".lumx");
    write_bundle(dir.string(), build_apl_set(rays, o));
    manifests.push_back(lumx_test::read_text(dir / "manifest.json"));
  }
  EXPECT_EQ(manifests[0], manifests[1]);  // the manifest holds every payload's SHA-256
  EXPECT_EQ(manifests[2], manifests[3]);
  EXPECT_NE(manifests[0], manifests[2]);  // the smoothing did change the maps
  fs::remove_all(root);
}

TEST(AplBuilder, MapsAreTurnedSoTheBeamLiesInsideAWedge) {
  // Downward cos^20 beams: the flux-weighted mean direction is nadir, which the photometric frame puts at
  // the lower square's centre, where the concentric map's four wedges meet. The builder turns it onto
  // map_frame_target() (mid-wedge), the same frame for every level.
  MemoryRaySource rays = emitter_rays(8, 4000, 7, 0.2, 20);
  glm::dvec3 mean(0.0);
  rays.rewind();
  RayChunk c;
  while (rays.next(c, 4096))
    for (std::size_t i = 0; i < c.size(); ++i) mean += double(c.flux[i]) * glm::dvec3(c.direction(i));
  AplBuildOptions o;
  o.level_counts = {1, 8, 64};
  const AplSet set = build_apl_set(rays, o);
  ASSERT_TRUE(check_apl_set(set).empty());
  const glm::vec3 turned = set.levels[0].frame.map_direction(glm::vec3(glm::normalize(mean)));
  EXPECT_GT(glm::dot(turned, map_frame_target()), 1.0f - 1e-6f);
  EXPECT_LT(glm::length(glm::normalize(mean) - glm::dvec3(0, 0, -1)), 0.02);  // the lobes' mean is nadir
  for (const AplLevel& l : set.levels) EXPECT_TRUE(l.frame.to_map == set.levels[0].frame.to_map);
  // The maps hold the rays' far field in photometric directions: the first and second moments of the
  // level-0 map, summed over texels at their centres' photometric directions, match the rays' own, as
  // they do for the same rays binned in the photometric frame. A texel centre is off its rays by at most
  // half a texel diagonal (R 32: 3.2°), and a smooth moment's error is second order in that offset,
  // ~0.3 % of the flux; 1 % allows for it.
  double total = 0, zz = 0;
  rays.rewind();
  while (rays.next(c, 4096))
    for (std::size_t i = 0; i < c.size(); ++i) {
      total += c.flux[i];
      zz += double(c.flux[i]) * double(c.direction(i).z) * double(c.direction(i).z);
    }
  o.orient_maps = false;
  const AplSet plain = build_apl_set(rays, o);
  EXPECT_TRUE(plain.levels[0].frame.is_identity());
  for (const AplSet* s : {&set, &plain}) {
    const AplLevel& l = s->levels[0];
    const SphereMap& m = l.apls[0].map;
    glm::dvec3 first(0.0);
    double second = 0;
    for (int y = 0; y < m.height(); ++y)
      for (int x = 0; x < m.width(); ++x) {
        const glm::dvec3 w(l.frame.world_direction(
            sphere_map::uv_to_direction({(float(x) + 0.5f) / float(m.width()), (float(y) + 0.5f) / float(m.height())})));
        first += double(m.at(x, y, 0)) * m.texel_solid_angle() * w;
        second += double(m.at(x, y, 0)) * m.texel_solid_angle() * w.z * w.z;
      }
    EXPECT_LT(glm::length(first - mean), 0.01 * total) << (s == &set ? "turned" : "photometric");
    EXPECT_NEAR(second, zz, 0.01 * total) << (s == &set ? "turned" : "photometric");
  }
  // Broader light (mean resultant below kMinMapFrameResultant) keeps the photometric frame: light spread
  // evenly, and the cos² lobes (mean resultant 3/4) whose horizon the photometric frame keeps on the map's
  // equator.
  std::mt19937 rng(4);
  std::normal_distribution<float> g;
  RayChunk even;
  for (int i = 0; i < 20000; ++i) even.push_back({0, 0, 0}, glm::normalize(glm::vec3(g(rng), g(rng), g(rng))), 1.0f);
  MemoryRaySource even_rays(std::move(even), RaysetInfo{});
  o.orient_maps = true;
  o.level_counts = {1, 8};
  EXPECT_TRUE(build_apl_set(even_rays, o).levels[0].frame.is_identity());
  MemoryRaySource broad = emitter_rays(8, 4000, 7);
  EXPECT_TRUE(build_apl_set(broad, o).levels[0].frame.is_identity());
}

TEST(RayFarField, MatchesTheAnalyticLobeAndLevelOne) {
  // 1 M rays from a small disc, directions ∝ cos³ about nadir: I(γ) = Φ · 4/(2π) · cos³γ (lower half).
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  RayChunk c;
  const int n = 1000000;
  const float per_ray = 1000.0f / float(n);
  for (int i = 0; i < n; ++i) {
    const float cos_t = std::pow(u(rng), 0.25f), sin_t = std::sqrt(1 - cos_t * cos_t), az = float(2 * kPi) * u(rng);
    c.push_back({0.01f * u(rng), 0.01f * u(rng), 0.0f}, {sin_t * std::cos(az), sin_t * std::sin(az), -cos_t}, per_ray);
  }
  MemoryRaySource rays(std::move(c), RaysetInfo{});
  FarFieldGrid grid;
  grid.c_step_deg = 10;
  grid.gamma_step_deg = 5;
  const Photometry p = far_field_from_rays(rays, grid);
  const IntensityTable table(p);
  EXPECT_NEAR(table.flux_lm(), 1000.0, 5.0);  // 0.5 %: the bilinear table of a smooth lobe
  // Every vertex away from the poles: within 5σ of the cell's Poisson noise (plus 2 % for the curvature
  // of cos³ across a 5° cell).
  for (std::size_t ih = 0; ih + 1 < p.horizontal_deg.size(); ++ih)
    for (std::size_t iv = 1; iv + 1 < p.vertical_deg.size(); ++iv) {
      const double g = p.vertical_deg[iv] * kDegToRad;
      const double expected = g < kPi / 2 ? 1000.0 * 4 / (2 * kPi) * std::pow(std::cos(g), 3) : 0.0;
      const double omega = (std::cos(g - 2.5 * kDegToRad) - std::cos(g + 2.5 * kDegToRad)) * 10 * kDegToRad;
      const double sigma = std::sqrt(std::max(expected * omega / per_ray, 1.0)) * per_ray / omega;
      ASSERT_NEAR(p.at(ih, iv), expected, 5 * sigma + 0.02 * expected) << "C " << p.horizontal_deg[ih] << " γ " << p.vertical_deg[iv];
    }
  // Level 1 of the APL set built from the same rays has the same far field (its map is the rays'
  // histogram at the resolution the rule gives): compare flux and the peak region.
  AplBuildOptions o;
  o.level_counts = {1, 8};
  const AplSet set = build_apl_set(rays, o);
  const Photometry from_apl = far_field_photometry(set, 0, grid);
  EXPECT_NEAR(IntensityTable(from_apl).flux_lm(), table.flux_lm(), 0.01 * table.flux_lm());
  const glm::dvec3 down(0, 0, -1), slanted = glm::normalize(glm::dvec3(0.5, 0.0, -1.0));
  EXPECT_NEAR(IntensityTable(from_apl).intensity(slanted), table.intensity(slanted), 0.03 * table.max_cd());
  EXPECT_NEAR(IntensityTable(from_apl).intensity(down), table.intensity(down), 0.05 * table.max_cd());
}

TEST(AplBuilder, ConvergencePlacementFindsAnEnclosedEmitter) {
  // Rays from a point emitter at the origin, recorded where they cross two caps at z = ±0.02 m (a
  // cylinder of radius 0.01 m): the top cap sees the upward rays, the bottom cap the downward ones. APLs
  // on the caps misplace the light; at the rays' convergence point they do not.
  std::mt19937 rng(31);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  RayChunk c;
  while (c.size() < 200000) {
    const float z = 2 * u(rng) - 1, phi = float(2 * kPi) * u(rng), s = std::sqrt(1 - z * z);
    const glm::vec3 w(s * std::cos(phi), s * std::sin(phi), z);
    if (std::abs(z) < 0.9f) continue;  // only rays that leave through a cap
    const float t = 0.02f / std::abs(z);
    c.push_back(t * w, w, 1.0f);
  }
  MemoryRaySource rays(std::move(c), RaysetInfo{});
  AplBuildOptions o;
  o.level_counts = {1, 8};
  o.map_resolution = 32;
  AplErrorOptions eo;
  eo.relative_distances = {1, 10};
  eo.min_timing_seconds = 0;
  // Patch centres on the maps' texel corners (the lookup returns texel means there), so the comparison
  // sees placement alone, not the R 32 maps' interpolation error.
  eo.rotated_patches = false;
  o.place_at_convergence = false;  // the dissertation's rule: APLs at their seeds' box centres
  const AplErrorReport on_caps = evaluate_apl_errors(build_apl_set(rays, o), rays, eo);
  o.place_at_convergence = true;
  // Every line passes through the origin, and the rays leave it in two cones: a point source behind
  // two apertures, which step 7 builds as one masked APL there (apl/point_sources.h).
  {
    AplBuildReport found;
    const AplSet point = build_apl_set(rays, o, &found);
    EXPECT_EQ(found.point_sources, 1u) << found.point_source_note;
    ASSERT_EQ(point.levels.size(), 1u);
    ASSERT_EQ(point.levels[0].size(), 1u);
    EXPECT_LT(glm::length(point.levels[0].apls[0].position), 1e-6f);
    ASSERT_TRUE(point.levels[0].apls[0].mask);
    EXPECT_EQ(point.levels[0].apls[0].mask->caps().size(), 2u);
  }
  o.point_sources.enabled = false;  // step 6's placement, which this test is about
  AplBuildReport report;
  const AplSet moved = build_apl_set(rays, o, &report);
  EXPECT_EQ(report.moved_to_convergence, 9u);
  EXPECT_FALSE(report.slid_to_convergence);  // every line meets in one point: clustering by line degenerates
  for (const Apl& a : moved.levels[1].apls) EXPECT_LT(glm::length(a.position), 1e-3f);  // the emitter
  EXPECT_TRUE(check_apl_set(moved).empty());
  const AplErrorReport converged = evaluate_apl_errors(moved, rays, eo);
  for (std::size_t s = 0; s < 2; ++s) {
    EXPECT_LT(converged.levels[1].errors[s].relative_rmse, 0.5 * on_caps.levels[1].errors[s].relative_rmse) << s;
    EXPECT_LT(converged.levels[1].errors[s].relative_rmse, 2 * converged.reference.sphere[s].noise_floor) << s;
  }
}

TEST(LineFit, NearestPointEigenSolveAndShiftSums) {
  // Lines through (1, 2, 3) in four directions: the nearest point is (1, 2, 3), at distance 0.
  const glm::vec3 c(1, 2, 3);
  LineFit fit;
  const glm::vec3 dirs[] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, glm::normalize(glm::vec3(1, 1, 1))};
  for (int i = 0; i < 4; ++i) fit.add(c + float(i + 1) * dirs[i], dirs[i], 1.0f + float(i));
  const glm::dvec3 x = fit.solve(glm::dvec3(0.0), 1e-6);
  EXPECT_NEAR(glm::length(x - glm::dvec3(c)), 0.0, 1e-5);
  EXPECT_NEAR(fit.mean_line_distance2(x), 0.0, 1e-9);
  // Start points at distances 1, 2, 3, 4 with weights 1..4: Σ w d² / Σ w = (1 + 8 + 27 + 64) / 10.
  EXPECT_NEAR(fit.mean_start_distance2(glm::dvec3(c)), 10.0, 1e-4);
  // A point off the lines: its mean squared distance across them, by hand for the axis lines.
  LineFit axis;
  axis.add({0, 0, 0}, {0, 0, 1}, 2.0f);
  EXPECT_NEAR(axis.mean_line_distance2({3, 4, 7}), 25.0, 1e-9);
  // Parallel lines (a beam) do not fix the coordinate along them: it comes from the anchor; across the
  // beam the lines decide (their mean, 0.5, 0), whatever the anchor says.
  LineFit beam;
  beam.add({0, 0, 5}, {0, 0, 1}, 1.0f);
  beam.add({0, 1, -2}, {0, 0, 1}, 1.0f);
  const glm::dvec3 y = beam.solve({9, 9, 0.25}, 1e-3);
  EXPECT_NEAR(y.x, 0.0, 1e-9);
  EXPECT_NEAR(y.y, 0.5, 1e-9);
  EXPECT_NEAR(y.z, 0.25, 1e-9);
  // Merging fits with different origins equals adding the lines to one fit.
  LineFit a, b, both;
  std::mt19937 rng(3);
  std::normal_distribution<float> g;
  for (int i = 0; i < 200; ++i) {
    const glm::vec3 p(100 + g(rng), -50 + g(rng), g(rng)), w = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
    (i < 100 ? a : b).add(p, w, 1.0f + float(i % 7));
    both.add(p, w, 1.0f + float(i % 7));
  }
  a.add(b);
  const glm::dvec3 q(101, -49, 0.5);
  EXPECT_NEAR(a.mean_line_distance2(q), both.mean_line_distance2(q), 1e-9 * both.mean_line_distance2(q));
  EXPECT_NEAR(a.mean_start_distance2(q), both.mean_start_distance2(q), 1e-9 * both.mean_start_distance2(q));
  EXPECT_NEAR(glm::length(a.solve(q, 1e-6) - both.solve(q, 1e-6)), 0.0, 1e-9);
  // Eigen-decomposition: M V = V diag(λ).
  const glm::dmat3 M(4, 1, 0.5, 1, 3, -0.25, 0.5, -0.25, 1);
  glm::dvec3 l;
  glm::dmat3 V;
  LineFit::symmetric_eigen(M, l, V);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(glm::length(M * V[i] - l[i] * V[i]), 0.0, 1e-12);
  // Bad rays are left out.
  LineFit bad;
  bad.add({0, 0, 0}, {0, 0, 2}, 1.0f);
  bad.add({NAN, 0, 0}, {0, 0, 1}, 1.0f);
  bad.add({0, 0, 0}, {0, 0, 1}, -1.0f);
  EXPECT_EQ(bad.weight, 0.0);
}

TEST(AplBuilder, SmoothingKeepsEveryAplsFluxAndReducesItsNoise) {
  MemoryRaySource rays = emitter_rays(8, 3000, 17);
  AplBuildOptions o;
  o.level_counts = {1, 8, 64};
  o.map_resolution = 32;  // 2·32² = 2048 texels for 375 rays per APL at 8 APLs: sparse
  const AplSet raw = build_apl_set(rays, o);
  o.map_smoothing_rays = 16;
  const AplSet smooth = build_apl_set(rays, o);
  ASSERT_EQ(raw.levels.size(), smooth.levels.size());
  EXPECT_TRUE(check_apl_set(smooth).empty());
  for (std::size_t k = 0; k < raw.levels.size(); ++k)
    for (std::size_t a = 0; a < raw.levels[k].size(); ++a) {
      const Apl &r = raw.levels[k].apls[a], &s = smooth.levels[k].apls[a];
      EXPECT_EQ(r.flux.x, s.flux.x);  // from the same fixed-point sums
      EXPECT_NEAR(s.map.integral().x, s.flux.x, 1e-5 * s.flux.x) << k << " " << a;  // the map keeps it
      EXPECT_EQ(glm::length(r.position - s.position), 0.0f);
    }
  // Noise: the 8-APL maps are each one emitter's cos² lobe (I ∝ cos² θ below, 0 above), 3000 rays over
  // 2048 texels. Smoothed with 16 rays per child, their texels are closer to it than the raw histogram's
  // (relative RMS over all texels).
  auto rms_error = [](const SphereMap& m, const MapFrame& frame, double flux) {
    double se = 0, st = 0;
    for (int y = 0; y < m.height(); ++y)
      for (int x = 0; x < m.width(); ++x) {
        const glm::vec3 w = frame.world_direction(
            sphere_map::uv_to_direction({(float(x) + 0.5f) / float(m.width()), (float(y) + 0.5f) / float(m.height())}));
        const double truth = w.z < 0 ? flux * 3.0 / (2.0 * kPi) * double(w.z) * double(w.z) : 0.0;  // ∫ = flux
        se += (m.at(x, y, 0) - truth) * (m.at(x, y, 0) - truth);
        st += truth * truth;
      }
    return std::sqrt(se / st);
  };
  double raw_err = 0, smooth_err = 0;
  for (std::size_t a = 0; a < 8; ++a) {
    raw_err += rms_error(raw.levels[1].apls[a].map, raw.levels[1].frame, raw.levels[1].apls[a].flux.x);
    smooth_err += rms_error(smooth.levels[1].apls[a].map, smooth.levels[1].frame, smooth.levels[1].apls[a].flux.x);
  }
  // Measured: 0.44 raw, 0.24 smoothed (≈ 1/√16 per reliable child, plus the prior's bias).
  EXPECT_LT(smooth_err, 0.65 * raw_err) << raw_err / 8 << " " << smooth_err / 8;
  EXPECT_THROW(([&] {
                 AplBuildOptions bad = o;
                 bad.map_resolution = 24;  // not a power of two
                 build_apl_set(rays, bad);
               }()),
               std::invalid_argument);
}

namespace {

/// `n` rays from a ball of radius `source_m` at `centre` (uniform in volume, isotropic), recorded where
/// they leave a sphere of radius `record_m` about `centre`; `source_m` = 0 is a point source.
MemoryRaySource enclosed_rays(int n, double source_m, double record_m, glm::dvec3 centre, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  RayChunk c;
  for (int i = 0; i < n; ++i) {
    glm::dvec3 q(g(rng), g(rng), g(rng));
    q = glm::normalize(q) * source_m * std::cbrt(u(rng));
    const glm::dvec3 w = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
    // Exit of q + t w from the sphere |x| = record_m: t = −q·w + √((q·w)² − |q|² + r²).
    const double b = glm::dot(q, w), t = -b + std::sqrt(b * b - glm::dot(q, q) + record_m * record_m);
    c.push_back(glm::vec3(centre + q + t * w), glm::vec3(w), 1.0f);
  }
  return MemoryRaySource(std::move(c), RaysetInfo{});
}

}  // namespace

TEST(AplBuilder, ClustersByLineOnlyWhenTheLinesMeet) {
  AplBuildOptions o;
  o.level_counts = {1, 8, 64};
  o.map_resolution = 16;
  {  // a 2 mm source recorded on a 20 mm sphere: by line, and no APL left without light
    MemoryRaySource rays = enclosed_rays(60000, 0.002, 0.02, {0.3, 0.2, 0.1}, 1);
    AplBuildReport r1, r2;
    o.threads = 1;
    const AplSet a = build_apl_set(rays, o, &r1);
    o.threads = 2;
    o.chunk_rays = 7000;
    const AplSet b = build_apl_set(rays, o, &r2);
    EXPECT_TRUE(r1.slid_to_convergence);
    EXPECT_LT(r1.line_convergence, 0.5 * r1.line_convergence_shuffled);
    for (const Apl& apl : a.levels.back().apls) EXPECT_GT(apl.flux.x, 0.0);
    // Every APL ends up near the source (within its 2 mm), not on the recording sphere.
    for (const Apl& apl : a.levels.back().apls) EXPECT_LT(glm::length(glm::dvec3(apl.position) - glm::dvec3(0.3, 0.2, 0.1)), 0.004);
    // Deterministic on this path too: 1 and 2 threads, different chunks, the same set.
    ASSERT_EQ(a.levels.size(), b.levels.size());
    for (std::size_t k = 0; k < a.levels.size(); ++k)
      for (std::size_t i = 0; i < a.levels[k].size(); ++i) {
        EXPECT_EQ(a.levels[k].apls[i].position, b.levels[k].apls[i].position);
        EXPECT_EQ(a.levels[k].apls[i].map.values(), b.levels[k].apls[i].map.values());
      }
    o.threads = 1;
    o.chunk_rays = 1 << 16;
  }
  {  // an ideal point source away from the origin: its lines meet in one point, so start points
    MemoryRaySource rays = enclosed_rays(60000, 0.0, 0.05, {0.3, 0.2, 0.1}, 2);
    AplBuildReport r;
    const AplSet set = build_apl_set(rays, o, &r);
    EXPECT_FALSE(r.slid_to_convergence);
    for (const Apl& apl : set.levels.back().apls) EXPECT_GT(apl.flux.x, 0.0);
    for (const Apl& apl : set.levels.back().apls) EXPECT_LT(glm::length(glm::dvec3(apl.position) - glm::dvec3(0.3, 0.2, 0.1)), 1e-4);
  }
  {  // flat emitters whose directions do not depend on position (uniform hemisphere and batwing, wider
     // than Lambertian): start points, whatever their plain ratio says
    for (int batwing = 0; batwing < 2; ++batwing) {
      std::mt19937 rng(3 + unsigned(batwing));
      std::uniform_real_distribution<float> u(0.0f, 1.0f);
      RayChunk c;
      while (c.size() < 60000) {
        const float ct = u(rng), st = std::sqrt(1 - ct * ct), az = float(2 * kPi) * u(rng);
        if (batwing && u(rng) > st * st) continue;  // ∝ sin²θ on top of uniform
        c.push_back({0.1f * u(rng) - 0.05f, 0.1f * u(rng) - 0.05f, 0.0f}, {st * std::cos(az), st * std::sin(az), -ct}, 1.0f);
      }
      MemoryRaySource rays(std::move(c), RaysetInfo{});
      AplBuildReport r;
      build_apl_set(rays, o, &r);
      EXPECT_FALSE(r.slid_to_convergence) << batwing << " " << r.line_convergence << " " << r.line_convergence_shuffled;
      EXPECT_LT(r.line_convergence, 0.85) << batwing;  // the plain ratio alone would have let them slide
      EXPECT_NEAR(r.line_convergence / r.line_convergence_shuffled, 1.0, 0.02) << batwing;
    }
  }
  {  // separate emitters: start points (their lines do not meet), unless lines are forced
    MemoryRaySource rays = emitter_rays(8, 3000, 5);
    AplBuildReport r;
    build_apl_set(rays, o, &r);
    EXPECT_FALSE(r.slid_to_convergence);
    o.line_clustering = AplBuildOptions::LineClustering::lines;
    build_apl_set(rays, o, &r);
    EXPECT_TRUE(r.slid_to_convergence);
  }
  {  // and an enclosed source clusters by start point when that is forced
    MemoryRaySource rays = enclosed_rays(20000, 0.002, 0.02, {0, 0, 0}, 4);
    o.line_clustering = AplBuildOptions::LineClustering::start_points;
    AplBuildReport r;
    build_apl_set(rays, o, &r);
    EXPECT_FALSE(r.slid_to_convergence);
  }
}

TEST(AplBuilder, MillionsOfRaysInOneTexelDoNotOverflow) {
  // Rays of equal flux in one direction from one point: all of them × the largest flux in one texel, past
  // the 2^23 that a fixed 2^-40 unit would allow in 64 bits. Rays are generated chunk by chunk. Release
  // build: 10⁸ rays of 1e-8 lm sum to 1 lm within 1e-6 (hard-cases.md §6 item 39); sanitizer build (ten
  // times slower): 9 M rays of 0.5 lm.
#if defined(__SANITIZE_ADDRESS__)
  const std::uint64_t count = 9000000;
  const float ray_flux = 0.5f;
#else
  const std::uint64_t count = 100000000;
  const float ray_flux = 1e-8f;
#endif
  struct Beam : RaySource {
    RaysetInfo info_;
    std::uint64_t n, at = 0;
    float f;
    Beam(std::uint64_t count_, float flux_) : n(count_), f(flux_) { info_.ray_count = n; }
    const RaysetInfo& info() const override { return info_; }
    bool next(RayChunk& out, std::size_t max_rays) override {
      out.clear();
      for (; at < n && out.size() < max_rays; ++at) out.push_back({0, 0, 0}, {0, 0, -1}, f);
      return !out.empty();
    }
    void rewind() override { at = 0; }
  } beam(count, ray_flux);
  AplBuildOptions o;
  o.level_counts = {1};
  o.seed_rays = 1000;
  o.map_resolution = 8;
  const AplSet set = build_apl_set(beam, o);
  EXPECT_TRUE(check_apl_set(set).empty());
  const double total = double(count) * double(ray_flux);  // the float flux of each ray, summed exactly
  EXPECT_NEAR(set.levels[0].apls[0].flux.x, total, 1e-9 * total);
  EXPECT_NEAR(set.levels[0].apls[0].map.integral().x, total, 1e-6 * total);
}

TEST(LineFit, ANearlyParallelBundleTakesItsAxisCoordinateFromTheAnchor) {
  // Lines within 0.003 rad of +z through points near the z axis: the mean projector's eigenvalue along
  // z is ~1e-5. Below the threshold (1e-3) the z coordinate is the anchor's; with a threshold below the
  // eigenvalue the lines decide it (their waist, near z = 0).
  LineFit fit;
  std::mt19937 rng(8);
  std::normal_distribution<float> g;
  for (int i = 0; i < 1000; ++i) {
    const glm::vec3 w = glm::normalize(glm::vec3(0.003f * g(rng), 0.003f * g(rng), 1.0f));
    const glm::vec3 p = glm::vec3(0.001f * g(rng), 0.001f * g(rng), 0.0f) + 0.5f * g(rng) * w;
    fit.add(p, w, 1.0f);
  }
  glm::dvec3 l;
  glm::dmat3 V;
  LineFit::symmetric_eigen(fit.A / fit.weight, l, V);
  EXPECT_LT(std::min({l.x, l.y, l.z}), 1e-4);
  EXPECT_GT(std::min({l.x, l.y, l.z}), 1e-6);
  const glm::dvec3 anchored = fit.solve({0, 0, 7}, 1e-3);
  EXPECT_NEAR(anchored.z, 7.0, 1e-6);
  EXPECT_NEAR(anchored.x, 0.0, 1e-3);
  const glm::dvec3 free = fit.solve({0, 0, 7}, 1e-7);
  EXPECT_LT(std::abs(free.z), 0.5);
}
