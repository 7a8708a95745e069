// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// `lumx bake`: lumx::bake::bake_luminaire (lumx/bake/bake.h) with a progress bar showing passes, particles/s,
// the current held-out error and the ETA, then the bake's passes and the bundle's report as `lumx build`
// prints it.
#include "bake_command.h"

#include "bake_preview.h"
#include "cli_support.h"
#include "eval_commands.h"
#include "progress.h"

#include <lumx/bake/bake.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

namespace lumx_cli {

int run_bake(BakeArgs a) {
  return guarded(a.luminaire, [&] {
    lumx::bake::BakeOptions o;
    o.particles = a.particles;
    o.target_error = a.build.no_eval ? 0.0 : a.target_error;  // the stopping rule grades the levels
    o.target_distance = a.target_distance;
    o.time_limit_seconds = a.time_limit;
    o.pass_particles = a.pass_particles;
    o.seed = a.seed;
    o.threads = int(a.build.threads);
    o.max_depth = a.max_depth;
    o.volume_voxels = a.volume_voxels;
    o.rays_out = a.rays_out;
    a.build.rays = a.rays_out.empty() ? a.luminaire : a.rays_out;
    a.build.out = a.out;
    o.bundle = bundle_options(a.build);
    o.read.warnings = [](const lumx::Diagnostic& d) { print_diag(d); };
    ProgressBar bar(0, "", a.build.progress);
    o.progress = [&](const lumx::bake::BakeProgress& p) {
      char status[160];
      const int n = std::snprintf(status, sizeof status, "pass %d  %.2f M particles  %.0f k/s", p.pass,
                                  double(p.particles) / 1e6, p.particles_per_second / 1e3);
      if (std::isfinite(p.error) && n > 0 && std::size_t(n) < sizeof status)
        std::snprintf(status + n, sizeof status - std::size_t(n), "  error %.2f %%", 100 * p.error);
      bar.update(p.fraction, p.phase, status);
    };
    std::unique_ptr<BakePreview> preview;
    if (!a.preview.empty()) {
      preview = std::make_unique<BakePreview>(a.preview, a.preview_resolution);
      o.on_pass = [&](const lumx::bake::BakePass& pass, lumx::RaySource& exits) { preview->on_pass(pass, exits); };
    }
    const lumx::bake::BakeResult r = lumx::bake::bake_luminaire(a.luminaire, a.out, o);
    bar.done();

    std::printf("luminaire: %s, %zu parts, %zu triangles, %zu emitters, %.4g lm emitted\n", a.luminaire.c_str(),
                r.parts, r.triangles, r.emitters, r.emitted_lm);
    const lumx::bake::TraceCounters& c = r.counters;
    std::printf(
        "trace:     %llu particles in %zu passes (%.2f s with grading): %llu exited (%.4g lm), %llu absorbed, "
        "%llu ended by roulette, %llu at the depth cap, %llu leaked; %llu segments\n",
        (unsigned long long)c.emitted, r.passes.size(), r.trace_seconds, (unsigned long long)c.exited, c.exited_lm,
        (unsigned long long)c.absorbed, (unsigned long long)c.roulette_killed, (unsigned long long)c.depth_capped,
        (unsigned long long)c.leaked, (unsigned long long)c.segments);
    if (o.target_error > 0) {
      std::printf("passes:    target %.2f %% at d = %g (finest level, held out, upper bound); stopped by %s\n",
                  100 * o.target_error, o.target_distance, r.stopped_by.c_str());
      for (std::size_t i = 0; i < r.passes.size(); ++i) {
        const lumx::bake::BakePass& p = r.passes[i];
        std::printf("           pass %zu: %10llu particles, %9.2f s, error %.2f %% (estimate %.2f %%), far field "
                    "%.2f %%\n",
                    i + 1, (unsigned long long)p.particles, p.seconds, 100 * p.error, 100 * p.error_estimate,
                    100 * p.far_field_error);
      }
    } else {
      std::printf("passes:    %zu, no target error; stopped by %s\n", r.passes.size(), r.stopped_by.c_str());
    }
    if (preview)
      std::printf("preview:   %s (intensity.png, polar.png, per pass intensity_/histogram_/polar_passNN.png, "
                  "convergence.txt)\n",
                  a.preview.c_str());
    if (!a.rays_out.empty())
      std::printf("rays:      %s (IES TM-25, the exits as a near-field rayset)\n", a.rays_out.c_str());
    print_build_result(r.bundle, a.build, lumx::PhotometricQuantity::photometric);
    return 0;
  });
}

}  // namespace lumx_cli
