// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// the reference moved to the patch centres by a pilot's shape, and the border allowance of beam masks (apl/error.h).
#include "apl/error_detail.h"

LUMX_NAMESPACE_BEGIN

AplSet centring_pilot(const AplSet& set, double sigma) {
  if (set.levels.empty()) throw std::invalid_argument("centring_pilot: the set has no level");
  std::size_t best = 0;
  for (std::size_t k = 1; k < set.levels.size(); ++k)
    if (std::abs(std::log(double(std::max<std::size_t>(1, set.levels[k].size())) / 64.0)) <
        std::abs(std::log(double(std::max<std::size_t>(1, set.levels[best].size())) / 64.0)))
      best = k;
  AplSet pilot;  // the set's metadata and that one level, without copying the others' maps
  pilot.quantity = set.quantity;
  pilot.channels = set.channels;
  pilot.bounds = set.bounds;
  pilot.provenance = set.provenance;
  pilot.levels.push_back(set.levels[best]);
  auto texel = [](int R) { return std::sqrt(4.0 * kPi / (2.0 * double(R) * double(R))); };
  int R = pilot.levels[0].map_resolution;
  // A masked level (point sources behind apertures) already has its borders as geometry: its pilot is
  // its maps unsmoothed (a kernel would blur what the mask divides by its coverage), halved to R 8 at most
  // for their noise (a sharpened texel map's pilot estimated the box's masked level, 2.7-3.2 % off, at
  // 19-30 %). The held-out evaluators join its masks with the graded set's (pilot_with_known_borders).
  if (pilot.levels[0].has_masks()) {
    int to = R;
    while (to > 8 && to % 2 == 0) to /= 2;
    if (to != R) pilot.levels[0] = downsampled_level(pilot.levels[0], to);
    return pilot;
  }
  if (sigma > 0) {
    const double cut = std::log(1e3) * sigma * sigma;  // 1 − cos of the kernel's truncation (κ = 1/σ²)
    auto too_fine = [&](int r) {
      const double T = 2.0 * double(r) * double(r);
      return r > SphereMapKernel::kMaxResolution ||
             T * T * std::min(1.0, cut / 2.0) > double(SphereMapKernel::kMaxWeights / 4);
    };
    int to = R;
    while (too_fine(to) && to % 2 == 0 && to / 2 >= 32) to /= 2;
    if (to != R) pilot.levels[0] = downsampled_level(pilot.levels[0], to);
    R = to;
    if (R >= 32 && !too_fine(R))
      pilot.levels[0] =
          smoothed_level(pilot.levels[0], *SphereMapKernel::shared(R, 1.0 / (sigma * sigma)), 0, KernelMode::sharpened);
  } else if (R >= 32 && R <= SphereMapKernel::kMaxResolution) {
    pilot.levels[0] =
        smoothed_level(pilot.levels[0], *SphereMapKernel::shared(R, 1.0 / ((1.5 * texel(R)) * (1.5 * texel(R)))), 0,
                       KernelMode::sharpened);
  }
  return pilot;
}

AplSet pilot_with_known_borders(AplSet pilot, const AplSet& lit) {
  if (pilot.levels.empty() || !pilot.levels[0].has_masks()) return pilot;
  const AplLevel* known = most_masked_level(lit);
  if (!known) return pilot;
  AplLevel& level = pilot.levels[0];
  for (Apl& a : level.apls) {
    if (!a.mask) continue;
    const Apl* match = detail::same_source(a, *known, pilot.bounds.radius);
    if (!match || match->mask == a.mask) continue;
    std::vector<DirectionMask::Cap> caps = a.mask->caps();
    caps.insert(caps.end(), match->mask->caps().begin(), match->mask->caps().end());
    a.mask = std::make_shared<const DirectionMask>(DirectionMask::from_caps(std::move(caps)));
  }
  refresh_coverages(level);
  return pilot;
}

void border_allowance(ReferenceIrradiance& ref, const AplSet& pilot, const std::vector<MaskEvidence>& evidence,
                      unsigned threads) {
  // Caps further than this (rad) beyond their reach are not read: a hull would have to gain a fan at
  // least this wide, which the rays of a beam, 500 at least (PointSourceOptions::min_rays), leave empty
  // with a probability far below any that counts.
  constexpr double kBorderReach = 0.25;
  if (pilot.levels.empty() || !pilot.levels[0].has_masks()) return;
  const AplLevel& level = pilot.levels[0];
  const std::vector<glm::dvec3> dirs = ref.spheres.evaluation_directions(1);
  // Per pilot APL: its own mask's caps, and those of the matching mask of each evidence level (empty:
  // none matches), with their vertices as directions.
  struct Beam {
    std::vector<detail::CapVertices> own;
    std::vector<std::vector<detail::CapVertices>> evidence;  ///< per evidence level; empty: no match
  };
  std::vector<Beam> beams(level.size());
  for (std::size_t i = 0; i < level.size(); ++i) {
    const Apl& a = level.apls[i];
    if (!a.mask) continue;
    beams[i].own = detail::cap_vertices(*a.mask);
    for (const MaskEvidence& ev : evidence) {
      const Apl* found =
          ev.level && ev.flux_per_ray > 0 ? detail::same_source(a, *ev.level, pilot.bounds.radius) : nullptr;
      beams[i].evidence.push_back(found ? detail::cap_vertices(*found->mask) : std::vector<detail::CapVertices>{});
    }
  }
  // What patch centre x, seen along the outward unit u, may still receive (lx²).
  auto allowance_at = [&](const glm::dvec3& x, const glm::dvec3& u) {
    double total = 0;
    for (std::size_t i = 0; i < level.size(); ++i) {
      const Apl& a = level.apls[i];
      if (!a.mask) continue;
      const glm::dvec3 d = x - glm::dvec3(a.position);
      const double r2 = glm::dot(d, d);
      if (!(r2 > 0)) continue;
      const glm::dvec3 w = d / std::sqrt(r2);
      const double cosine = glm::dot(w, u);  // the patch's normal is −u (evaluate_level)
      if (cosine <= 0 || a.mask->contains(w)) continue;
      // The beam's intensity just inside its border: the pilot's at the hull vertex nearest w (a map
      // read beyond the border would give what its texels hold there, nothing or a part).
      const glm::vec3 m =
          level.frame.map_direction(glm::vec3(detail::nearest_hull_vertex(beams[i].own, w, kBorderReach)));
      const double I = luminance_of(pilot.channels, glm::dvec3(a.map.lookup(m))) /
                       double(std::max(kMinMaskCoverage, a.coverage.lookup(m).x));
      if (!(I > 0)) continue;
      double expected_rays = 0;  // Σ over the hull sets of λ·Ω at their nearest cap
      bool any = false;
      for (std::size_t h = 0; h < evidence.size(); ++h) {
        if (beams[i].evidence[h].empty()) continue;
        any = true;
        double gain = INFINITY;
        for (const detail::CapVertices& cv : beams[i].evidence[h])
          if (detail::cap_near(*cv.cap, w, kBorderReach)) gain = std::min(gain, detail::cap_gain(cv, w));
        if (gain == 0) {  // inside this hull (which the pilot's mask did not take): lit for certain
          expected_rays = 0;
          break;
        }
        expected_rays += I / evidence[h].flux_per_ray * gain;
      }
      if (!any) continue;
      const double L = I * cosine / r2;
      total += std::exp(-expected_rays) * L * L;
    }
    return total;
  };
  for (std::size_t s = 0; s < ref.sphere.size(); ++s) {
    SphereReference& sr = ref.sphere[s];
    if (!sr.centred) continue;
    const std::size_t np = std::min(dirs.size(), sr.irradiance.size());
    sr.border.assign(sr.irradiance.size(), 0.0);
    // Patches are independent: each job fills its own, so any thread count gives the same values.
    constexpr std::size_t kJobs = 64;
    detail::parallel_jobs(kJobs, threads, [&](std::size_t job) {
      for (std::size_t p = np * job / kJobs; p < np * (job + 1) / kJobs; ++p)
        sr.border[p] = allowance_at(ref.spheres.centre() + ref.spheres.radius(s) * dirs[p], dirs[p]);
    });
    double sum = 0, mean = 0;
    for (std::size_t p = 0; p < sr.irradiance.size(); ++p) sum += sr.border[p], mean += sr.irradiance[p];
    const double n = double(sr.border.size());
    sr.border_share = mean > 0 ? std::sqrt(sum / n) / (mean / n) : 0.0;
  }
}

std::vector<MaskEvidence> mask_evidence(const AplSet& own, std::uint64_t own_rays, const AplSet* lit,
                                        std::uint64_t lit_rays) {
  std::vector<MaskEvidence> out;
  if (own.levels.empty() || !own.levels[0].has_masks() || own_rays == 0) return out;
  double flux = 0;
  for (const Apl& a : own.levels[0].apls) flux += luminance_of(own.channels, a.flux);
  if (!(flux > 0)) return out;
  out.push_back({&own.levels[0], flux / double(own_rays)});
  if (lit && lit_rays > 0)
    if (const AplLevel* known = most_masked_level(*lit)) out.push_back({known, flux / double(lit_rays)});
  return out;
}

double centring_pilot_sigma(int patch_resolution) {
  return 0.375 * std::sqrt(4.0 * kPi / (2.0 * double(patch_resolution) * double(patch_resolution)));
}

std::vector<std::vector<double>> pilot_on_patches(const AplSet& pilot, const ReferenceIrradiance& like,
                                                  const AplErrorOptions& options, int k) {
  AplErrorOptions o = options;
  o.min_timing_seconds = 0;
  o.progress = nullptr;
  o.relative_distances = like.spheres.relative_distances();
  o.patch_resolution = like.spheres.patch_resolution();
  o.rotated_patches = like.spheres.rotated_patches();
  o.patch_subsamples = k;
  BoundingSphere bounds;
  bounds.center = like.spheres.centre();
  bounds.radius = 0.5 * like.spheres.diameter();
  ReferenceIrradiance at = like;
  at.spheres = MeasurementSpheres(bounds, o);
  return evaluate_level(pilot, 0, at, o).irradiance;
}

ReferenceIrradiance centred_reference(const ReferenceIrradiance& ref, const AplSet& pilot,
                                      const AplErrorOptions& options, int k) {
  // By default 4 × 4 points a patch; for a masked pilot, whose patches hold sharp borders, as many as
  // detail::masked_pilot_subsamples allows (16 × 16 on the fit's R 32 patches).
  if (k == 0) k = pilot.levels.at(0).has_masks() ? detail::masked_pilot_subsamples(ref.spheres, 16) : 4;
  if (k < 2 || k > 16) throw std::invalid_argument("centred_reference: k must be 0 or in [2, 16]");
  ReferenceIrradiance out = ref;
  const std::vector<std::vector<double>> at_centre = pilot_on_patches(pilot, ref, options, 1),
                                         mean = pilot_on_patches(pilot, ref, options, k);
  const bool masked = pilot.levels.at(0).has_masks();
  for (std::size_t s = 0; s < out.sphere.size(); ++s) {
    SphereReference& sr = out.sphere[s];
    for (std::size_t p = 0; p < sr.irradiance.size(); ++p)
      detail::centre_patch(sr, p, at_centre[s][p], mean[s][p], masked);
    if (masked) detail::refresh_noise_floors(sr);
    sr.centred = true;
  }
  return out;
}

ReferenceIrradiance checked_centred_reference(const ReferenceIrradiance& ref, const ReferenceIrradiance& fine,
                                              const AplSet& pilot, const AplErrorOptions& options) {
  const int R = ref.spheres.patch_resolution();
  if (fine.spheres.patch_resolution() != 2 * R || fine.sphere.size() != ref.sphere.size() ||
      fine.spheres.rotated_patches() != ref.spheres.rotated_patches())
    throw std::invalid_argument("checked_centred_reference: the fine reference is not on the quarters of the patches");
  const std::vector<std::vector<double>> centre = pilot_on_patches(pilot, ref, options, 1);
  // The quarters' means at 2 × 2 points each: the same 4 × 4 points per patch as centred_reference's P̄.
  // A masked pilot's patches hold sharp borders, whose lit share 2 × 2 points find to a quarter: up to
  // 8 × 8 points a quarter there (detail::masked_pilot_subsamples; docs/apl_sets.md, "What the table
  // stores").
  const bool masked = pilot.levels.at(0).has_masks();
  const std::vector<std::vector<double>> quarters =
      pilot_on_patches(pilot, fine, options, masked ? detail::masked_pilot_subsamples(fine.spheres, 8) : 2);
  ReferenceIrradiance out = ref;
  const std::size_t W = std::size_t(2 * R), Wf = 2 * W;
  for (std::size_t s = 0; s < out.sphere.size(); ++s) {
    SphereReference& sr = out.sphere[s];
    const SphereReference& fr = fine.sphere[s];
    const std::vector<double>& pq = quarters[s];
    std::vector<double> delta(sr.irradiance.size()), pilot_mean(sr.irradiance.size());
    double q = 0, q0 = 0, shift = 0, mean = 0, excess_sq = 0;
    for (std::size_t y = 0; y < std::size_t(R); ++y)
      for (std::size_t x = 0; x < W; ++x) {
        const std::size_t p = y * W + x;
        std::size_t f[4];
        for (int b = 0; b < 2; ++b)
          for (int a = 0; a < 2; ++a) f[2 * b + a] = (2 * y + std::size_t(b)) * Wf + 2 * x + std::size_t(a);
        double pbar = 0, rbar = 0, r[4], qi = 0, q0i = 0;
        for (int j = 0; j < 4; ++j) {
          pbar += 0.25 * pq[f[j]];
          r[j] = fr.irradiance[f[j]] - pq[f[j]];
          rbar += 0.25 * r[j];
          q0i += 0.75 * fr.variance[f[j]];
        }
        for (int j = 0; j < 4; ++j) qi += (r[j] - rbar) * (r[j] - rbar);
        q += qi;
        q0 += q0i;
        excess_sq += (qi - q0i) * (qi - q0i);
        // The move the centring makes (by adding, or for a masked pilot by scaling: centre_patch).
        delta[p] = masked ? detail::centred_value(sr.irradiance[p], centre[s][p], pbar, true) - sr.irradiance[p]
                          : centre[s][p] - pbar;
        pilot_mean[p] = pbar;
        shift += delta[p] * delta[p];
        mean += sr.irradiance[p];
      }
    const double n = double(sr.irradiance.size());
    mean /= n;
    // The excess q − q0 is a sum of n per-patch terms; its standard error from their scatter about their
    // mean, and the check uses the upper bound q − q0 + 2·SE, so a pilot is not trusted on noise alone.
    const double mean_excess = (q - q0) / n;
    const double se = std::sqrt(std::max(0.0, excess_sq / n - mean_excess * mean_excess) * n);
    sr.centring_shift = mean > 0 ? std::sqrt(shift / n) / mean : 0.0;
    sr.pilot_shape_error = mean > 0 ? std::sqrt(std::max(0.0, q - q0 + 2 * se) / (4 * n)) / mean : 0.0;
    sr.centred = 2 * sr.pilot_shape_error < sr.centring_shift;
    if (!sr.centred) continue;
    for (std::size_t p = 0; p < sr.irradiance.size(); ++p)
      detail::centre_patch(sr, p, centre[s][p], pilot_mean[p], masked);
    if (masked) detail::refresh_noise_floors(sr);
  }
  return out;
}

LUMX_NAMESPACE_END
