// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// `lumx build RAYS OUT`: a rayset in, a bundle out (lumx/io/bundle_builder.h: APL levels by clustering,
// error tables graded on held-out rays, the far field as IES and EULUMDAT), then the speed-against-error
// table.
#include "build_command.h"

#include "cli_support.h"
#include "eval_commands.h"
#include "progress.h"

#include <lumx/io/rayset_io.h>

#include <algorithm>
#include <cstdio>
#include <iostream>

namespace lumx_cli {

int run_build(const BuildArgs& a) {
  return guarded(a.rays, [&] {
    lumx::RaysetReadOptions ro;
    ro.warnings = [](const lumx::Diagnostic& d) { print_diag(d); };
    std::unique_ptr<lumx::RaySource> rays = lumx::open_rayset(a.rays, ro);
    const lumx::RaysetInfo& info = rays->info();
    std::printf("rayset:   %s (%s %s), %llu rays, flux in %s\n", a.rays.c_str(), info.format.c_str(),
                info.version.c_str(), (unsigned long long)info.ray_count, lumx::flux_unit(info.quantity));
    return build_bundle(*rays, a, bundle_options(a));
  });
}

lumx::BundleBuildOptions bundle_options(const BuildArgs& a) {
  lumx::BundleBuildOptions o;
  lumx::AplBuildOptions& bo = o.apl;
  if (!a.levels.empty()) bo.level_counts = a.levels;
  bo.seed_rays = a.seed_rays;
  bo.map_resolution = a.map_resolution;
  bo.rays_per_texel = a.rays_per_texel;
  bo.min_resolution = std::min(bo.min_resolution, a.max_resolution);
  bo.max_resolution = a.max_resolution;
  bo.place_at_convergence = a.converge;
  bo.point_sources.enabled = a.point_sources;
  using LC = lumx::AplBuildOptions::LineClustering;
  bo.line_clustering = a.cluster_by == "start" ? LC::start_points : a.cluster_by == "line" ? LC::lines : LC::automatic;
  bo.apl_exponent = a.apl_exponent;
  bo.map_smoothing_rays = a.smooth_rays;
  bo.threads = a.threads;
  o.evaluate = !a.no_eval;
  o.errors.patch_resolution = a.patch_resolution;
  o.far_field.c_step_deg = a.c_step_deg;
  o.far_field.gamma_step_deg = a.gamma_step_deg;
  o.far_field.luminous_efficacy_lm_per_w = a.efficacy_lm_per_w;
  o.source_name = a.rays;
  o.representations = a.representations;
  o.representation_options.execution.threads = a.threads;
  return o;
}

int build_bundle(lumx::RaySource& rays, const BuildArgs& a, lumx::BundleBuildOptions o) {
  lumx::BundleBuildResult r;
  {
    ProgressBar bar(0, "", a.progress);
    o.progress = [&](double f, const char* phase) { bar.update(f, phase); };
    r = lumx::build_bundle(rays, a.out, o);
  }
  print_build_result(r, a, rays.info().quantity);
  return 0;
}

void print_build_result(const lumx::BundleBuildResult& r, const BuildArgs& a, lumx::PhotometricQuantity quantity) {
  std::printf("levels:   ");
  for (std::size_t k = 0; k < r.apls.size(); ++k)
    std::printf("%s%zu APLs (R %d)", k ? ", " : "", r.apls[k], r.built_resolution[k]);
  std::printf(" as built%s", a.no_eval || a.map_resolution > 0 ? "" : "; resolutions then chosen on held-out rays");
  std::printf("\n          from %llu seeds: seeds %.2f s, tree %.2f s, assignment %.2f s\n",
              (unsigned long long)r.build.seeds, r.build.seconds_seed, r.build.seconds_tree, r.build.seconds_assign);
  if (a.converge) {
    const lumx::AplBuildReport& br = r.build;
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
    if (br.point_sources > 0)
      std::printf("point sources: %zu; every ray's line passes through one: one masked APL per source (beam borders "
                  "as geometry)\n",
                  br.point_sources);
  }
  if (r.error_tables_stored && r.held_out.fitted) {
    std::printf("maps:     resolutions chosen on held-out rays:");
    for (std::size_t k = 0; k < r.resolution.size(); ++k) {
      std::printf(" %d", r.resolution[k]);
      const std::vector<double>& kappa = r.held_out.choice.kappa;
      const std::vector<lumx::KernelMode>& mode = r.held_out.choice.mode;
      const lumx::KernelMode m = k < mode.size() ? mode[k] : lumx::KernelMode::plain;
      if (k < kappa.size() && kappa[k] > 0)
        std::printf(" (kernel σ %.1f°%s%s)", 180.0 / lumx::kPi / std::sqrt(kappa[k]),
                    m == lumx::KernelMode::plain ? "" : ", ", lumx::kernel_mode_name(m));
    }
    std::printf(" (levels 0..%zu)\n", r.resolution.size() - 1);
  }
  for (const std::string& note : r.notes) std::fprintf(stderr, "%s: note: %s\n", a.rays.c_str(), note.c_str());
  if (r.far_field_attached)
    std::printf("far field: %.2f lm (%s; level 0's maps at R %d%s), attached as IES and EULUMDAT\n", r.far_field_lm,
                quantity == lumx::PhotometricQuantity::radiometric ? "rays in W, converted to lm"
                                                                                : "rays in lm",
                r.far_field_resolution,
                r.far_field_kernel_sigma_deg > 0
                    ? (", kernel σ " + std::to_string(r.far_field_kernel_sigma_deg).substr(0, 4) + "°" +
                       (r.far_field_kernel_mode == lumx::KernelMode::plain
                            ? std::string()
                            : std::string(", ") + lumx::kernel_mode_name(r.far_field_kernel_mode)))
                          .c_str()
                    : "");
  std::printf("bundle:   %s, %llu bytes; evaluation %.2f s, far field %.2f s, writing %.2f s; %.2f s in all\n",
              a.out.c_str(), (unsigned long long)r.bytes, r.seconds_evaluation, r.seconds_far_field, r.seconds_write,
              r.seconds_build + r.seconds_evaluation + r.seconds_far_field + r.seconds_write);
  if (r.evaluated)
    std::cout << "\n"
              << format_error_table(r.held_out.report, a.out + " (its levels rebuilt from the even rays)",
                                    a.rays + " (odd rays the levels never saw)", r.held_out.report.reference.quantity);
  if (!r.representation_grades.empty())
    std::cout << "\n" << format_model_grades(r.representation_grades, "each rebuilt from the even rays, graded on the odd");
}

}  // namespace lumx_cli
