// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/tracer.h — light particles traced from a luminaire's emitters through its geometry until they exit
// (dissertation 000 §4.2): Embree 3 over all parts, BSDF importance sampling in adjoint transport, Russian
// roulette and a counted depth cap.
//
// Determinism. Particle i's random numbers are a PCG32 stream selected by (seed, i) alone
// (lumx/bake/random.h); particles are traced in fixed chunks of `chunk_particles`, and the sink receives the
// chunks in chunk order, whatever the thread count. Results are therefore bit-identical for any number of
// threads, and a trace of particles [a, b) gives the same particles as the same range of a longer trace.
//
// Estimator. N particles are emitted; an emitter is picked with probability ∝ its flux (luminance), so
// each particle starts with flux Φ_total / N lm (per channel, the emitter's colour). Its flux after a
// bounce is multiplied by the BSDF sample weight f·|cos|/pdf (with the adjoint shading-normal factor) and
// by Beer–Lambert transmittance inside volumes; Russian roulette divides survivors by their survival
// probability. The exiting fluxes are then an unbiased estimate of the luminaire's emission: summed, the
// exit flux; binned by direction, its far field.
#pragma once

#include <lumx/bake/luminaire.h>

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace bake {

/// A particle leaving the luminaire: the point on the last surface it left (or where it was emitted,
/// if it hit nothing), its direction and its flux.
struct ExitParticle {
  glm::vec3 position{0.0f};   ///< m
  glm::vec3 direction{0.0f};  ///< unit
  glm::vec3 flux_lm{0.0f};    ///< per channel; luminance() of it is lm
  std::uint64_t index = 0;    ///< particle index
  std::uint32_t emitter = 0;  ///< emitter it came from
  std::uint32_t bounces = 0;  ///< scattering events before exit
};

/// A straight piece of a particle's path inside the luminaire (from emission or a scattering event to the
/// next surface it hits), for the radiance volume's track-length estimator.
struct PathSegment {
  glm::vec3 origin{0.0f};     ///< m
  glm::vec3 direction{0.0f};  ///< unit, direction of propagation
  float length_m = 0.0f;
  glm::vec3 flux_lm{0.0f};    ///< flux carried along the segment (at its start)
};

/// One chunk's output, in particle order.
struct ParticleChunk {
  std::uint64_t first_particle = 0;
  std::uint64_t particle_count = 0;
  std::vector<ExitParticle> exits;
  std::vector<PathSegment> segments;  ///< empty unless TraceOptions::record_segments
};

/// Receives chunks in chunk order, from one thread at a time.
class ParticleSink {
 public:
  virtual ~ParticleSink() = default;
  virtual void consume(const ParticleChunk& chunk) = 0;
};

struct TraceCounters {
  std::uint64_t emitted = 0;
  std::uint64_t exited = 0;
  std::uint64_t absorbed = 0;       ///< ended by a BSDF that scattered nothing (black, back of one-sided)
  std::uint64_t roulette_killed = 0;
  std::uint64_t depth_capped = 0;   ///< still alive at max_depth
  std::uint64_t leaked = 0;         ///< rejected: geometric and shading normals disagree on a side
  std::uint64_t segments = 0;       ///< straight pieces traced (rays cast)
  double emitted_lm = 0.0;          ///< luminance of the emitted flux
  double exited_lm = 0.0;           ///< luminance of the exiting flux

  void add(const TraceCounters& o);
};

struct TraceOptions {
  std::uint64_t seed = 1;
  std::uint64_t first_particle = 0;     ///< trace particles [first_particle, first_particle + particles)
  std::uint64_t particles = 1000000;
  /// Flux normalisation: each particle carries Φ_total / normalization_particles (0 = `particles`), so a
  /// trace split into passes gives the same fluxes as one trace of all of them.
  std::uint64_t normalization_particles = 0;
  std::uint32_t chunk_particles = 4096;
  int threads = 0;                      ///< 0 = all hardware threads
  int max_depth = 256;                  ///< hard cap on scattering events (counted in depth_capped)
  int roulette_depth = 5;               ///< Russian roulette from this many scattering events on
  bool record_segments = false;
};

/// An Embree scene over a LuminaireScene, built once and traced many times.
class Tracer {
 public:
  /// Throws lumx::Error when the scene has no triangles and no punctual emitter, no emitter with flux, or an
  /// emitter that cannot be sampled (a rayset that cannot be read).
  explicit Tracer(const LuminaireScene& scene);
  ~Tracer();
  Tracer(const Tracer&) = delete;
  Tracer& operator=(const Tracer&) = delete;

  /// Total emitted flux, lm, and per channel.
  double total_flux_lm() const;
  Rgb total_flux_rgb() const;

  /// Traces, delivering chunks to `sink` in order; returns the counters of this trace.
  TraceCounters trace(const TraceOptions& options, ParticleSink& sink) const;

  const LuminaireScene& scene() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bake
LUMX_NAMESPACE_END
