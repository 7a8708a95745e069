// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/build_command.h — `lumx build RAYS OUT`: a rayset in, a bundle out.
#pragma once

#include <lumx/apl/builder.h>
#include <lumx/io/bundle_io.h>
#include <lumx/rays/rayset.h>
#include <lumx/volume/radiance_volume.h>

#include <map>

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
  int patch_resolution = 16;         ///< --patches R for the error evaluation
  bool no_eval = false;              ///< --no-eval: skip the error evaluation (no error tables)
  double c_step_deg = 2.5, gamma_step_deg = 1.0;  ///< far-field grid
  double efficacy_lm_per_w = 0;      ///< --efficacy for radiometric rays (default: the header's Φv/Φe)
  bool progress = false;             ///< --progress: show the bar even when stderr is not a terminal
  bool converge = true;              ///< --converge / --no-converge: rays as lines (AplBuildOptions)
  std::string cluster_by = "auto";   ///< --cluster-by auto|start|line: step 1b's choice
  double apl_exponent = 0;           ///< --resolution-exponent
  double smooth_rays = 0;            ///< --smooth: AplBuildOptions::map_smoothing_rays
  unsigned threads = 0;              ///< --threads (0: every core); the bundle does not depend on it
};

int run_build(const BuildArgs& a);

/// What a bundle gets beside its levels and far field: a radiance volume, more attachments, provenance.
struct BundleExtras {
  const lumx::RadianceVolume* volume = nullptr;
  std::vector<lumx::BundleAttachment> attachments;
  std::map<std::string, std::string> provenance;
};

/// `lumx build`'s work on rays already open (a.rays names them in messages and provenance): levels, error
/// tables on held-out rays, the far field, the bundle at a.out. Throws lumx::Error; returns 0.
int build_bundle(lumx::RaySource& rays, const BuildArgs& a, const BundleExtras& extras);

/// The builder options a bundle was made with, as the JSON `lumx build` stores in its provenance
/// ("build_options"), and back; `lumx eval` rebuilds from half of the source rays with them.
std::string build_options_json(const lumx::AplBuildOptions& o);
/// Throws std::invalid_argument naming the key when the text is not such JSON.
lumx::AplBuildOptions build_options_from_json(const std::string& text);

}  // namespace lumx_cli
