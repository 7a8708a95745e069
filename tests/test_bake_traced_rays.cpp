// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// A trace's exits as a RaySource: the same rays after rewind(), their flux the exit flux, written as TM-25 and
// read back unchanged, and an observer that sees the first pass only.
#include "luminaire_test_scenes.h"

#include <lumx/bake/traced_rays.h>
#include <lumx/io/rayset_io.h>

#include "test_support.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace {

using namespace lumx_test;

lumx::RayChunk drain(lumx::RaySource& source, std::size_t chunk) {
  lumx::RayChunk all, c;
  while (source.next(c, chunk))
    for (std::size_t i = 0; i < c.size(); ++i) all.push_back(c.position(i), c.direction(i), c.flux[i]);
  return all;
}

struct CountingObserver : lumx::bake::ParticleSink {
  std::uint64_t chunks = 0, exits = 0, segments = 0;
  void consume(const lumx::bake::ParticleChunk& c) override {
    ++chunks;
    exits += c.exits.size();
    segments += c.segments.size();
  }
};

TEST(BakeTracedRays, RewindServesTheSameRaysAndTm25KeepsThem) {
  SceneBuilder b("integrating sphere");
  b.begin_part("wall", b.add_material(lambertian(0.7)));
  add_sphere(b, 0.1, 16, 32, 0.6, false);
  b.point_light({0.0, 0.0, 0.02}, 2.0);
  const lumx::bake::Tracer tracer(b.scene());
  lumx::bake::TraceOptions o;
  o.particles = 30000;
  o.record_segments = true;
  CountingObserver observer;
  lumx::bake::TracedRaySource source(tracer, o, 7000, &observer);
  const lumx::RayChunk first = drain(source, 999);
  ASSERT_TRUE(source.first_pass_complete());
  EXPECT_EQ(first.size(), source.counters().exited);
  EXPECT_EQ(source.info().ray_count, first.size());
  EXPECT_EQ(observer.exits, first.size());
  EXPECT_GT(observer.segments, first.size());
  double flux = 0.0;
  for (float f : first.flux) flux += f;
  EXPECT_NEAR(flux, source.counters().exited_lm, 1e-6 * flux);

  source.rewind();
  const lumx::RayChunk second = drain(source, 4096);
  EXPECT_EQ(observer.exits, first.size());  // the observer saw the first pass only
  ASSERT_EQ(second.size(), first.size());
  for (std::size_t i = 0; i < first.size(); ++i) {
    ASSERT_EQ(first.position(i), second.position(i)) << i;
    ASSERT_EQ(first.direction(i), second.direction(i)) << i;
    ASSERT_EQ(first.flux[i], second.flux[i]) << i;
  }

  const auto path = lumx_test::unique_temp_path("lumx_traced_rays.tm25ray");
  lumx::write_tm25(path.string(), source.info(), source);
  auto read = lumx::open_rayset(path.string());
  EXPECT_EQ(read->info().ray_count, first.size());
  const lumx::RayChunk back = drain(*read, 5000);
  ASSERT_EQ(back.size(), first.size());
  for (std::size_t i = 0; i < first.size(); i += 97) {
    EXPECT_NEAR(glm::distance(back.position(i), first.position(i)), 0.0f, 1e-6f) << i;
    EXPECT_EQ(back.flux[i], first.flux[i]) << i;
  }
  std::filesystem::remove(path);
}

}  // namespace
