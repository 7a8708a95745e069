// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The appearance renderer (lumx/render/appearance.h) on the prismatic pendant of procedural_luminaire.h: eye
// paths per second at several depths n_b and for the path-traced reference, by thread count. The pendant's
// emitters are seen through its refractor, so deep paths are the common case.
#include "procedural_luminaire.h"

#include <lumx/render/appearance.h>

#include <benchmark/benchmark.h>

namespace {

const lumx::bake::LuminaireScene& pendant() {
  static const lumx::bake::LuminaireScene scene = lumx_bench::prismatic_pendant();
  return scene;
}

lumx::render::PinholeCamera view(const lumx::Aabb& box) {
  lumx::render::PinholeCamera c;
  const glm::dvec3 centre = box.center();
  const double radius = 0.5 * glm::length(box.extent());
  c.position = centre + 3.0 * radius * glm::normalize(glm::dvec3(1.0, -1.3, -0.9));
  c.look_at = centre;
  c.vertical_fov_deg = 40.0;
  c.width = 64;
  c.height = 48;
  return c;
}

// Arguments: depth (−1 = reference), threads.
void BM_RenderAppearance(benchmark::State& state) {
  const lumx::render::AppearanceRenderer renderer(pendant(), nullptr, [](const glm::dvec3&, const glm::dvec3&) {
    return glm::dvec3(10.0);  // a uniform grey room, cd/m²
  });
  const lumx::render::PinholeCamera camera = view(renderer.bounds());
  lumx::render::AppearanceOptions o;
  o.depth = int(state.range(0));
  o.threads = int(state.range(1));
  o.samples_per_pixel = 4;
  std::uint64_t rays = 0;
  for (auto _ : state) {
    const lumx::render::AppearanceImage image = renderer.render(camera, o);
    rays += image.rays;
    benchmark::DoNotOptimize(image.image.pixels.data());
  }
  const double paths = double(state.iterations()) * camera.width * camera.height * o.samples_per_pixel;
  state.counters["paths/s"] = benchmark::Counter(paths, benchmark::Counter::kIsRate);
  state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(BM_RenderAppearance)
    ->ArgsProduct({{0, 2, 8, -1}, {1, 2}})
    ->ArgNames({"depth", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_MAIN();
