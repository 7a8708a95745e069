// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// `lumx build RAYS OUT`: a rayset in, a bundle out — APL levels by clustering (lumx/apl/builder.h), the
// error of every level against the rays on measurement spheres stored as the levels' error tables
// (lumx/apl/error.h), and the rays' far field as IES and EULUMDAT attachments (lumx/rays/far_field.h);
// then the speed-against-error table.
#include "build_command.h"

#include "cli_support.h"
#include "eval_commands.h"
#include "progress.h"

#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/far_field.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/photometry_io.h>
#include <lumx/io/rayset_io.h>
#include <lumx/photometry/intensity_table.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <thread>

namespace lumx_cli {

namespace {

/// lm per W for the far field of a radiometric rayset: the caller's, else the header's Φv / Φe.
double efficacy_for(const lumx::RaysetInfo& info, double given) {
  if (given > 0) return given;
  const auto v = info.values.find("luminous flux lm"), e = info.values.find("radiant flux W");
  if (v != info.values.end() && e != info.values.end() && v->second > 0 && e->second > 0 && std::isfinite(v->second) &&
      std::isfinite(e->second))
    return v->second / e->second;
  return 0;
}

}  // namespace

std::string build_options_json(const lumx::AplBuildOptions& o) {
  using LC = lumx::AplBuildOptions::LineClustering;
  const nlohmann::json j = {{"levels", o.level_counts},
                            {"seed_rays", o.seed_rays},
                            {"cluster_window", o.cluster_window},
                            {"map_resolution", o.map_resolution},
                            {"min_resolution", o.min_resolution},
                            {"max_resolution", o.max_resolution},
                            {"rays_per_texel", o.rays_per_texel},
                            {"apl_exponent", o.apl_exponent},
                            {"converge", o.place_at_convergence},
                            {"cluster_by", o.line_clustering == LC::start_points ? "start"
                                           : o.line_clustering == LC::lines      ? "line"
                                                                                 : "auto"},
                            {"smooth", o.map_smoothing_rays}};
  return j.dump();
}

lumx::AplBuildOptions build_options_from_json(const std::string& text) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (!j.is_object()) throw std::invalid_argument("build_options: not a JSON object");
  lumx::AplBuildOptions o;
  auto get = [&](const char* key, auto& value) {
    if (!j.contains(key)) return;
    try {
      value = j.at(key).get<std::decay_t<decltype(value)>>();
    } catch (const nlohmann::json::exception&) {
      throw std::invalid_argument(std::string("build_options: /") + key + " has the wrong type");
    }
  };
  get("levels", o.level_counts);
  get("seed_rays", o.seed_rays);
  get("cluster_window", o.cluster_window);
  get("map_resolution", o.map_resolution);
  get("min_resolution", o.min_resolution);
  get("max_resolution", o.max_resolution);
  get("rays_per_texel", o.rays_per_texel);
  get("apl_exponent", o.apl_exponent);
  get("converge", o.place_at_convergence);
  get("smooth", o.map_smoothing_rays);
  std::string by = "auto";
  get("cluster_by", by);
  using LC = lumx::AplBuildOptions::LineClustering;
  o.line_clustering = by == "start" ? LC::start_points : by == "line" ? LC::lines : LC::automatic;
  return o;
}

int run_build(const BuildArgs& a) {
  return guarded(a.rays, [&] {
    lumx::RaysetReadOptions ro;
    ro.warnings = [](const lumx::Diagnostic& d) { print_diag(d); };
    std::unique_ptr<lumx::RaySource> rays = lumx::open_rayset(a.rays, ro);
    const lumx::RaysetInfo& info = rays->info();
    std::printf("rayset:   %s (%s %s), %llu rays, flux in %s\n", a.rays.c_str(), info.format.c_str(),
                info.version.c_str(), (unsigned long long)info.ray_count, lumx::flux_unit(info.quantity));
    return build_bundle(*rays, a, {});
  });
}

int build_bundle(lumx::RaySource& source, const BuildArgs& a, const BundleExtras& extras) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  lumx::RaySource* const rays = &source;
  const lumx::RaysetInfo& info = source.info();

  // Levels by clustering.
  lumx::AplBuildOptions bo;
  if (!a.levels.empty()) bo.level_counts = a.levels;
  bo.seed_rays = a.seed_rays;
  bo.map_resolution = a.map_resolution;
  bo.rays_per_texel = a.rays_per_texel;
  bo.place_at_convergence = a.converge;
  using LC = lumx::AplBuildOptions::LineClustering;
  bo.line_clustering = a.cluster_by == "start" ? LC::start_points : a.cluster_by == "line" ? LC::lines : LC::automatic;
  bo.apl_exponent = a.apl_exponent;
  bo.map_smoothing_rays = a.smooth_rays;
  bo.threads = a.threads > 0 ? a.threads : std::max(1u, std::thread::hardware_concurrency());
  lumx::AplBuildReport br;
  lumx::AplSet set;
  {
    ProgressBar bar(double(info.ray_count), "rays", a.progress);
    bo.progress = [&](double f, const char* phase) { bar.update(f, phase); };
    set = lumx::build_apl_set(*rays, bo, &br);
  }
  const auto build_done = Clock::now();
  set.provenance["source"] = a.rays;
  set.provenance["source_rays"] = std::to_string(info.ray_count);
  set.provenance["build_options"] = build_options_json(bo);
  for (const auto& [key, value] : extras.provenance) set.provenance[key] = value;
  std::printf("levels:   ");
  for (std::size_t k = 0; k < set.levels.size(); ++k)
    std::printf("%s%zu APLs (R %d)", k ? ", " : "", set.levels[k].size(), set.levels[k].map_resolution);
  std::printf(" as built%s", a.no_eval || a.map_resolution > 0 ? "" : "; resolutions then chosen on held-out rays");
  std::printf("\n          from %llu seeds: seeds %.2f s, tree %.2f s, assignment %.2f s\n",
              (unsigned long long)br.seeds, br.seconds_seed, br.seconds_tree, br.seconds_assign);
  if (a.converge) {
    std::printf(
        "lines:    RMS distance from their convergence point / start points' %.3f; with directions "
        "shuffled %.3f (ratio %.3f)",
        br.line_convergence, br.line_convergence_shuffled,
        br.line_convergence / std::max(1e-300, br.line_convergence_shuffled));
    if (!br.shift_by_start.empty()) {
      std::printf("\n          mean squared shift across the rays per level, mm^2, by start point / by line:");
      for (std::size_t k = 0; k < br.shift_by_start.size() && k < br.shift_by_line.size(); ++k)
        std::printf(" %.3g/%.3g", br.shift_by_start[k] * 1e6, br.shift_by_line[k] * 1e6);
    }
    std::printf("\n          clustered by %s; %zu APLs at their rays' convergence point\n",
                br.slid_to_convergence ? "line" : "start point", br.moved_to_convergence);
  }

  // Error of every level against the rays, stored in the bundle for the LOD error-target rule.
  lumx::AplErrorReport report;
  lumx::ResolutionChoice choice;
  const lumx::AplLevel built_level0 = set.levels.at(0);  // for the far field (choice.far_field_resolution)
  const bool evaluate = !a.no_eval;
  if (evaluate) {
    lumx::AplErrorOptions eo;
    eo.patch_resolution = a.patch_resolution;
    ProgressBar bar(0, "", a.progress);
    eo.progress = [&](double f, const char* phase) { bar.update(f, phase); };
    // Honest tables: a set built the same way from the even rays, graded on the odd ones it never saw
    // (apl/error.h). The bundle's own levels, from every ray, have half its noise variance.
    lumx::AplBuildOptions half = bo;
    half.progress = [&](double f, const char*) { bar.update(0.5 * f, "held-out build"); };
    eo.progress = [&](double f, const char* phase) { bar.update(0.5 + 0.5 * f, phase); };
    // With --map-resolution the resolution is the caller's; else it is fitted on held-out rays.
    const auto build_half = [&](lumx::RaySource& train) { return lumx::build_apl_set(train, half); };
    report = a.map_resolution > 0 ? lumx::evaluate_held_out(*rays, build_half, eo)
                                  : lumx::evaluate_held_out_fitted(*rays, build_half, eo, &choice);
    if (lumx::apply_held_out_fit(set, report, a.map_resolution > 0 ? nullptr : &choice)) {
      if (a.map_resolution == 0) {
        std::printf("maps:     resolutions chosen on held-out rays:");
        for (std::size_t k = 0; k < set.levels.size(); ++k) std::printf(" %d", set.levels[k].map_resolution);
        std::printf(" (levels 0..%zu)\n", set.levels.size() - 1);
      }
      set.provenance["error_tables"] = a.map_resolution > 0
                                           ? "held out: levels built from the even rays, irradiance at patch "
                                             "centres against the odd rays, their noise removed"
                                           : "held out: levels built from the even rays, map resolutions chosen "
                                             "on rays 1, 5, 9, ..., irradiance at patch centres against rays 3, "
                                             "7, 11, ..., their noise removed";
    } else {
      std::fprintf(stderr,
                   "%s: note: the half rayset gives other levels than the whole; no error table is "
                   "stored\n",
                   a.rays.c_str());
    }
  }
  const auto evaluated = Clock::now();

  // The rays' far field as IES and EULUMDAT, shipped inside the bundle.
  lumx::BundleWriteOptions wo;
  lumx::FarFieldGrid grid;
  grid.c_step_deg = a.c_step_deg;
  grid.gamma_step_deg = a.gamma_step_deg;
  grid.luminous_efficacy_lm_per_w = efficacy_for(info, a.efficacy_lm_per_w);
  if (info.quantity == lumx::PhotometricQuantity::radiometric && !(grid.luminous_efficacy_lm_per_w > 0)) {
    std::fprintf(stderr,
                 "%s: note: the rays carry W and no luminous efficacy is known (give --efficacy LM_PER_W); "
                 "no IES/EULUMDAT far field is attached\n",
                 a.rays.c_str());
  } else {
    // Level 0's maps at the resolution fitted on held-out rays for the far field alone (d = 5, 10),
    // tabulated on the Type C grid: the ray histogram on that grid would give each of its ~26 000
    // cells a few hundred rays of a million (a Lambertian disk's IES from 1 M rays: 15 % off at d = 10
    // binned, 3.5 % from the fitted map).
    // Only level 0 is needed: a set of that one level, not a copy of every level's maps.
    lumx::AplSet far_set;
    far_set.quantity = set.quantity;
    far_set.channels = set.channels;
    far_set.provenance = set.provenance;
    far_set.levels.push_back(choice.far_field_resolution > 0 &&
                                     choice.far_field_resolution <= built_level0.map_resolution
                                 ? lumx::downsampled_level(built_level0, choice.far_field_resolution)
                                 : set.levels.at(0));
    const lumx::Photometry far = lumx::far_field_photometry(far_set, 0, grid);
    wo.attachments.push_back({"far_field.ies", "application/x-ies-lm63", lumx::format_ies(far)});
    wo.attachments.push_back({"far_field.ldt", "application/x-eulumdat", lumx::format_ldt(far)});
    std::printf("far field: %.2f lm (%s; level 0's maps at R %d), attached as IES and EULUMDAT\n",
                lumx::IntensityTable(far).flux_lm(),
                info.quantity == lumx::PhotometricQuantity::radiometric
                    ? ("rays in W at " + std::to_string(grid.luminous_efficacy_lm_per_w) + " lm/W").c_str()
                    : "rays in lm",
                far_set.levels[0].map_resolution);
  }
  const auto far_done = Clock::now();
  for (const auto& attachment : extras.attachments) wo.attachments.push_back(attachment);
  lumx::write_bundle(a.out, set, extras.volume, wo);
  const lumx::BundleReader written(a.out);
  const auto seconds = [](Clock::time_point from, Clock::time_point to) {
    return std::chrono::duration<double>(to - from).count();
  };
  std::printf("bundle:   %s, %llu bytes; evaluation %.2f s, far field %.2f s, writing %.2f s; %.2f s in all\n",
              a.out.c_str(), (unsigned long long)written.manifest().total_bytes(), seconds(build_done, evaluated),
              seconds(evaluated, far_done), seconds(far_done, Clock::now()), seconds(start, Clock::now()));
  if (evaluate)
    std::cout << "\n"
              << format_error_table(report, a.out + " (its levels rebuilt from the even rays)",
                                    a.rays + " (the odd rays)", set.quantity);
  return 0;
}

}  // namespace lumx_cli
