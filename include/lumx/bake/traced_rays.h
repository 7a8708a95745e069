// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/traced_rays.h — a trace's exiting particles as a RaySource (a virtual near-field goniophotometer):
// next() traces the next batch of particles and serves their exits as rays (start point on the last surface,
// direction, flux in lm); rewind() starts again from particle 0 and, the trace being deterministic, serves the
// same rays bit for bit. So the APL builder, the TM-25 writer and the held-out evaluators read a luminaire's
// light exactly as they read a measured rayset, and particles are never all in memory.
#pragma once

#include <lumx/bake/tracer.h>
#include <lumx/rays/rayset.h>

#include <cstddef>
#include <cstdint>

LUMX_NAMESPACE_BEGIN
namespace bake {

class TracedRaySource : public RaySource {
 public:
  /// `options.particles` particles in all (first_particle must be 0), traced `batch_particles` at a time.
  /// `observer`, if given, receives every traced chunk in order (segments too, when
  /// options.record_segments) once: each particle the first time it is traced — e.g. to fill a radiance volume.
  TracedRaySource(const Tracer& tracer, const TraceOptions& options, std::uint64_t batch_particles = 1u << 17,
                  ParticleSink* observer = nullptr);

  const RaysetInfo& info() const override { return info_; }
  bool next(RayChunk& out, std::size_t max_rays) override;
  void rewind() override;

  /// Counters of the first complete pass (valid once next() has returned false once).
  const TraceCounters& counters() const { return counters_; }
  bool first_pass_complete() const { return first_pass_complete_; }

 private:
  bool refill();

  const Tracer& tracer_;
  TraceOptions options_;
  std::uint64_t batch_;
  ParticleSink* observer_;
  RaysetInfo info_;
  std::uint64_t next_particle_ = 0;
  std::uint64_t observed_until_ = 0;  // particles [0, observed_until_) were shown to the observer
  RayChunk pending_;
  std::size_t pending_position_ = 0;
  TraceCounters counters_, pass_counters_;
  bool first_pass_complete_ = false;
};

}  // namespace bake
LUMX_NAMESPACE_END
