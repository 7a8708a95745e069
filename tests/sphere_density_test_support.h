// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Exact intensity distributions on the sphere (total flux 1000 lm), directions drawn from them exactly,
// and an equal-area grid of directions to compare a reconstruction with them: what the spherical
// adaptive-kernel tests measure lumx::render::AdaptiveKernelDensitySphere against.
#pragma once

#include <lumx/render/spherical_kernel_density.h>

#include "kernel_density_test_support.h"

#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace lumx_test {

constexpr double kSphereFlux = 1000.0;  // lm
constexpr double kTwoPi = 2.0 * 3.14159265358979323846;

struct SphereField {
  std::string name;
  std::function<double(const glm::dvec3&)> intensity_cd;
  std::function<glm::dvec3(UnitRandom&)> sample;
};

inline glm::dvec3 from_z_phi(double z, double phi) {
  const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

/// I = Φ / 4π.
inline SphereField uniform_sphere_field() {
  return {"uniform", [](const glm::dvec3&) { return kSphereFlux / (2.0 * kTwoPi); },
          [](UnitRandom& r) { return from_z_phi(2.0 * r() - 1.0, kTwoPi * r()); }};
}

/// A Lambertian emitter facing +Z: I = Φ/π · max(0, cos θ); cos θ = √U inverts its CDF.
inline SphereField lambertian_field() {
  return {"lambertian", [](const glm::dvec3& w) { return kSphereFlux / (0.5 * kTwoPi) * std::max(0.0, w.z); },
          [](UnitRandom& r) { return from_z_phi(std::sqrt(r()), kTwoPi * r()); }};
}

/// A narrow beam along +X (away from the poles of the z–φ grids the tests integrate on) holding `share` of the flux, von Mises–Fisher with concentration κ (angular
/// spread ≈ 1/√κ rad), over a uniform background; cos θ = 1 + ln(U + (1 − U) e^{−2κ}) / κ inverts its CDF.
inline SphereField beam_field(double kappa = 200.0, double share = 0.5) {
  const double norm = kappa / (kTwoPi * (1.0 - std::exp(-2.0 * kappa)));
  return {"narrow beam",
          [=](const glm::dvec3& w) {
            return (1.0 - share) * kSphereFlux / (2.0 * kTwoPi) + share * kSphereFlux * norm * std::exp(kappa * (w.x - 1.0));
          },
          [=](UnitRandom& r) {
            if (r() >= share) return from_z_phi(2.0 * r() - 1.0, kTwoPi * r());
            const double u = r();
            const double z = 1.0 + std::log(u + (1.0 - u) * std::exp(-2.0 * kappa)) / kappa;
            const glm::dvec3 w = from_z_phi(std::clamp(z, -1.0, 1.0), kTwoPi * r());
            return glm::dvec3(w.z, w.x, w.y);
          }};
}

inline std::vector<lumx::render::DirectionDeposit> draw_directions(const SphereField& f, std::size_t n, std::uint64_t seed) {
  UnitRandom r(seed);
  std::vector<lumx::render::DirectionDeposit> out(n);
  for (auto& d : out) d = {f.sample(r), kSphereFlux / double(n)};
  return out;
}

/// Centres of an nz × nphi grid of equal-area cells (uniform in z = cos θ and in φ), each of 4π/(nz·nphi) sr.
inline std::vector<glm::dvec3> equal_area_directions(int nz, int nphi) {
  std::vector<glm::dvec3> out;
  out.reserve(std::size_t(nz) * std::size_t(nphi));
  for (int j = 0; j < nz; ++j)
    for (int k = 0; k < nphi; ++k) out.push_back(from_z_phi(-1.0 + (j + 0.5) * 2.0 / nz, (k + 0.5) * kTwoPi / nphi));
  return out;
}

}  // namespace lumx_test
