// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The particle tracer of lumx/bake/tracer.h: emitter sampling, the Embree scene, the path loop and the ordered,
// chunked parallel driver.
#include <lumx/bake/tracer.h>

#include "bake/emitter_sampler.h"
#include "bake/path_state.h"

#include <lumx/bake/bsdf.h>
#include <lumx/bake/random.h>

#include <embree3/rtcore.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <thread>

LUMX_NAMESPACE_BEGIN
namespace bake {

void TraceCounters::add(const TraceCounters& o) {
  emitted += o.emitted;
  exited += o.exited;
  absorbed += o.absorbed;
  roulette_killed += o.roulette_killed;
  depth_capped += o.depth_capped;
  leaked += o.leaked;
  segments += o.segments;
  emitted_lm += o.emitted_lm;
  exited_lm += o.exited_lm;
}

namespace {

double max_component(const Rgb& c) { return std::max(c.x, std::max(c.y, c.z)); }

using detail::Frame;
using detail::MediumStack;
using detail::RayStarts;
using detail::shading_normal;

}  // namespace

struct Tracer::Impl {
  const LuminaireScene& scene;
  RTCDevice device = nullptr;
  RTCScene rtc_scene = nullptr;
  std::vector<Bsdf> bsdfs;                 // one per material
  std::vector<Rgb> absorption;             // per material, 1/m
  std::vector<std::uint8_t> part_volume;   // per part: its material is a closed solid
  EmitterSampler emitters;
  RayStarts starts;                         // Embree's frame and the self-intersection offset

  std::vector<float> vertices;              // Embree's shared vertex buffer, in its frame (RayStarts)
  std::vector<glm::vec3> triangle_normals;  // 3 per triangle, in vertex order (empty: flat shading)
  std::vector<MediumStack> emitter_media;  // per emitter: the solids its light starts in (innermost on top)

  explicit Impl(const LuminaireScene& s) : scene(s), emitters(s) {
    for (const Material& m : s.materials) {
      bsdfs.emplace_back(m);
      absorption.push_back(m.absorption_per_m());
    }
    part_volume.resize(s.parts.size());
    for (std::size_t p = 0; p < s.parts.size(); ++p) part_volume[p] = s.materials.at(s.parts[p].material).volume;

    glm::dvec3 lo{std::numeric_limits<double>::infinity()}, hi{-std::numeric_limits<double>::infinity()};
    for (const glm::vec3& p : s.positions) {
      lo = glm::min(lo, glm::dvec3(p));
      hi = glm::max(hi, glm::dvec3(p));
    }
    if (!s.positions.empty()) starts = RayStarts(lo, hi);

    device = rtcNewDevice(nullptr);
    if (!device) throw std::runtime_error("Embree: rtcNewDevice failed");
    rtc_scene = rtcNewScene(device);
    rtcSetSceneFlags(rtc_scene, RTC_SCENE_FLAG_ROBUST);
    if (s.triangle_count() > 0) {
      // One Embree geometry per part (geomID = part index, so a hit names its part without a lookup), all
      // sharing one vertex buffer (padded: Embree reads 16 bytes at the last vertex).
      vertices.resize(3 * s.positions.size() + 1);
      for (std::size_t i = 0; i < s.positions.size(); ++i) {
        const glm::vec3 v = starts.to_embree(glm::dvec3(s.positions[i]));
        vertices[3 * i] = v.x;
        vertices[3 * i + 1] = v.y;
        vertices[3 * i + 2] = v.z;
      }
      for (std::size_t p = 0; p < s.parts.size(); ++p) {
        const Part& part = s.parts[p];
        if (part.triangle_count == 0) continue;
        RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vertices.data(), 0,
                                   3 * sizeof(float), s.positions.size());
        rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, s.indices.data(),
                                   std::size_t(part.first_triangle) * 3 * sizeof(std::uint32_t),
                                   3 * sizeof(std::uint32_t), part.triangle_count);
        rtcCommitGeometry(geom);
        rtcAttachGeometryByID(rtc_scene, geom, unsigned(p));
        rtcReleaseGeometry(geom);
      }
      // The three vertex normals of each triangle side by side: one cache line per hit instead of four.
      if (!s.normals.empty()) {
        triangle_normals.resize(s.indices.size());
        for (std::size_t i = 0; i < s.indices.size(); ++i) triangle_normals[i] = s.normals[s.indices[i]];
      }
    }
    rtcCommitScene(rtc_scene);

    // Which solids each emitter sits in (a point light inside a glass ball starts inside the glass).
    emitter_media.resize(s.emitters.size());
    for (std::size_t e = 0; e < s.emitters.size(); ++e) {
      const Emitter& em = s.emitters[e];
      if (em.kind == EmitterKind::surface) {
        const Part& part = s.parts.at(em.part);
        if (part.triangle_count == 0) continue;
        const std::uint32_t t = part.first_triangle;
        const glm::dvec3 a = s.positions[s.indices[3 * t]], b = s.positions[s.indices[3 * t + 1]],
                         c = s.positions[s.indices[3 * t + 2]];
        const glm::dvec3 n = glm::cross(b - a, c - a);
        if (!(glm::length(n) > 0.0)) continue;
        const glm::dvec3 centroid = (a + b + c) / 3.0, nn = glm::normalize(n);
        emitter_media[e] = media_at(starts.off_surface(centroid, nn, nn), std::uint32_t(part.material));
      } else {
        emitter_media[e] = media_at(glm::dvec3(em.to_world[3]), std::uint32_t(-1));
      }
    }
  }

  /// The volume parts enclosing point p, innermost on top: walk a ray from p and note the solids it leaves
  /// through their inside (back) face before entering them. `skip_material` marks the emitter's own surface.
  MediumStack media_at(const glm::dvec3& p, std::uint32_t skip_material) const {
    MediumStack found;
    std::vector<std::uint32_t> entered;
    const glm::dvec3 d = glm::normalize(glm::dvec3(0.2718281828, 0.3141592653, 0.9));  // off every axis
    glm::dvec3 o = p;
    for (int step = 0; step < 256; ++step) {
      RTCRayHit rh = cast(o, d);
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
      const std::uint32_t part = rh.hit.geomID;
      glm::dvec3 ng{rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
      const glm::dvec3 hit = o + double(rh.ray.tfar) * d;
      if (glm::length(ng) > 0.0) {
        ng = glm::normalize(ng);
        if (part_volume[part] && scene.parts[part].material != skip_material) {
          const auto it = std::find(entered.begin(), entered.end(), part);
          if (glm::dot(d, ng) < 0.0)
            entered.push_back(part);
          else if (it != entered.end())
            entered.erase(it);
          else if (found.size < MediumStack::kCapacity)
            found.part[found.size++] = part;  // outward order: innermost first
        }
        o = starts.off_surface(hit, ng, d);
      } else {
        o = hit + starts.scale * d;
      }
    }
    MediumStack stack;  // innermost on top
    for (int i = found.size - 1; i >= 0; --i) stack.push(found.part[i]);
    return stack;
  }

  RTCRayHit cast(const glm::dvec3& origin, const glm::dvec3& direction) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    RTCRayHit rh;
    const glm::vec3 local = starts.to_embree(origin);
    rh.ray.org_x = local.x, rh.ray.org_y = local.y, rh.ray.org_z = local.z;
    rh.ray.dir_x = float(direction.x), rh.ray.dir_y = float(direction.y), rh.ray.dir_z = float(direction.z);
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.time = 0.0f;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    // Embree requires every coordinate of the origin and direction to be finite and below 1.8e18
    // (FLT_LARGE; its debug builds assert it): a ray from out there, or one whose path overflowed, hits
    // nothing (found by fuzz_gltf: tests/data/fuzz/gltf/embree_ray_origin_beyond_flt_large.glb).
    constexpr float kEmbreeLarge = 1.8e18f;
    for (const float v : {rh.ray.org_x, rh.ray.org_y, rh.ray.org_z, rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z})
      if (!(std::abs(v) < kEmbreeLarge)) return rh;
    rtcIntersect1(rtc_scene, &context, &rh);
    return rh;
  }

  ~Impl() {
    if (rtc_scene) rtcReleaseScene(rtc_scene);
    if (device) rtcReleaseDevice(device);
  }

  void trace_particle(std::uint64_t index, const TraceOptions& o, double particle_flux, ParticleChunk& out,
                      TraceCounters& c) const;
};

Tracer::Tracer(const LuminaireScene& scene) : impl_(std::make_unique<Impl>(scene)) {}
Tracer::~Tracer() = default;

double Tracer::total_flux_lm() const { return impl_->emitters.total_flux_lm(); }
Rgb Tracer::total_flux_rgb() const { return impl_->emitters.total_flux_rgb(); }
const LuminaireScene& Tracer::scene() const { return impl_->scene; }

void Tracer::Impl::trace_particle(std::uint64_t index, const TraceOptions& o, double particle_flux,
                                  ParticleChunk& out, TraceCounters& c) const {
  Pcg32 rng(mix64(o.seed) ^ mix64(index + 0x5bd1e995ULL), index);
  const EmittedParticle e = emitters.sample(rng);
  c.emitted += 1;
  Rgb beta = particle_flux * e.flux_weight;  // per channel; luminance(e.flux_weight) = weight
  c.emitted_lm += luminance(beta);
  const double beta0_max = std::max(max_component(beta), 1e-300);
  if (!(max_component(beta) > 0.0)) {
    c.absorbed += 1;
    return;
  }

  glm::dvec3 position = e.position;
  glm::dvec3 direction = e.direction;
  glm::dvec3 origin = e.has_surface ? starts.off_surface(e.position, e.surface_normal, e.direction) : e.position;
  // Rayset rays start anywhere: find their solids per particle; other emitters sit in fixed ones.
  MediumStack media = scene.emitters[e.emitter].kind == EmitterKind::rayset ? media_at(e.position, std::uint32_t(-1))
                                                                           : emitter_media[e.emitter];
  std::uint32_t bounces = 0;

  for (;;) {
    const RTCRayHit rh = cast(origin, direction);
    c.segments += 1;

    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
      if (!(max_component(beta) > 0.0)) {  // nothing left to carry (an opaque-tinted solid): not an exit
        c.absorbed += 1;
        return;
      }
      ExitParticle x;
      x.position = glm::vec3(position);
      x.direction = glm::vec3(direction);
      x.flux_lm = glm::vec3(beta);
      x.index = index;
      x.emitter = e.emitter;
      x.bounces = bounces;
      out.exits.push_back(x);
      c.exited += 1;
      c.exited_lm += luminance(beta);
      return;
    }

    const double t = double(rh.ray.tfar);
    // Beer–Lambert inside the current solid: transmittance exp(−σ t) over the segment. The segment carries
    // its mean flux over its length, Φ₀ (1 − e^{−σt}) / (σt), so the radiance volume's track-length deposit
    // Φ ℓ is right inside absorbing glass too.
    Rgb mean_flux = beta;
    if (!media.empty() && t > 0.0) {
      const Rgb& sigma = absorption[scene.parts[media.top()].material];
      for (int ch = 0; ch < 3; ++ch) {
        if (!(sigma[ch] > 0.0)) continue;
        const double tau = sigma[ch] * t, transmittance = std::exp(-tau);
        mean_flux[ch] = beta[ch] * (tau > 1e-8 ? -std::expm1(-tau) / tau : 1.0);
        beta[ch] *= transmittance;
      }
    }
    if (o.record_segments) {
      PathSegment seg;
      seg.origin = glm::vec3(origin);
      seg.direction = glm::vec3(direction);
      seg.length_m = float(t);
      seg.flux_lm = glm::vec3(mean_flux);
      out.segments.push_back(seg);
    }

    const std::uint32_t part_index = rh.hit.geomID;
    const std::size_t tri = std::size_t(scene.parts[part_index].first_triangle) + rh.hit.primID;
    const std::uint32_t material_index = scene.parts[part_index].material;
    const Material& material = scene.materials[material_index];
    // Embree's Ng is (v1 − v0) × (v2 − v0): the counter-clockwise front side, as glTF's winding.
    glm::dvec3 ng{rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
    const double ng_len = glm::length(ng);
    position = origin + t * direction;
    if (!(ng_len > 0.0) || !std::isfinite(ng_len)) {  // degenerate triangle: pass straight through
      origin = position + starts.scale * direction;
      continue;
    }
    ng /= ng_len;
    glm::dvec3 ns = shading_normal(ng, triangle_normals, tri, rh.hit.u, rh.hit.v);

    const glm::dvec3 wo = -direction;
    const bool front = glm::dot(wo, ng) > 0.0;
    const bool thin_two_sided =
        !material.volume && (material.double_sided || material.transmission > 0.0 || material.diffuse_transmission > 0.0);
    if (!front && !material.volume) {
      if (!thin_two_sided) {  // the back of a one-sided opaque surface is black
        c.absorbed += 1;
        return;
      }
      ng = -ng;
      ns = -ns;
    }

    if (bounces >= std::uint32_t(o.max_depth)) {
      c.depth_capped += 1;
      return;
    }
    ++bounces;

    const Frame frame(ns);
    const glm::dvec3 wo_local = frame.to_local(wo);
    // Light leaks: wo must lie on the same side of the geometric and the shading surface (Veach 1997 §5.3).
    if ((glm::dot(wo, ng) > 0.0) != (wo_local.z > 0.0)) {
      c.leaked += 1;
      return;
    }
    const double u_lobe = rng.next_double();
    const glm::dvec2 u{rng.next_double(), rng.next_double()};
    const std::optional<BsdfSample> s = bsdfs[material_index].sample(wo_local, u_lobe, u, TransportMode::importance);
    if (!s || !(max_component(s->weight) > 0.0)) {
      c.absorbed += 1;
      return;
    }
    const glm::dvec3 wi = glm::normalize(frame.to_world(s->wi));
    const double wi_ng = glm::dot(wi, ng);
    if ((wi_ng > 0.0) != (s->wi.z > 0.0) || wi_ng == 0.0) {
      c.leaked += 1;
      return;
    }
    // Adjoint shading-normal correction (Veach 1997 eq. 5.17): |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|).
    const double correction = std::abs(wo_local.z) * std::abs(wi_ng) /
                              std::max(std::abs(glm::dot(wo, ng)) * std::abs(s->wi.z), 1e-300);
    beta *= s->weight * correction;
    if (!(std::isfinite(beta.x) && std::isfinite(beta.y) && std::isfinite(beta.z))) {
      c.absorbed += 1;  // a non-finite weight is a defect; end the path rather than poison the sums
      return;
    }

    if (material.volume && s->transmitted) {
      if (front)
        media.push(part_index);
      else
        media.remove(part_index);
    }

    if (int(bounces) >= o.roulette_depth) {
      // Survival ∝ throughput relative to the emitted flux (capped at 1): particles that lost most of their
      // flux end early, survivors are re-weighted by 1/q so the estimate stays unbiased.
      const double q = std::min(1.0, max_component(beta) / beta0_max);
      if (rng.next_double() >= q) {
        c.roulette_killed += 1;
        return;
      }
      beta /= q;
    }

    origin = starts.after_hit(position, ng, direction, t, wi);
    direction = wi;
  }
}

TraceCounters Tracer::trace(const TraceOptions& o, ParticleSink& sink) const {
  TraceCounters total;
  if (o.particles == 0) return total;
  const std::uint64_t normalization = o.normalization_particles ? o.normalization_particles : o.particles;
  const double particle_flux = impl_->emitters.total_flux_lm() / double(normalization);
  const std::uint64_t chunk = std::max<std::uint32_t>(1, o.chunk_particles);
  const std::uint64_t chunks = (o.particles + chunk - 1) / chunk;
  const int threads = o.threads > 0 ? o.threads : int(std::max(1u, std::thread::hardware_concurrency()));

  struct Work {
    ParticleChunk chunk;
    TraceCounters counters;
  };
  std::uint64_t next_chunk = 0;
  tbb::task_arena arena(threads);
  arena.execute([&] {
    tbb::parallel_pipeline(
        std::size_t(2 * threads),
        tbb::make_filter<void, std::uint64_t>(tbb::filter_mode::serial_in_order,
                                              [&](tbb::flow_control& fc) -> std::uint64_t {
                                                if (next_chunk >= chunks) {
                                                  fc.stop();
                                                  return 0;
                                                }
                                                return next_chunk++;
                                              }) &
            tbb::make_filter<std::uint64_t, std::shared_ptr<Work>>(
                tbb::filter_mode::parallel,
                [&](std::uint64_t k) {
                  auto w = std::make_shared<Work>();
                  const std::uint64_t begin = o.first_particle + k * chunk;
                  const std::uint64_t end = o.first_particle + std::min(o.particles, (k + 1) * chunk);
                  w->chunk.first_particle = begin;
                  w->chunk.particle_count = end - begin;
                  w->chunk.exits.reserve(end - begin);
                  for (std::uint64_t i = begin; i < end; ++i)
                    impl_->trace_particle(i, o, particle_flux, w->chunk, w->counters);
                  return w;
                }) &
            tbb::make_filter<std::shared_ptr<Work>, void>(tbb::filter_mode::serial_in_order,
                                                          [&](const std::shared_ptr<Work>& w) {
                                                            sink.consume(w->chunk);
                                                            total.add(w->counters);
                                                          }));
  });
  return total;
}

}  // namespace bake
LUMX_NAMESPACE_END
