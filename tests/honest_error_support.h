// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The analytic suite of the held-out error estimate (tests/test_apl_honest_error.cpp) and the studies
// built on it (studies/study_pinhole_box.cpp, study_far_field.cpp, study_spot.cpp): its emitters, the
// exact irradiance on the measurement spheres, the set lumx build ships, and the held-out estimate of the
// box's masked level per seed. No GoogleTest here: the tests assert on these results, the studies write
// them as CSV.
#pragma once

#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/evaluation.h>
#include <lumx/apl/map_fit.h>

#include "analytic_emitters.h"

#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace lumx_test {

/// Rays each emitter of the suite writes: the targets (docs/apl_sets.md) are stated for 1 M rays.
constexpr std::uint64_t kSuiteRays = 1000000;

inline PlanarEmitter lambertian_disk() {
  return {"Lambertian disk r = 0.1 m", PlanarEmitter::Shape::disk, 0.1, 0, 1, 1000};
}
inline PlanarEmitter lambertian_rectangle() {
  return {"Lambertian rectangle 1.2 x 0.3 m", PlanarEmitter::Shape::rectangle, 0.6, 0.15, 1, 4000};
}
/// A cos^m spot of radius 2 cm.
inline PlanarEmitter spot(double m) {
  return {"cos^" + std::to_string(int(m)) + " spot r = 2 cm", PlanarEmitter::Shape::disk, 0.02, 0, m, 800};
}
inline PinholeBox pinhole_box() {
  return suite_pinhole_box();
}

/// The suite's emitter i: 0 the disk, 1 the rectangle, 2 the cos^20 spot, 3 the cos^50 spot, 4 and above
/// the box with holes.
inline std::unique_ptr<AnalyticEmitter> suite_emitter(int i) {
  switch (i) {
    case 0:
      return std::make_unique<PlanarEmitter>(lambertian_disk());
    case 1:
      return std::make_unique<PlanarEmitter>(lambertian_rectangle());
    case 2:
      return std::make_unique<PlanarEmitter>(spot(20));
    case 3:
      return std::make_unique<PlanarEmitter>(spot(50));
    default:
      return std::make_unique<PinholeBox>(pinhole_box());
  }
}

/// The exact irradiance at every evaluation point (k = 1: the patch centres) and its mean over each patch
/// (k×k sub-points), per sphere.
struct ExactOnSpheres {
  std::vector<std::vector<double>> at_centre, patch_mean;
};
inline ExactOnSpheres exact_on_spheres(const AnalyticEmitter& em, const lumx::MeasurementSpheres& ms, int k) {
  ExactOnSpheres out;
  const std::vector<glm::dvec3> centres = ms.evaluation_directions(1), sub = ms.evaluation_directions(k);
  const std::size_t k2 = std::size_t(k * k);
  for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
    auto at = [&](const glm::dvec3& u) {
      return em.irradiance(glm::dvec3(glm::vec3(ms.centre() + ms.radius(s) * u)), -u);
    };
    std::vector<double> c(centres.size()), m(centres.size(), 0.0);
    for (std::size_t p = 0; p < centres.size(); ++p) {
      c[p] = at(centres[p]);
      for (std::size_t j = 0; j < k2; ++j) m[p] += at(sub[p * k2 + j]) / double(k2);
    }
    out.at_centre.push_back(std::move(c));
    out.patch_mean.push_back(std::move(m));
  }
  return out;
}

/// Relative RMSE of a row's point values against exact values, per sphere.
inline std::vector<double> true_errors(const std::vector<std::vector<double>>& exact, const lumx::LevelErrors& row) {
  std::vector<double> out;
  for (std::size_t s = 0; s < exact.size(); ++s)
    out.push_back(lumx::compare_irradiance(exact[s], row.irradiance[s]).relative_rmse);
  return out;
}

/// The set lumx build ships from `rays` (two threads): fitted on held-out rays, then built from every ray
/// with the fit applied; `choice` receives the fit. Throws std::runtime_error if the fit does not apply.
inline lumx::AplSet shipped_set(lumx::RaySource& rays, lumx::ResolutionChoice& choice, bool orient_maps = true) {
  lumx::AplBuildOptions bo;
  bo.threads = 2;
  bo.orient_maps = orient_maps;
  const lumx::AplBuildOptions half_bo = lumx::half_rays_build_options(bo, rays.info().ray_count);
  const lumx::AplErrorReport held_out = lumx::evaluate_held_out_fitted(
      rays, [&](lumx::RaySource& r) { return lumx::build_apl_set(r, half_bo); }, lumx::AplErrorOptions{}, &choice);
  lumx::AplSet set = lumx::build_apl_set(rays, bo);
  if (!lumx::apply_held_out_fit(set, held_out, &choice))
    throw std::runtime_error("shipped_set: the fit does not apply");
  return set;
}

/// Level k's irradiance at the evaluation points `dirs` of sphere s, each queried alone as a renderer does.
inline std::vector<double> level_at_points(const lumx::AplSet& set, std::size_t k, const lumx::MeasurementSpheres& ms,
                                           std::size_t s, const std::vector<glm::dvec3>& dirs) {
  std::vector<double> model(dirs.size());
  for (std::size_t p = 0; p < dirs.size(); ++p)
    model[p] = lumx::luminance_of(
        set.channels,
        lumx::irradiance(set, k, glm::vec3(ms.centre() + ms.radius(s) * dirs[p]), glm::vec3(-dirs[p])).irradiance);
  return model;
}

/// The held-out estimate of the box's masked level on the rays of one seed: the level
/// evaluate_held_out_fitted grades (built from the even rays, point sources as masked APLs), with, per
/// sphere, its relative distance, its error against the exact irradiance at the patch centres, the
/// estimate with the noise removed, whether it is resolved, its upper bound and the sphere's border
/// allowance (SphereReference::border_share). Relative figures, not percent.
struct MaskedLevelEstimate {
  std::uint64_t seed = 0;
  int map_resolution = 0;
  bool masked = false;
  std::vector<double> relative_distance, truth, estimate, upper, border_share;
  std::vector<bool> resolved;
};
inline MaskedLevelEstimate masked_level_estimate(std::uint64_t seed) {
  const PinholeBox box = pinhole_box();
  auto rays = box.source(kSuiteRays, seed);
  lumx::AplBuildOptions bo;
  bo.threads = 2;
  lumx::ResolutionChoice choice;
  const lumx::AplErrorReport r = lumx::evaluate_held_out_fitted(
      *rays,
      [&](lumx::RaySource& train) {
        return lumx::build_apl_set(train, lumx::half_rays_build_options(bo, rays->info().ray_count));
      },
      lumx::AplErrorOptions{}, &choice);
  const lumx::LevelErrors& row = r.levels.back();
  MaskedLevelEstimate out;
  out.seed = seed;
  out.map_resolution = row.map_resolution;
  out.masked = row.masked;
  const ExactOnSpheres exact = exact_on_spheres(box, r.reference.spheres, 1);
  out.truth = true_errors(exact.at_centre, row);
  for (std::size_t s = 0; s < out.truth.size(); ++s) {
    const lumx::IrradianceErrors& e = row.errors[s];
    out.relative_distance.push_back(r.reference.sphere[s].relative_distance);
    out.estimate.push_back(e.relative_rmse_noise_removed);
    out.upper.push_back(e.noise_removed_upper);
    out.resolved.push_back(e.resolved);
    out.border_share.push_back(r.reference.sphere[s].border_share);
  }
  return out;
}

/// Counted over the spheres of some estimates: those whose truth is above 10 % (a patch centre in a
/// sliver one mask misses), those where the upper bound is below 3/4 of the truth (the estimate
/// flatters), and those resolved more than 25 % from the truth.
struct MaskedEstimateCounts {
  int spheres = 0, spikes = 0, flatters = 0, resolved_off = 0;
};
inline bool is_spike(const MaskedLevelEstimate& m, std::size_t s) {
  return m.truth[s] > 0.1;
}
inline bool flatters(const MaskedLevelEstimate& m, std::size_t s) {
  return m.upper[s] < 0.75 * m.truth[s];
}
inline bool resolved_off(const MaskedLevelEstimate& m, std::size_t s) {
  return m.resolved[s] && std::abs(m.estimate[s] - m.truth[s]) > 0.25 * m.truth[s];
}
inline MaskedEstimateCounts count_masked_estimates(const std::vector<MaskedLevelEstimate>& estimates) {
  MaskedEstimateCounts n;
  for (const MaskedLevelEstimate& m : estimates)
    for (std::size_t s = 0; s < m.truth.size(); ++s) {
      ++n.spheres;
      n.spikes += is_spike(m, s);
      n.flatters += flatters(m, s);
      n.resolved_off += resolved_off(m, s);
    }
  return n;
}

}  // namespace lumx_test
