// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// What `lumx render room` spends its time on: direct illuminance from an APL level at room points, with and
// without shadow rays against an occluder; particles traced into the room and deposited; the kernel
// reconstruction of one surface's deposits.
#include <lumx/bake/luminaire_builder.h>
#include <lumx/render/room_render.h>

#include <benchmark/benchmark.h>

#include <cmath>

namespace {

namespace render = lumx::render;

/// `count` APLs of 100 cd each (constant 16² maps) spread over a 0.5 m cube.
lumx::AplSet spread_set(int count) {
  lumx::AplSet set;
  lumx::AplLevel level;
  level.map_resolution = 16;
  for (int i = 0; i < count; ++i) {
    lumx::Apl a;
    a.position = glm::vec3(0.5f * std::fmod(0.618f * float(i), 1.0f) - 0.25f, 0.5f * std::fmod(0.414f * float(i), 1.0f) - 0.25f,
                           0.5f * std::fmod(0.732f * float(i), 1.0f) - 0.25f);
    a.map = lumx::SphereMap(16, 1);
    for (float& v : a.map.values()) v = 100.0f;
    a.flux = a.map.integral();
    level.apls.push_back(std::move(a));
  }
  set.levels.push_back(std::move(level));
  set.bounds.radius = 0.45;
  return set;
}

void BM_RoomAplIlluminance(benchmark::State& state) {
  render::Room room;
  room.luminaire_position_m = {1.5, 1.5, 1.6};
  if (state.range(1)) room.occluders.push_back({{1.2, 1.2, 0.7}, {1.8, 1.8, 0.75}});
  const render::RoomScene scene(room);
  const lumx::AplSet set = spread_set(int(state.range(0)));
  const render::AplRoomIlluminance method(set, 0, room.luminaire_position_m, scene);
  std::uint64_t key = 0;
  double sum = 0;
  for (auto _ : state) {
    const double u = 0.05 + 2.9 * std::fmod(0.618 * double(key), 1.0), v = 0.05 + 2.9 * std::fmod(0.414 * double(key), 1.0);
    sum += method.at(0, {u, v, 0.0}, {0, 0, 1}, u, v, key++);
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations());
  state.counters["APLs"] = double(state.range(0));
}
BENCHMARK(BM_RoomAplIlluminance)->ArgsProduct({{1, 64, 512}, {0, 1}})->ArgNames({"apls", "occluder"});

void BM_RoomReferenceTrace(benchmark::State& state) {
  render::Room room;
  room.luminaire_position_m = {1.5, 1.5, 1.6};
  room.occluders.push_back({{1.2, 1.2, 0.7}, {1.8, 1.8, 0.75}});
  const render::RoomScene scene(room);
  lumx::bake::LuminaireBuilder b("point");
  b.point_light({0, 0, 0}, 100.0);
  const lumx::bake::Tracer tracer(b.scene());
  render::ReferenceOptions o;
  o.particles = std::uint64_t(state.range(0));
  o.threads = 1;
  for (auto _ : state) benchmark::DoNotOptimize(render::trace_room_particles(tracer, scene, room.luminaire_position_m, o));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_RoomReferenceTrace)->Arg(100000)->Unit(benchmark::kMillisecond);

void BM_KernelDensitySurface(benchmark::State& state) {
  std::vector<render::Deposit2D> deposits;
  std::uint64_t z = 1;
  for (std::int64_t i = 0; i < state.range(0); ++i) {
    z = z * 6364136223846793005ull + 1442695040888963407ull;
    const double a = double(z >> 11) * 0x1.0p-53;
    z = z * 6364136223846793005ull + 1442695040888963407ull;
    const double c = double(z >> 11) * 0x1.0p-53;
    deposits.push_back({3.0 * a * a, 3.0 * c, 1e-3});
  }
  for (auto _ : state) {
    const render::AdaptiveKernelDensity2D kde(deposits, 3.0, 3.0);
    benchmark::DoNotOptimize(kde.evaluate_grid(60, 60));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_KernelDensitySurface)->Arg(100000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
