// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The glTF 2.0 scattering model (Appendix B with KHR_materials_{ior,specular,transmission,
// diffuse_transmission,volume}) as a BSDF for particle and radiance transport.
//
// Notation: m = metallic, t = transmission, s = specular factor, d = diffuse_transmission, ρ = base colour,
// τ = max channel of ρ, ρ_dt = diffuse_transmission_color, μ = |cos θ|, h the microfacet normal, D and G2 the
// GGX density and height-correlated masking (lumx/bake/microfacet.h).
//
// Seen from outside (wo.z > 0), the particle kernel f*(wo, wi) is the sum of
//   reflection    [m F_metal(wo·h) + (1 − m) s F_d(wo·h)] D(h) G2 / (4 μo μi)           h = ‖wo + wi‖
//   diffuse       (1 − m)(1 − t)(1 − d) ρ/π · C(μo, μi)
//   diffuse tr.   (1 − m)(1 − t) d ρ ρ_dt/π · C(μo, μi)                                   wi.z < 0
//   interface tr. (1 − m) t ρ (1 − s F̂(wo·h)) × [thin: D G2 / (4 μo μi) with wi mirrored to (x, y, −z);
//                                                volume: Walter et al. 2007 eq. 21 with η = ior]
// where F_metal is Schlick with F0 = ρ, F_d the dielectric Fresnel per channel (Schlick with
// F0 = min(F0(ior)·specular_color, 1) for thin/opaque; for a volume the exact Fresnel curve rescaled to the
// same F0: F_d = F0 + (1 − F0)(F_exact − F0(ior))/(1 − F0(ior))), F̂ = max channel of F_d, and the diffuse
// coupling
//   C(μo, μi) = (1 − s F̂(μo)) (1 − s F̂(μi)) / (1 − s F̂_avg),   F̂_avg = 2∫₀¹ F̂(μ) μ dμ,
// is symmetric (so the kernel is reciprocal) and gives the diffuse lobes the albedo ρ (1 − s F̂(μo)): what
// the specular layer does not reflect at normal-ish incidence enters the base (glTF's fresnel_mix with the
// layer Fresnel taken at the macro normal). With s = 0 the diffuse lobe is exactly Lambertian with albedo ρ.
// A rough layer reflects the average of F over its visible microfacets, which (F being convex) exceeds
// F(μo) by up to 0.13 % of 1 − F(μo) for glTF's GGX (measured over roughness 0.1–1, μo 0.1–1); the rough
// coupling is therefore scaled by κ = 1 − 0.005 s so that the directional albedo never exceeds one.
// The transmissive interface reflects with s F_d(wo·h) and transmits with (1 − s F̂(wo·h)) ρ, so with
// white ρ and s = 1 its reflectance and transmittance sum to one exactly for a smooth surface.
// From inside a volume (wo.z < 0) only the bare dielectric interface remains: reflection F_exact(wo·h, 1/ior)
// (with total internal reflection) and refraction 1 − F_exact.
//
// Sampling draws a lobe with probability ∝ an albedo estimate at wo (lobe_probabilities), then a direction:
// GGX visible normals (Heitz 2018) for the specular and interface lobes — the interface then reflects with
// probability P_R(wo·h) = s F̂ / (s F̂ + (1 − s F̂) τ) and transmits otherwise — and cosine-weighted
// directions for the diffuse lobes. pdf() is that mixture's exact solid-angle density (delta lobes
// excluded); sample()'s weight is eval·|cos θi|/pdf for non-delta directions.
#include <lumx/bake/bsdf.h>

#include <lumx/bake/fresnel.h>
#include <lumx/math/constants.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

LUMX_NAMESPACE_BEGIN
namespace bake {

namespace {

double max_channel(const Rgb& c) {
  return std::max(c.x, std::max(c.y, c.z));
}

double unit_or(double v, double fallback) {
  return std::isfinite(v) ? std::clamp(v, 0.0, 1.0) : fallback;
}

Rgb unit_colour(const Rgb& c) {
  Rgb r;
  for (int i = 0; i < 3; ++i) r[i] = unit_or(c[i], 0.0);
  return r;
}

bool finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

Rgb finite_or_zero(const Rgb& c) {
  return finite(c) ? glm::max(c, Rgb{0.0}) : Rgb{0.0};
}

glm::dvec3 flip_z(const glm::dvec3& w) {
  return {w.x, w.y, -w.z};
}

glm::dvec3 reflect_about(const glm::dvec3& wo, const glm::dvec3& n) {
  return 2.0 * glm::dot(wo, n) * n - wo;
}

/// Refraction of wo (pointing away on the incident side) through the interface with normal n on that side,
/// eta = ηₜ/ηᵢ: wt = −wo/η + (cos θᵢ/η − cos θₜ) n. False under total internal reflection.
bool refract_about(const glm::dvec3& wo, const glm::dvec3& n, double eta, glm::dvec3& wt) {
  const double cos_i = glm::dot(wo, n);
  if (cos_i <= 0.0) return false;
  const double sin2_t = std::max(0.0, 1.0 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0) return false;
  const double cos_t = std::sqrt(1.0 - sin2_t);
  wt = -wo / eta + (cos_i / eta - cos_t) * n;
  return true;
}

/// Normalised half vector, or false when the sum vanishes.
bool half_vector(const glm::dvec3& a, const glm::dvec3& b, glm::dvec3& h) {
  const glm::dvec3 s = a + b;
  const double len2 = glm::dot(s, s);
  if (!(len2 > 1e-30)) return false;
  h = s / std::sqrt(len2);
  return h.z > 0.0;
}

/// Walter et al. 2007 §5.3 refraction geometry for wo.z > 0 (incident side, index 1) and wi.z < 0
/// (relative index η): the generalised half vector m = ‖wo + η wi‖ turned to +z (eq. 16), and the squared
/// denominator (wi·m + wo·m/η)² of the half-vector Jacobian ‖∂ωm/∂ωi‖ = |wi·m| / (wi·m + wo·m/η)²
/// (eq. 17 divided by η²). False when no front-facing microfacet connects the two directions.
struct RefractionGeometry {
  glm::dvec3 m{0.0, 0.0, 1.0};
  double wo_dot_m = 0.0, wi_dot_m = 0.0, denom2 = 0.0;
};

bool refraction_geometry(const glm::dvec3& wo, const glm::dvec3& wi, double eta, RefractionGeometry& g) {
  glm::dvec3 m = wo + eta * wi;
  const double len2 = glm::dot(m, m);
  if (!(len2 > 1e-30)) return false;
  m /= std::sqrt(len2);
  if (m.z < 0.0) m = -m;
  if (!(m.z > 0.0)) return false;
  g.m = m;
  g.wo_dot_m = glm::dot(wo, m);
  g.wi_dot_m = glm::dot(wi, m);
  if (g.wo_dot_m <= 0.0 || g.wi_dot_m >= 0.0) return false;
  const double d = g.wi_dot_m + g.wo_dot_m / eta;
  g.denom2 = d * d;
  return g.denom2 > 1e-300;
}

/// Cosine-weighted direction on the +z hemisphere (Malley's method).
glm::dvec3 cosine_hemisphere(const glm::dvec2& u) {
  const double r = std::sqrt(std::clamp(u.x, 0.0, 1.0)), phi = 2.0 * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u.x))};
}

}  // namespace

Bsdf::Bsdf(const Material& material) : material_(material) {
  // Sanitise: NaN factors fall back to glTF's defaults, everything is clamped to its meaningful range.
  const double roughness = unit_or(material.roughness, 1.0);
  const double alpha = roughness * roughness;
  smooth_ = alpha < kSmoothAlpha;
  ggx_ = GgxDistribution(std::max(alpha, kSmoothAlpha));
  eta_ = (std::isfinite(material.ior) && material.ior > 0.0) ? std::clamp(material.ior, 1.0, 10.0) : 1.5;
  index_matched_ = material.volume && eta_ - 1.0 < kIndexMatchedTolerance;
  if (index_matched_) eta_ = 1.0;
  metallic_ = unit_or(material.metallic, 1.0);
  transmission_ = unit_or(material.transmission, 0.0);
  specular_ = unit_or(material.specular, 1.0);
  diffuse_transmission_ = unit_or(material.diffuse_transmission, 0.0);
  base_ = unit_colour(material.base_color);
  diffuse_transmission_color_ = unit_colour(material.diffuse_transmission_color);
  base_max_ = max_channel(base_);
  plain_f0_ = fresnel_f0_from_ior(eta_);
  // KHR_materials_specular: F0 = min(F0(ior) · specularColor, 1) per channel (the colour may exceed 1).
  for (int c = 0; c < 3; ++c) {
    const double colour = material.specular_color[c];
    dielectric_f0_[c] = std::min(1.0, plain_f0_ * (std::isfinite(colour) ? std::max(0.0, colour) : 1.0));
  }

  // Diffuse coupling normaliser 1 − s F̂_avg with F̂_avg = 2∫₀¹ F̂(μ) μ dμ: closed form for Schlick
  // (2∫(1 − μ)⁵ μ dμ = 1/21), composite Simpson on 256 intervals for the rescaled exact curve.
  double fresnel_avg;
  if (!material.volume) {
    const double f0 = max_channel(dielectric_f0_);
    fresnel_avg = f0 + (1.0 - f0) / 21.0;
  } else {
    constexpr int kIntervals = 256;
    double sum = 0.0;
    for (int i = 0; i <= kIntervals; ++i) {
      const double mu = double(i) / kIntervals;
      const double w = (i == 0 || i == kIntervals) ? 1.0 : (i % 2 ? 4.0 : 2.0);
      sum += w * dielectric_fresnel_max(mu) * mu;
    }
    fresnel_avg = 2.0 * sum / (3.0 * kIntervals);
  }
  coupling_norm_ = 1.0 - specular_ * std::clamp(fresnel_avg, 0.0, 1.0);
  coupling_margin_ = smooth_ ? 1.0 : 1.0 - kRoughCouplingMargin * specular_;

  const bool reflects = metallic_ > 0.0 || (specular_ > 0.0 && !index_matched_);
  has_delta_ =
      (smooth_ && (reflects || transmission_ > 0.0)) || (index_matched_ && transmission_ > 0.0 && metallic_ < 1.0);
}

Rgb Bsdf::dielectric_fresnel(double cos_theta) const {
  if (!material_.volume) {
    Rgb f;
    for (int c = 0; c < 3; ++c) f[c] = fresnel_schlick(dielectric_f0_[c], 1.0, cos_theta);
    return f;
  }
  if (index_matched_) return Rgb{0.0};
  // The exact curve's rise from its normal value to 1, laid over the specular-coloured F0.
  const double rise = std::clamp((fresnel_dielectric(cos_theta, eta_) - plain_f0_) / (1.0 - plain_f0_), 0.0, 1.0);
  return dielectric_f0_ + (Rgb{1.0} - dielectric_f0_) * rise;
}

double Bsdf::dielectric_fresnel_max(double cos_theta) const {
  return max_channel(dielectric_fresnel(cos_theta));
}

Rgb Bsdf::metal_fresnel(double cos_theta) const {
  Rgb f;
  for (int c = 0; c < 3; ++c) f[c] = fresnel_schlick(base_[c], 1.0, cos_theta);
  return f;
}

double Bsdf::diffuse_coupling(double cos_o, double cos_i) const {
  if (!(coupling_norm_ > 1e-12)) return 0.0;
  const double c = (1.0 - specular_ * dielectric_fresnel_max(cos_o)) *
                   (1.0 - specular_ * dielectric_fresnel_max(cos_i)) / coupling_norm_;
  return std::max(0.0, c * coupling_margin_);
}

double Bsdf::interface_reflect_probability(double cos_theta) const {
  if (index_matched_) return 0.0;
  const double reflected = specular_ * dielectric_fresnel_max(cos_theta);
  const double total = reflected + (1.0 - reflected) * base_max_;
  return total > 0.0 ? std::clamp(reflected / total, 0.0, 1.0) : 1.0;
}

// Lobe choice ∝ each lobe's albedo estimate at μo, the Fresnel estimates floored at 0.05 so a lobe whose
// Fresnel vanishes at μo but not at tilted microfacets is still drawn.
Bsdf::LobeProbabilities Bsdf::lobe_probabilities(double cos_o) const {
  constexpr double kFresnelFloor = 0.05;
  const double fd = dielectric_fresnel_max(cos_o);
  const double fd_est = index_matched_ ? 0.0 : std::max(fd, kFresnelFloor);
  const double dielectric = 1.0 - metallic_;
  const double entering = 1.0 - specular_ * fd;
  LobeProbabilities p;
  p.specular = metallic_ * std::max(max_channel(metal_fresnel(cos_o)), kFresnelFloor) +
               dielectric * (1.0 - transmission_) * specular_ * fd_est;
  p.interface = dielectric * transmission_ * (specular_ * fd_est + (1.0 - specular_ * fd_est) * base_max_);
  p.diffuse = dielectric * (1.0 - transmission_) * (1.0 - diffuse_transmission_) * entering * base_max_;
  p.diffuse_transmission = dielectric * (1.0 - transmission_) * diffuse_transmission_ * entering *
                           max_channel(base_ * diffuse_transmission_color_);
  const double total = p.specular + p.interface + p.diffuse + p.diffuse_transmission;
  if (!(total > 0.0) || !std::isfinite(total)) return LobeProbabilities{};
  p.specular /= total;
  p.interface /= total;
  p.diffuse /= total;
  p.diffuse_transmission /= total;
  return p;
}

// The particle kernel f*(wo, wi): the particle arrives from wo's side (see the file comment).
Rgb Bsdf::kernel(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (material_.volume && wo.z < 0.0) return kernel_inside(wo, wi);
  if (!(wo.z > 0.0) || wi.z == 0.0) return Rgb{0.0};
  const double dielectric = 1.0 - metallic_;
  Rgb f{0.0};
  if (wi.z > 0.0) {
    glm::dvec3 h;
    if (!smooth_ && half_vector(wo, wi, h)) {
      const double c = glm::dot(wo, h);
      const Rgb fresnel = metallic_ * metal_fresnel(c) + dielectric * specular_ * dielectric_fresnel(c);
      f += fresnel * (ggx_.normal_density(h) * ggx_.masking_shadowing(wo, wi) / (4.0 * wo.z * wi.z));
    }
    f += dielectric * (1.0 - transmission_) * (1.0 - diffuse_transmission_) * base_ *
         (diffuse_coupling(wo.z, wi.z) / kPi);
    return finite_or_zero(f);
  }
  const double cos_i = -wi.z;
  f += dielectric * (1.0 - transmission_) * diffuse_transmission_ * base_ * diffuse_transmission_color_ *
       (diffuse_coupling(wo.z, cos_i) / kPi);
  if (transmission_ > 0.0 && dielectric > 0.0 && !smooth_ && !index_matched_) {
    if (!material_.volume) {
      // Thin wall: the reflected lobe mirrored to the other side, no bending.
      const glm::dvec3 wr = flip_z(wi);
      glm::dvec3 h;
      if (half_vector(wo, wr, h)) {
        const double c = glm::dot(wo, h);
        const double weight = dielectric * transmission_ * (1.0 - specular_ * dielectric_fresnel_max(c));
        f += weight * base_ * (ggx_.normal_density(h) * ggx_.masking_shadowing(wo, wr) / (4.0 * wo.z * wr.z));
      }
    } else {
      // Walter et al. 2007 eq. 21 without the radiance factor ηo² (adjoint transport, Veach §5.2):
      // f* = (1 − F) D G2 |wi·m| |wo·m| / (|cos θi| |cos θo| (wi·m + wo·m/η)²).
      RefractionGeometry g;
      if (refraction_geometry(wo, wi, eta_, g)) {
        const double weight = dielectric * transmission_ * (1.0 - specular_ * dielectric_fresnel_max(g.wo_dot_m));
        f += weight * base_ *
             (ggx_.normal_density(g.m) * ggx_.masking_shadowing(wo, wi) * std::abs(g.wi_dot_m) * g.wo_dot_m /
              (cos_i * wo.z * g.denom2));
      }
    }
  }
  return finite_or_zero(f);
}

// Inside a volume: the bare interface, relative index 1/ior, in the frame flipped so that wo is up.
Rgb Bsdf::kernel_inside(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (smooth_ || index_matched_ || wi.z == 0.0) return Rgb{0.0};
  const glm::dvec3 a = flip_z(wo), b = flip_z(wi);
  const double eta = 1.0 / eta_;
  double f = 0.0;
  if (b.z > 0.0) {
    glm::dvec3 h;
    if (half_vector(a, b, h))
      f = fresnel_dielectric(glm::dot(a, h), eta) * ggx_.normal_density(h) * ggx_.masking_shadowing(a, b) /
          (4.0 * a.z * b.z);
  } else {
    RefractionGeometry g;
    if (refraction_geometry(a, b, eta, g))
      f = (1.0 - fresnel_dielectric(g.wo_dot_m, eta)) * ggx_.normal_density(g.m) * ggx_.masking_shadowing(a, b) *
          std::abs(g.wi_dot_m) * g.wo_dot_m / (-b.z * a.z * g.denom2);
  }
  return std::isfinite(f) ? Rgb{std::max(0.0, f)} : Rgb{0.0};
}

Rgb Bsdf::eval(const glm::dvec3& wo, const glm::dvec3& wi, TransportMode mode) const {
  if (!finite(wo) || !finite(wi)) return Rgb{0.0};
  // Radiance transport is the adjoint of the particle kernel: f(wo, wi) = f*(wi, wo). Outside a volume the
  // kernel is reciprocal, so both modes agree.
  if (mode == TransportMode::radiance && material_.volume) return kernel(wi, wo);
  return kernel(wo, wi);
}

double Bsdf::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (!finite(wo) || !finite(wi) || wi.z == 0.0) return 0.0;
  if (material_.volume && wo.z < 0.0) return pdf_inside(wo, wi);
  if (!(wo.z > 0.0)) return 0.0;
  const LobeProbabilities p = lobe_probabilities(wo.z);
  double density = 0.0;
  if (wi.z > 0.0) {
    glm::dvec3 h;
    if (!smooth_ && half_vector(wo, wi, h)) {
      const double c = glm::dot(wo, h);
      if (c > 0.0) {
        const double chosen = p.specular + p.interface * interface_reflect_probability(c);
        density += chosen * ggx_.visible_normal_density(wo, h) / (4.0 * c);
      }
    }
    density += p.diffuse * wi.z / kPi;
  } else {
    density += p.diffuse_transmission * (-wi.z) / kPi;
    if (p.interface > 0.0 && !smooth_ && !index_matched_) {
      if (!material_.volume) {
        const glm::dvec3 wr = flip_z(wi);
        glm::dvec3 h;
        if (half_vector(wo, wr, h)) {
          const double c = glm::dot(wo, h);
          if (c > 0.0)
            density +=
                p.interface * (1.0 - interface_reflect_probability(c)) * ggx_.visible_normal_density(wo, h) / (4.0 * c);
        }
      } else {
        RefractionGeometry g;
        if (refraction_geometry(wo, wi, eta_, g))
          density += p.interface * (1.0 - interface_reflect_probability(g.wo_dot_m)) *
                     ggx_.visible_normal_density(wo, g.m) * std::abs(g.wi_dot_m) / g.denom2;
      }
    }
  }
  return std::isfinite(density) ? std::max(0.0, density) : 0.0;
}

double Bsdf::pdf_inside(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (smooth_ || index_matched_) return 0.0;
  const glm::dvec3 a = flip_z(wo), b = flip_z(wi);
  const double eta = 1.0 / eta_;
  double density = 0.0;
  if (b.z > 0.0) {
    glm::dvec3 h;
    if (half_vector(a, b, h)) {
      const double c = glm::dot(a, h);
      if (c > 0.0) density = fresnel_dielectric(c, eta) * ggx_.visible_normal_density(a, h) / (4.0 * c);
    }
  } else {
    RefractionGeometry g;
    if (refraction_geometry(a, b, eta, g))
      density = (1.0 - fresnel_dielectric(g.wo_dot_m, eta)) * ggx_.visible_normal_density(a, g.m) *
                std::abs(g.wi_dot_m) / g.denom2;
  }
  return std::isfinite(density) ? std::max(0.0, density) : 0.0;
}

std::optional<BsdfSample> Bsdf::finish_sample(const glm::dvec3& wo, const glm::dvec3& wi, TransportMode mode) const {
  if (!finite(wi) || wi.z == 0.0) return std::nullopt;
  const double density = pdf(wo, wi);
  if (!(density > 0.0) || !std::isfinite(density)) return std::nullopt;
  BsdfSample s;
  s.wi = wi;
  s.pdf = density;
  s.weight = finite_or_zero(eval(wo, wi, mode) * (std::abs(wi.z) / density));
  s.transmitted = (wi.z > 0.0) != (wo.z > 0.0);
  return s;
}

namespace {
std::optional<BsdfSample> delta_sample(const glm::dvec3& wo, const glm::dvec3& wi, double probability,
                                       const Rgb& coefficient) {
  if (!(probability > 0.0) || !finite(wi) || wi.z == 0.0) return std::nullopt;
  BsdfSample s;
  s.wi = wi;
  s.pdf = probability;
  s.weight = finite_or_zero(coefficient / probability);
  s.delta = true;
  s.transmitted = (wi.z > 0.0) != (wo.z > 0.0);
  return s;
}
}  // namespace

std::optional<BsdfSample> Bsdf::sample(const glm::dvec3& wo, double u_lobe, const glm::dvec2& u,
                                       TransportMode mode) const {
  if (!finite(wo) || !std::isfinite(u_lobe) || !std::isfinite(u.x) || !std::isfinite(u.y)) return std::nullopt;
  if (material_.volume && wo.z < 0.0) return sample_inside(wo, u_lobe, u, mode);
  if (!(wo.z > 0.0)) return std::nullopt;
  const LobeProbabilities p = lobe_probabilities(wo.z);
  const double dielectric = 1.0 - metallic_;
  const glm::dvec3 mirror{-wo.x, -wo.y, wo.z};
  double x = std::clamp(u_lobe, 0.0, 1.0);

  if (x < p.specular) {
    if (smooth_) {
      const Rgb coefficient = metallic_ * metal_fresnel(wo.z) + dielectric * specular_ * dielectric_fresnel(wo.z);
      return delta_sample(wo, mirror, p.specular + p.interface * interface_reflect_probability(wo.z), coefficient);
    }
    const glm::dvec3 wi = reflect_about(wo, ggx_.sample_visible_normal(wo, u));
    if (wi.z <= 0.0) return std::nullopt;
    return finish_sample(wo, wi, mode);
  }
  x -= p.specular;

  if (x < p.interface) {
    const double x_branch = std::clamp(x / p.interface, 0.0, 1.0);
    if (smooth_ || index_matched_) {
      const double reflect_p = smooth_ ? interface_reflect_probability(wo.z) : 0.0;
      if (x_branch < reflect_p) {
        const Rgb coefficient = metallic_ * metal_fresnel(wo.z) + dielectric * specular_ * dielectric_fresnel(wo.z);
        return delta_sample(wo, mirror, p.specular + p.interface * reflect_p, coefficient);
      }
      const double probability = p.interface * (1.0 - reflect_p);
      const Rgb importance = dielectric * transmission_ * base_ * (1.0 - specular_ * dielectric_fresnel_max(wo.z));
      if (!material_.volume || index_matched_) return delta_sample(wo, -wo, probability, importance);
      glm::dvec3 wi;
      if (!refract_about(wo, glm::dvec3(0.0, 0.0, 1.0), eta_, wi)) return std::nullopt;
      if (mode == TransportMode::importance) return delta_sample(wo, wi, probability, importance);
      // Radiance: the adjoint's coefficient is the inside interface's transmittance at wi, and radiance
      // crossing into the denser side is scaled by 1/η² (Veach 1997 §5.2).
      const double inside = 1.0 - fresnel_dielectric(-wi.z, 1.0 / eta_);
      return delta_sample(wo, wi, probability, Rgb{inside / (eta_ * eta_)});
    }
    const glm::dvec3 h = ggx_.sample_visible_normal(wo, u);
    const double reflect_p = interface_reflect_probability(glm::dot(wo, h));
    glm::dvec3 wi;
    if (x_branch < reflect_p) {
      wi = reflect_about(wo, h);
      if (wi.z <= 0.0) return std::nullopt;
    } else if (!material_.volume) {
      const glm::dvec3 wr = reflect_about(wo, h);
      if (wr.z <= 0.0) return std::nullopt;
      wi = flip_z(wr);
    } else {
      if (!refract_about(wo, h, eta_, wi) || wi.z >= 0.0) return std::nullopt;
    }
    return finish_sample(wo, wi, mode);
  }
  x -= p.interface;

  if (x < p.diffuse) return finish_sample(wo, cosine_hemisphere(u), mode);
  if (p.diffuse_transmission > 0.0) return finish_sample(wo, flip_z(cosine_hemisphere(u)), mode);
  if (p.diffuse > 0.0) return finish_sample(wo, cosine_hemisphere(u), mode);
  return std::nullopt;
}

std::optional<BsdfSample> Bsdf::sample_inside(const glm::dvec3& wo, double u_lobe, const glm::dvec2& u,
                                              TransportMode mode) const {
  const glm::dvec3 a = flip_z(wo);
  const double eta = 1.0 / eta_;
  const double x = std::clamp(u_lobe, 0.0, 1.0);
  // The outside kernel's transmission coefficient at the exit direction (for the radiance adjoint).
  const auto outside_coefficient = [&](double cos_exit) {
    return (1.0 - metallic_) * transmission_ * base_ * (1.0 - specular_ * dielectric_fresnel_max(cos_exit));
  };
  if (index_matched_) {
    const Rgb weight = mode == TransportMode::importance ? Rgb{1.0} : outside_coefficient(-wo.z);
    return delta_sample(wo, -wo, 1.0, weight);
  }
  if (smooth_) {
    const double reflectance = fresnel_dielectric(a.z, eta);
    if (x < reflectance) return delta_sample(wo, glm::dvec3(-wo.x, -wo.y, wo.z), reflectance, Rgb{reflectance});
    glm::dvec3 t;
    if (!refract_about(a, glm::dvec3(0.0, 0.0, 1.0), eta, t)) return std::nullopt;
    const glm::dvec3 wi = flip_z(t);
    const double probability = 1.0 - reflectance;
    if (mode == TransportMode::importance) return delta_sample(wo, wi, probability, Rgb{probability});
    return delta_sample(wo, wi, probability, outside_coefficient(wi.z) * (eta_ * eta_));
  }
  const glm::dvec3 h = ggx_.sample_visible_normal(a, u);
  const double c = glm::dot(a, h);
  glm::dvec3 b;
  if (x < fresnel_dielectric(c, eta)) {
    b = reflect_about(a, h);
    if (b.z <= 0.0) return std::nullopt;
  } else if (!refract_about(a, h, eta, b) || b.z >= 0.0) {
    return std::nullopt;
  }
  return finish_sample(wo, flip_z(b), mode);
}

}  // namespace bake
LUMX_NAMESPACE_END
