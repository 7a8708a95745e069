// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/bake_command.h — `lumx bake LUMINAIRE BUNDLE`: a luminaire's geometry in, a bundle out.
#pragma once

#include "build_command.h"

#include <cstdint>
#include <string>

namespace lumx_cli {

struct BakeArgs {
  std::string luminaire, out;
  std::uint64_t particles = 1000000;  ///< --particles: the budget
  double target_error = 0.05;         ///< --target-error (fraction; 0: trace the whole budget)
  double target_distance = 1;         ///< --target-distance d
  double time_limit = 0;              ///< --time-limit seconds (0: none)
  std::uint64_t pass_particles = 0;   ///< --pass-particles (0: automatic)
  std::uint64_t seed = 1;             ///< --seed
  int volume_voxels = 32768;          ///< --volume-voxels (0: no radiance volume)
  std::string rays_out;               ///< --rays-out FILE.tm25ray: the exits as an IES TM-25 rayset
  int max_depth = 256;                ///< --max-depth
  std::string preview;                ///< --preview DIR: images and a table after every pass
  int preview_resolution = 64;        ///< --preview-resolution R
  BuildArgs build;                    ///< levels, error tables, far field, threads (as `lumx build`)
};

int run_bake(BakeArgs a);

}  // namespace lumx_cli
