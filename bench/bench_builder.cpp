// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Building APL sets from rays (Google Benchmark).
//
//   build/bench/lumx_bench_builder [--benchmark_filter=...]
//
//   cluster_tree/N   PLOC tree over N seeds (eq. 4.1) and the 1/8/64/256/512 cuts; N = 62.5 k … 1 M shows
//                    the scaling (targets: 250 k < 5 s, 1 M < 20 s on one core)
//   build/N/T        build_apl_set over N synthetic rays (250 k seeds, levels 1…512) with T assignment
//                    threads, then write_bundle; 10 M rays on 2 threads has a "< 60 s" target.
//                    peak_rss_MiB is the process's high-water mark (the 10 M rays themselves are 280 MB).
//   read_tm25/N      stream an N-ray TM-25 file (written first) from the page cache: throughput, memory
//   build_file/N/T   what `lumx build FILE OUT --threads T` does on an N-ray TM-25 file, by phase
//   harmonic_estimate/R/T   the spectral pilot of one level sum (math/sphere_map_harmonics.h): expansion to
//                    degree min(R, 96), shrinkage, synthesis, on a map of 10⁶ rays of a cos^20 lobe, T threads
//   kernel_apply/R/N  one SphereMapKernel::apply (σ 3 texel widths) to a map of N rays of a cos^20 lobe at
//                    R: an APL's sparse map of a 512-APL level (N ≈ 2 000) and a level sum (N = 10⁶); the
//                    held-out fit smooths every map of a level once per kernel width it tries (on a
//                    slow 2-core machine, medians of 3: R 32 66 µs sparse, 133 µs dense; R 128 0.63 ms and
//                    2.3 ms, so a 512-APL level at R 128 takes 0.32 s per width on one thread)
// Rays: 64 emitters on a 0.3 m ring, 1 mm discs, cos³ lobes tilted outwards, in memory (SoA floats).
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/io/photometry_io.h>
#include <lumx/rays/far_field.h>
#include <lumx/io/bundle_builder.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/rayset_io.h>
#include <lumx/math/sphere_map_harmonics.h>
#include <lumx/math/sphere_map_kernel.h>

#include <unistd.h>

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

using namespace lumx;

namespace {

RayChunk ring_rays(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  RayChunk rays;
  rays.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int e = int(i % 64);
    const float angle = float(2 * kPi) * float(e) / 64.0f;
    const glm::vec3 centre(0.3f * std::cos(angle), 0.3f * std::sin(angle), 0.0f);
    const float rho = 0.001f * std::sqrt(u(rng)), phi = float(2 * kPi) * u(rng);
    const float cos_t = std::pow(u(rng), 0.25f), sin_t = std::sqrt(1 - cos_t * cos_t), az = float(2 * kPi) * u(rng);
    glm::vec3 w(sin_t * std::cos(az), sin_t * std::sin(az), -cos_t);
    w = glm::normalize(w + glm::vec3(0.3f * std::cos(angle), 0.3f * std::sin(angle), 0.0f));
    rays.push_back(centre + glm::vec3(rho * std::cos(phi), rho * std::sin(phi), 0.0f), w, 1.0f + float(e % 7));
  }
  return rays;
}

/// The ring rays of ring_rays(), generated chunk by chunk (for writing files without holding them).
class RingSource final : public RaySource {
 public:
  explicit RingSource(std::size_t total) { info_.file = "ring", info_.ray_count = total; }
  const RaysetInfo& info() const override { return info_; }
  bool next(RayChunk& out, std::size_t max_rays) override {
    const std::size_t m = std::min<std::size_t>(max_rays, info_.ray_count - done_);
    if (m == 0) return false;
    out = ring_rays(m, unsigned(done_ + 3));
    done_ += m;
    return true;
  }
  void rewind() override { done_ = 0; }

 private:
  RaysetInfo info_;
  std::size_t done_ = 0;
};

double peak_rss_mib() {
  std::ifstream f("/proc/self/status");
  std::string key;
  while (f >> key)
    if (key == "VmHWM:") {
      double kib;
      f >> kib;
      return kib / 1024.0;
    }
  return 0;
}

void cluster_tree(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0));
  const RayChunk rays = ring_rays(n, 1);
  std::vector<glm::vec3> p(n);
  for (std::size_t i = 0; i < n; ++i) p[i] = rays.position(i);
  for (auto _ : state) {
    const ClusterTree t = build_cluster_tree(p, rays.flux);
    benchmark::DoNotOptimize(cut_cluster_tree(t, {1, 8, 64, 256, 512}));
  }
  state.counters["seeds"] = double(n);
}
BENCHMARK(cluster_tree)->Arg(62500)->Arg(250000)->Arg(1000000)->Unit(benchmark::kSecond)->Iterations(1);

void build(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0));
  RaysetInfo info;
  info.file = "ring";
  MemoryRaySource source(ring_rays(n, 2), info);
  AplBuildReport report;
  AplBuildOptions o;
  o.threads = unsigned(state.range(1));
  const std::string dir = (std::filesystem::temp_directory_path() / ("lumx_bench_build_" + std::to_string(::getpid()))).string();
  double write_s = 0;
  for (auto _ : state) {
    const AplSet set = build_apl_set(source, o, &report);
    const auto t0 = std::chrono::steady_clock::now();
    write_bundle(dir, set);
    write_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  std::filesystem::remove_all(dir);
  state.counters["rays"] = double(n);
  state.counters["threads"] = double(o.threads);
  state.counters["seed_s"] = report.seconds_seed;
  state.counters["tree_s"] = report.seconds_tree;
  state.counters["assign_s"] = report.seconds_assign;
  state.counters["write_s"] = write_s;
  state.counters["R_512"] = report.map_resolution.back();
  state.counters["peak_rss_MiB"] = peak_rss_mib();
}
BENCHMARK(build)->Args({1000000, 1})->Args({10000000, 1})->Args({10000000, 2})->Unit(benchmark::kSecond)->Iterations(1);

/// Streaming a TM-25 file from the page cache: written once with write_tm25, then read whole by
/// summarize_rays (two passes). bytes_per_second counts both passes; peak_rss_MiB is the whole process's
/// high-water mark (writing and reading), against a file of file_MiB.
void read_tm25(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0));
  const std::string path = (std::filesystem::temp_directory_path() / ("lumx_bench_" + std::to_string(::getpid()) + ".tm25ray")).string();
  {
    // Generated chunk by chunk, so writing does not raise the memory high-water mark either.
    RingSource source(n);
    write_tm25(path, source.info(), source);
  }
  const double file_bytes = double(std::filesystem::file_size(path));
  for (auto _ : state) {
    const auto rays = open_rayset(path);
    benchmark::DoNotOptimize(summarize_rays(*rays));
  }
  state.counters["peak_rss_MiB"] = peak_rss_mib();
  state.counters["file_MiB"] = file_bytes / (1 << 20);
  state.SetBytesProcessed(std::int64_t(2 * file_bytes) * std::int64_t(state.iterations()));  // two passes
  std::filesystem::remove(path);
}
BENCHMARK(read_tm25)->Arg(10000000)->Unit(benchmark::kMillisecond)->Iterations(3);

/// What `lumx build FILE OUT --threads T` does (build_bundle, io/bundle_builder.h), on an N-ray TM-25 file
/// written first: stream the file, build the levels, the held-out fit of every level's maps (resolution and
/// kernel) and its error tables, the far field as IES and LDT from level 0's fitted maps, and write the
/// bundle; each phase's seconds and the bundle's bytes (targets: 1 M rays ≤ 30 s, 10 M ≤ 90 s, the
/// 1 M-ray bundle ≤ 8 MiB). Run it alone (--benchmark_filter=build_file) for a meaningful peak_rss_MiB: the
/// in-memory benchmarks above raise the process's high-water mark.
void build_file(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0));
  const auto tmp = std::filesystem::temp_directory_path();
  const std::string path = (tmp / ("lumx_bench_file_" + std::to_string(::getpid()) + ".tm25ray")).string();
  const std::string dir = (tmp / ("lumx_bench_file_" + std::to_string(::getpid()) + ".lumx")).string();
  {
    RingSource source(n);
    write_tm25(path, source.info(), source);
  }
  BundleBuildResult r;
  for (auto _ : state) {
    const auto rays = open_rayset(path);
    BundleBuildOptions o;
    o.apl.threads = unsigned(state.range(1));
    r = build_bundle(*rays, dir, o);
  }
  state.counters["file_MiB"] = double(std::filesystem::file_size(path)) / (1 << 20);
  state.counters["build_s"] = r.seconds_build;
  state.counters["held_out_fit_and_tables_s"] = r.seconds_evaluation;
  state.counters["far_field_s"] = r.seconds_far_field;
  state.counters["write_s"] = r.seconds_write;
  state.counters["bundle_MiB"] = double(r.bytes) / (1 << 20);
  state.counters["R_finest"] = r.resolution.empty() ? 0.0 : double(r.resolution.back());
  state.counters["peak_rss_MiB"] = peak_rss_mib();
  std::filesystem::remove(path);
  std::filesystem::remove_all(dir);
}
BENCHMARK(build_file)->Args({1000000, 2})->Args({10000000, 2})->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

namespace {
/// `rays` rays of a cos^20 lobe about −z binned at R, one channel.
SphereMap cos20_lobe_map(int R, int rays) {
  SphereMap map(R, 1);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < rays; ++i) {
    const double ct = std::pow(u(rng), 1.0 / 21.0), st = std::sqrt(1 - ct * ct), phi = 2 * kPi * u(rng);
    int x, y;
    map.texel_of(glm::vec3(float(st * std::cos(phi)), float(st * std::sin(phi)), float(-ct)), x, y);
    map.at(x, y, 0) += 1.0f;
  }
  return map;
}

void harmonic_estimate_bench(benchmark::State& state) {
  const SphereMap map = cos20_lobe_map(int(state.range(0)), 1000000);
  for (auto _ : state) benchmark::DoNotOptimize(harmonic_estimate(map, unsigned(state.range(1))).estimate.data());
}
}  // namespace
BENCHMARK(harmonic_estimate_bench)->Name("harmonic_estimate")->ArgsProduct({{32, 64, 128}, {1, 2}})->Unit(benchmark::kMillisecond);

namespace {
void kernel_apply(benchmark::State& state) {
  const int R = int(state.range(0));
  const SphereMap map = cos20_lobe_map(R, int(state.range(1)));
  const double texel = std::sqrt(4.0 * kPi / (2.0 * double(R) * double(R)));
  const auto kernel = SphereMapKernel::shared(R, 1.0 / ((3 * texel) * (3 * texel)));
  for (auto _ : state) benchmark::DoNotOptimize(kernel->apply(map).data());
}
}  // namespace
BENCHMARK(kernel_apply)->ArgsProduct({{32, 128}, {2000, 1000000}})->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
