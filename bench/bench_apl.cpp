// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// APL queries against this machine's measured ceiling (Google Benchmark).
//
//   build/bench/lumx_bench_apl [--benchmark_filter=...]
//
// The set: levels of 1, 8, 64, 256 and 512 APLs with 256 × 512 RGB maps (the dissertation's default,
// 000 §4.6), filled with smooth random lobes; ~1.3 GB of float maps in memory. Reported per call:
//   intensity         one bilinear map lookup (math/sphere_map.h) in a random direction
//   bare_lookup       the ceiling loop of performance.md §3c, measured here in the same run: bilinear RGB
//                     lookups at random (map, u, v) over the 512 maps, no direction mapping
//   irradiance/N      irradiance(x, n) summed over level N at random shading points in a 2 m box, and at
//                     coherent ones (a raster of neighbouring points, as a renderer's pixels are);
//                     ns_per_light = time / N, to compare with bare_lookup
//   atan2f_alone, direction_to_square, sh_evaluate_4_bands   the pieces a lookup and a volume deposit use
//   sample/pdf        SphereMapSampler on a 256 × 512 map
//   volume            RadianceVolume::radiance at random points and directions (32³, 4 bands, RGB)
// Bytes per level (memory and disk) are printed by the `bundle_bytes` benchmark as counters.
#include <lumx/apl/evaluation.h>
#include <lumx/apl/apl_set.h>
#include <lumx/apl/error.h>
#include <lumx/apl/map_fit.h>
#include <lumx/io/bundle_io.h>
#include <lumx/volume/radiance_volume.h>
#include <lumx/math/spherical_harmonics.h>
#include <lumx/math/sphere_map_sampler.h>

#include <benchmark/benchmark.h>

#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <random>

using namespace lumx;

namespace {

constexpr int kResolution = 256;

SphereMap lobe_map(std::mt19937& rng, int R = kResolution) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const glm::vec3 axis = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, -1.0f));
  const float sharp = 1.0f + 30.0f * u(rng), scale = 10.0f + 100.0f * u(rng);
  SphereMap m(R, 3);
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x) {
      const glm::vec3 w = sphere_map::uv_to_direction({(x + 0.5f) / m.width(), (y + 0.5f) / m.height()});
      const float v = scale * std::pow(std::max(0.0f, glm::dot(w, axis)), sharp) + 0.5f;
      m.at(x, y, 0) = v;
      m.at(x, y, 1) = 0.9f * v;
      m.at(x, y, 2) = 0.8f * v;
    }
  // Ask for transparent huge pages, as performance.md §3c recommends for the map pool (+15–30 %).
  ::madvise(m.data(), m.bytes(), MADV_HUGEPAGE);
  return m;
}

/// The finest level holds 512 random lobes; each coarser level sums groups of children, so the levels
/// are cuts of one tree (as a builder makes them) and the set passes check_apl_set.
const AplSet& big_set() {
  static const AplSet set = [] {
    AplSet s;
    s.channels = ChannelLayout::rgb;
    s.bounds.radius = 0.3;
    std::mt19937 rng(42);
    std::uniform_real_distribution<float> u(-0.3f, 0.3f);
    const int counts[] = {1, 8, 64, 256, 512};
    std::vector<AplLevel> levels(5);
    levels[4].map_resolution = kResolution;
    for (int i = 0; i < 512; ++i) {
      Apl a;
      a.position = {u(rng), u(rng), u(rng)};
      a.parent = i / 2;
      a.map = lobe_map(rng);
      levels[4].apls.push_back(std::move(a));
    }
    for (int k = 3; k >= 0; --k) {
      const int n = counts[k], group = counts[k + 1] / n;
      levels[std::size_t(k)].map_resolution = kResolution;
      for (int p = 0; p < n; ++p) {
        Apl a;
        a.parent = k == 0 ? -1 : p / (n / counts[k - 1]);
        a.map = SphereMap(kResolution, 3);
        ::madvise(a.map.data(), a.map.bytes(), MADV_HUGEPAGE);
        glm::vec3 centre(0.0f);
        for (int c = p * group; c < (p + 1) * group; ++c) {
          const Apl& child = levels[std::size_t(k + 1)].apls[std::size_t(c)];
          for (std::size_t t = 0; t < a.map.values().size(); ++t) a.map.values()[t] += child.map.values()[t];
          centre += child.position;
        }
        a.position = centre / float(group);
        levels[std::size_t(k)].apls.push_back(std::move(a));
      }
    }
    s.levels = std::move(levels);
    update_fluxes(s);
    return s;
  }();
  return set;
}

std::vector<glm::vec3> random_directions(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g;
  std::vector<glm::vec3> d(n);
  for (auto& v : d) v = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
  return d;
}

/// Times `query(direction)` over 4096 random directions, cycled.
template <class Query>
void over_random_directions(benchmark::State& state, unsigned seed, Query query) {
  const auto dirs = random_directions(4096, seed);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(query(dirs[i]));
    i = (i + 1) & 4095;
  }
}

void intensity(benchmark::State& state) {
  std::mt19937 rng(1);
  const SphereMap map = lobe_map(rng);
  over_random_directions(state, 2, [&](const glm::vec3& w) { return map.lookup(w); });
}
BENCHMARK(intensity);

// What the direction → square map costs, against glibc's atan2f that it replaced (math/sphere_map.h).
void atan2f_alone(benchmark::State& state) {
  over_random_directions(state, 3, [](const glm::vec3& w) { return std::atan2(w.y, w.x); });
}
BENCHMARK(atan2f_alone);

void direction_to_square(benchmark::State& state) {
  over_random_directions(state, 3, [](const glm::vec3& w) {
    int half;
    return sphere_map::direction_to_square(w, half);
  });
}
BENCHMARK(direction_to_square);

// Real SH up to band 3 (16 coefficients), Sloan's recurrences (math/spherical_harmonics.h).
void sh_evaluate_4_bands(benchmark::State& state) {
  float y[16];
  over_random_directions(state, 4, [&](const glm::vec3& w) {
    sh::evaluate(glm::dvec3(w), 4, y);
    benchmark::DoNotOptimize(y);  // all 16 coefficients are observed, so none is optimised away
    return y[15];
  });
}
BENCHMARK(sh_evaluate_4_bands);

void bare_lookup(benchmark::State& state) {
  const AplLevel& level = big_set().levels[4];
  std::uint64_t s = 0x9E3779B97F4A7C15ull;
  auto next = [&] {  // splitmix64, as in the ceiling measurement
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  };
  const int W = 2 * kResolution, H = kResolution;
  for (auto _ : state) {
    const std::uint64_t r = next();
    const SphereMap& m = level.apls[r % level.size()].map;
    const float px = float((r >> 16) & 0xFFFF) * (float(W - 1) / 65536.0f);
    const float py = float((r >> 32) & 0xFFFF) * (float(H - 1) / 65536.0f);
    const int x = int(px), y = int(py);
    const float tx = px - float(x), ty = py - float(y);
    const glm::vec3 v = (m.texel(x, y) * (1 - tx) + m.texel(x + 1, y) * tx) * (1 - ty) +
                        (m.texel(x, y + 1) * (1 - tx) + m.texel(x + 1, y + 1) * tx) * ty;
    benchmark::DoNotOptimize(v);
  }
}
BENCHMARK(bare_lookup);

void irradiance_at(benchmark::State& state, bool coherent) {
  const AplSet& set = big_set();
  const std::size_t k = std::size_t(state.range(0));
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<glm::vec3> points(4096);
  for (std::size_t i = 0; i < points.size(); ++i)
    points[i] = coherent ? glm::vec3(-0.5f + float(i % 64) * 0.002f, -0.5f + float(i / 64) * 0.002f, -1.0f)
                         : glm::vec3(u(rng), u(rng), -1.0f + 0.5f * u(rng));
  const glm::vec3 n(0, 0, 1);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(irradiance(set, k, points[i], n).irradiance);
    i = (i + 1) & 4095;
  }
  const double lights = double(set.levels[k].size());
  state.counters["lights"] = lights;
  state.counters["ns_per_light"] =
      benchmark::Counter(double(state.iterations()) * lights, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
void irradiance_random(benchmark::State& state) { irradiance_at(state, false); }
void irradiance_coherent(benchmark::State& state) { irradiance_at(state, true); }
BENCHMARK(irradiance_random)->DenseRange(0, 4)->Unit(benchmark::kMicrosecond);

/// One level of 512 one-channel APLs (as the builder makes them) at map resolution R = range(0): the
/// cost of a shading point against the size of the maps the held-out fit chooses (R 16–32 for 1 M rays
/// of smooth emitters) and the rule's R 128. The maps are the box-downsampled copies of one R 128 set.
/// range(1) = 1 draws them in a turned MapFrame (a beam's, apl_set.h): the cost of turning each
/// direction before its lookup.
void irradiance_512_apls_by_resolution(benchmark::State& state) {
  static const AplSet fine = [] {
    AplSet s;
    s.bounds.radius = 0.3;
    std::mt19937 rng(42);
    std::uniform_real_distribution<float> u(-0.3f, 0.3f);
    AplLevel level;
    level.map_resolution = 128;
    for (int i = 0; i < 512; ++i) {
      Apl a;
      a.position = {u(rng), u(rng), u(rng)};
      SphereMap rgb = lobe_map(rng, 128);
      a.map = SphereMap(128, 1);
      for (std::size_t t = 0; t < a.map.values().size(); ++t) a.map.values()[t] = rgb.values()[3 * t];
      level.apls.push_back(std::move(a));
    }
    s.levels.push_back(std::move(level));
    update_fluxes(s);
    return s;
  }();
  AplSet set = fine;
  set.levels[0] = downsampled_level(fine.levels[0], int(state.range(0)));
  if (state.range(1) != 0) set.levels[0].frame = map_frame_for(glm::dvec3(0.2, -0.1, -1.0));
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<glm::vec3> points(4096);
  for (glm::vec3& p : points) p = glm::vec3(u(rng), u(rng), -1.0f + 0.5f * u(rng));
  const glm::vec3 n(0, 0, 1);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(irradiance(set, 0, points[i], n).irradiance);
    i = (i + 1) & 4095;
  }
  state.counters["map_bytes"] = double(set.levels[0].map_bytes());
}
BENCHMARK(irradiance_512_apls_by_resolution)
    ->Args({16, 0})->Args({32, 0})->Args({64, 0})->Args({128, 0})->Args({32, 1})->Args({128, 1})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(irradiance_coherent)->DenseRange(0, 4)->Unit(benchmark::kMicrosecond);

/// range(0) point sources behind four square apertures each (apl/point_sources.h), R 4 maps as the fit
/// chose for the box with holes, read plain (range(1) = 0) or inside their beam masks (1): what a mask's
/// containment test (caps × log vertices) and coverage lookup add per light.
void irradiance_masked_apls(benchmark::State& state) {
  const int sources = int(state.range(0));
  const bool masked = state.range(1) != 0;
  AplSet set;
  set.bounds.radius = 0.1;
  AplLevel level;
  level.map_resolution = 4;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < sources; ++i) {
    Apl a;
    a.position = glm::vec3(0.05f * float(u(rng)), 0.05f * float(u(rng)), 0.05f * float(u(rng)));
    std::vector<glm::dvec3> dirs;
    const glm::dvec3 axes[4] = {{0, 0, -1}, {1, 0, -1}, {-1, 0, -1}, {0, 1, -1}};
    for (const glm::dvec3& axis : axes)  // 20 000 directions through a 0.3 × 0.3 square about each axis
      for (int j = 0; j < 20000; ++j) {
        const glm::dvec3 z = glm::normalize(axis), x = glm::normalize(glm::cross(z, glm::dvec3(0, 1, 0.1)));
        dirs.push_back(glm::normalize(z + 0.15 * u(rng) * x + 0.15 * u(rng) * glm::cross(z, x)));
      }
    a.mask = std::make_shared<const DirectionMask>(*DirectionMask::from_directions(dirs));
    a.map = SphereMap(4, 1);
    for (const glm::dvec3& w : dirs) {
      int x, y;
      a.map.texel_of(glm::vec3(w), x, y);
      a.map.at(x, y, 0) += 1.0f;
    }
    refresh_coverage(a, level.frame);
    if (!masked) a.mask.reset(), a.coverage = SphereMap();
    level.apls.push_back(std::move(a));
  }
  set.levels.push_back(std::move(level));
  update_fluxes(set);
  std::vector<glm::vec3> points(4096);
  for (glm::vec3& p : points) p = glm::vec3(float(u(rng)), float(u(rng)), -1.0f + 0.5f * float(u(rng)));
  const glm::vec3 n(0, 0, 1);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(irradiance(set, 0, points[i], n).irradiance);
    i = (i + 1) & 4095;
  }
  state.counters["ns_per_light"] = benchmark::Counter(double(state.iterations()) * sources,
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(irradiance_masked_apls)->Args({2, 0})->Args({2, 1})->Args({64, 0})->Args({64, 1})->Unit(benchmark::kMicrosecond);

void sample(benchmark::State& state) {
  std::mt19937 rng(4);
  const SphereMap map = lobe_map(rng);
  const SphereMapSampler sampler(map);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<glm::vec2> us(4096);
  for (auto& v : us) v = {u(rng), u(rng)};
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(sampler.sample(us[i].x, us[i].y));
    i = (i + 1) & 4095;
  }
}
BENCHMARK(sample);

void pdf(benchmark::State& state) {
  std::mt19937 rng(5);
  const SphereMap map = lobe_map(rng);
  const SphereMapSampler sampler(map);
  over_random_directions(state, 6, [&](const glm::vec3& w) { return sampler.pdf(w); });
}
BENCHMARK(pdf);

void volume(benchmark::State& state) {
  RadianceVolume v(Aabb{glm::dvec3(-0.3), glm::dvec3(0.3)}, 32768, 4, 3);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (int i = 0; i < 20000; ++i)
    v.add_segment({u(rng), u(rng), u(rng)}, glm::normalize(glm::dvec3(u(rng), u(rng), u(rng))), 0.3,
                  glm::vec3(1.0f));
  std::vector<glm::dvec3> xs(4096), ws(4096);
  for (std::size_t i = 0; i < xs.size(); ++i) {
    xs[i] = {u(rng), u(rng), u(rng)};
    ws[i] = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
  }
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(v.radiance(xs[i], ws[i]));
    i = (i + 1) & 4095;
  }
}
BENCHMARK(volume);

/// Track-length deposits (000 §4.4) as a bake makes them: segments of 0.2 m through the luminaire's box
/// on a 32³ grid with 4 SH bands and 3 channels. items/s counts voxel-segments (one per voxel a segment
/// crosses, the unit of work of the deposit loop); the segment rate is items/s over their mean count.
void volume_add_segment(benchmark::State& state) {
  RadianceVolume v(Aabb{glm::dvec3(-0.3), glm::dvec3(0.3)}, 32768, 4, 3);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  constexpr std::size_t kSegments = 4096;
  constexpr double kLength = 0.2;
  std::vector<glm::dvec3> origin(kSegments), direction(kSegments);
  std::vector<std::uint64_t> voxels(kSegments);
  const glm::dvec3 lo = v.bounds().lo;
  for (std::size_t i = 0; i < kSegments; ++i) {
    origin[i] = {u(rng), u(rng), u(rng)};
    direction[i] = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
    // Voxels crossed: one, plus one per grid plane crossed on each axis (within the grid).
    const RayInterval span = v.bounds().clip(origin[i], direction[i], 0.0, kLength);
    const glm::dvec3 a = origin[i] + span.t0 * direction[i], b = origin[i] + span.t1 * direction[i];
    voxels[i] = 1;
    for (int k = 0; k < 3; ++k)
      voxels[i] += std::uint64_t(std::abs(std::floor((b[k] - lo[k]) / v.voxel_size()) -
                                          std::floor((a[k] - lo[k]) / v.voxel_size())));
  }
  std::size_t i = 0;
  std::uint64_t deposited = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(v.add_segment(origin[i], direction[i], kLength, glm::vec3(1.0f)));
    deposited += voxels[i];
    i = (i + 1) % kSegments;
  }
  state.SetItemsProcessed(std::int64_t(deposited));
  state.counters["voxels_per_segment"] = double(deposited) / double(std::max<std::int64_t>(1, state.iterations()));
}
BENCHMARK(volume_add_segment);

/// Bytes per level in memory (float maps) and on disk (the bundle's payloads: half, ZIP, with mips).
void bundle_bytes(benchmark::State& state) {
  const AplSet& set = big_set();
  const std::string dir = (std::filesystem::temp_directory_path() / ("lumx_bench_bundle_" + std::to_string(::getpid()))).string();
  for (auto _ : state) write_bundle(dir, set);
  const BundleReader r(dir);
  for (std::size_t k = 0; k < set.levels.size(); ++k) {
    const std::string n = std::to_string(set.levels[k].size());
    state.counters["mem_MiB_L" + n] = double(set.levels[k].map_bytes()) / (1 << 20);
    state.counters["disk_MiB_L" + n] = double(r.manifest().levels[k].maps[0].bytes) / (1 << 20);
  }
  state.counters["disk_MiB_total"] = double(r.manifest().total_bytes()) / (1 << 20);
  std::filesystem::remove_all(dir);
}
BENCHMARK(bundle_bytes)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
