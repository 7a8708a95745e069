// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/render_room_command.h — `lumx render room BUNDLE -o DIR`: the luminaire lighting an empty
// room, rendered by a particle-traced reference, each APL level, level of detail and the far field, with
// pictures, difference images and a table of error, time and speed-up (docs/render.md).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lumx_cli {

struct RenderRoomArgs {
  std::string bundle, out;
  std::vector<double> room{3.0, 3.0, 2.0};  ///< --room W D H, m
  std::vector<double> luminaire_at;         ///< --luminaire-at X Y Z, m (empty: default placement)
  std::vector<double> occluders;            ///< --occluder x0 y0 z0 x1 y1 z1, repeatable (6 values each)
  double albedo = 0.5;                      ///< --albedo
  std::vector<double> eye, look_at;         ///< --eye, --look-at, m (empty: default view)
  double fov = 0;                           ///< --fov, degrees (0: default 75)
  std::vector<int> size;                    ///< --size W H, pixels (empty: 480 320)
  std::uint64_t particles = 1000000;        ///< --particles: the reference's
  std::vector<std::size_t> levels;          ///< --levels: APL counts of stored levels to render (empty: all)
  std::uint64_t seed = 1;                   ///< --seed
  unsigned threads = 0;                     ///< --threads
  double time_limit = 0;                    ///< --time-limit, s, for the reference's tracing
  double difference_range = 0.5;            ///< --difference-range: ± of the difference images' colour bar
  bool progress = false;                    ///< --progress
  bool json = false;                        ///< --json
};

int run_render_room(const RenderRoomArgs& a);

}  // namespace lumx_cli
