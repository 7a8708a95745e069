// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The appearance renderer of lumx/render/appearance.h: an Embree scene over the luminaire, the eye-path loop
// (radiance transport, next-event estimation to surface and punctual emitters, the glow at n_b, Russian
// roulette in the reference) and the pixel loop in passes.
#include <lumx/render/appearance.h>

#include "bake/path_state.h"

#include <lumx/bake/bsdf.h>
#include <lumx/bake/random.h>
#include <lumx/core/diagnostic.h>
#include <lumx/math/constants.h>
#include <lumx/photometry/intensity_table.h>

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <thread>

LUMX_NAMESPACE_BEGIN
namespace render {

using bake::Bsdf;
using bake::Material;
using bake::Pcg32;
using bake::Rgb;

namespace {

double max_component(const Rgb& c) { return std::max(c.x, std::max(c.y, c.z)); }
bool finite3(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

using bake::detail::Frame;
using bake::detail::MediumStack;
using bake::detail::RayStarts;
using bake::detail::shading_normal;

/// Power heuristic with β = 2 (Veach 1997 §9.2.4).
double power_heuristic(double pdf_a, double pdf_b) {
  const double a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  return a + b > 0.0 ? a / (a + b) : 0.0;
}

std::size_t pick(const std::vector<double>& cdf, double u) {
  const double target = u * cdf.back();
  const auto it = std::upper_bound(cdf.begin(), cdf.end(), target);
  return std::min<std::size_t>(std::size_t(it - cdf.begin()), cdf.size() - 1);
}

/// A punctual emitter as next-event estimation sees it: intensity (cd per channel) toward a world direction.
struct PointSource {
  bake::EmitterKind kind = bake::EmitterKind::point;
  glm::dvec3 position{0.0};
  glm::dmat3 to_local{1.0};  // world direction → the emitter's frame
  Rgb intensity_cd{0.0};     // point, spot: on the axis; ies: colour × multiplier
  double inner = 0.0, outer = 0.0;
  std::shared_ptr<IntensityTable> table;

  Rgb intensity(const glm::dvec3& w) const {
    switch (kind) {
      case bake::EmitterKind::point: return intensity_cd;
      case bake::EmitterKind::spot: {
        const glm::dvec3 l = glm::normalize(to_local * w);
        return intensity_cd * bake::spot_falloff(-l.z, inner, outer);
      }
      case bake::EmitterKind::ies: return intensity_cd * table->intensity(glm::normalize(to_local * w));
      default: return Rgb{0.0};
    }
  }
};

struct PathCounters {
  std::uint64_t rays = 0;
  std::uint64_t depth_capped = 0;
};

}  // namespace

struct AppearanceRenderer::Impl {
  const bake::LuminaireScene& scene;
  const RadianceVolume* volume;
  BackgroundLuminance background;
  RTCDevice device = nullptr;
  RTCScene rtc_scene = nullptr;
  std::vector<Bsdf> bsdfs;
  std::vector<Rgb> absorption;
  /// Per material: every lobe is a Dirac lobe (smooth metal or glass), so next-event estimation adds nothing.
  std::vector<std::uint8_t> has_smooth_lobes_only;
  std::vector<float> vertices;
  std::vector<glm::vec3> triangle_normals;
  RayStarts starts;  // Embree's frame and the self-intersection offset, as the tracer's
  Aabb box;
  // Surface emitters for next-event estimation: emissive triangles ∝ luminance × area.
  std::vector<std::uint32_t> emissive_triangles;
  std::vector<double> emissive_cdf;
  double emissive_weight_total = 0.0;  // Σ Y(L_e) A over emissive triangles, cd/m² · m²
  std::vector<PointSource> point_sources;

  Impl(const bake::LuminaireScene& s, const RadianceVolume* v, BackgroundLuminance bg)
      : scene(s), volume(v), background(std::move(bg)) {
    if (s.triangle_count() == 0)
      throw_at_field(s.name, "triangles", "the luminaire has no triangles: there is nothing for a camera to see");
    for (const Material& m : s.materials) {
      bsdfs.emplace_back(m);
      absorption.push_back(m.absorption_per_m());
      const double r = std::isfinite(m.roughness) ? std::clamp(m.roughness, 0.0, 1.0) : 1.0;
      const bool smooth = r * r < Bsdf::kSmoothAlpha;
      const double metallic = std::isfinite(m.metallic) ? std::clamp(m.metallic, 0.0, 1.0) : 1.0;
      const double transmission = std::isfinite(m.transmission) ? std::clamp(m.transmission, 0.0, 1.0) : 0.0;
      const bool diffuse = (1.0 - metallic) * (1.0 - transmission) > 0.0;
      has_smooth_lobes_only.push_back(smooth && !diffuse ? 1 : 0);
    }
    for (const glm::vec3& p : s.positions) {
      box.lo = glm::min(box.lo, glm::dvec3(p));
      box.hi = glm::max(box.hi, glm::dvec3(p));
    }
    starts = RayStarts(box.lo, box.hi);

    device = rtcNewDevice(nullptr);
    if (!device) throw std::runtime_error("Embree: rtcNewDevice failed");
    rtc_scene = rtcNewScene(device);
    rtcSetSceneFlags(rtc_scene, RTC_SCENE_FLAG_ROBUST);
    vertices.resize(3 * s.positions.size() + 1);  // padded: Embree reads 16 bytes at the last vertex
    for (std::size_t i = 0; i < s.positions.size(); ++i) {
      const glm::vec3 q = starts.to_embree(glm::dvec3(s.positions[i]));
      vertices[3 * i] = q.x;
      vertices[3 * i + 1] = q.y;
      vertices[3 * i + 2] = q.z;
    }
    for (std::size_t p = 0; p < s.parts.size(); ++p) {  // geomID = part index, as in the tracer
      const bake::Part& part = s.parts[p];
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
    rtcCommitScene(rtc_scene);
    if (!s.normals.empty()) {
      triangle_normals.resize(s.indices.size());
      for (std::size_t i = 0; i < s.indices.size(); ++i) triangle_normals[i] = s.normals[s.indices[i]];
    }

    for (const bake::Emitter& e : s.emitters) {
      if (e.kind == bake::EmitterKind::surface) {
        const bake::Part& part = s.parts.at(e.part);
        const double y = bake::luminance(s.materials.at(part.material).emitted_luminance());
        if (!(y > 0.0) || !std::isfinite(y)) continue;
        for (std::uint32_t k = 0; k < part.triangle_count; ++k) {
          const std::uint32_t t = part.first_triangle + k;
          const double a = bake::triangle_area(s, t);
          if (!(a > 0.0) || !std::isfinite(a)) continue;
          emissive_weight_total += y * a;
          emissive_triangles.push_back(t);
          emissive_cdf.push_back(emissive_weight_total);
        }
      } else if (e.kind == bake::EmitterKind::point || e.kind == bake::EmitterKind::spot ||
                 e.kind == bake::EmitterKind::ies) {
        PointSource ps;
        ps.kind = e.kind;
        ps.position = glm::dvec3(e.to_world[3]);
        glm::dmat3 linear(e.to_world);
        for (int c = 0; c < 3; ++c) {
          const double len = glm::length(linear[c]);
          if (len > 0.0) linear[c] /= len;
        }
        if (!(std::abs(glm::determinant(linear)) > 1e-12)) continue;  // the tracer reports singular frames
        ps.to_local = glm::inverse(linear);
        ps.inner = e.inner_cone_rad;
        ps.outer = e.outer_cone_rad;
        if (e.kind == bake::EmitterKind::ies) {
          if (!e.photometry) continue;
          ps.table = std::make_shared<IntensityTable>(*e.photometry);
          ps.intensity_cd = e.color * e.multiplier;
        } else {
          ps.intensity_cd = e.intensity_cd;
        }
        point_sources.push_back(std::move(ps));
      }
    }
  }

  ~Impl() {
    if (rtc_scene) rtcReleaseScene(rtc_scene);
    if (device) rtcReleaseDevice(device);
  }

  RTCRayHit cast(const glm::dvec3& origin, const glm::dvec3& direction, float tfar) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    RTCRayHit rh;
    const glm::vec3 local = starts.to_embree(origin);
    rh.ray.org_x = local.x, rh.ray.org_y = local.y, rh.ray.org_z = local.z;
    rh.ray.dir_x = float(direction.x), rh.ray.dir_y = float(direction.y), rh.ray.dir_z = float(direction.z);
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = tfar;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.time = 0.0f;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rtc_scene, &context, &rh);
    return rh;
  }

  bool occluded(const glm::dvec3& origin, const glm::dvec3& direction, double distance) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    RTCRay ray;
    const glm::vec3 local = starts.to_embree(origin);
    ray.org_x = local.x, ray.org_y = local.y, ray.org_z = local.z;
    ray.dir_x = float(direction.x), ray.dir_y = float(direction.y), ray.dir_z = float(direction.z);
    ray.tnear = 0.0f;
    ray.tfar = float(distance);
    ray.mask = 0xFFFFFFFFu;
    ray.time = 0.0f;
    ray.flags = 0;
    rtcOccluded1(rtc_scene, &context, &ray);
    return ray.tfar < 0.0f;
  }

  glm::dvec3 triangle_vertex(std::size_t t, int k) const { return glm::dvec3(scene.positions[scene.indices[3 * t + k]]); }

  /// Solid-angle density with which next-event estimation picks the point y of an emissive triangle seen
  /// from distance r at cosine cos_l: (Y(L_e) / Σ Y(L_e) A) · r² / cos_l.
  double light_pdf(double emitted_y, double r2, double cos_l) const {
    if (!(emissive_weight_total > 0.0) || !(cos_l > 0.0)) return 0.0;
    return emitted_y / emissive_weight_total * r2 / cos_l;
  }

  /// Direct light at a non-specular vertex (p, geometric normal ng facing wo, shading frame) from one surface
  /// sample and every punctual emitter, weighted by f |wi·ns| and the medium's transmittance.
  /// Next-event estimation at p, reached along d_in after t metres (for where the shadow ray starts).
  Rgb direct_light(const glm::dvec3& p, const glm::dvec3& ng, const glm::dvec3& d_in, double t_in, const Frame& frame,
                   const glm::dvec3& wo_local, const Bsdf& bsdf, const Rgb& sigma_same, const Rgb& sigma_across,
                   Pcg32& rng, PathCounters& counters) const {
    Rgb sum{0.0};
    glm::dvec3 wi_side{0.0};  // set by connect(): the light's direction, to choose the medium
    auto transmittance = [&](double distance) {
      const Rgb& sigma = (wi_side.z > 0.0) == (wo_local.z > 0.0) ? sigma_same : sigma_across;
      Rgb tr{1.0};
      for (int c = 0; c < 3; ++c)
        if (sigma[c] > 0.0) tr[c] = std::exp(-sigma[c] * distance);
      return tr;
    };
    auto connect = [&](const glm::dvec3& target, glm::dvec3& wi, double& distance, glm::dvec3& wi_local) {
      const glm::dvec3 v = target - p;
      distance = glm::length(v);
      if (!(distance > 0.0)) return false;
      wi = v / distance;
      wi_local = frame.to_local(wi);
      wi_side = wi_local;
      // The geometric and shading sides must agree (no light through the surface by its shading normal).
      if ((glm::dot(wi, ng) > 0.0) != (wi_local.z > 0.0)) return false;
      // As a path's next ray: a shadow ray on the side the path arrived from steps back along its segment,
      // so that at a concave edge it cannot start in the plane of the other face and pass through it.
      const glm::dvec3 origin = starts.after_hit(p, ng, d_in, t_in, wi);
      const glm::dvec3 to_target = target - origin;
      const double reach = glm::length(to_target);
      counters.rays += 1;
      return !(reach > 0.0) || !occluded(origin, to_target / reach, reach * (1.0 - 1e-4) - starts.scale);
    };

    const double u_light = rng.next_double(), u1 = rng.next_double(), u2 = rng.next_double();
    if (!emissive_triangles.empty()) {
      const std::uint32_t t = emissive_triangles[pick(emissive_cdf, u_light)];
      const double su = std::sqrt(u1);  // uniform on the triangle (Turk 1990)
      const glm::dvec3 a = triangle_vertex(t, 0), b = triangle_vertex(t, 1), c = triangle_vertex(t, 2);
      const glm::dvec3 y = (1.0 - su) * a + su * (1.0 - u2) * b + su * u2 * c;
      glm::dvec3 nl = glm::cross(b - a, c - a);
      const double nl_len = glm::length(nl);
      const Material& m = scene.materials[scene.parts[scene.triangle_part[t]].material];
      glm::dvec3 wi, wi_local;
      double distance = 0.0;
      if (nl_len > 0.0 && connect(y, wi, distance, wi_local)) {
        nl /= nl_len;
        const double cos_front = -glm::dot(wi, nl);  // > 0: the vertex sees the emitter's front
        const double cos_l = std::abs(cos_front);
        if ((cos_front > 0.0 || m.double_sided) && cos_l > 0.0) {
          const Rgb le = m.emitted_luminance();
          const double pdf_light = light_pdf(bake::luminance(le), distance * distance, cos_l);
          const Rgb f = bsdf.eval(wo_local, wi_local, bake::TransportMode::radiance);
          const double pdf_bsdf = bsdf.pdf(wo_local, wi_local);
          if (pdf_light > 0.0 && max_component(f) > 0.0)
            sum += f * le * transmittance(distance) *
                   (std::abs(wi_local.z) * power_heuristic(pdf_light, pdf_bsdf) / pdf_light);
        }
      }
    }
    for (const PointSource& ps : point_sources) {
      glm::dvec3 wi, wi_local;
      double distance = 0.0;
      if (!connect(ps.position, wi, distance, wi_local)) continue;
      const Rgb f = bsdf.eval(wo_local, wi_local, bake::TransportMode::radiance);
      if (!(max_component(f) > 0.0)) continue;
      // E = I(−wi) / r² on a surface facing the source; the cosine is the BSDF's |wi·ns|.
      sum += f * ps.intensity(-wi) * transmittance(distance) * (std::abs(wi_local.z) / (distance * distance));
    }
    return sum;
  }

  /// Luminance (cd/m² per channel) arriving at the eye along `ray` (see appearance.h for what a path sees).
  Rgb radiance(glm::dvec3 origin, glm::dvec3 direction, const AppearanceOptions& o, Pcg32& rng,
               PathCounters& counters) const {
    const bool reference = o.depth < 0;
    const bool use_glow = !reference && o.glow && volume != nullptr;
    Rgb sum{0.0}, beta{1.0};
    MediumStack media;
    int scatterings = 0;
    bool specular_before = true;  // the eye "vertex" counts as specular: emitters seen directly get weight 1
    double pdf_before = 0.0;      // solid-angle pdf of the last BSDF sample (non-delta)
    glm::dvec3 previous = origin;

    for (;;) {
      const RTCRayHit rh = cast(origin, direction, std::numeric_limits<float>::infinity());
      counters.rays += 1;
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
        if (background) {
          const glm::dvec3 bg = background(previous, direction);
          if (finite3(bg)) sum += beta * glm::max(bg, glm::dvec3(0.0));
        }
        return sum;
      }
      const double t = double(rh.ray.tfar);
      if (!media.empty() && t > 0.0) {
        const Rgb& sigma = absorption[scene.parts[media.top()].material];
        for (int c = 0; c < 3; ++c)
          if (sigma[c] > 0.0) beta[c] *= std::exp(-sigma[c] * t);
      }
      const std::uint32_t part_index = rh.hit.geomID;
      const std::size_t tri = std::size_t(scene.parts[part_index].first_triangle) + rh.hit.primID;
      const std::uint32_t material_index = scene.parts[part_index].material;
      const Material& material = scene.materials[material_index];
      const glm::dvec3 position = origin + t * direction;
      glm::dvec3 ng{rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
      const double ng_len = glm::length(ng);
      if (!(ng_len > 0.0) || !std::isfinite(ng_len)) {  // degenerate triangle: pass straight through
        origin = position + starts.scale * direction;
        continue;
      }
      ng /= ng_len;
      glm::dvec3 ns = shading_normal(ng, triangle_normals, tri, rh.hit.u, rh.hit.v);
      const glm::dvec3 wo = -direction;
      const bool front = glm::dot(wo, ng) > 0.0;

      // Emission: the front of a surface emitter, or either side when double-sided.
      const Rgb le = material.emitted_luminance();
      const bool emits = bake::luminance(le) > 0.0 && (front || material.double_sided);
      if (emits) {
        double weight = 1.0;
        if (!specular_before) {
          const double cos_l = std::abs(glm::dot(wo, ng));
          weight = power_heuristic(pdf_before, light_pdf(bake::luminance(le), t * t, cos_l));
        }
        sum += beta * le * weight;
      }

      // The end of a depth-limited path: the glow of what lies beyond (non-emissive surfaces only).
      if (!reference && scatterings >= o.depth) {
        if (use_glow && !emits) {
          // Radiance is constant along the segment inside the luminaire, so after a scattering event the
          // lookup moves back toward the last vertex by up to one voxel: off the surface, into voxels the
          // particles' segments filled from every side (the volume holds no exits, so voxels straddling an
          // outer wall are part empty). The eye ray's first hit is looked up where it is.
          const double back = scatterings > 0 ? std::min(0.5 * t, volume->voxel_size()) : 0.0;
          const glm::vec3 g = volume->radiance(position - back * direction, -direction);
          sum += beta * glm::dvec3(g);
        }
        return sum;
      }
      if (reference && scatterings >= o.reference_max_depth) {
        counters.depth_capped += 1;
        return sum;
      }

      const bool thin_two_sided = !material.volume && (material.double_sided || material.transmission > 0.0 ||
                                                       material.diffuse_transmission > 0.0);
      if (!front && !material.volume) {
        if (!thin_two_sided) return sum;  // the back of a one-sided opaque surface is black
        ng = -ng;
        ns = -ns;
      }
      const Frame frame(ns);
      const glm::dvec3 wo_local = frame.to_local(wo);
      if ((glm::dot(wo, ng) > 0.0) != (wo_local.z > 0.0)) return sum;  // shading normal leaks (Veach §5.3)
      const Bsdf& bsdf = bsdfs[material_index];

      const Rgb sigma = media.empty() ? Rgb{0.0} : absorption[scene.parts[media.top()].material];
      // Next-event estimation wherever a non-specular lobe exists; its light paths end at depth
      // scatterings + 1, within the same limit as the hits it is combined with.
      if (has_smooth_lobes_only[material_index] == 0) {
        // The medium on the far side of the surface, for a light sampled through a solid's boundary.
        Rgb sigma_across = sigma;
        if (material.volume) {
          MediumStack across = media;
          if (front)
            across.push(part_index);
          else
            across.remove(part_index);
          sigma_across = across.empty() ? Rgb{0.0} : absorption[scene.parts[across.top()].material];
        }
        sum += beta * direct_light(position, ng, direction, t, frame, wo_local, bsdf, sigma, sigma_across, rng, counters);
      }

      const double u_lobe = rng.next_double();
      const glm::dvec2 u{rng.next_double(), rng.next_double()};
      const std::optional<bake::BsdfSample> s = bsdf.sample(wo_local, u_lobe, u, bake::TransportMode::radiance);
      if (!s || !(max_component(s->weight) > 0.0)) return sum;
      const glm::dvec3 wi = glm::normalize(frame.to_world(s->wi));
      const double wi_ng = glm::dot(wi, ng);
      if ((wi_ng > 0.0) != (s->wi.z > 0.0) || wi_ng == 0.0) return sum;
      beta *= s->weight;  // radiance transport: no shading-normal correction
      if (!finite3(beta)) return sum;
      if (material.volume && s->transmitted) {
        if (front)
          media.push(part_index);
        else
          media.remove(part_index);
      }
      ++scatterings;
      specular_before = s->delta;
      pdf_before = s->pdf;

      if (reference && scatterings >= o.roulette_depth) {
        const double q = std::min(1.0, max_component(beta));
        if (rng.next_double() >= q) return sum;
        beta /= q;
      }
      previous = position;
      origin = starts.after_hit(position, ng, direction, t, wi);
      direction = wi;
    }
  }
};

AppearanceRenderer::AppearanceRenderer(const bake::LuminaireScene& scene, const RadianceVolume* volume,
                                       BackgroundLuminance background)
    : impl_(std::make_unique<Impl>(scene, volume, std::move(background))) {}
AppearanceRenderer::~AppearanceRenderer() = default;

Aabb AppearanceRenderer::bounds() const { return impl_->box; }
bool AppearanceRenderer::has_volume() const { return impl_->volume != nullptr; }

Image AppearanceRenderer::luminaire_mask(const PinholeCamera& camera) const {
  const std::string why = camera.invalid_reason();
  if (!why.empty()) throw_at_field("camera", "camera", why);
  Image mask(camera.width, camera.height, {"mask"});
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const CameraRay r = camera.ray(x + 0.5, y + 0.5);
      const RTCRayHit rh = impl_->cast(r.origin, r.direction, std::numeric_limits<float>::infinity());
      mask.at(x, y) = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? 0.0f : 1.0f;
    }
  return mask;
}

AppearanceImage AppearanceRenderer::render(const PinholeCamera& camera, const AppearanceOptions& o) const {
  const std::string why = camera.invalid_reason();
  if (!why.empty()) throw_at_field("camera", "camera", why);
  if (o.samples_per_pixel < 1) throw_at_field("options", "samples_per_pixel", "must be at least 1");
  if (o.depth < kReferenceDepth) throw_at_field("options", "depth", "must be >= 0 (or kReferenceDepth)");
  if (o.pass_samples < 1) throw_at_field("options", "pass_samples", "must be at least 1");
  const auto start = std::chrono::steady_clock::now();
  const int w = camera.width, h = camera.height;
  const std::size_t pixels = std::size_t(w) * std::size_t(h);
  std::vector<glm::dvec3> sum_even(pixels, glm::dvec3(0.0)), sum_odd(pixels, glm::dvec3(0.0));
  const int threads = o.threads > 0 ? o.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  tbb::task_arena arena(threads);
  std::atomic<std::uint64_t> rays{0}, capped{0};
  const std::uint64_t seed_mix = bake::mix64(o.seed ^ 0x61707065617261ULL);  // "appeara"

  int done = 0;
  while (done < o.samples_per_pixel) {
    const int begin = done, end = std::min(o.samples_per_pixel, done + o.pass_samples);
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
        PathCounters counters;
        for (int y = rows.begin(); y < rows.end(); ++y)
          for (int x = 0; x < w; ++x) {
            const std::size_t p = std::size_t(y) * std::size_t(w) + std::size_t(x);
            for (int s = begin; s < end; ++s) {
              // Sample s of pixel p: its own stream, whatever the thread, pass or order.
              Pcg32 rng(seed_mix ^ bake::mix64(std::uint64_t(s) * 0x9e3779b97f4a7c15ULL + p), p);
              const double jx = rng.next_double(), jy = rng.next_double();
              const CameraRay ray = camera.ray(x + jx, y + jy);
              const Rgb l = impl_->radiance(ray.origin, ray.direction, o, rng, counters);
              const Rgb value = finite3(l) ? l : Rgb{0.0};
              (s % 2 == 0 ? sum_even[p] : sum_odd[p]) += value;
            }
          }
        rays += counters.rays;
        capped += counters.depth_capped;
      });
    });
    done = end;
    if (o.progress) o.progress(double(done) / double(o.samples_per_pixel));
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (o.time_limit_seconds > 0 && elapsed >= o.time_limit_seconds && done >= 2) break;
  }

  AppearanceImage out;
  out.samples_per_pixel = done;
  out.image = Image(w, h, {"R", "G", "B"});
  out.first_half = Image(w, h, {"R", "G", "B"});
  out.second_half = Image(w, h, {"R", "G", "B"});
  const double n_even = double((done + 1) / 2), n_odd = double(done / 2);
  for (std::size_t p = 0; p < pixels; ++p)
    for (int c = 0; c < 3; ++c) {
      out.image.pixels[3 * p + c] = float((sum_even[p][c] + sum_odd[p][c]) / double(done));
      out.first_half.pixels[3 * p + c] = float(sum_even[p][c] / n_even);
      out.second_half.pixels[3 * p + c] = n_odd > 0 ? float(sum_odd[p][c] / n_odd) : out.first_half.pixels[3 * p + c];
    }
  out.rays = rays;
  out.depth_capped = capped;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace render
LUMX_NAMESPACE_END
