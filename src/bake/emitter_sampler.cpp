// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Emitter sampling for the particle tracer (see emitter_sampler.h for the estimator of each kind).
#include "bake/emitter_sampler.h"

#include <lumx/io/rayset_io.h>
#include <lumx/math/constants.h>
#include <lumx/math/sphere_map.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

LUMX_NAMESPACE_BEGIN
namespace bake {
namespace {

/// Most rays a rayset emitter holds in memory (28 bytes each): 50 M rays = 1.4 GB.
constexpr std::uint64_t kMaxEmitterRays = 50'000'000;
/// Resolution of the equal-area map an IES emitter's directions are drawn from (2 · 64² texels).
constexpr int kIesSamplingResolution = 64;

/// Index i with cdf[i−1] ≤ u·total < cdf[i] (cdf inclusive, increasing, last = total).
std::size_t pick(const std::vector<double>& cdf, double u) {
  const double target = u * cdf.back();
  const auto it = std::upper_bound(cdf.begin(), cdf.end(), target);
  return std::min<std::size_t>(std::size_t(it - cdf.begin()), cdf.size() - 1);
}

/// The rotation of a node's frame: its linear part orthonormalised (Gram–Schmidt on the columns, keeping the
/// −z axis lights shine along exact, and handedness). Scale and shear do not change an emitter's
/// intensities (KHR_lights_punctual, EXT_lights_ies); a singular frame has no direction and is refused.
bool rotation_of(const glm::dmat4& m, glm::dmat3& r) {
  glm::dvec3 z(m[2]), x(m[0]);
  const double lz = glm::length(z);
  if (!(lz > 0.0) || !std::isfinite(lz)) return false;
  z /= lz;
  x -= glm::dot(x, z) * z;
  const double lx = glm::length(x);
  if (!(lx > 1e-12 * glm::length(glm::dvec3(m[0]))) || !std::isfinite(lx)) return false;
  x /= lx;
  glm::dvec3 y = glm::cross(z, x);
  if (glm::dot(y, glm::dvec3(m[1])) < 0.0) y = -y;  // keep a mirrored frame mirrored
  r = glm::dmat3(x, y, z);
  return true;
}

glm::dvec3 uniform_sphere(double u1, double u2) {
  const double z = 1.0 - 2.0 * u1, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

/// Cosine-weighted direction about +z (Malley's method).
glm::dvec3 cosine_hemisphere(double u1, double u2) {
  const double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u1))};
}

/// Any unit vector pair completing n to an orthonormal basis.
void basis(const glm::dvec3& n, glm::dvec3& s, glm::dvec3& t) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z), b = n.x * n.y * a;
  s = {1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x};
  t = {b, sign + n.y * n.y * a, -n.y};
}

}  // namespace

EmitterSampler::EmitterSampler(const LuminaireScene& scene) : scene_(scene) {
  double cumulative = 0.0;
  for (std::size_t ei = 0; ei < scene.emitters.size(); ++ei) {
    const Emitter& e = scene.emitters[ei];
    const Rgb flux = emitter_flux_rgb(scene, e);
    const double flux_y = luminance(flux);
    if (!(flux_y > 0.0) || !std::isfinite(flux_y)) continue;  // lumx check reports zero-flux emitters
    Source s;
    s.kind = e.kind;
    s.colour = flux / flux_y;
    s.to_world = e.to_world;
    if ((e.kind == EmitterKind::spot || e.kind == EmitterKind::ies || e.kind == EmitterKind::rayset) &&
        !rotation_of(e.to_world, s.rotation))
      throw_at_field(scene.name, e.source.empty() ? e.name : e.source,
                     std::string(to_string(e.kind)) + " emitter '" + e.name +
                         "': its node's transform is singular (a zero scale), so it has no direction");
    switch (e.kind) {
      case EmitterKind::surface: {
        const Part& part = scene.parts.at(e.part);
        double area = 0.0;
        for (std::uint32_t k = 0; k < part.triangle_count; ++k) {
          const std::uint32_t t = part.first_triangle + k;
          const double a = triangle_area(scene, t);
          if (!(a > 0.0) || !std::isfinite(a)) continue;
          area += a;
          s.triangles.push_back(t);
          s.area_cdf.push_back(area);
        }
        if (s.triangles.empty()) continue;
        s.two_sided = scene.materials.at(part.material).double_sided;
        break;
      }
      case EmitterKind::point: break;
      case EmitterKind::spot: {
        s.inner = e.inner_cone_rad;
        s.outer = e.outer_cone_rad;
        s.cos_outer = std::cos(e.outer_cone_rad);
        const double cone = 2.0 * kPi * (1.0 - s.cos_outer);
        const double effective = flux_y / std::max(luminance(e.intensity_cd), 1e-300);
        s.cone_over_effective = cone / effective;
        break;
      }
      case EmitterKind::ies: {
        s.table = std::make_shared<IntensityTable>(*e.photometry);
        s.profile_flux = s.table->flux_lm();
        // Importance per texel: the largest intensity at its centre and corners, plus a floor of 10⁻³ of the
        // peak so that no direction with light can have zero density (the weight I/pdf stays bounded).
        SphereMap map(kIesSamplingResolution, 1);
        const double peak = s.table->max_cd();
        const int w = map.width(), h = map.height();
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x) {
            double m = 0.0;
            for (const auto& off : {glm::dvec2(0.5, 0.5), glm::dvec2(0.02, 0.02), glm::dvec2(0.98, 0.02),
                                    glm::dvec2(0.02, 0.98), glm::dvec2(0.98, 0.98)}) {
              const glm::vec2 uv{float((x + off.x) / w), float((y + off.y) / h)};
              m = std::max(m, s.table->intensity(glm::dvec3(sphere_map::uv_to_direction(uv))));
            }
            map.at(x, y, 0) = float(m + 1e-3 * peak);
          }
        s.direction_sampler = std::make_shared<SphereMapSampler>(map);
        break;
      }
      case EmitterKind::rayset: {
        auto source = open_rayset(e.rayset_path);
        s.rays = read_all_rays(*source, kMaxEmitterRays);
        double c = 0.0;
        s.ray_cdf.reserve(s.rays.size());
        for (std::size_t i = 0; i < s.rays.size(); ++i) {
          c += std::max(0.0, double(s.rays.flux[i]));
          s.ray_cdf.push_back(c);
        }
        if (!(c > 0.0)) continue;
        break;
      }
    }
    cumulative += flux_y;
    emitter_cdf_.push_back(cumulative);
    emitter_index_.push_back(std::uint32_t(ei));
    sources_.push_back(std::move(s));
    total_flux_lm_ += flux_y;
    total_flux_rgb_ += flux;
  }
  if (sources_.empty())
    throw_at_field(scene.name, "emitters",
                   scene.emitters.empty() ? "the luminaire has no emitter" : "no emitter of the luminaire emits any flux");
}

EmittedParticle EmitterSampler::sample(Pcg32& rng) const {
  const std::size_t k = pick(emitter_cdf_, rng.next_double());
  const Source& s = sources_[k];
  EmittedParticle p;
  p.emitter = emitter_index_[k];
  p.flux_weight = s.colour;
  const double u1 = rng.next_double(), u2 = rng.next_double();
  switch (s.kind) {
    case EmitterKind::surface: {
      const std::uint32_t t = s.triangles[pick(s.area_cdf, rng.next_double())];
      const glm::dvec3 a = scene_.positions[scene_.indices[3 * t]];
      const glm::dvec3 b = scene_.positions[scene_.indices[3 * t + 1]];
      const glm::dvec3 c = scene_.positions[scene_.indices[3 * t + 2]];
      const double su = std::sqrt(rng.next_double()), v = rng.next_double();  // uniform on the triangle
      p.position = (1.0 - su) * a + su * (1.0 - v) * b + su * v * c;
      glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
      if (s.two_sided && rng.next_double() < 0.5) n = -n;
      glm::dvec3 tx, ty;
      basis(n, tx, ty);
      const glm::dvec3 d = cosine_hemisphere(u1, u2);
      p.direction = glm::normalize(d.x * tx + d.y * ty + d.z * n);
      p.has_surface = true;
      p.surface_normal = n;
      break;
    }
    case EmitterKind::point:
      p.position = glm::dvec3(s.to_world[3]);
      p.direction = uniform_sphere(u1, u2);
      break;
    case EmitterKind::spot: {
      const double mu = 1.0 - u1 * (1.0 - s.cos_outer);  // uniform solid angle in the outer cone
      const double r = std::sqrt(std::max(0.0, 1.0 - mu * mu)), phi = 2.0 * kPi * u2;
      p.position = glm::dvec3(s.to_world[3]);
      p.direction = glm::normalize(s.rotation * glm::dvec3(r * std::cos(phi), r * std::sin(phi), -mu));
      p.flux_weight *= spot_falloff(mu, s.inner, s.outer) * s.cone_over_effective;
      break;
    }
    case EmitterKind::ies: {
      const DirectionSample d = s.direction_sampler->sample(float(u1), float(u2));
      p.position = glm::dvec3(s.to_world[3]);
      if (!(d.pdf > 0.0f)) {
        p.flux_weight = Rgb{0.0};
        break;
      }
      const glm::dvec3 local = glm::normalize(glm::dvec3(d.direction));
      p.direction = glm::normalize(s.rotation * local);
      p.flux_weight *= s.table->intensity(local) / (double(d.pdf) * s.profile_flux);
      break;
    }
    case EmitterKind::rayset: {
      const std::size_t i = pick(s.ray_cdf, u1);
      p.position = glm::dvec3(s.to_world * glm::dvec4(glm::dvec3(s.rays.position(i)), 1.0));
      p.direction = glm::normalize(s.rotation * glm::dvec3(s.rays.direction(i)));
      break;
    }
  }
  return p;
}

}  // namespace bake
LUMX_NAMESPACE_END
