// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Adaptive-kernel illuminance reconstruction (lumx/render/adaptive_kernel_density.h), Google Benchmark.
//
//   build/bench/lumx_bench_kernel_density [--benchmark_filter=...]
//
// Deposits from the point source 0.5 m above a 3 m × 2 m wall (tests/kernel_density_test_support.h), per
// benchmark argument N = 10⁴, 10⁵, 10⁶ and threads = 1, 2:
//   build/N/threads     building the estimator: bandwidth rule, tabulated pilot, local bandwidths, kd-tree
//   grid256/N/threads   evaluate_grid(256, 256) on a built estimator
//   point/N             one evaluate() at a random point (kd-tree query with the mirror images)
// Counters: h0_m, h_min_m, h_max_m (bandwidths, m) and, for grid256, relative_rmse against the exact field
// (the 10⁶ figure, which the unit tests do not reach).
#include <lumx/render/adaptive_kernel_density.h>

#include "kernel_density_test_support.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <map>

namespace {

using namespace lumx::render;
using namespace lumx_test;

const std::vector<Deposit2D>& deposits(std::size_t n) {
  static std::map<std::size_t, std::vector<Deposit2D>> cache;
  auto it = cache.find(n);
  if (it == cache.end()) it = cache.emplace(n, draw_deposits(point_source_field(), n, 42)).first;
  return it->second;
}

AdaptiveKernelOptions with_threads(int threads) {
  AdaptiveKernelOptions o;
  o.threads = threads;
  return o;
}

void build(benchmark::State& state) {
  const auto& d = deposits(std::size_t(state.range(0)));
  for (auto _ : state) {
    AdaptiveKernelDensity2D e(d, kWallWidth, kWallHeight, with_threads(int(state.range(1))));
    benchmark::DoNotOptimize(e.pilot_bandwidth_m());
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * state.range(0));
}

void grid256(benchmark::State& state) {
  const auto& d = deposits(std::size_t(state.range(0)));
  const AdaptiveKernelDensity2D e(d, kWallWidth, kWallHeight, with_threads(int(state.range(1))));
  std::vector<double> g;
  for (auto _ : state) {
    g = e.evaluate_grid(256, 256);
    benchmark::DoNotOptimize(g.data());
  }
  const auto exact = exact_grid(point_source_field(), 256, 256);
  double se = 0, mean = 0;
  for (std::size_t p = 0; p < g.size(); ++p) se += (g[p] - exact[p]) * (g[p] - exact[p]), mean += exact[p];
  state.counters["relative_rmse"] = std::sqrt(se / double(g.size())) / (mean / double(g.size()));
  state.counters["h0_m"] = e.pilot_bandwidth_m();
  state.counters["h_min_m"] = e.min_bandwidth_m();
  state.counters["h_max_m"] = e.max_bandwidth_m();
}

void point(benchmark::State& state) {
  const auto& d = deposits(std::size_t(state.range(0)));
  const AdaptiveKernelDensity2D e(d, kWallWidth, kWallHeight, with_threads(1));
  UnitRandom r(7);
  for (auto _ : state) benchmark::DoNotOptimize(e.evaluate(r() * kWallWidth, r() * kWallHeight));
}

}  // namespace

BENCHMARK(build)->ArgsProduct({{10000, 100000, 1000000}, {1, 2}})->Unit(benchmark::kMillisecond);
BENCHMARK(grid256)->ArgsProduct({{10000, 100000, 1000000}, {1, 2}})->Unit(benchmark::kMillisecond);
BENCHMARK(point)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
