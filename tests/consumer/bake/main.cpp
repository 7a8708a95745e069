// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Traces a Lambertian emissive square (1 cm², 1000 cd/m²) built in code and prints its exit flux, which must
// be π L A = 0.0314159 lm exactly (every particle leaves unobstructed).
#include <lumx/bake/tracer.h>

#include <cmath>
#include <cstdio>

namespace {
struct SumSink : lumx::bake::ParticleSink {
  double lm = 0.0;
  void consume(const lumx::bake::ParticleChunk& c) override {
    for (const auto& x : c.exits) lm += lumx::bake::luminance(glm::dvec3(x.flux_lm));
  }
};
}  // namespace

int main() {
  lumx::bake::LuminaireScene s;
  s.name = "square";
  s.positions = {{0, 0, 0}, {0.01f, 0, 0}, {0.01f, 0.01f, 0}, {0, 0.01f, 0}};
  s.indices = {0, 1, 2, 0, 2, 3};
  s.triangle_part = {0, 0};
  lumx::bake::Material m;
  m.base_color = lumx::bake::Rgb{0.0};
  m.emissive = lumx::bake::Rgb{1.0};
  m.emissive_strength = 1000.0;
  s.materials = {m};
  lumx::bake::Part p;
  p.name = "square";
  p.triangle_count = 2;
  s.parts = {p};
  lumx::bake::Emitter e;
  e.kind = lumx::bake::EmitterKind::surface;
  s.emitters = {e};
  const lumx::bake::Tracer tracer(s);
  lumx::bake::TraceOptions o;
  o.particles = 10000;
  SumSink sink;
  const auto c = tracer.trace(o, sink);
  const double expected = 3.14159265358979 * 1000.0 * 1e-4;
  std::printf("bake consumer: %llu particles, exit flux %.7f lm (pi L A = %.7f lm)\n",
              static_cast<unsigned long long>(c.exited), sink.lm, expected);
  return std::abs(sink.lm - expected) < 1e-5 * expected && c.exited == o.particles ? 0 : 1;
}
