// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// TracedRaySource: exits served as rays, one batch of particles at a time.
#include <lumx/bake/traced_rays.h>

#include <lumx/core/diagnostic.h>

#include <algorithm>
#include <limits>

LUMX_NAMESPACE_BEGIN
namespace bake {
namespace {

/// Collects a batch's exits as rays (luminance flux) and forwards chunks to an observer.
struct BatchSink : ParticleSink {
  RayChunk* rays = nullptr;
  ParticleSink* observer = nullptr;
  void consume(const ParticleChunk& c) override {
    for (const ExitParticle& x : c.exits)
      rays->push_back(x.position, x.direction, float(luminance(glm::dvec3(x.flux_lm))));
    if (observer) observer->consume(c);
  }
};

}  // namespace

TracedRaySource::TracedRaySource(const Tracer& tracer, const TraceOptions& options, std::uint64_t batch_particles,
                                 ParticleSink* observer)
    : tracer_(tracer), options_(options), batch_(std::max<std::uint64_t>(1, batch_particles)), observer_(observer) {
  if (options_.first_particle != 0)
    throw std::invalid_argument("TracedRaySource: traces start at particle 0 (rewind() restarts there)");
  options_.normalization_particles = options_.normalization_particles ? options_.normalization_particles
                                                                      : options_.particles;
  info_.file = tracer.scene().name;
  info_.format = "lumx trace";
  info_.version = "1";
  info_.quantity = PhotometricQuantity::photometric;
  info_.simulated = true;
  // The exit count is known only after a pass; until then ray_count is the particle count (an upper bound).
  info_.ray_count = options_.particles;
  // The exit flux is known once a pass is complete (then set); the emitted flux is kept as a named value.
  info_.header_flux = std::numeric_limits<double>::quiet_NaN();
  info_.values["emitted luminous flux lm"] = tracer.total_flux_lm();
  info_.text["light source"] = tracer.scene().name;
}

bool TracedRaySource::refill() {
  pending_.clear();
  pending_position_ = 0;
  while (pending_.empty() && next_particle_ < options_.particles) {
    TraceOptions o = options_;
    o.first_particle = next_particle_;
    o.particles = std::min(batch_, options_.particles - next_particle_);
    BatchSink sink;
    sink.rays = &pending_;
    // Each particle reaches the observer once, even when a pass is cut short by rewind().
    const bool observe = observer_ && o.first_particle >= observed_until_;
    sink.observer = observe ? observer_ : nullptr;
    if (!observe) o.record_segments = false;
    pass_counters_.add(tracer_.trace(o, sink));
    next_particle_ += o.particles;
    if (observe) observed_until_ = next_particle_;
  }
  if (!pending_.empty()) return true;
  if (!first_pass_complete_) {
    first_pass_complete_ = true;
    counters_ = pass_counters_;
    info_.ray_count = counters_.exited;
    info_.header_flux = counters_.exited_lm;
  }
  return false;
}

bool TracedRaySource::next(RayChunk& out, std::size_t max_rays) {
  out.clear();
  if (pending_position_ >= pending_.size() && !refill()) return false;
  const std::size_t end = std::min(pending_.size(), pending_position_ + std::max<std::size_t>(1, max_rays));
  out.reserve(end - pending_position_);
  for (std::size_t i = pending_position_; i < end; ++i)
    out.push_back(pending_.position(i), pending_.direction(i), pending_.flux[i]);
  pending_position_ = end;
  return true;
}

void TracedRaySource::rewind() {
  next_particle_ = 0;
  pending_.clear();
  pending_position_ = 0;
  pass_counters_ = TraceCounters{};
}

}  // namespace bake
LUMX_NAMESPACE_END
