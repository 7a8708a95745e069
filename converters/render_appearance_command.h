// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/render_appearance_command.h — `lumx render appearance BUNDLE -o DIR`: the luminaire as a camera sees
// it at several depths n_b (with the radiance volume's glow) against a path-traced reference, with images, a
// table and the suggested n_b (lumx/render/appearance_study.h).
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace lumx_cli {

struct RenderAppearanceArgs {
  std::string bundle, out;
  std::vector<int> depths{0, 1, 2, 4, 8};  ///< --depths
  int spp = 16;                            ///< --spp: samples per pixel of each depth-limited image
  int reference_spp = 256;                 ///< --reference-spp
  std::vector<double> eye, look_at;        ///< --eye X Y Z, --look-at X Y Z (m; default: a 3/4 view from below)
  double fov = 40;                         ///< --fov: vertical, degrees
  std::vector<int> size{160, 120};         ///< --size W H
  std::string glb;                         ///< --glb: luminaire geometry instead of the bundle's attachment
  int background_level = -1;               ///< --background-level: APL level lighting the room (-1: finest)
  double room_albedo = 0.5;                ///< --room-albedo
  bool no_glow = false;                    ///< --no-glow
  std::uint64_t seed = 1;
  unsigned threads = 0;
  double time_limit = 0;                   ///< --time-limit: seconds for the reference (0: none)
  bool json = false;
  bool progress = false;
};

/// Adds the `appearance` subcommand to the `render` command.
void add_render_appearance_command(CLI::App& render, int& status);

int run_render_appearance(const RenderAppearanceArgs& a);

}  // namespace lumx_cli
