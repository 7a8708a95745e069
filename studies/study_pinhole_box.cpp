// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Studies of the box with holes (tests/analytic_emitters.h, PinholeBox: two isotropic point sources inside
// a cube with four square holes), the figures of docs/apl_sets.md, "Honest error" (the box with holes,
// what maps can do on the box, beam masks, and the held-out estimate of the masked level). Every error is
// the relative RMSE (eq. 5.1) against the exact irradiance at the same points of each measurement sphere
// (the patch centres), in percent. The CSV columns are described in studies/study_support.h.
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/evaluation.h>
#include <lumx/math/direction_mask.h>
#include <lumx/math/sphere_map.h>

#include "honest_error_support.h"
#include "study_support.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

using namespace lumx;
using namespace lumx_test;
using lumx_study::cell;
using lumx_study::StudyArgs;
using lumx_study::StudyCsv;

namespace {

/// The box's two sources (PinholeBox of suite_pinhole_box), m.
const std::vector<glm::dvec3> kSources = {{-0.02, 0.01, 0.0}, {0.015, -0.01, 0.01}};

/// m: the distance from point c to the line through o along unit w (double: the tolerances reach 10⁻⁷ m,
/// below a float's resolution of these coordinates).
double distance_to_line(const glm::dvec3& c, const glm::dvec3& o, const glm::dvec3& w) {
  const glm::dvec3 v = c - o;
  return glm::length(v - glm::dot(v, w) * w);
}

// borders: the finest level's point error with plain maps (no kernel, no fit, point sources off: the
// clustered set) at R 64, 128 and 256, from 1 M and from 10 M emitted rays, every level of 2, 8 and 512
// APLs. From 1 M rays R 64 alone, the resolution the rule gives them. --quick: 1 M rays only.
// Keys: emitted_rays, leaving_rays, R, apls; quantity relative_rmse_pct per d.
void borders(const StudyArgs& args, std::FILE* out) {
  StudyCsv csv(out, {"emitted_rays", "leaving_rays", "R", "apls"});
  const std::unique_ptr<AnalyticEmitter> em = suite_emitter(4);
  const AplErrorOptions eo;
  std::vector<std::uint64_t> ray_counts = {1000000};
  if (!args.quick) ray_counts.push_back(10000000);
  for (const std::uint64_t n : ray_counts) {
    auto rays = em->source(n, 15);
    for (const int R : {64, 128, 256}) {
      AplBuildOptions bo;
      bo.threads = 2;
      bo.map_resolution = R;
      bo.max_resolution = R;
      bo.level_counts = {2, 8, 512};
      bo.point_sources.enabled = false;
      const AplSet set = build_apl_set(*rays, bo);
      const MeasurementSpheres ms(set.bounds, eo);
      const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
      const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
      for (std::size_t k = 0; k < set.levels.size(); ++k) {
        const std::vector<std::string> key = {cell(n), cell(rays->info().ray_count), cell(R),
                                              cell(set.levels[k].size())};
        for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
          const std::vector<double> model = level_at_points(set, k, ms, s, dirs);
          csv.put(key, "relative_rmse_pct", ms.relative_distances()[s],
                  100 * compare_irradiance(exact.at_centre[s], model).relative_rmse);
        }
      }
      if (n == 1000000) break;
    }
  }
}

// exact-beams: the representation's own floor on the box. Two APLs placed exactly at the two sources,
// each map the exact intensity of its source averaged over every texel (4 × 4 equal-area sub-directions
// per texel; no rays, so no noise), read bilinearly as a renderer reads them, at R 64 … 1024, and the
// same maps read at the nearest texel. The measurement spheres are those of the set the builder makes
// from the suite's rays (seed 15). --quick: R 64 and 128 only.
// Keys: R, reading (bilinear, nearest). Quantities per d: relative_rmse_pct; for bilinear also
// carrier_points (the fewest points whose squared errors make 90 % of the sum), lit_points and
// lit_mean_over_mean (the lit points' mean irradiance over the sphere's mean). Per R: points (per sphere).
void exact_beams(const StudyArgs& args, std::FILE* out) {
  StudyCsv csv(out, {"R", "reading"});
  const PinholeBox box = pinhole_box();
  const std::unique_ptr<AnalyticEmitter> em = suite_emitter(4);
  const AplErrorOptions eo;
  AplBuildOptions bo;
  bo.threads = 2;
  bo.level_counts = {2};
  const AplSet built = build_apl_set(*em->source(kSuiteRays, 15), bo);
  const MeasurementSpheres ms(built.bounds, eo);
  const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
  const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
  const std::vector<PinholeBox::Source> sources = {{kSources[0], 500}, {kSources[1], 500}};
  std::vector<int> resolutions = {64, 128};
  if (!args.quick) resolutions.insert(resolutions.end(), {256, 512, 1024});
  for (const int R : resolutions) {
    AplSet set;
    set.bounds = built.bounds;
    set.levels.resize(1);
    set.levels[0].map_resolution = R;
    for (const PinholeBox::Source& s : sources) {
      // One source alone behind the same holes: visible in w iff its far irradiance along w is non-zero.
      const PinholeBox one("one source", 0.05, box.holes(), {s});
      Apl a;
      a.position = glm::vec3(s.p);
      a.map = SphereMap(R, 1);
      constexpr int kSub = 4;
      for (int y = 0; y < R; ++y)
        for (int x = 0; x < 2 * R; ++x) {
          int lit = 0;
          for (int j = 0; j < kSub; ++j)
            for (int i = 0; i < kSub; ++i) {
              const glm::vec2 uv((float(x) + (float(i) + 0.5f) / kSub) / float(2 * R),
                                 (float(y) + (float(j) + 0.5f) / kSub) / float(R));
              const glm::dvec3 w = glm::normalize(glm::dvec3(sphere_map::uv_to_direction(uv)));
              lit += one.irradiance(s.p + 100.0 * w, -w) > 0;
            }
          a.map.at(x, y, 0) = float(s.flux / (4 * kPi) * lit / (kSub * kSub));
        }
      a.flux = a.map.integral();
      set.levels[0].apls.push_back(std::move(a));
    }
    const std::vector<std::string> bilinear = {cell(R), "bilinear"}, nearest = {cell(R), "nearest"};
    csv.put(bilinear, "points", double(dirs.size()));
    for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
      const double d = ms.relative_distances()[s];
      const std::vector<double> model = level_at_points(set, 0, ms, s, dirs);
      csv.put(bilinear, "relative_rmse_pct", d, 100 * compare_irradiance(exact.at_centre[s], model).relative_rmse);
      std::vector<double> sq(dirs.size());
      double total = 0, lit_sum = 0, all_sum = 0;
      std::size_t lit = 0;
      for (std::size_t p = 0; p < dirs.size(); ++p) {
        sq[p] = (model[p] - exact.at_centre[s][p]) * (model[p] - exact.at_centre[s][p]);
        total += sq[p];
        all_sum += exact.at_centre[s][p];
        if (exact.at_centre[s][p] > 0) lit_sum += exact.at_centre[s][p], ++lit;
      }
      std::sort(sq.begin(), sq.end(), std::greater<double>());
      std::size_t carriers = 0;
      for (double acc = 0; carriers < sq.size() && acc < 0.9 * total; ++carriers) acc += sq[carriers];
      csv.put(bilinear, "carrier_points", d, double(carriers));
      csv.put(bilinear, "lit_points", d, double(lit));
      csv.put(bilinear, "lit_mean_over_mean", d, (lit_sum / double(lit)) / (all_sum / double(dirs.size())));
    }
    // The same maps read at the nearest texel (a staircase border instead of a one-texel ramp).
    for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
      std::vector<double> model(dirs.size(), 0.0);
      for (std::size_t p = 0; p < dirs.size(); ++p) {
        const glm::dvec3 x = ms.centre() + ms.radius(s) * dirs[p];
        for (const Apl& a : set.levels[0].apls) {
          const glm::dvec3 d = x - glm::dvec3(a.position);
          const double r = glm::length(d);
          const glm::dvec3 w = d / r;
          const double cosine = glm::dot(dirs[p], w);
          if (cosine > 0) model[p] += a.map.lookup_nearest(glm::vec3(w)).x * cosine / (r * r);
        }
      }
      csv.put(nearest, "relative_rmse_pct", ms.relative_distances()[s],
              100 * compare_irradiance(exact.at_centre[s], model).relative_rmse);
    }
  }
}

// beam-masks: borders as geometry. Each APL's map read inside a DirectionMask (lumx/math/direction_mask.h),
// the hull of the directions of every ray whose line passes through the APL's position, normalised by the
// mask's coverage of its texels, at R 16, 32 and 64, on the suite's rays (seed 15). Three sets:
//   two_at_sources      two APLs at the two sources, maps binned from the rays (no kernel), plain and
//                       masked;
//   builder_512         the builder's 512-APL level with plain maps (point sources off), each APL masked by
//                       the lines through it within 1/1000 of the bounding radius when at least 500 pass;
//   builder_512_placed  the same level with every ray moved to the APL its line passes nearest (among
//                       those within 10⁻⁶ of the bounding radius of that, to the one whose map is brightest
//                       along the ray), maps binned again, read masked where a mask was made.
// Keys: set, R, reading (plain, masked; empty for a set's counts). Quantity per d: relative_rmse_pct.
// Counts: two_at_sources source_1_caps, source_2_caps (the caps of each source's mask; R empty);
// builder_512 masks, masked_apls, masked_flux_pct, off_source_least_mm, off_source_median_mm,
// off_source_most_mm (the unmasked APLs' distances to the nearer source), sources_apart_mm;
// builder_512_placed empty_apls, masked_flux_pct. --quick changes nothing.
void beam_masks(const StudyArgs&, std::FILE* out) {
  StudyCsv csv(out, {"set", "R", "reading"});
  const std::unique_ptr<AnalyticEmitter> em = suite_emitter(4);
  const AplErrorOptions eo;
  auto rays = em->source(kSuiteRays, 15);
  AplBuildOptions bo;
  bo.threads = 2;
  bo.map_resolution = 64;
  bo.max_resolution = 64;
  bo.level_counts = {2, 8, 512};
  bo.point_sources.enabled = false;  // the clustered set the study masks by hand
  const AplSet set = build_apl_set(*rays, bo);
  const MeasurementSpheres ms(set.bounds, eo);
  const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
  const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
  std::vector<glm::dvec3> origin, direction;
  double ray_flux = 0;
  {
    RayChunk c;
    rays->rewind();
    while (rays->next(c, 1 << 16))
      for (std::size_t i = 0; i < c.size(); ++i) {
        origin.emplace_back(c.position(i));
        direction.emplace_back(c.direction(i));
        ray_flux = c.flux[i];
      }
  }
  // One light: a position, its map in the frame to_map turns world directions into, and maybe a mask.
  struct Light {
    glm::dvec3 position;
    const SphereMap* map;
    glm::mat3 to_map;
    const DirectionMask* mask = nullptr;
    const SphereMap* coverage = nullptr;  // the mask's, at the map's resolution
  };
  const auto put_errors = [&](const std::vector<std::string>& key, const std::vector<Light>& lights) {
    for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
      std::vector<double> model(dirs.size(), 0.0);
      for (std::size_t p = 0; p < dirs.size(); ++p) {
        const glm::dvec3 x = glm::dvec3(glm::vec3(ms.centre() + ms.radius(s) * dirs[p]));
        for (const Light& l : lights) {
          const glm::dvec3 d = x - l.position;
          const double r = glm::length(d);
          const glm::dvec3 w = d / r;
          const double cosine = glm::dot(dirs[p], w);
          if (cosine <= 0) continue;
          const glm::vec3 m = l.to_map * glm::vec3(w);
          const double i = l.mask ? l.mask->normalised_lookup(*l.map, *l.coverage, m, w).x : l.map->lookup(m).x;
          model[p] += i * cosine / (r * r);
        }
      }
      csv.put(key, "relative_rmse_pct", ms.relative_distances()[s],
              100 * compare_irradiance(exact.at_centre[s], model).relative_rmse);
    }
  };
  // Two APLs at the sources: each ray belongs to the source its line passes through.
  std::vector<std::vector<glm::dvec3>> from(2);
  for (std::size_t j = 0; j < origin.size(); ++j)
    for (std::size_t t = 0; t < 2; ++t) {
      if (distance_to_line(kSources[t], origin[j], direction[j]) < 1e-5) {
        from[t].push_back(direction[j]);
        break;
      }
    }
  if (from[0].size() + from[1].size() != origin.size())
    throw std::runtime_error("a ray's line passes through neither source");
  std::vector<DirectionMask> source_masks;
  for (std::size_t t = 0; t < 2; ++t) {
    std::string why;
    const auto m = DirectionMask::from_directions(from[t], {}, &why);
    if (!m) throw std::runtime_error("no mask for source " + std::to_string(t + 1) + ": " + why);
    csv.put({"two_at_sources", "", ""}, "source_" + std::to_string(t + 1) + "_caps", double(m->caps().size()));
    source_masks.push_back(*m);
  }
  for (const int R : {16, 32, 64}) {
    std::vector<SphereMap> maps(2, SphereMap(R, 1));
    for (std::size_t t = 0; t < 2; ++t)
      for (const glm::dvec3& w : from[t]) {
        int x, y;
        maps[t].texel_of(glm::vec3(w), x, y);
        maps[t].at(x, y, 0) += float(ray_flux / maps[t].texel_solid_angle());
      }
    const std::vector<SphereMap> covers = {source_masks[0].coverage(R, glm::mat3(1.0f), 8),
                                           source_masks[1].coverage(R, glm::mat3(1.0f), 8)};
    for (const bool masked : {false, true}) {
      std::vector<Light> lights(2);
      for (std::size_t t = 0; t < 2; ++t)
        lights[t] = {kSources[t], &maps[t], glm::mat3(1.0f), masked ? &source_masks[t] : nullptr,
                     masked ? &covers[t] : nullptr};
      put_errors({"two_at_sources", cell(R), masked ? "masked" : "plain"}, lights);
    }
  }
  // The builder's finest level at R 16, 32, 64: a mask per position through which at least 500 lines pass.
  for (const int R : {16, 32, 64}) {
    AplBuildOptions rb = bo;
    rb.map_resolution = R;
    rb.max_resolution = R;
    const AplSet built = R == 64 ? AplSet{} : build_apl_set(*rays, rb);
    const AplLevel& level = (R == 64 ? set : built).levels.back();
    const double eps = 1e-3 * set.bounds.radius;
    std::deque<DirectionMask> masks;  // the lights point into these: they must not move
    std::deque<SphereMap> covers;
    std::vector<glm::dvec3> mask_at;
    std::vector<double> off_source;  // mm, from each unmasked APL to the nearer source
    std::vector<Light> plain, masked;
    std::size_t masked_apls = 0;
    double masked_flux = 0, flux = 0;
    for (const Apl& a : level.apls) {
      const glm::dvec3 c(a.position);
      plain.push_back({c, &a.map, level.frame.to_map, nullptr, nullptr});
      flux += a.flux.y;
      std::size_t which = masks.size();
      for (std::size_t q = 0; q < mask_at.size(); ++q)
        if (glm::length(mask_at[q] - c) < eps) which = q;
      if (which == masks.size()) {
        std::vector<glm::dvec3> through;
        for (std::size_t j = 0; j < origin.size(); ++j)  // lines that pass c before they start
          if (glm::dot(c - origin[j], direction[j]) <= 0 && distance_to_line(c, origin[j], direction[j]) < eps)
            through.push_back(direction[j]);
        const auto m = through.size() >= 500 ? DirectionMask::from_directions(through) : std::nullopt;
        if (m) {
          masks.push_back(*m), mask_at.push_back(c);
          covers.push_back(m->coverage(level.map_resolution, glm::transpose(level.frame.to_map), 8));
        }
      }
      masked.push_back(plain.back());
      if (which < masks.size()) {
        masked.back().mask = &masks[which];
        masked.back().coverage = &covers[which];
        ++masked_apls, masked_flux += a.flux.y;
      } else {
        off_source.push_back(1e3 * std::min(glm::length(c - kSources[0]), glm::length(c - kSources[1])));
      }
    }
    std::sort(off_source.begin(), off_source.end());
    const std::vector<std::string> counts = {"builder_512", cell(R), ""};
    csv.put(counts, "masks", double(masks.size()));
    csv.put(counts, "masked_apls", double(masked_apls));
    csv.put(counts, "masked_flux_pct", 100 * masked_flux / flux);
    if (!off_source.empty()) {
      csv.put(counts, "off_source_least_mm", off_source.front());
      csv.put(counts, "off_source_median_mm", off_source[off_source.size() / 2]);
      csv.put(counts, "off_source_most_mm", off_source.back());
    }
    csv.put(counts, "sources_apart_mm", 1e3 * glm::length(kSources[0] - kSources[1]));
    put_errors({"builder_512", cell(R), "plain"}, plain);
    put_errors({"builder_512", cell(R), "masked"}, masked);
    // Placement: every ray moved to the APL its line passes nearest.
    std::vector<SphereMap> moved(level.apls.size(), SphereMap(R, 1));
    std::vector<double> line_distance(level.apls.size());
    std::size_t emptied = level.apls.size();
    std::vector<bool> used(level.apls.size(), false);
    for (std::size_t j = 0; j < origin.size(); ++j) {
      double best = INFINITY;
      for (std::size_t a = 0; a < level.apls.size(); ++a) {
        line_distance[a] = distance_to_line(glm::dvec3(level.apls[a].position), origin[j], direction[j]);
        best = std::min(best, line_distance[a]);
      }
      const glm::vec3 m = level.frame.map_direction(glm::vec3(direction[j]));
      std::size_t pick = 0;
      float brightest = -1;
      for (std::size_t a = 0; a < level.apls.size(); ++a) {
        if (line_distance[a] > best + 1e-6 * set.bounds.radius) continue;
        const float b = level.apls[a].map.lookup(m).x;
        if (b > brightest) brightest = b, pick = a;
      }
      int x, y;
      moved[pick].texel_of(m, x, y);
      moved[pick].at(x, y, 0) += float(ray_flux / moved[pick].texel_solid_angle());
      if (!used[pick]) used[pick] = true, --emptied;
    }
    std::vector<Light> placed = masked;
    double placed_masked = 0;
    for (std::size_t a = 0; a < placed.size(); ++a) {
      placed[a].map = &moved[a];
      if (placed[a].mask) placed_masked += moved[a].integral().x;
    }
    double placed_total = 0;
    for (const SphereMap& m : moved) placed_total += m.integral().x;
    csv.put({"builder_512_placed", cell(R), ""}, "empty_apls", double(emptied));
    csv.put({"builder_512_placed", cell(R), ""}, "masked_flux_pct", 100 * placed_masked / placed_total);
    put_errors({"builder_512_placed", cell(R), "masked"}, placed);
  }
}

// masked-estimate: the held-out estimate of the box's masked level (masked_level_estimate of
// tests/honest_error_support.h) on the rays of seeds 11, 12, … (--seeds N: N seeds, 20 by default;
// --quick: 5). Keys: seed, R (the graded level's), masked (1 if its APLs are masked). Quantities per d:
// truth_pct, estimate_pct (noise removed), resolved (1 or 0), upper_pct, border_share_pct. Then, keyed
// seed "all": spheres, spikes (truth above 10 %), flatters (upper bound below 3/4 of the truth),
// resolved_off (resolved more than 25 % from the truth), as count_masked_estimates counts them.
void masked_estimate(const StudyArgs& args, std::FILE* out) {
  StudyCsv csv(out, {"seed", "R", "masked"});
  const int seeds = args.seeds > 0 ? args.seeds : args.quick ? 5 : 20;
  std::vector<MaskedLevelEstimate> estimates;
  for (int i = 0; i < seeds; ++i) {
    estimates.push_back(masked_level_estimate(11 + std::uint64_t(i)));
    const MaskedLevelEstimate& m = estimates.back();
    const std::vector<std::string> key = {cell(m.seed), cell(m.map_resolution), m.masked ? "1" : "0"};
    for (std::size_t s = 0; s < m.truth.size(); ++s) {
      const double d = m.relative_distance[s];
      csv.put(key, "truth_pct", d, 100 * m.truth[s]);
      csv.put(key, "estimate_pct", d, 100 * m.estimate[s]);
      csv.put(key, "resolved", d, m.resolved[s] ? 1.0 : 0.0);
      csv.put(key, "upper_pct", d, 100 * m.upper[s]);
      csv.put(key, "border_share_pct", d, 100 * m.border_share[s]);
    }
  }
  const MaskedEstimateCounts n = count_masked_estimates(estimates);
  const std::vector<std::string> all = {"all", "", ""};
  csv.put(all, "spheres", n.spheres);
  csv.put(all, "spikes", n.spikes);
  csv.put(all, "flatters", n.flatters);
  csv.put(all, "resolved_off", n.resolved_off);
}

}  // namespace

int main(int argc, char** argv) {
  return lumx_study::study_main(
      argc, argv, "Studies of the box with holes (docs/apl_sets.md, \"Honest error\"): CSV of the figures.",
      {{"borders",
        "plain maps at R 64-256 from 1 M and 10 M rays: borders, not rays, limit the finest level (--quick: 1 M)",
        borders},
       {"exact-beams", "exact maps at the two sources, R 64-1024: what texel maps can do at all (--quick: R 64, 128)",
        exact_beams},
       {"beam-masks", "maps read inside direction masks: at the sources, on the builder's level, placed", beam_masks},
       {"masked-estimate",
        "the held-out estimate of the masked level per seed, and its counts (--seeds N, 20; --quick: 5)",
        masked_estimate}});
}
