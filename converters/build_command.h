// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/build_command.h — `lumx build RAYS OUT`: a rayset in, a bundle out.
#pragma once

#include <lumx/io/bundle_builder.h>
#include <lumx/rays/rayset.h>

#include <cstddef>
#include <string>
#include <vector>

namespace lumx_cli {

struct BuildArgs {
  std::string rays, out;
  std::vector<std::size_t> levels;   ///< --levels (default 1 8 64 256 512)
  std::size_t seed_rays = 250000;    ///< --seeds
  int map_resolution = 0;            ///< --map-resolution (0: by the rays-per-texel rule)
  double rays_per_texel = 8;         ///< --rays-per-texel
  int max_resolution = 128;          ///< --max-resolution: the finest R the rule may give
  int patch_resolution = 16;         ///< --patches R for the error evaluation
  bool no_eval = false;              ///< --no-eval: skip the error evaluation (no error tables)
  double c_step_deg = 2.5, gamma_step_deg = 1.0;  ///< far-field grid
  double efficacy_lm_per_w = 0;      ///< --efficacy for radiometric rays (default: the header's Φv/Φe)
  bool progress = false;             ///< --progress: show the bar even when stderr is not a terminal
  bool converge = true;              ///< --converge / --no-converge: rays as lines (AplBuildOptions)
  std::string cluster_by = "auto";   ///< --cluster-by auto|start|line: step 1b's choice
  bool point_sources = true;         ///< --point-sources / --no-point-sources: step 7 (AplBuildOptions)
  double apl_exponent = 0;           ///< --resolution-exponent
  double smooth_rays = 0;            ///< --smooth: AplBuildOptions::map_smoothing_rays
  unsigned threads = 0;              ///< --threads (0: every core); the bundle does not depend on it
  std::vector<std::string> representations;  ///< --representations: registered names besides "apl"
};

int run_build(const BuildArgs& a);

/// The library options `lumx build`'s arguments stand for (lumx/io/bundle_builder.h).
lumx::BundleBuildOptions bundle_options(const BuildArgs& a);

/// `lumx build`'s work on rays already open (a.rays names them in messages): lumx::build_bundle to a.out
/// with a progress bar, then its report and speed-against-error table printed. Throws lumx::Error; returns 0.
int build_bundle(lumx::RaySource& rays, const BuildArgs& a, lumx::BundleBuildOptions o);

/// Prints what lumx::build_bundle did: levels, line convergence, fitted resolutions, notes (on stderr),
/// the far field, the bundle's size and times, and the speed-against-error table.
void print_build_result(const lumx::BundleBuildResult& r, const BuildArgs& a, lumx::PhotometricQuantity quantity);

}  // namespace lumx_cli
