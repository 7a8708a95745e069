// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Particle tracing throughput against the ray-casting ceiling on the same scene, in the same run:
//   BM_TraceParticles/<scene>/<threads>   particles/s and path segments/s of lumx::bake::Tracer
//   BM_RawIntersect/<scene>/<threads>     rtcIntersect1 rays/s: incoherent rays from random points in the
//                                          luminaire's box in uniform directions (a generic ceiling)
//   BM_ReplayRays/<scene>/<threads>       rtcIntersect1 rays/s on exactly the rays a trace casts (recorded
//                                          segments and exits, replayed in order): the ceiling of that trace
// Scenes: 0 = the procedural prismatic pendant (277 824 triangles), 1 = the flower lamp from ../shared
// (7 898 triangles; skipped when absent). Compare segments/s with rays/s of the same scene and thread count.
#include "procedural_luminaire.h"

#include <lumx/bake/gltf_reader.h>
#include <lumx/bake/random.h>
#include <lumx/bake/tracer.h>

#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <filesystem>
#include <map>
#include <limits>
#include <memory>

namespace {

const lumx::bake::LuminaireScene* scene_for(int index) {
  if (index == 0) {
    static const auto pendant = std::make_unique<lumx::bake::LuminaireScene>(lumx_bench::prismatic_pendant());
    return pendant.get();
  }
  static const std::unique_ptr<lumx::bake::LuminaireScene> flower = []() -> std::unique_ptr<lumx::bake::LuminaireScene> {
    const std::filesystem::path path =
        std::filesystem::path(LUMX_SHARED_DIR_DEFAULT) / "data/luminaires/zhu2021-flower/flower.glb";
    if (!std::filesystem::exists(path)) return nullptr;
    return std::make_unique<lumx::bake::LuminaireScene>(lumx::bake::read_gltf_luminaire(path.string()));
  }();
  return flower.get();
}

struct CountingSink : lumx::bake::ParticleSink {
  std::uint64_t exits = 0;
  void consume(const lumx::bake::ParticleChunk& c) override { exits += c.exits.size(); }
};

void BM_TraceParticles(benchmark::State& state) {
  const auto* scene = scene_for(int(state.range(0)));
  if (!scene) {
    state.SkipWithError("the flower lamp is not in ../shared");
    return;
  }
  static std::map<int, std::unique_ptr<lumx::bake::Tracer>> tracers;
  auto& tracer = tracers[int(state.range(0))];
  if (!tracer) tracer = std::make_unique<lumx::bake::Tracer>(*scene);
  lumx::bake::TraceOptions o;
  o.particles = 200000;
  o.threads = int(state.range(1));
  std::uint64_t particles = 0, segments = 0;
  for (auto _ : state) {
    CountingSink sink;
    const auto c = tracer->trace(o, sink);
    o.seed += 1;
    particles += c.emitted;
    segments += c.segments;
    benchmark::DoNotOptimize(sink.exits);
  }
  state.counters["particles_per_s"] = benchmark::Counter(double(particles), benchmark::Counter::kIsRate);
  state.counters["segments_per_s"] = benchmark::Counter(double(segments), benchmark::Counter::kIsRate);
  state.counters["segments_per_particle"] = double(segments) / double(std::max<std::uint64_t>(1, particles));
}

/// The rays a trace of `particles` particles casts: every internal segment and every exit ray.
std::vector<RTCRay> traced_rays(const lumx::bake::LuminaireScene& scene, std::uint64_t particles) {
  struct RecordingSink : lumx::bake::ParticleSink {
    std::vector<RTCRay> rays;
    void add(const glm::vec3& o, const glm::vec3& d) {
      RTCRay r;
      r.org_x = o.x, r.org_y = o.y, r.org_z = o.z;
      r.dir_x = d.x, r.dir_y = d.y, r.dir_z = d.z;
      r.tnear = 0.0f, r.tfar = std::numeric_limits<float>::infinity(), r.mask = 0xFFFFFFFFu, r.time = 0.0f, r.flags = 0;
      rays.push_back(r);
    }
    void consume(const lumx::bake::ParticleChunk& c) override {
      for (const auto& s : c.segments) add(s.origin, s.direction);
      for (const auto& x : c.exits) add(x.position, x.direction);
    }
  } sink;
  const lumx::bake::Tracer tracer(scene);
  lumx::bake::TraceOptions o;
  o.particles = particles;
  o.record_segments = true;
  tracer.trace(o, sink);
  return std::move(sink.rays);
}

void cast_rays(benchmark::State& state, const lumx::bake::LuminaireScene* scene, const std::vector<RTCRay>* given);

void BM_ReplayRays(benchmark::State& state) {
  const auto* scene = scene_for(int(state.range(0)));
  if (!scene) {
    state.SkipWithError("the flower lamp is not in ../shared");
    return;
  }
  static std::map<int, std::vector<RTCRay>> recorded;
  auto& rays = recorded[int(state.range(0))];
  if (rays.empty()) rays = traced_rays(*scene, 60000);
  cast_rays(state, scene, &rays);
}

void BM_RawIntersect(benchmark::State& state) {
  const auto* scene = scene_for(int(state.range(0)));
  if (!scene) {
    state.SkipWithError("the flower lamp is not in ../shared");
    return;
  }
  cast_rays(state, scene, nullptr);
}

void cast_rays(benchmark::State& state, const lumx::bake::LuminaireScene* scene, const std::vector<RTCRay>* given) {
  RTCDevice device = rtcNewDevice(nullptr);
  RTCScene rtc = rtcNewScene(device);
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), scene->positions.size()));
  glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < scene->positions.size(); ++i) {
    vb[3 * i] = scene->positions[i].x, vb[3 * i + 1] = scene->positions[i].y, vb[3 * i + 2] = scene->positions[i].z;
    lo = glm::min(lo, scene->positions[i]);
    hi = glm::max(hi, scene->positions[i]);
  }
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                            3 * sizeof(unsigned), scene->triangle_count()));
  std::copy(scene->indices.begin(), scene->indices.end(), ib);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(rtc, geom);
  rtcReleaseGeometry(geom);
  rtcSetSceneFlags(rtc, RTC_SCENE_FLAG_ROBUST);
  rtcCommitScene(rtc);

  std::vector<RTCRay> rays(given ? given->size() : std::size_t(1) << 18);
  const std::size_t n = rays.size();
  if (given) std::copy(given->begin(), given->end(), rays.begin());
  lumx::bake::Pcg32 rng(1, 2);
  for (auto& r : rays) {
    if (given) break;
    const double z = 1 - 2 * rng.next_double(), phi = 2 * lumx::kPi * rng.next_double(), s = std::sqrt(1 - z * z);
    r.org_x = lo.x + float(rng.next_double()) * (hi.x - lo.x);
    r.org_y = lo.y + float(rng.next_double()) * (hi.y - lo.y);
    r.org_z = lo.z + float(rng.next_double()) * (hi.z - lo.z);
    r.dir_x = float(s * std::cos(phi)), r.dir_y = float(s * std::sin(phi)), r.dir_z = float(z);
    r.tnear = 0.0f, r.tfar = std::numeric_limits<float>::infinity(), r.mask = 0xFFFFFFFFu, r.time = 0.0f, r.flags = 0;
  }
  tbb::task_arena arena(int(state.range(1)));
  std::uint64_t cast = 0;
  for (auto _ : state) {
    std::atomic<unsigned> hits{0};
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
        unsigned local = 0;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          RTCRayHit rh;
          rh.ray = rays[i];
          rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
          rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
          rtcIntersect1(rtc, &context, &rh);
          local += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        }
        hits += local;
      });
    });
    cast += n;
    benchmark::DoNotOptimize(hits.load());
  }
  state.counters["rays_per_s"] = benchmark::Counter(double(cast), benchmark::Counter::kIsRate);
  rtcReleaseScene(rtc);
  rtcReleaseDevice(device);
}

}  // namespace

BENCHMARK(BM_TraceParticles)->ArgsProduct({{0, 1}, {1, 2}})->ArgNames({"scene", "threads"})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReplayRays)->ArgsProduct({{0, 1}, {1, 2}})->ArgNames({"scene", "threads"})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RawIntersect)->ArgsProduct({{0, 1}, {1, 2}})->ArgNames({"scene", "threads"})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
