// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// A representation the library does not know: an isotropic point light, registered by the tests alone
// (tests/test_light_model_seam.cpp, tests/test_light_model_seam_room.cpp).
#pragma once

#include <lumx/core/diagnostic.h>
#include <lumx/model/registry.h>
#include <lumx/rays/rayset.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <string>

namespace lumx_test {

inline constexpr double kPi = 3.14159265358979323846;

// ---- the toy representation: one isotropic point light, I = Φ / 4π toward every direction ----
class IsotropicPoint final : public lumx::LightModel {
 public:
  IsotropicPoint(const glm::dvec3& p, double flux) : p_(p), flux_(flux) {}
  const glm::dvec3& position() const { return p_; }
  double scalar_flux() const { return flux_; }

  std::string type() const override { return "test-isotropic-point"; }
  std::string description() const override { return "isotropic point light"; }
  lumx::PhotometricQuantity quantity() const override { return lumx::PhotometricQuantity::photometric; }
  lumx::ChannelLayout channels() const override { return lumx::ChannelLayout::luminance; }
  lumx::BoundingSphere bounds() const override {
    lumx::BoundingSphere b;
    b.center = p_;
    return b;
  }
  glm::dvec3 flux() const override { return glm::dvec3(flux_); }
  glm::dvec3 intensity(const glm::dvec3&) const override { return glm::dvec3(flux_ / (4 * kPi)); }
  glm::dvec3 irradiance(const glm::dvec3& x, const glm::dvec3& n, const lumx::Visibility* v) const override {
    const glm::dvec3 to_light = p_ - x;
    const double r2 = glm::dot(to_light, to_light);
    const double cosine = glm::dot(n, to_light) / std::sqrt(r2);
    if (!(cosine > 0) || (v && !v->visible(p_, x))) return glm::dvec3(0.0);
    return glm::dvec3(flux_ / (4 * kPi) * cosine / r2);
  }
  lumx::PositionMeasure position_measure() const override { return lumx::PositionMeasure::discrete; }
  lumx::ModelEmission sample_emission(const std::array<double, 4>& u) const override {
    lumx::ModelEmission e;
    const double z = 1 - 2 * u[1], phi = 2 * kPi * u[2], s = std::sqrt(std::max(0.0, 1 - z * z));
    e.position = p_;
    e.direction = {s * std::cos(phi), s * std::sin(phi), z};
    e.pdf_position = 1;
    e.pdf_direction = 1 / (4 * kPi);
    e.flux = glm::dvec3(flux_);
    return e;
  }
  lumx::EmissionDensity emission_pdf(std::size_t element, const glm::dvec3&, const glm::dvec3&) const override {
    return element == 0 ? lumx::EmissionDensity{1, 1 / (4 * kPi)} : lumx::EmissionDensity{};
  }
  std::size_t bytes() const override { return sizeof(*this); }

 private:
  glm::dvec3 p_;
  double flux_;
};

inline lumx::ModelType isotropic_point_type() {
  lumx::ModelType t;
  t.name = "test-isotropic-point";
  t.description = "an isotropic point light (registered by the seam's test)";
  t.write = [](const lumx::LightModel& m, lumx::ModelPayloadSink& sink) {
    const auto& point = dynamic_cast<const IsotropicPoint&>(m);
    const double f = point.scalar_flux();
    sink.add("flux.f64", std::string(reinterpret_cast<const char*>(&f), sizeof f));
    nlohmann::json j;
    j["position"] = {point.position().x, point.position().y, point.position().z};
    return j.dump();
  };
  t.read = [](const std::string& section, const lumx::ModelPayloadSource& payloads,
              const lumx::ModelLoadOptions&) -> std::unique_ptr<lumx::LightModel> {
    const nlohmann::json j = nlohmann::json::parse(section);
    const auto p = j.find("position");
    if (p == j.end() || !p->is_array() || p->size() != 3)
      lumx::throw_at_field(payloads.where(), "section/position", "must be three numbers");
    if (payloads.size("flux.f64") != sizeof(double))
      lumx::throw_at_field(payloads.where(), "payloads/flux.f64", "must be 8 bytes");
    const std::string bytes = payloads.read("flux.f64");
    double f = 0;
    std::memcpy(&f, bytes.data(), sizeof f);
    if (!(f >= 0) || !std::isfinite(f)) lumx::throw_at_field(payloads.where(), "payloads/flux.f64", "not a finite flux");
    return std::make_unique<IsotropicPoint>(glm::dvec3((*p)[0].get<double>(), (*p)[1].get<double>(), (*p)[2].get<double>()), f);
  };
  // Φ = Σ ray flux; the point is the flux-weighted mean of the start points.
  t.build = [](lumx::RaySource& rays, const lumx::ModelBuildOptions&) -> std::unique_ptr<lumx::LightModel> {
    lumx::RayChunk c;
    double f = 0;
    glm::dvec3 m(0.0);
    while (rays.next(c, 1 << 14))
      for (std::size_t i = 0; i < c.size(); ++i) f += c.flux[i], m += double(c.flux[i]) * glm::dvec3(c.position(i));
    return std::make_unique<IsotropicPoint>(f > 0 ? m / f : m, f);
  };
  return t;
}

// Registered once per program (an inline variable), by whichever test file includes this header.
inline const lumx::ModelRegistration kIsotropicPoint{isotropic_point_type()};

// An isotropic point source at `centre` of total flux `flux`: rays start 1 cm out along their direction
// (a recording sphere, as a goniophotometer's rays do), so their start points are not all one point.
inline lumx::MemoryRaySource isotropic_rays(const glm::dvec3& centre, double flux, std::size_t n, std::uint32_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  lumx::RayChunk c;
  c.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double z = 1 - 2 * u01(rng), phi = 2 * kPi * u01(rng), s = std::sqrt(std::max(0.0, 1 - z * z));
    const glm::dvec3 d(s * std::cos(phi), s * std::sin(phi), z);
    c.push_back(glm::vec3(centre + 0.01 * d), glm::vec3(d), float(flux / double(n)));
  }
  lumx::RaysetInfo info;
  info.file = "isotropic";
  return lumx::MemoryRaySource(std::move(c), std::move(info));
}

}  // namespace lumx_test
