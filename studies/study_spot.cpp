// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Studies of the suite's spots, cos^20 and cos^50 lobes from a 2 cm disk (docs/apl_sets.md, "Honest
// error": what limits the spots, bias against noise, two-scale at 4.5 texel widths). Every error is the
// finest level's relative RMSE (eq. 5.1) against the exact irradiance at the patch centres of each
// measurement sphere, in percent. The CSV columns are described in studies/study_support.h.
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/map_fit.h>
#include <lumx/math/sphere_map.h>
#include <lumx/math/sphere_map_kernel.h>

#include "honest_error_support.h"
#include "study_support.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

using namespace lumx;
using namespace lumx_test;
using lumx_study::cell;
using lumx_study::kernel_label;
using lumx_study::kernel_sigma_deg;
using lumx_study::StudyArgs;
using lumx_study::StudyCsv;

namespace {

// more-rays: the shipped finest level (shipped_set: fitted on held-out rays as lumx build does) of each
// spot from 1 M and 4 M rays (seeds 13 and 14), with the maps in the photometric frame and turned
// (MapFrame, as shipped); from the 1 M rays also the finest level at R 128 with σ 1.5 texel widths,
// sharpened, set by hand on the unfitted set; then the floor of maps at the spot's centre, one APL whose
// map is the exact intensity averaged over each texel (I(ω) = r² E(r ω) at r = 10⁴ m, 4 × 4
// sub-directions), at R 64 and 128, read bilinearly. Spheres at d ≥ 1 only. --quick: 1 M rays only.
// Keys: emitter, frame (photometric, turned; empty for the exact maps), rays, map (fitted, by hand,
// exact at the centre), apls, R, kernel, sigma_deg. Quantity per d: relative_rmse_pct.
void more_rays(const StudyArgs& args, std::FILE* out) {
  StudyCsv csv(out, {"emitter", "frame", "rays", "map", "apls", "R", "kernel", "sigma_deg"});
  std::vector<std::uint64_t> ray_counts = {1000000};
  if (!args.quick) ray_counts.push_back(4000000);
  for (int which : {2, 3}) {
    const std::unique_ptr<AnalyticEmitter> em = suite_emitter(which);
    const auto put_errors = [&](const std::vector<std::string>& key, const AplSet& set, std::size_t k,
                                const MeasurementSpheres& ms, const ExactOnSpheres& exact) {
      const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
      for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
        if (ms.relative_distances()[s] < 1) continue;
        csv.put(key, "relative_rmse_pct", ms.relative_distances()[s],
                100 * compare_irradiance(exact.at_centre[s], level_at_points(set, k, ms, s, dirs)).relative_rmse);
      }
    };
    for (const bool turned : {false, true}) {
      const char* frame = turned ? "turned" : "photometric";
      for (const std::uint64_t n : ray_counts) {
        auto rays = em->source(n, 11 + std::uint64_t(which));
        ResolutionChoice choice;
        const AplSet set = shipped_set(*rays, choice, turned);
        const MeasurementSpheres ms(set.bounds, AplErrorOptions{});
        const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
        const std::size_t k = set.levels.size() - 1;
        put_errors(
            {em->name(), frame, cell(n), "fitted", cell(set.levels[k].size()), cell(set.levels[k].map_resolution),
             kernel_label(kernel_mode_name(choice.mode.at(k)), choice.kappa.at(k)),
             cell(kernel_sigma_deg(choice.kappa.at(k)))},
            set, k, ms, exact);
        if (n == 1000000) {
          AplBuildOptions bo;
          bo.threads = 2;
          bo.orient_maps = turned;
          AplSet by_hand = build_apl_set(*rays, bo);
          const int R = 128;
          const double texel = std::sqrt(4.0 * kPi / (2.0 * R * R));
          const double kappa = 1.0 / ((1.5 * texel) * (1.5 * texel));
          by_hand.levels[k] = fitted_level(by_hand.levels[k], R, kappa, KernelMode::sharpened);
          put_errors({em->name(), frame, cell(n), "by hand", cell(by_hand.levels[k].size()), cell(R), "sharpened",
                      cell(kernel_sigma_deg(kappa))},
                     by_hand, k, ms, exact);
        }
      }
    }
    AplBuildOptions bo;
    bo.threads = 2;
    bo.level_counts = {1};
    const AplSet built = build_apl_set(*em->source(200000, 3), bo);
    const MeasurementSpheres ms(built.bounds, AplErrorOptions{});
    const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
    for (const int R : {64, 128}) {
      AplSet set;
      set.bounds = built.bounds;
      set.levels.resize(1);
      set.levels[0].map_resolution = R;
      Apl a;
      a.map = SphereMap(R, 1);
      for (int y = 0; y < R; ++y)
        for (int x = 0; x < 2 * R; ++x) {
          double sum = 0;
          for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
              const glm::dvec3 w = glm::normalize(glm::dvec3(sphere_map::uv_to_direction(
                  {(float(x) + (float(i) + 0.5f) / 4) / float(2 * R), (float(y) + (float(j) + 0.5f) / 4) / float(R)})));
              sum += 1e8 * em->irradiance(1e4 * w, -w);
            }
          a.map.at(x, y, 0) = float(sum / 16);
        }
      a.flux = a.map.integral();
      set.levels[0].apls.push_back(std::move(a));
      put_errors({em->name(), "", "", "exact at the centre", "1", cell(R), "none", cell(0.0)}, set, 0, ms, exact);
    }
  }
}

// bias-noise: bias against noise in the shipped spots. K sets built as lumx build builds them
// (shipped_set, maps in the photometric frame), each from 1 M rays of its own seed (101, 102, …), all
// measured on the first seed's spheres; the same for the spots turned 45° about y (RotatedEmitter). With
// e_k the k-th set's point errors against the exact irradiance, E|ē|² = |b|² + σ²/K and
// E|e_k|² = |b|² + σ², so |b|² = (K|ē|² − mean |e_k|²)/(K − 1) (clamped at 0) and σ² the rest, both
// normalised as eq. 5.1 by the exact mean over the sphere. --seeds K: K sets (4 by default, at least 2);
// --quick: 2. Keys: emitter, turned_deg, seed, kernel. Per seed (kernel: the fit's choice for the finest
// level) apls, R, sigma_deg; keyed seed "all" (kernel empty), per d: rms_pct (of one set), bias_pct,
// noise_pct.
void bias_noise(const StudyArgs& args, std::FILE* out) {
  StudyCsv csv(out, {"emitter", "turned_deg", "seed", "kernel"});
  const int K = args.seeds > 0 ? args.seeds : args.quick ? 2 : 4;
  if (K < 2) throw std::invalid_argument("bias-noise needs --seeds 2 or more");
  for (const double turn : {0.0, 45.0}) {
    for (int which : {2, 3}) {
      std::unique_ptr<AnalyticEmitter> em = suite_emitter(which);
      const std::string name = em->name();
      if (turn != 0) em = std::make_unique<RotatedEmitter>(std::move(em), turn);
      std::vector<std::vector<std::vector<double>>> err(
          static_cast<std::size_t>(K));  // [seed][sphere][point], model − exact
      std::vector<double> mean_exact, distances;
      std::unique_ptr<MeasurementSpheres> spheres;
      for (int k = 0; k < K; ++k) {
        const std::uint64_t seed = 101 + std::uint64_t(k);
        auto rays = em->source(1000000, seed);
        ResolutionChoice choice;
        const AplSet set = shipped_set(*rays, choice, false);
        if (k == 0) spheres = std::make_unique<MeasurementSpheres>(set.bounds, AplErrorOptions{});
        const MeasurementSpheres& ms = *spheres;
        const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
        const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
        const std::size_t top = set.levels.size() - 1;
        const std::vector<std::string> key = {
            name, cell(turn), cell(seed), kernel_label(kernel_mode_name(choice.mode.at(top)), choice.kappa.at(top))};
        csv.put(key, "apls", double(set.levels[top].size()));
        csv.put(key, "R", set.levels[top].map_resolution);
        csv.put(key, "sigma_deg", kernel_sigma_deg(choice.kappa.at(top)));
        err[std::size_t(k)].resize(ms.sphere_count());
        if (k == 0) {
          mean_exact.resize(ms.sphere_count());
          distances = ms.relative_distances();
        }
        for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
          const std::vector<double> model = level_at_points(set, top, ms, s, dirs);
          double m = 0;
          for (std::size_t p = 0; p < dirs.size(); ++p) {
            err[std::size_t(k)][s].push_back(model[p] - exact.at_centre[s][p]);
            m += exact.at_centre[s][p] / double(dirs.size());
          }
          if (k == 0) mean_exact[s] = m;
        }
      }
      const std::vector<std::string> key = {name, cell(turn), "all", ""};
      for (std::size_t s = 0; s < distances.size(); ++s) {
        const std::size_t P = err[0][s].size();
        double each = 0, of_mean = 0;
        for (std::size_t p = 0; p < P; ++p) {
          double mean = 0;
          for (const auto& e : err) {
            each += e[s][p] * e[s][p] / (K * double(P));
            mean += e[s][p] / K;
          }
          of_mean += mean * mean / double(P);
        }
        const double b2 = std::max(0.0, (K * of_mean - each) / (K - 1)), norm = mean_exact[s];
        csv.put(key, "rms_pct", distances[s], 100 * std::sqrt(each) / norm);
        csv.put(key, "bias_pct", distances[s], 100 * std::sqrt(b2) / norm);
        csv.put(key, "noise_pct", distances[s], 100 * std::sqrt(std::max(0.0, each - b2)) / norm);
      }
    }
  }
}

// wide-two-scale: the cos^20 spot's 512-APL level built from 1 M rays (build_apl_set without the held-out
// fit, maps in the photometric frame), its maps at R 128 smoothed two-scale at σ 4.5 texel widths and
// extrapolated at σ 3 texel widths. --seeds N: seeds 101 … 100 + N (2 by default); --quick: 1.
// Keys: emitter, seed, apls, R, kernel, sigma_deg. Quantity per d: relative_rmse_pct.
void wide_two_scale(const StudyArgs& args, std::FILE* out) {
  StudyCsv csv(out, {"emitter", "seed", "apls", "R", "kernel", "sigma_deg"});
  const int seeds = args.seeds > 0 ? args.seeds : args.quick ? 1 : 2;
  const std::unique_ptr<AnalyticEmitter> em = suite_emitter(2);
  const int R = 128;
  const double texel = std::sqrt(4.0 * kPi / (2.0 * R * R));
  const std::pair<double, KernelMode> kernels[2] = {{1.0 / ((4.5 * texel) * (4.5 * texel)), KernelMode::two_scale},
                                                    {1.0 / ((3.0 * texel) * (3.0 * texel)), KernelMode::extrapolated}};
  for (int si = 0; si < seeds; ++si) {
    const std::uint64_t seed = 101 + std::uint64_t(si);
    auto rays = em->source(1000000, seed);
    AplBuildOptions bo;
    bo.threads = 2;
    bo.orient_maps = false;
    const AplSet built = build_apl_set(*rays, bo);
    const MeasurementSpheres ms(built.bounds, AplErrorOptions{});
    const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
    const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
    const std::size_t k = built.levels.size() - 1;
    if (built.levels[k].map_resolution != R)
      throw std::runtime_error("the finest level was built at R " + std::to_string(built.levels[k].map_resolution) +
                               ", not " + std::to_string(R));
    for (const auto& [kappa, mode] : kernels) {
      AplSet set = built;
      set.levels[k] = fitted_level(built.levels[k], R, kappa, mode);
      const std::vector<std::string> key = {em->name(),
                                            cell(seed),
                                            cell(set.levels[k].size()),
                                            cell(R),
                                            kernel_label(kernel_mode_name(mode), kappa),
                                            cell(kernel_sigma_deg(kappa))};
      for (std::size_t s = 0; s < ms.sphere_count(); ++s)
        csv.put(key, "relative_rmse_pct", ms.relative_distances()[s],
                100 * compare_irradiance(exact.at_centre[s], level_at_points(set, k, ms, s, dirs)).relative_rmse);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  return lumx_study::study_main(
      argc, argv, "Studies of the suite's spots (docs/apl_sets.md, \"Honest error\"): CSV of the figures.",
      {{"more-rays", "the shipped finest level from 1 M and 4 M rays, both frames, by hand, exact maps (--quick: 1 M)",
        more_rays},
       {"bias-noise",
        "bias and noise of the shipped finest level over K seeds, upright and turned (--seeds K, 4; --quick: 2)",
        bias_noise},
       {"wide-two-scale", "two-scale at 4.5 against extrapolated at 3 texel widths, R 128 (--seeds N, 2; --quick: 1)",
        wide_two_scale}});
}
