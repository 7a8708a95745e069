// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/apl/error.h — how far each level of an APL set is from the luminaire it represents: reference
// irradiance on measurement spheres from rays the set was not built from, the error at single points as a
// renderer queries them, the reference's own noise (estimated and removed), cost per level, and the
// per-level error tables that the LOD error-target rule reads (apl/lod.h).
//
// Method (dissertation 000 §5.3, "virtual measurement spheres", Figure 5.8; seed 001 §6):
//   - Spheres. Around the set's bounding sphere (centre c = bounds.center, diameter D = 2·bounds.radius)
//     we place spheres of radius ρ = d·D for relative distances d (default 0.5, 0.75, 1, 2, 5, 10; d = 0.5
//     is the bounding sphere itself, d = 5 the traditional start of the far field).
//   - Patches. Each sphere is cut into N equal-area patches: the texels of an equal-area sphere map of
//     resolution R_patch (math/sphere_map.h), seen from c. Every texel covers 4π/N sr, so every patch covers
//     the area A = 4πρ²/N. R_patch = 16 gives N = 2·16² = 512.
//   - Reference. Every ray (start p, direction ω, flux Φ) is followed to where it leaves each sphere, and
//     Φ is added to the patch that contains the exit point's direction from c. The reference irradiance of
//     patch i is E_ref(i) = Σ Φ / A (lx for lm, W/m² for W): flux through the patch per unit area, the
//     histogram estimate of irradiance on the sphere (000 §5.3).
//       · Rays start inside or on the sphere for d ≥ 0.5 when the bounds hold every start point. A ray
//         starting outside is counted (`started_outside`); it contributes at its exit point if its line
//         crosses the sphere ahead of it, and is otherwise counted in `missed`.
//   - Held-out rays. The reference must come from rays the set was not built from: evaluate_held_out
//     builds from the even rays and gathers the reference from the odd ones (rays/holdout.h; each half's
//     flux ×2, so both estimate the whole luminaire), or, when the reference is centred (below), from
//     rays 3, 7, 11, … while rays 1, 5, 9, … make the pilot. Against its own rays a set's noise is the
//     reference's noise and cancels: on the 100 k-ray OSRAM blue LED that scored every level below the
//     rays' noise floor. evaluate_apl_errors grades a given set against given rays and is honest only when
//     they are independent of it.
//   - Model at a point. A level's irradiance at patch i is irradiance(set, k, x, n) (apl/evaluation.h) at
//     one point, x = c + ρ·u with u the patch centre's direction, and the normal n = −u pointing to the
//     sphere's centre, so light leaving the luminaire outward counts with the same projected area as the
//     reference's flux per area. That is what a shading point sees, texel noise and all. The reference
//     is a patch average, which equals the irradiance at the patch centre to second order in the patch
//     size (the texel centre is its centroid to that order); a lobe narrower than a few patches has patch
//     means well below its peak, so the held-out evaluators move the reference to the patch centres by
//     the shape of a pilot set built from rays the graded set never saw (centred_reference:
//     E_c = E_ref + P(centre) − P̄). A kink within a patch that the pilot does not resolve (a sharp
//     shadow border) still counts as error of the model there. A masked pilot (point sources behind
//     apertures, whose borders are geometry) scales instead, E_c = E_ref·P(centre)/P̄, takes the graded
//     set's beam masks too (pilot_with_known_borders), and adds to the upper bound what a patch centre
//     beyond every mask may still receive (border_allowance).
//     patch_subsamples = k > 1 averages the model over k×k points per patch instead (0: k per level by
//     the map resolution): a patch-averaged figure that hides texel noise, reported as such, never as
//     the headline.
//   - Far field. The "far field" row is level 0's summed maps, Σ_i I_i(ω) (far_field_intensity, the
//     intensity the IES/LDT export samples), as one point at the bounding-sphere centre c:
//     E = I(ω)·max(0, −n·ω)/r².
//
// Metrics, per (level, d), over the N patches (E_ref = reference, E = model):
//   relative RMSE (000 eq. 5.1)   ε = √(Σ_i (E_ref(i) − E(i))² / N) / (Σ_i E_ref(i) / N)
//   normalised distributions      p_i = E_ref(i) / Σ_j E_ref(j),  q_i = E(i) / Σ_j E(j)   (Σ p = Σ q = 1;
//                                 equal-area patches make these probabilities of a patch receiving light)
//   l² distance (001 §6)          D_l²(p, q) = √(Σ_i (p_i − q_i)²)                          ∈ [0, √2]
//   Hellinger distance (001 §6)   D_H(p, q) = √(½ Σ_i (√p_i − √q_i)²)                      ∈ [0, 1]
//   ε measures absolute (flux) errors relative to the mean; D_l² and D_H only the shape of the pattern.
//   A metric is NaN when it is undefined: no patch, or a distribution with no light (Σ = 0).
//
// Noise. E_ref(i) is a Monte-Carlo estimate: M rays, each in patch i with some probability. Its variance
// is estimated from the rays themselves, v_i = (Σ_{j∈i} Φ_j² − (Σ_{j∈i} Φ_j)²/M) / A² (the variance of a
// sum of M independent draws of Φ·[ray in i]; for equal fluxes n_iΦ²(1 − n_i/M), the binomial variance).
// With m the mean of E_ref, r_i = E(i) − E_ref(i):
//   noise floor                 σ = √(Σ_i v_i / N) / m        (the ε an exact model would show)
//   noise removed               ε̂² = ε² − σ²                 (E[r_i²] = (E(i) − E_true(i))² + v_i when the
//                                                             model is independent of the reference)
//   its standard error          u = √(Σ_i 2 v_i² + 4 max(0, r_i² − v_i) v_i) / (N m²)   (r_i Gaussian)
//   ε̂ is resolved when ε̂² > 2u; otherwise only the bound ε̂ < √(max(0, ε̂²) + 2u) is reported. A model is
// never reported better than the reference can tell.
// The even and odd rays of the reference also give `split_noise_floor`, √(Σ (E_a − E_b)²/N)/m/2 (a half
// has √2 × the noise and a difference of two halves √2 × more): a second estimate of σ, from the rays'
// scatter rather than a formula; the tests check that the two agree.
//
// Cost. A level's points are evaluated on `threads` threads; its irradiance is timed with std::chrono on
// one thread (the whole pass when it runs on one thread, then points spread over every sphere until
// `min_timing_seconds` have passed; none when the option is 0 and the pass ran on several) and reported
// as ns per irradiance evaluation, beside the bytes of its maps (AplLevel::map_bytes()).
//
// Determinism and memory. The rays are streamed once, in order, and summed in double: the same set,
// rays and options give bit-identical errors (timings aside), whatever the chunk size and thread count.
// Memory is O(spheres × N) for the reference and O(spheres × N × k²) while a level is evaluated,
// independent of the ray count; the fit also keeps a level's lookups, O(spheres × N × APLs), up to
// kLookupBytes.
#pragma once

#include <lumx/apl/evaluation.h>
#include <lumx/apl/apl_set.h>
#include <lumx/rays/holdout.h>
#include <lumx/rays/rayset.h>
#include <lumx/math/detail/parallel_jobs.h>
#include <lumx/math/sphere_map.h>
#include <lumx/math/sphere_map_kernel.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// The three metrics of one model against one reference on one sphere (see the header comment).
struct IrradianceErrors {
  double relative_rmse = NAN;  ///< 000 eq. 5.1 against the reference, noise included (a fraction: 0.04 = 4 %)
  /// ε̂ = √max(0, ε² − σ²): the relative RMSE with the reference's noise variance removed (see above);
  /// NaN without a variance estimate.
  double relative_rmse_noise_removed = NAN;
  /// √(max(0, ε² − σ²) + 2u): what ε̂ is known to be below (its value plus two standard errors of ε̂²).
  double noise_removed_upper = NAN;
  /// u: the standard error of ε̂² (of ε² − σ², from the reference's noise; header comment).
  double noise_removed_standard_error = NAN;
  bool resolved = false;   ///< ε̂² > 2u: the error stands out of the reference's noise
  double l2 = NAN;         ///< l² distance of the normalised distributions (001 §6)
  double hellinger = NAN;  ///< Hellinger distance of the normalised distributions (001 §6)
};

/// Relative RMSE (eq. 5.1), l² and Hellinger distances of `model` against `reference`, patch by patch.
/// Throws std::invalid_argument when the sizes differ. Undefined metrics are NaN: every metric for no
/// patch; the relative RMSE when Σ reference = 0; l² and Hellinger when either sum is 0 or a value is
/// negative (they compare probability distributions).
inline IrradianceErrors compare_irradiance(const std::vector<double>& reference, const std::vector<double>& model) {
  if (reference.size() != model.size())
    throw std::invalid_argument("compare_irradiance: " + std::to_string(reference.size()) + " reference values, " +
                                std::to_string(model.size()) + " model values");
  IrradianceErrors e;
  const std::size_t n = reference.size();
  if (n == 0) return e;
  double sum_ref = 0, sum_model = 0, sq = 0;
  bool non_negative = true;
  for (std::size_t i = 0; i < n; ++i) {
    sum_ref += reference[i];
    sum_model += model[i];
    sq += (reference[i] - model[i]) * (reference[i] - model[i]);
    non_negative = non_negative && reference[i] >= 0 && model[i] >= 0;
  }
  const double mean_ref = sum_ref / double(n);
  if (mean_ref != 0) e.relative_rmse = std::sqrt(sq / double(n)) / mean_ref;
  if (!non_negative || !(sum_ref > 0) || !(sum_model > 0)) return e;
  double l2 = 0, h = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double p = reference[i] / sum_ref, q = model[i] / sum_model;
    l2 += (p - q) * (p - q);
    h += (std::sqrt(p) - std::sqrt(q)) * (std::sqrt(p) - std::sqrt(q));
  }
  e.l2 = std::sqrt(l2);
  e.hellinger = std::sqrt(0.5 * h);
  return e;
}

/// compare_irradiance, plus the noise-removed relative RMSE from the reference's variance per patch.
/// `border` (optional, per patch, (lx)²: SphereReference::border) widens the upper bound by its mean over
/// m², b: √(max(0, ε² − σ²) + 2u + b); the estimate is resolved only when ε² − σ² > 2u + b.
inline IrradianceErrors compare_irradiance(const std::vector<double>& reference, const std::vector<double>& model,
                                           const std::vector<double>& variance,
                                           const std::vector<double>* border = nullptr) {
  IrradianceErrors e = compare_irradiance(reference, model);
  if (variance.size() != reference.size())
    throw std::invalid_argument("compare_irradiance: " + std::to_string(variance.size()) + " variances for " +
                                std::to_string(reference.size()) + " patches");
  if (border && !border->empty() && border->size() != reference.size())
    throw std::invalid_argument("compare_irradiance: " + std::to_string(border->size()) + " border terms for " +
                                std::to_string(reference.size()) + " patches");
  double b = 0;
  if (border)
    for (double x : *border) b += std::max(0.0, x);
  const std::size_t n = reference.size();
  double sum_ref = 0, sq = 0, var = 0, u2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r2 = (model[i] - reference[i]) * (model[i] - reference[i]), v = std::max(0.0, variance[i]);
    sum_ref += reference[i];
    sq += r2;
    var += v;
    u2 += 2 * v * v + 4 * std::max(0.0, r2 - v) * v;
  }
  if (n == 0 || !(sum_ref > 0)) return e;
  const double m2 = (sum_ref / double(n)) * (sum_ref / double(n));
  const double excess = (sq - var) / double(n) / m2;  // ε² − σ²
  const double u = std::sqrt(u2) / double(n) / m2;
  e.relative_rmse_noise_removed = std::sqrt(std::max(0.0, excess));
  const double allowance = b / double(n) / m2;
  e.noise_removed_upper = std::sqrt(std::max(0.0, excess) + 2 * u + allowance);
  e.noise_removed_standard_error = u;
  // Resolved: out of the reference's noise and of what its borders may hide.
  e.resolved = excess > 2 * u + allowance;
  return e;
}

/// The noise floor of a reference from its two independent halves (each scaled to estimate the whole):
/// √(Σ (a_i − b_i)² / N) / mean((a + b)/2) / 2 — the relative RMSE of the halves against each other,
/// over 2 (see the header comment for the factor). NaN when empty or without light; throws
/// std::invalid_argument when the sizes differ.
inline double noise_floor(const std::vector<double>& half_a, const std::vector<double>& half_b) {
  if (half_a.size() != half_b.size()) throw std::invalid_argument("noise_floor: the halves have different sizes");
  const std::size_t n = half_a.size();
  if (n == 0) return NAN;
  double sum = 0, sq = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sum += 0.5 * (half_a[i] + half_b[i]);
    sq += (half_a[i] - half_b[i]) * (half_a[i] - half_b[i]);
  }
  if (!(sum > 0)) return NAN;
  return 0.5 * std::sqrt(sq / double(n)) / (sum / double(n));
}

struct AplErrorOptions {
  /// Relative distances d of the measurement spheres (radius d·D); sorted, positive, distinct.
  std::vector<double> relative_distances = {0.5, 0.75, 1, 2, 5, 10};
  /// R_patch: the patches are the texels of a sphere map of this resolution, N = 2·R² (1..1024).
  int patch_resolution = 16;
  /// k: 1 (default) = one point per patch, its centre, as a renderer queries; k > 1 = the mean over k×k
  /// sub-texel centres (≤ 16), or 0: per level, k = ⌈R_map / R_patch⌉ within [1, 16] and `max_apl_lookups`
  /// — patch-averaged figures that hide the maps' texel noise (header comment).
  int patch_subsamples = 1;
  /// true (default): the patches are laid out in a frame rotated from the photometric frame (patch_frame()
  /// below), so their centres fall at generic places of the maps' texel grids. With false the patch centres
  /// of R_patch = 16 are the texel centres of every R 16 map drawn in the photometric frame (MapFrame
  /// identity; and of coarser maps' texel edges and corners),
  /// where a bilinear lookup returns a texel's mean exactly: the maps' interpolation error (largest along
  /// the concentric map's diagonals, where direction → square is not smooth) is then never seen, and a
  /// level at R 16 is graded ~2× better than at a renderer's random shading points (docs/apl_sets.md).
  bool rotated_patches = true;
  /// Bound on one level's APL lookups (APLs × k² × N × spheres) when k is automatic (2·10⁸: 5–10 s at
  /// 25–50 ns per lookup on one thread).
  double max_apl_lookups = 2e8;
  /// D used when the set's bounding diameter is smaller (m). A point source (every ray from one point,
  /// D = 0) still gets spheres; its relative errors do not depend on the radius, since its pattern on
  /// every sphere is the intensity scaled by 1/ρ².
  double min_diameter = 1e-3;
  std::size_t chunk_rays = 1 << 16;  ///< rays per read
  /// The level timings run on one thread until at least this long has passed (0: the one-thread pass
  /// only, and none when the points ran on several threads: no time is then reported).
  double min_timing_seconds = 0.01;
  /// Threads a level's points are evaluated on (0: the hardware's, at most 8). Each point is evaluated
  /// alone, so the errors do not depend on it; the timings are of one thread's loop, as a renderer's shading
  /// point is one thread's work.
  unsigned threads = 0;
  bool far_field = true;         ///< evaluate the far-field row
  IrradianceOptions irradiance;  ///< passed to irradiance() (minimum distance)
  /// Called with the fraction done (0..1) and a phase ("rays", "levels"), at most a few hundred times.
  std::function<void(double, const char*)> progress;
};

/// The measurement spheres and their patches: geometry only (no rays).
class MeasurementSpheres {
 public:
  MeasurementSpheres() = default;
  /// Throws std::invalid_argument for bad options (see AplErrorOptions) or a non-finite bound.
  MeasurementSpheres(const BoundingSphere& bounds, const AplErrorOptions& o)
      : centre_(bounds.center),
        resolution_(o.patch_resolution),
        subsamples_(o.patch_subsamples),
        rotated_(o.rotated_patches) {
    if (o.relative_distances.empty()) throw std::invalid_argument("apl_error: no relative distance given");
    distances_ = o.relative_distances;
    std::sort(distances_.begin(), distances_.end());
    for (std::size_t j = 0; j < distances_.size(); ++j)
      if (!(distances_[j] > 0) || !std::isfinite(distances_[j]) || (j > 0 && distances_[j] == distances_[j - 1]))
        throw std::invalid_argument("apl_error: relative distances must be positive, finite and distinct");
    if (resolution_ < 1 || resolution_ > 1024)
      throw std::invalid_argument("apl_error: patch_resolution must be in [1, 1024]");
    if (subsamples_ < 0 || subsamples_ > 16)
      throw std::invalid_argument("apl_error: patch_subsamples must be in [1, 16], or 0 (automatic)");
    if (!(o.max_apl_lookups > 0)) throw std::invalid_argument("apl_error: max_apl_lookups must be positive");
    max_lookups_ = o.max_apl_lookups;
    if (!std::isfinite(bounds.radius) || !(bounds.radius >= 0) || !std::isfinite(bounds.center.x) ||
        !std::isfinite(bounds.center.y) || !std::isfinite(bounds.center.z))
      throw std::invalid_argument("apl_error: the bounding sphere is not finite");
    if (!(o.min_diameter > 0) || !std::isfinite(o.min_diameter))
      throw std::invalid_argument("apl_error: min_diameter must be positive");
    diameter_ = std::max(2.0 * bounds.radius, o.min_diameter);
  }

  std::size_t sphere_count() const { return distances_.size(); }
  /// N = 2·R_patch² patches per sphere.
  std::size_t patch_count() const { return std::size_t(2) * std::size_t(resolution_) * std::size_t(resolution_); }
  int patch_resolution() const { return resolution_; }
  /// The option as given: k, or 0 for automatic (see subsamples_for).
  int patch_subsamples() const { return subsamples_; }
  /// k for a level of `apls` APLs with maps of resolution `map_resolution`: the option when it is fixed;
  /// else ⌈map_resolution / R_patch⌉ within [1, 16], lowered while APLs · k² · N · spheres > max_apl_lookups.
  int subsamples_for(int map_resolution, std::size_t apls) const {
    if (subsamples_ > 0) return subsamples_;
    int k = std::clamp((map_resolution + resolution_ - 1) / resolution_, 1, 16);
    const double per_k2 = double(std::max<std::size_t>(apls, 1)) * double(patch_count()) * double(sphere_count());
    while (k > 1 && per_k2 * k * k > max_lookups_) --k;
    return k;
  }
  const std::vector<double>& relative_distances() const { return distances_; }
  glm::dvec3 centre() const { return centre_; }
  /// D: the bounding diameter, or min_diameter when that is larger.
  double diameter() const { return diameter_; }
  /// ρ = d·D of sphere s (m).
  double radius(std::size_t s) const { return distances_.at(s) * diameter_; }
  /// Area of one patch of sphere s: 4πρ²/N (m²).
  double patch_area(std::size_t s) const {
    const double r = radius(s);
    return 4.0 * kPi * r * r / double(patch_count());
  }
  /// The patch (texel index y·2R + x) that contains unit direction u seen from the centre.
  std::size_t patch_of(const glm::vec3& u) const {
    int x, y;
    sphere_map::texel_of(to_patch_frame(u), resolution_, x, y);
    return std::size_t(y) * std::size_t(2 * resolution_) + std::size_t(x);
  }
  /// Unit directions of the evaluation points: the centres of k×k sub-texels of every patch, patch by
  /// patch (k = 1: the patch centres).
  std::vector<glm::dvec3> evaluation_directions(int k) const {
    if (k < 1 || k > 16) throw std::invalid_argument("apl_error: subsamples must be in [1, 16]");
    const int R = resolution_;
    std::vector<glm::dvec3> out;
    out.reserve(patch_count() * std::size_t(k * k));
    for (int y = 0; y < R; ++y)
      for (int x = 0; x < 2 * R; ++x)
        for (int j = 0; j < k; ++j)
          for (int i = 0; i < k; ++i) {
            const float u = (float(x) + (float(i) + 0.5f) / float(k)) / float(2 * R);
            const float v = (float(y) + (float(j) + 0.5f) / float(k)) / float(R);
            out.push_back(from_patch_frame(glm::normalize(glm::dvec3(sphere_map::uv_to_direction({u, v})))));
          }
    return out;
  }
  bool rotated_patches() const { return rotated_; }
  /// The rotation from the patch frame to the photometric frame: 1 rad about the axis (1, √2, √3)/√6. Any
  /// rotation whose angle and axis are not commensurate with the map's π/4 wedges would do; this one is fixed
  /// so that figures are reproducible.
  static glm::dmat3 patch_frame() {
    const glm::dvec3 a = glm::normalize(glm::dvec3(1.0, std::sqrt(2.0), std::sqrt(3.0)));
    const double c = std::cos(1.0), s = std::sin(1.0), t = 1.0 - c;
    // Rodrigues: R = cI + s[a]× + t·a aᵀ (columns, as glm stores them).
    return glm::dmat3(glm::dvec3(c + t * a.x * a.x, t * a.x * a.y + s * a.z, t * a.x * a.z - s * a.y),
                      glm::dvec3(t * a.x * a.y - s * a.z, c + t * a.y * a.y, t * a.y * a.z + s * a.x),
                      glm::dvec3(t * a.x * a.z + s * a.y, t * a.y * a.z - s * a.x, c + t * a.z * a.z));
  }

 private:
  glm::vec3 to_patch_frame(const glm::vec3& u) const {
    if (!rotated_) return u;
    static const glm::mat3 inverse = glm::mat3(glm::transpose(patch_frame()));
    return inverse * u;
  }
  glm::dvec3 from_patch_frame(const glm::dvec3& u) const {
    if (!rotated_) return u;
    static const glm::dmat3 forward = patch_frame();
    return forward * u;
  }

  glm::dvec3 centre_{0.0};
  double diameter_ = 0;
  int resolution_ = 0, subsamples_ = 0;
  bool rotated_ = true;
  double max_lookups_ = 2e8;
  std::vector<double> distances_;
};

/// The reference irradiance on one sphere.
struct SphereReference {
  double relative_distance = 0;       ///< d
  double radius = 0;                  ///< ρ = d·D, m
  double patch_area = 0;              ///< 4πρ²/N, m²
  std::vector<double> irradiance;     ///< E_ref per patch: Σ Φ / A (lx or W/m²)
  std::vector<double> variance;       ///< v_i: the estimated variance of E_ref(i) ((lx)², header comment)
  std::vector<double> half_even;      ///< from even-indexed rays only, × 2
  std::vector<double> half_odd;       ///< from odd-indexed rays only, × 2
  double flux = 0;                    ///< Σ Φ gathered on this sphere (lm or W)
  std::uint64_t rays = 0;             ///< rays gathered (flux > 0)
  std::uint64_t started_outside = 0;  ///< rays (flux > 0) whose start point lies outside this sphere
  std::uint64_t missed = 0;           ///< of those, rays whose line never leaves the sphere ahead of them
  double noise_floor = NAN;           ///< σ = √(mean v_i) / mean E_ref: the ε an exact model would show
  double split_noise_floor = NAN;     ///< noise_floor(half_even, half_odd): the same from the halves' scatter
  double centring_shift = NAN;        ///< checked_centred_reference: RMS move to the patch centres / mean E_ref
  double pilot_shape_error = NAN;  ///< checked_centred_reference: upper bound of the pilot's shape error / mean E_ref
  /// False: E_ref per patch is the patch mean Σ Φ / A. True: moved to the patch centres by a pilot's shape
  /// within each patch (centred_reference), where a level evaluated at one point per patch is queried.
  bool centred = false;
  /// (lx)² per patch: what the centre may receive beyond every beam mask the rays gave, as an expected
  /// square (border_allowance); empty: none. Added to the noise-removed upper bound and to what an
  /// estimate must exceed to be resolved, never to ε̂.
  std::vector<double> border;
  double border_share = 0;  ///< √(mean border) / mean E_ref: the same as a relative RMSE
};

/// The reference of every sphere, from one pass over a rayset.
struct ReferenceIrradiance {
  MeasurementSpheres spheres;
  std::vector<SphereReference> sphere;  ///< one per relative distance, increasing
  PhotometricQuantity quantity = PhotometricQuantity::photometric;
  std::uint64_t rays = 0;  ///< rays streamed
  std::uint64_t zero_flux_rays = 0;
  double flux = 0;  ///< Σ Φ of every ray (lm or W)
};

namespace detail {
/// σ and the halves' σ of a sphere from its patches (gather_reference, and again after centre_patch
/// scales variances).
inline void refresh_noise_floors(SphereReference& sr) {
  double sum = 0, var = 0;
  for (std::size_t p = 0; p < sr.irradiance.size(); ++p) sum += sr.irradiance[p], var += sr.variance[p];
  const double n = double(sr.irradiance.size());
  sr.noise_floor = sum > 0 ? std::sqrt(var / n) / (sum / n) : NAN;
  if (sr.half_even.size() == sr.irradiance.size() && sr.half_odd.size() == sr.irradiance.size())
    sr.split_noise_floor = noise_floor(sr.half_even, sr.half_odd);
}
}  // namespace detail

/// Streams `rays` once (rewinding first) and gathers the reference irradiance on the spheres around
/// `bounds`. Throws std::invalid_argument for bad options, or for a ray with a non-finite position or
/// direction, a zero direction, or a negative or non-finite flux (the ray's index in the message).
inline ReferenceIrradiance gather_reference(RaySource& rays, const BoundingSphere& bounds,
                                            const AplErrorOptions& options = {}) {
  ReferenceIrradiance ref;
  ref.spheres = MeasurementSpheres(bounds, options);
  ref.quantity = rays.info().quantity;
  const MeasurementSpheres& ms = ref.spheres;
  const std::size_t ns = ms.sphere_count(), np = ms.patch_count();
  // Per sphere, flux sums of the even and odd rays (the full sum is their sum).
  std::vector<std::vector<double>> even(ns, std::vector<double>(np, 0.0)), odd = even, squares = even;
  std::vector<double> radius2(ns);
  ref.sphere.resize(ns);
  for (std::size_t s = 0; s < ns; ++s) {
    ref.sphere[s].relative_distance = ms.relative_distances()[s];
    ref.sphere[s].radius = ms.radius(s);
    ref.sphere[s].patch_area = ms.patch_area(s);
    radius2[s] = ms.radius(s) * ms.radius(s);
  }
  const glm::dvec3 c = ms.centre();
  const std::uint64_t expected = rays.info().ray_count;
  RayChunk chunk;
  rays.rewind();
  std::uint64_t index = 0;
  int reported = -1;
  while (rays.next(chunk, std::max<std::size_t>(1, options.chunk_rays))) {
    for (std::size_t i = 0; i < chunk.size(); ++i, ++index) {
      const double flux = chunk.flux[i];
      const glm::dvec3 o = glm::dvec3(chunk.position(i)) - c;
      const glm::dvec3 w(chunk.direction(i));
      const double a = glm::dot(w, w);
      if (!(flux >= 0) || !std::isfinite(flux) || !std::isfinite(o.x + o.y + o.z) || !std::isfinite(a) || !(a > 0))
        throw std::invalid_argument("apl_error: ray " + std::to_string(index) +
                                    " has a non-finite position, a zero or non-finite direction, or a negative or "
                                    "non-finite flux");
      if (flux == 0) {
        ++ref.zero_flux_rays;
        continue;
      }
      ref.flux += flux;
      // |o + tω|² = ρ²  ⇔  a t² + 2 b t + (|o|² − ρ²) = 0; the exit is the larger root.
      const double b = glm::dot(o, w), oo = glm::dot(o, o);
      for (std::size_t s = 0; s < ns; ++s) {
        SphereReference& sr = ref.sphere[s];
        const double cc = oo - radius2[s];
        const double disc = b * b - a * cc;
        if (cc > 0) {  // starts outside: only the exit of a crossing ahead counts
          ++sr.started_outside;
          if (disc < 0 || -b + std::sqrt(disc) <= 0) {
            ++sr.missed;
            continue;
          }
        }
        const double t = (-b + std::sqrt(std::max(0.0, disc))) / a;
        const glm::dvec3 h = o + t * w;
        const double len = glm::length(h);
        // On the sphere |h| = ρ > 0; guard anyway so a degenerate case lands in a fixed patch.
        const glm::vec3 u = len > 0 ? glm::vec3(h / len) : glm::vec3(0, 0, 1);
        const std::size_t p = ms.patch_of(u);
        (index % 2 == 0 ? even : odd)[s][p] += flux;
        squares[s][p] += flux * flux;
        sr.flux += flux;
        ++sr.rays;
      }
    }
    if (options.progress && expected > 0) {
      const int pct = int(100.0 * double(index) / double(expected));
      if (pct != reported) {
        options.progress(std::min(1.0, double(index) / double(expected)), "rays");
        reported = pct;
      }
    }
  }
  ref.rays = index;
  for (std::size_t s = 0; s < ns; ++s) {
    SphereReference& sr = ref.sphere[s];
    const double inv_area = 1.0 / sr.patch_area;
    sr.irradiance.resize(np);
    sr.half_even.resize(np);
    sr.half_odd.resize(np);
    sr.variance.resize(np);
    const double M = double(std::max<std::uint64_t>(sr.rays, 1));
    for (std::size_t p = 0; p < np; ++p) {
      const double f = even[s][p] + odd[s][p];
      sr.irradiance[p] = f * inv_area;
      sr.half_even[p] = 2.0 * even[s][p] * inv_area;
      sr.half_odd[p] = 2.0 * odd[s][p] * inv_area;
      sr.variance[p] = std::max(0.0, squares[s][p] - f * f / M) * inv_area * inv_area;
    }
    detail::refresh_noise_floors(sr);
  }
  return ref;
}

/// One row of the evaluation: a level (or the far field) against the reference on every sphere.
struct LevelErrors {
  int level = -1;                               ///< index in AplSet::levels; −1 for the far field
  std::size_t apls = 0;                         ///< APLs evaluated per point
  int map_resolution = 0;                       ///< R of the level's maps
  int subsamples = 1;                           ///< k: k×k evaluation points per patch
  std::vector<IrradianceErrors> errors;         ///< one per sphere (increasing d)
  std::vector<std::vector<double>> irradiance;  ///< per sphere, the model's E per patch
  double ns_per_evaluation = NAN;  ///< mean time of one irradiance evaluation on one thread (ns; NaN: untimed)
  std::size_t bytes = 0;           ///< AplLevel::map_bytes() (for the far field: level 0's)
  std::size_t clamped = 0;         ///< APL distances clamped to the minimum (IrradianceResult::clamped)
  bool masked = false;             ///< the level has masked APLs (point sources behind apertures)
};

namespace detail {

/// The evaluation points of every sphere for k × k points per patch, in float as irradiance() takes them:
/// point i = s·P + e (P = N·k²) is at the centre + ρ_s·dirs[e], with normal −dirs[e] (facing the centre).
struct EvaluationPoints {
  std::vector<glm::vec3> x, normal;  ///< per point; per direction e
  std::size_t per_sphere = 0;        ///< P
  EvaluationPoints(const MeasurementSpheres& ms, int k) {
    const std::vector<glm::dvec3> dirs = ms.evaluation_directions(k);
    per_sphere = dirs.size();
    x.resize(ms.sphere_count() * dirs.size());
    normal.resize(dirs.size());
    for (std::size_t e = 0; e < dirs.size(); ++e) normal[e] = glm::vec3(-dirs[e]);
    for (std::size_t s = 0; s < ms.sphere_count(); ++s)
      for (std::size_t e = 0; e < dirs.size(); ++e)
        x[s * dirs.size() + e] = glm::vec3(ms.centre() + ms.radius(s) * dirs[e]);
  }
  const glm::vec3& normal_of(std::size_t i) const { return normal[i % per_sphere]; }
};

/// Evaluates `point_irradiance(i, x, n, clamped)` (a scalar at point i, x, with normal n; `clamped` counts
/// clamped distances, null in the timing repeats; called from several threads at once unless o.threads is
/// 1) at every evaluation point of every sphere (EvaluationPoints), averages the subsamples per patch,
/// compares, and times the loop on one thread.
template <class PointIrradiance>
void evaluate_rows(const ReferenceIrradiance& ref, const AplErrorOptions& o, LevelErrors& row,
                   PointIrradiance&& point_irradiance) {
  const MeasurementSpheres& ms = ref.spheres;
  const std::size_t ns = ms.sphere_count(), np = ms.patch_count();
  row.subsamples = ms.subsamples_for(row.map_resolution, row.apls);
  const std::size_t k2 = std::size_t(row.subsamples) * std::size_t(row.subsamples);
  // Computed before the clock starts.
  const EvaluationPoints points(ms, row.subsamples);
  const std::vector<glm::vec3>& xs = points.x;
  std::vector<double> values(xs.size());
  using Clock = std::chrono::steady_clock;
  double seconds = 0;
  std::size_t timed = 0, clamped = 0;  // point evaluations timed; clamped distances
  if (parallel_threads(xs.size(), o.threads) == 1) {
    const auto t0 = Clock::now();
    for (std::size_t i = 0; i < xs.size(); ++i) values[i] = point_irradiance(i, xs[i], points.normal_of(i), &clamped);
    seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    timed = xs.size();
  } else {
    // Contiguous ranges of points, each with its own count of clamped distances.
    const std::size_t jobs = std::min<std::size_t>(xs.size(), 64);
    std::vector<std::size_t> clamped_in(jobs, 0);
    parallel_jobs(jobs, o.threads, [&](std::size_t j) {
      for (std::size_t i = xs.size() * j / jobs; i < xs.size() * (j + 1) / jobs; ++i)
        values[i] = point_irradiance(i, xs[i], points.normal_of(i), &clamped_in[j]);
    });
    for (std::size_t c : clamped_in) clamped += c;
  }
  // Timed (further) on one thread until min_timing_seconds have passed: batches of 64 points taken with a
  // stride prime to their count, so that every sphere is sampled whatever the batches' number.
  const std::size_t n = xs.size();
  std::size_t stride = n > 0 ? 7919 % n : 1;
  if (n > 0 && std::gcd(stride, n) != 1) stride = 1;
  std::size_t next = 0;
  volatile double sink = 0;
  while (seconds < o.min_timing_seconds && n > 0 && timed < 100000 * n) {
    const auto t1 = Clock::now();
    double s = 0;
    for (int b = 0; b < 64; ++b, next = (next + stride) % n)
      s += point_irradiance(next, xs[next], points.normal_of(next), nullptr);
    sink = sink + s;
    seconds += std::chrono::duration<double>(Clock::now() - t1).count();
    timed += 64;
  }
  row.clamped = clamped;
  row.ns_per_evaluation = timed == 0 ? NAN : 1e9 * seconds / double(timed);
  row.irradiance.assign(ns, std::vector<double>(np, 0.0));
  row.errors.resize(ns);
  for (std::size_t s = 0; s < ns; ++s) {
    for (std::size_t p = 0; p < np; ++p) {
      double sum = 0;
      for (std::size_t j = 0; j < k2; ++j) sum += values[s * points.per_sphere + p * k2 + j];
      row.irradiance[s][p] = sum / double(k2);
    }
    row.errors[s] = compare_irradiance(ref.sphere[s].irradiance, row.irradiance[s], ref.sphere[s].variance,
                                       &ref.sphere[s].border);
  }
}

}  // namespace detail

/// Level `k` of `set` against the reference: errors per sphere, time per evaluation, bytes. The set's
/// bounding sphere should be the one the reference was gathered around (evaluate_apl_errors does that).
namespace detail {
/// The luminance of irradiance() from level k at x (normal n), its clamped distances added to `clamped`:
/// what evaluate_level grades at a point, and the lookups at points they do not hold.
inline double level_luminance_at(const AplSet& set, std::size_t k, const glm::vec3& x, const glm::vec3& n,
                                 const IrradianceOptions& options, std::size_t* clamped) {
  const IrradianceResult r = irradiance(set, k, x, n, options);
  if (clamped) *clamped += r.clamped;
  return luminance_of(set.channels, r.irradiance);
}
}  // namespace detail

inline LevelErrors evaluate_level(const AplSet& set, std::size_t k, const ReferenceIrradiance& ref,
                                  const AplErrorOptions& options = {}) {
  const AplLevel& level = set.levels.at(k);
  LevelErrors row;
  row.level = int(k);
  row.apls = level.size();
  row.map_resolution = level.map_resolution;
  row.bytes = level.map_bytes();
  row.masked = level.has_masks();
  detail::evaluate_rows(ref, options, row,
                        [&](std::size_t, const glm::vec3& x, const glm::vec3& n, std::size_t* clamped) {
                          return detail::level_luminance_at(set, k, x, n, options.irradiance, clamped);
                        });
  return row;
}

namespace detail {
/// Everything irradiance() computes for a level at the evaluation points of a reference before it reads a
/// texel (apl_geometry: which APLs light each point, their footprints as offsets into the maps, their
/// weights), kept so that levels differing from it only in their maps' values (the fit's candidates at
/// one resolution: one level's maps downsampled, then smoothed in turn) are evaluated by the blends
/// alone, to the same bits as evaluate_level. Memory: 20 bytes per point and APL (the fit's 12 288 points,
/// R 32 patches on six spheres, × 512 APLs: 126 MB). Under a memory budget, the lookups of as many points
/// as it holds are kept (the first ones, in evaluation order), and the other points are evaluated as
/// evaluate_level does: the same bits either way.
class LevelLookups {
 public:
  /// The bytes LevelLookups(set, k, ref, o) would hold for every point.
  static double bytes_for(const AplSet& set, std::size_t k, const ReferenceIrradiance& ref) {
    const AplLevel& level = set.levels.at(k);
    const double q = double(ref.spheres.subsamples_for(level.map_resolution, level.size()));
    const double points = double(ref.spheres.sphere_count()) * double(ref.spheres.patch_count()) * q * q;
    return points * bytes_per_point(level.size());
  }

  /// The lookups of level k of `set` at the evaluation points of `ref`, on o.threads threads: of every
  /// point, or of as many of the first points as `max_bytes` holds (bytes_for: at most that much).
  LevelLookups(const AplSet& set, std::size_t k, const ReferenceIrradiance& ref, const AplErrorOptions& o,
               double max_bytes = INFINITY) {
    const AplLevel& level = set.levels.at(k);
    // The lookups read plain maps; a masked level is graded by evaluate_level (fit_map_resolutions).
    if (level.has_masks()) throw std::invalid_argument("LevelLookups: level " + std::to_string(k) + " has masked APLs");
    apls_ = level.size();
    resolution_ = level.map_resolution;
    to_map_ = level.frame.to_map;
    turned_ = !level.frame.is_identity();
    for (const Apl& a : level.apls) {
      positions_.push_back(a.position);
      channels_.push_back(a.map.channels());
    }
    subsamples_ = ref.spheres.subsamples_for(level.map_resolution, apls_);
    const EvaluationPoints points(ref.spheres, subsamples_);
    points_ = points.x;
    const double held = std::floor(std::max(0.0, max_bytes) / bytes_per_point(apls_));
    const std::size_t n = held < double(points.x.size()) ? std::size_t(held) : points.x.size();
    entries_.resize(n * apls_);
    count_.assign(n, 0);
    clamped_.assign(n, 0);
    min_r_ = float(effective_min_distance(set, o.irradiance));
    ignore_normal_ = o.irradiance.ignore_normal;
    const std::size_t jobs = std::min<std::size_t>(n, 64);
    parallel_jobs(jobs, o.threads, [&](std::size_t j) {
      for (std::size_t i = n * j / jobs; i < n * (j + 1) / jobs; ++i) {
        Entry* out = entries_.data() + i * apls_;
        std::size_t count = 0, clamped = 0;
        for (std::size_t a = 0; a < apls_; ++a) {
          glm::vec3 w;
          float cosine, r2;
          if (!apl_geometry(level.apls[a].position, points.x[i], points.normal_of(i), min_r_, ignore_normal_, w, cosine,
                            r2, clamped))
            continue;
          const SphereMap::Footprint f = level.apls[a].map.footprint(turned_ ? to_map_ * w : w);
          Entry& e = out[count++];
          e.apl = std::uint32_t(a);
          // A footprint inside the square: texel (x0, y0) of the map and its right and lower neighbours;
          // across a seam (the squares' edges, whose neighbours are elsewhere) it is taken again.
          const float* p = f.texel[0];
          const std::ptrdiff_t C = level.apls[a].map.channels(), row = std::ptrdiff_t(level.apls[a].map.width()) * C;
          const bool inside = f.texel[1] - p == C && f.texel[2] - p == row && f.texel[3] - p == row + C;
          e.texel = inside ? std::uint32_t(p - level.apls[a].map.data()) : kSeam;
          e.tx = f.tx;
          e.ty = f.ty;
          e.weight = cosine * 1.0f / r2;  // irradiance()'s weight with visibility 1, to the bit
        }
        count_[i] = std::uint32_t(count);
        clamped_[i] = std::uint32_t(clamped);
      }
    });
  }

  /// The points whose lookups are kept (the first ones in evaluation order); of all of them when equal to
  /// the number of evaluation points.
  std::size_t points_looked_up() const { return count_.size(); }

  /// Level k of `set` against `ref` (as evaluate_level, the same bits). Throws std::invalid_argument when
  /// the level is not laid out as the one the lookups were taken from (its APLs, their positions, maps'
  /// resolutions and channels, or its frame, compared bit for bit), the irradiance options or the set's
  /// bounds give another clamp distance or normal rule, or `ref` has other evaluation points. Its
  /// ns_per_evaluation, when timed, is of the blends alone.
  LevelErrors evaluate(const AplSet& set, std::size_t k, const ReferenceIrradiance& ref,
                       const AplErrorOptions& o) const {
    const AplLevel& level = set.levels.at(k);
    check(set, level, ref, o);
    LevelErrors row;
    row.level = int(k);
    row.apls = level.size();
    row.map_resolution = level.map_resolution;
    row.bytes = level.map_bytes();
    evaluate_rows(ref, o, row, [&](std::size_t i, const glm::vec3& x, const glm::vec3& n, std::size_t* clamped) {
      if (i >= count_.size()) return level_luminance_at(set, k, x, n, o.irradiance, clamped);  // beyond the budget
      if (clamped) *clamped += clamped_[i];
      return luminance_of(set.channels, glm::dvec3(sum_at(level, i)));
    });
    return row;
  }

 private:
  static constexpr std::uint32_t kSeam = 0xffffffffu;
  struct Entry {
    std::uint32_t apl;
    std::uint32_t texel;  ///< offset of SphereMap::Footprint::texel[0] in the map's values; kSeam: across a seam
    float tx, ty, weight;
  };
  static double bytes_per_point(std::size_t apls) {
    return double(sizeof(Entry)) * double(apls) + sizeof(glm::vec3) + 2 * sizeof(std::uint32_t);
  }
  // The level's layout: what the lookups depend on besides the maps' values.
  std::size_t apls_ = 0;
  int resolution_ = 0;
  float min_r_ = 0;             ///< the clamp distance (effective_min_distance) the weights were taken with
  bool ignore_normal_ = false;  ///< and IrradianceOptions::ignore_normal
  glm::mat3 to_map_{1.0f};
  bool turned_ = false;  ///< to_map_ is not the identity (most sets: no 3×3 multiply per lookup)
  std::vector<glm::vec3> positions_;
  std::vector<int> channels_;
  std::vector<glm::vec3> points_;  ///< the evaluation points they were taken at
  int subsamples_ = 1;
  std::vector<Entry> entries_;  ///< point i's at [i·apls, i·apls + count_[i])
  std::vector<std::uint32_t> count_, clamped_;  ///< per point looked up: the first count_.size() points

  template <class T>
  static bool same_bits(const T& a, const T& b) {
    return std::memcmp(&a, &b, sizeof(T)) == 0;
  }

  void check(const AplSet& set, const AplLevel& level, const ReferenceIrradiance& ref, const AplErrorOptions& o) const {
    bool same = level.size() == apls_ && level.map_resolution == resolution_ &&
                same_bits(level.frame.to_map, to_map_) &&
                same_bits(float(effective_min_distance(set, o.irradiance)), min_r_) &&
                o.irradiance.ignore_normal == ignore_normal_ &&
                ref.spheres.subsamples_for(level.map_resolution, apls_) == subsamples_;
    if (same) {
      const EvaluationPoints points(ref.spheres, subsamples_);
      same = points.x.size() == points_.size() &&
             std::memcmp(points.x.data(), points_.data(), points_.size() * sizeof(glm::vec3)) == 0;
    }
    for (std::size_t a = 0; same && a < apls_; ++a)
      same = same_bits(level.apls[a].position, positions_[a]) && level.apls[a].map.resolution() == resolution_ &&
             level.apls[a].map.channels() == channels_[a];
    if (!same)
      throw std::invalid_argument(
          "LevelLookups: the level, its irradiance options or the reference are not the ones they were taken for");
  }

  /// irradiance()'s sum at point i: the blends in APL order, their texels prefetched 32 APLs ahead.
  glm::vec3 sum_at(const AplLevel& level, std::size_t i) const {
    constexpr std::size_t kChunk = 32;
    const Entry* e = entries_.data() + i * apls_;
    const std::size_t n = count_[i];
    glm::vec3 sum(0.0f);
    SphereMap::Footprint f[kChunk];
    for (std::size_t begin = 0; begin < n; begin += kChunk) {
      const std::size_t end = std::min(n, begin + kChunk);
      for (std::size_t j = begin; j < end; ++j) {
        const SphereMap& map = level.apls[e[j].apl].map;
        SphereMap::Footprint& fj = f[j - begin];
        if (e[j].texel != kSeam) {
          const float* p = map.data() + e[j].texel;
          const std::ptrdiff_t C = map.channels(), row = std::ptrdiff_t(map.width()) * C;
          fj.texel[0] = p;
          fj.texel[1] = p + C;
          fj.texel[2] = p + row;
          fj.texel[3] = p + row + C;
          fj.tx = e[j].tx;
          fj.ty = e[j].ty;
        } else {
          float r, r2;
          const glm::vec3 w = apl_direction(positions_[e[j].apl], points_[i], r, r2);
          fj = map.footprint(turned_ ? to_map_ * w : w);  // check(): the level's frame is to_map_
        }
        for (const float* t : fj.texel) __builtin_prefetch(t);
      }
      for (std::size_t j = begin; j < end; ++j) sum += level.apls[e[j].apl].map.blend(f[j - begin]) * e[j].weight;
    }
    return sum;
  }
};
}  // namespace detail

/// Irradiance at x (normal n) from level 0's far-field intensity Σ_i I_i(ω) placed at the bounding-sphere
/// centre (the "far field" row; see the header comment). Throws std::out_of_range without levels.
inline double far_field_irradiance(const AplSet& set, const glm::vec3& x, const glm::vec3& n,
                                   const IrradianceOptions& options = {}, std::size_t* clamped = nullptr) {
  const AplLevel& level = set.levels.at(0);
  const glm::vec3 d = x - glm::vec3(set.bounds.center);
  float r2 = glm::dot(d, d);
  const float r = std::sqrt(r2);
  const glm::vec3 w = r > 0 ? d * (1.0f / r) : glm::vec3(0, 0, -1);
  const float min_r = float(detail::effective_min_distance(set, options));
  if (r < min_r) {
    r2 = min_r * min_r;
    if (clamped) ++*clamped;
  }
  const float cosine = options.ignore_normal ? 1.0f : -glm::dot(n, w);
  if (cosine <= 0.0f) return 0.0;
  return luminance_of(set.channels, far_field_intensity(level, w)) * double(cosine) / double(r2);
}

/// The far-field row against the reference.
inline LevelErrors evaluate_far_field(const AplSet& set, const ReferenceIrradiance& ref,
                                      const AplErrorOptions& options = {}) {
  const AplLevel& level = set.levels.at(0);
  LevelErrors row;
  row.level = -1;
  row.apls = 1;
  row.map_resolution = level.map_resolution;
  row.bytes = level.map_bytes();
  detail::evaluate_rows(ref, options, row,
                        [&](std::size_t, const glm::vec3& x, const glm::vec3& n, std::size_t* clamped) {
                          return far_field_irradiance(set, x, n, options.irradiance, clamped);
                        });
  return row;
}

/// Everything `lumx eval --rays` reports.
struct AplErrorReport {
  ReferenceIrradiance reference;
  std::vector<LevelErrors> levels;  ///< one per set level, in order
  LevelErrors far_field;            ///< level == −1; empty errors when AplErrorOptions::far_field is off
};

inline AplSet centring_pilot(const AplSet& set, double sigma = 0);
inline AplSet pilot_with_known_borders(AplSet pilot, const AplSet& lit);
struct MaskEvidence;
inline void border_allowance(ReferenceIrradiance& ref, const AplSet& pilot, const std::vector<MaskEvidence>& evidence,
                             unsigned threads = 1);
inline std::vector<MaskEvidence> mask_evidence(const AplSet& own, std::uint64_t own_rays, const AplSet* lit,
                                               std::uint64_t lit_rays);
/// Whether the held-out evaluators centre the reference (checked_centred_reference) for these options:
/// one point per patch (the levels queried at the patch centres) and quarters within the spheres' limit.
inline bool centring_applies(const AplErrorOptions& o) {
  return o.patch_subsamples == 1 && 2 * o.patch_resolution <= 1024;
}
inline double centring_pilot_sigma(int patch_resolution);
inline ReferenceIrradiance checked_centred_reference(const ReferenceIrradiance& ref, const ReferenceIrradiance& fine,
                                                     const AplSet& pilot, const AplErrorOptions& options);
inline ReferenceIrradiance centred_reference(const ReferenceIrradiance& ref, const AplSet& pilot,
                                             const AplErrorOptions& options, int k = 0);

/// Gathers the reference from `rays` (one pass) around `set.bounds` and evaluates every level and the far
/// field. With a `pilot` (centring_pilot of a set built from rays `set` never saw, of width
/// centring_pilot_sigma(options.patch_resolution)) and one point per patch
/// (AplErrorOptions::patch_subsamples == 1), the reference is moved from the patch means to the patch
/// centres (centred_reference), where the levels are queried: graded against patch means, a model right
/// at points is charged with the patch's own curvature (a cos^50 spot's 512-APL level, 6.3 % off at
/// points at d = 10, is 74.5 % off the exact patch means). Averaged queries (k ≠ 1) keep the patch means they are
/// compared with. Throws std::invalid_argument for a set without levels, bad options or a bad ray.
inline AplErrorReport evaluate_apl_errors(const AplSet& set, RaySource& rays, const AplErrorOptions& options = {},
                                          const AplSet* pilot = nullptr, const std::vector<MaskEvidence>& evidence = {}) {
  if (set.levels.empty()) throw std::invalid_argument("apl_error: the set has no level");
  AplErrorReport report;
  report.reference = gather_reference(rays, set.bounds, options);
  if (pilot && centring_applies(options)) {
    AplErrorOptions fine = options;
    fine.patch_resolution = 2 * options.patch_resolution;
    fine.progress = nullptr;
    report.reference = checked_centred_reference(report.reference, gather_reference(rays, set.bounds, fine), *pilot, options);
    if (!evidence.empty()) border_allowance(report.reference, *pilot, evidence, options.threads);
  }
  const std::size_t rows = set.levels.size() + (options.far_field ? 1 : 0);
  for (std::size_t k = 0; k < set.levels.size(); ++k) {
    report.levels.push_back(evaluate_level(set, k, report.reference, options));
    if (options.progress) options.progress(double(k + 1) / double(rows), "levels");
  }
  if (options.far_field) {
    report.far_field = evaluate_far_field(set, report.reference, options);
    if (options.progress) options.progress(1.0, "levels");
  }
  return report;
}

/// Grades `set` against `rays` it was not built from (another run, another file). With one point per patch
/// the reference is centred where a pilot's shape passes the check (evaluate_apl_errors): `build_pilot`
/// (RaySource& → AplSet; e.g. one level of 64 APLs, built as the set was) makes the pilot from the even
/// rays and the levels are graded on the odd ones, so the pilot shares no ray with the rays that check
/// and grade. Otherwise (no centring for these options, or no pilot from the even rays: too few, or no
/// flux) every ray grades, uncentred. `lit_borders`: a set built from `lit_border_rays` other rays of this
/// luminaire whose beam masks the pilot's join (pilot_with_known_borders; the held-out evaluators pass
/// the graded set); a masked pilot's centred spheres get the border allowance of its own masks and
/// those (border_allowance).
template <class Build>
AplErrorReport evaluate_independent(const AplSet& set, RaySource& rays, Build&& build_pilot,
                                    const AplErrorOptions& options = {}, const AplSet* lit_borders = nullptr,
                                    std::uint64_t lit_border_rays = 0) {
  if (!centring_applies(options)) return evaluate_apl_errors(set, rays, options);
  AplSet own, pilot;
  std::uint64_t pilot_rays = 0;
  try {
    RayHalf even(rays, 0);
    pilot_rays = even.info().ray_count;
    own = centring_pilot(build_pilot(static_cast<RaySource&>(even)), centring_pilot_sigma(options.patch_resolution));
    pilot = lit_borders ? pilot_with_known_borders(own, *lit_borders) : own;
  } catch (const std::invalid_argument&) {
    return evaluate_apl_errors(set, rays, options);
  }
  RayHalf odd(rays, 1);
  return evaluate_apl_errors(set, odd, options, &pilot, mask_evidence(own, pilot_rays, lit_borders, lit_border_rays));
}

/// Honest errors of the sets a builder makes from a rayset: `build(RaySource&) -> AplSet` is called on the
/// even rays of `rays` (flux ×2, rays/holdout.h) and its set graded against the odd rays (flux ×2), which
/// it never saw. The set built from all the rays has
/// half this set's noise variance, so these errors bound its own from above. With one point per patch the
/// reference is centred where a pilot's shape passes the check (evaluate_apl_errors); the odd rays are then
/// split again, as in evaluate_held_out_fitted: a set `build` makes from rays 1, 5, 9, … gives the pilot and
/// rays 3, 7, 11, … grade, so the pilot is independent of both the graded set and the rays that check it.
/// Where no pilot can be built from those rays (too few, or no flux) every odd ray grades, uncentred.
template <class Build>
AplErrorReport evaluate_held_out(RaySource& rays, Build&& build, const AplErrorOptions& options = {}) {
  AplSet set;
  std::uint64_t train_rays = 0;
  {
    RayHalf train(rays, 0);
    set = build(static_cast<RaySource&>(train));
    train_rays = train.info().ray_count;
  }
  // The odd rays are to this set what another run's rays are: the pilot from rays 1, 5, 9, …, the
  // grading on rays 3, 7, 11, ….
  RayHalf odd(rays, 1);
  return evaluate_independent(set, odd, build, options, &set, train_rays);
}

// ---- Map resolution by held-out error
// A map of m rays over T texels has a relative noise of about 1/√(m/T) per texel, and a renderer's point
// query sees it; coarser texels trade that noise for blur. Which wins depends on the luminaire, the level
// and the ray count, so it is measured: each level's maps are box-downsampled (flux-exact on equal-area
// maps) by halving from the built resolution, every candidate is graded at the points of the
// measurement spheres against held-out rays moved to the patch centres (centred_reference), and the one
// with the least Σ_d log ε(d) (the geometric mean over the distances, so that each distance counts by its
// relative change: a one-APL level is hopeless near a spot whatever its maps, and a plain sum would let
// that decide its far field) is the best. For level 0, the far-field point, the sum runs over the
// distances where a point can serve: those where its maps as built (plain, at the built resolution) are
// within kUnusableError (25 %), or every distance when there are none. There the geometric mean still let
// the near field decide: a cos^20 spot's one-APL level chose R 32 unsmoothed, a point or two better at
// d = 2 and 5 (where its blur happens to mimic the 2 cm source's extent), and was 10.9 % off at d = 10
// against 3.0 % for R 128 sharpened, the far field's own choice. (Applied to every level, the rule also
// dropped d = 0.5 from an LED strip's middle levels, 72 % off there; with that sphere gone the one-
// standard-error rule no longer found R 32 as good as R 64 or R 64 as good as R 128, and the 10 M-ray
// bundle grew from 13.6 to 25.6 MB and its build from 82 to 94 s, for held-out errors the rays cannot
// tell apart.) The coarsest resolution with a candidate within one standard
// error of the best is kept (the one-standard-error rule in fit_map_resolutions). (The noise variance of the
// reference is the same for every candidate, so the raw ε ranks them.) The
// choice is made on a set built from half the rays; a set from all of them has half the noise variance
// and might afford one step finer — the choice is the conservative one.

/// One candidate of the fit: maps at `resolution`, smoothed by the von Mises–Fisher kernel of
/// concentration `kappa` (1/rad²; 0: not smoothed) in `mode` (KernelMode), and its Σ_d log ε(d).
struct FitCandidate {
  int resolution = 0;
  double kappa = 0;
  double cost = 0;
  KernelMode mode = KernelMode::plain;
};

/// Per level, the chosen resolution and kernel and every candidate tried (finest first).
struct ResolutionChoice {
  std::vector<int> resolution;                        ///< per level
  std::vector<double> kappa;                          ///< per level: the kernel's κ (0: none)
  std::vector<KernelMode> mode;                       ///< per level: how the kernel smooths
  std::vector<std::vector<FitCandidate>> tried;       ///< per level
  /// The resolution of level 0's maps for the far field alone (IES/EULUMDAT export), fitted at d = 5 and
  /// 10 on patches of R 64 (3° wide): a far field needs angular detail the near field's compromise can
  /// give away (evaluate_held_out_fitted). 0 when not fitted.
  int far_field_resolution = 0;
  double far_field_kappa = 0;  ///< and its kernel (0: none)
  KernelMode far_field_mode = KernelMode::plain;  ///< and how it smooths
};

/// The patch resolution fit_map_resolutions grades on in evaluate_held_out_fitted, for `rays` fitting rays
/// (0: unknown) and the report's patch resolution (see there).
inline int fit_patch_resolution(int patch_resolution, std::uint64_t rays) {
  const int low = std::min(1024, 2 * patch_resolution), high = std::max(low, 64);
  int R = low;
  while (R * 2 <= high && 2.0 * (2.0 * R) * (2.0 * R) * 32.0 <= double(rays)) R *= 2;
  return R;
}

/// The level's maps box-downsampled to resolution R (a power-of-two fraction of theirs; else throws).
inline AplLevel downsampled_level(const AplLevel& level, int R) {
  AplLevel out = level;
  if (R == level.map_resolution) return out;
  for (Apl& a : out.apls) {
    while (a.map.resolution() > R) a.map = a.map.downsampled();
    if (a.map.resolution() != R)
      throw std::invalid_argument("downsampled_level: " + std::to_string(R) + " is not a power-of-two fraction of " +
                                  std::to_string(level.map_resolution));
  }
  out.map_resolution = R;
  // A mask's coverage computed afresh at R, as a reader loading the level at R computes it (averaging the
  // children's would sample each texel finer than that, and the bundle would read back other values).
  if (out.has_masks()) refresh_coverages(out);
  return out;
}

/// A level's maps summed over its APLs and channels (one channel at its resolution): its far field.
inline SphereMap level_sum(const AplLevel& level) {
  SphereMap total(level.map_resolution, 1);
  for (const Apl& a : level.apls) accumulate_channels(total, a.map);
  return total;
}

/// Maps per thread at least when a level's maps are smoothed in parallel, so that a level of a few APLs
/// is not split over threads that cost more to start than its maps do to smooth.
inline constexpr std::size_t kMapsPerThread = 8;

/// K·f of every map of `level` (`kernel`'s resolution), on up to `threads` threads (0: the hardware's): what
/// every mode of one kernel starts from (SphereMapKernel::with_gain). Each map is smoothed alone, so the
/// result does not depend on the thread count.
inline std::vector<SphereMap> kernel_applied_maps(const AplLevel& level, const SphereMapKernel& kernel,
                                                  unsigned threads = 0) {
  std::vector<SphereMap> out(level.apls.size());
  detail::parallel_jobs(
      out.size(), threads, [&](std::size_t i) { out[i] = kernel.apply(level.apls[i].map); }, kMapsPerThread);
  return out;
}

/// The level's maps as `kernel` in `mode` smooths them, from their K·f already taken (`applied`,
/// kernel_applied_maps) and `gain` from the level's sum (kernel.gain(level_sum(level), mode); not read in
/// plain mode): the same bits as smoothing each map afresh.
inline AplLevel level_from_applied(const AplLevel& level, std::vector<SphereMap> applied,
                                   const SphereMapKernel& kernel, KernelMode mode, const SphereMap& gain,
                                   unsigned threads = 0) {
  if (applied.size() != level.apls.size())
    throw std::invalid_argument("level_from_applied: " + std::to_string(applied.size()) + " smoothed maps for " +
                                std::to_string(level.apls.size()) + " APLs");
  // Every field but the maps, which are written below (copying the input's maps first would cost a
  // level's map bytes, 64 MB at R 128 × 512 APLs, per candidate).
  AplLevel out;
  out.map_resolution = level.map_resolution;
  out.frame = level.frame;
  out.error = level.error;
  out.apls.resize(level.apls.size());
  for (std::size_t i = 0; i < level.apls.size(); ++i) {
    out.apls[i].position = level.apls[i].position;
    out.apls[i].flux = level.apls[i].flux;
    out.apls[i].parent = level.apls[i].parent;
    out.apls[i].mask = level.apls[i].mask;
    out.apls[i].coverage = level.apls[i].coverage;
  }
  const bool with_gain = mode != KernelMode::plain;
  detail::parallel_jobs(
      out.apls.size(), threads,
      [&](std::size_t i) {
        out.apls[i].map =
            with_gain ? kernel.with_gain(level.apls[i].map, std::move(applied[i]), gain) : std::move(applied[i]);
      },
      kMapsPerThread);
  return out;
}

/// The level's maps smoothed by `kernel` (whose resolution must be theirs) in `mode` with `gain` already
/// taken from the level's sum (kernel.gain(level_sum(level), mode); not read in plain mode), on up to
/// `threads` threads (0: the hardware's). Each map is smoothed alone, so the result does not depend on the
/// thread count.
inline AplLevel smoothed_level_with_gain(const AplLevel& level, const SphereMapKernel& kernel, KernelMode mode,
                                         const SphereMap& gain, unsigned threads = 0) {
  return level_from_applied(level, kernel_applied_maps(level, kernel, threads), kernel, mode, gain, threads);
}

/// The level's maps smoothed by `kernel` in `mode`. Any mode but plain takes one gain from the level's sum
/// (its far field) for every map (SphereMapKernel::apply_with_gain), so the sparse maps sum to the sum's
/// estimate.
inline AplLevel smoothed_level(const AplLevel& level, const SphereMapKernel& kernel, unsigned threads = 0,
                               KernelMode mode = KernelMode::plain, HarmonicEstimateCache* cache = nullptr) {
  const SphereMap gain =
      mode != KernelMode::plain && !level.apls.empty() ? kernel.gain(level_sum(level), mode, cache) : SphereMap();
  return smoothed_level_with_gain(level, kernel, mode, gain, threads);
}

/// The fitted maps of a level: downsampled to R, then smoothed by the kernel of κ in `mode` when κ > 0.
/// `cache`: where a spectral kernel's expansions are kept for the next level (one per set).
inline AplLevel fitted_level(const AplLevel& level, int R, double kappa, KernelMode mode = KernelMode::plain,
                             HarmonicEstimateCache* cache = nullptr) {
  AplLevel out = downsampled_level(level, R);
  // A masked level is never smoothed (fit_map_resolutions grades it plain): a kernel chosen for another
  // kind of level (a half set with other sources) is not applied to it.
  if (kappa > 0 && !out.has_masks()) out = smoothed_level(out, *SphereMapKernel::shared(R, kappa), 0, mode, cache);
  return out;
}

/// The kernels the fit tries at resolution R: σ = 0.75 and 1.5 texel widths (a texel is √(4π/2R²) rad
/// across), at R 32 to 128 only: coarser maps keep their bilinear interpolation error whatever their
/// noise (apl_sets.md), and finer ones would hold tens of millions of weights (SphereMapKernel::kMaxResolution).
inline std::vector<double> fit_kernel_kappas(int R) {
  if (R < 32 || R > SphereMapKernel::kMaxResolution) return {};
  const double texel = std::sqrt(4.0 * kPi / (2.0 * double(R) * double(R)));
  std::vector<double> out;
  for (double widths : {0.75, 1.5}) out.push_back(1.0 / ((widths * texel) * (widths * texel)));
  return out;
}

/// A kernel the fit tries: κ (1/rad²) and how it smooths.
struct FitKernel {
  double kappa = 0;
  KernelMode mode = KernelMode::plain;
};

/// The kernels the fit tries at resolution R: fit_kernel_kappas(R) as they are; sharpened
/// (SphereMapKernel::sharpening_gain: bias O(κ⁻²), so a spot's lobe keeps its peak) at σ = 0.75, 1.5 and 3
/// texel widths; and local linear (SphereMapKernel::local_linear_gain: no leak across the border of the
/// rays' support, such as a Lambertian emitter's horizon, where the others put most of their error) at
/// σ = 1.5 and 3 texel widths; extrapolated (SphereMapKernel::extrapolated_gain: two orders of blur
/// cancelled where sharpening cancels one, for a lobe a wide kernel would flatten even sharpened) at σ = 1.5
/// and 3 texel widths; and two-scale (SphereMapKernel::two_scale_gain: each map at σ against its own few
/// rays, the level's shape from its sum sharpened at σ/2; fit_map_resolutions tries it at the level's
/// built resolution only, and widens it only while that helps) at σ = 1.5, 3 and 4.5 texel widths (4.5: a
/// cos^20 spot's maps from 1 M rays, about 2 000 rays each, want σ 5° while its sum affords 2.5°; over
/// four seeds its finest level is 1.62–3.18 % at d ≥ 1 with that candidate and 1.87–3.21 % without,
/// apl_sets.md); and spectral (SphereMapKernel::spectral_gain: as two-scale, the level's shape from its
/// sum's harmonic expansion shrunk degree by degree, which no kernel's width can match on a narrow lobe: a
/// cos^20 spot's finest level 2.53/3.23 → 1.98/2.09 % at d = 5/10) at the same widths and on the same terms,
/// one width on a one-APL level; and spectral per order (harmonic_estimate_per_order: the expansion about the
/// sum's mean direction, shrunk per degree and order, which removes the noise a round beam's empty orders
/// hold and so goes below the bound of every per-degree weight, but loses power a beam that is not round
/// holds at orders it cannot see) at the same widths, only where the sum is a beam (mean resultant length
/// at least kMinPerOrderResultant). R 128's kernels are for
/// narrow lobes: a spot read through R 64 texels keeps their blur (a cos^20 spot's far field 4 % off,
/// noise-free), and R 128 with a kernel as wide as R 64's averages the same noise through finer texels
/// (apl_sets.md).
inline std::vector<FitKernel> fit_kernels(int R) {
  std::vector<FitKernel> out;
  for (double kappa : fit_kernel_kappas(R)) out.push_back({kappa, KernelMode::plain});
  if (R < 32 || R > SphereMapKernel::kMaxResolution) return out;
  const double texel = std::sqrt(4.0 * kPi / (2.0 * double(R) * double(R)));
  const auto kappa_of = [&](double widths) { return 1.0 / ((widths * texel) * (widths * texel)); };
  for (double widths : {0.75, 1.5, 3.0}) out.push_back({kappa_of(widths), KernelMode::sharpened});
  for (double widths : {1.5, 3.0}) out.push_back({kappa_of(widths), KernelMode::local_linear});
  for (double widths : {1.5, 3.0}) out.push_back({kappa_of(widths), KernelMode::extrapolated});
  for (double widths : {1.5, 3.0, 4.5}) out.push_back({kappa_of(widths), KernelMode::two_scale});
  // Spectral and spectral per order width by width: both smooth each map by the same kernel, so the second
  // finds the first's K·f still kept (fit_map_resolutions keeps the last one to three widths used).
  for (double widths : {1.5, 3.0, 4.5}) {
    out.push_back({kappa_of(widths), KernelMode::spectral});
    out.push_back({kappa_of(widths), KernelMode::spectral_per_order});
  }
  return out;
}

/// The mean resultant length from which the fit tries spectral per order: a beam, as the builder turns a
/// set's maps from (kMinMapFrameResultant, apl/builder.h; a cos^m lobe with m ≥ 8). A broad emitter's
/// mean direction is no axis of symmetry (a Lambertian panel's rectangle is not round about its normal).
inline constexpr double kMinPerOrderResultant = 0.9;

/// How much a kernel lowers a level's brightest directions, relative, and how much their mean may move by
/// its own noise. The level's maps are summed (its far field); the brightest directions are the texels of
/// the smoothed sum, brightest first, that hold 5 % of its flux (chosen on the smoothed map, so that texels
/// bright by noise alone are not picked and then "lowered" back to their mean); the lowering is of the
/// plain sum's mean over them, and the allowance 2/√n, n = set_rays · (their share of the plain flux)
/// (the rays that fell there, for rays of equal flux). Returns {lowering, allowance}. Here from the level's
/// plain sum and that sum smoothed.
inline std::pair<double, double> kernel_peak_change(const SphereMap& sum, const SphereMap& smooth,
                                                    std::uint64_t set_rays) {
  if (set_rays == 0) return {1.0, 0.0};
  std::vector<std::uint32_t> order(sum.texel_count());
  for (std::size_t t = 0; t < order.size(); ++t) order[t] = std::uint32_t(t);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return smooth.data()[a] > smooth.data()[b] || (smooth.data()[a] == smooth.data()[b] && a < b);
  });
  double total = 0;
  for (std::size_t t = 0; t < sum.texel_count(); ++t) total += double(sum.data()[t]);
  if (!(total > 0)) return {0.0, 0.0};
  double plain = 0, smoothed = 0;
  for (std::uint32_t t : order) {
    if (smoothed >= 0.05 * total) break;
    plain += double(sum.data()[t]);
    smoothed += double(smooth.data()[t]);
  }
  if (!(plain > 0)) return {0.0, 0.0};
  const double rays_there = double(set_rays) * plain / total;
  return {(plain - smoothed) / plain, 2.0 / std::sqrt(std::max(1.0, rays_there))};
}

/// kernel_peak_change of a level smoothed by `kernel` in `mode`.
inline std::pair<double, double> kernel_peak_change(const AplLevel& level, const SphereMapKernel& kernel,
                                                    std::uint64_t set_rays, KernelMode mode = KernelMode::plain) {
  if (level.apls.empty() || set_rays == 0) return {1.0, 0.0};
  const SphereMap sum = level_sum(level);
  return kernel_peak_change(sum, kernel.apply(sum, mode), set_rays);
}

/// The standard error of the difference of two candidates' Σ_d log ε(d) (fit_map_resolutions), from their
/// model values `a` and `b` per sphere and patch against the same reference. On sphere s, ε² = mean_p r_p² / m²
/// (r the residual, m the reference's mean), so log ε_a − log ε_b ≈ mean_p δ_p / (2 m² ε̄²) with
/// δ_p = r_a,p² − r_b,p² and ε̄² the mean of the two ε². With the reference E = E_true + η,
/// δ_p = (a − b)(a + b − 2E_true) − 2(a − b)η: the noise variance η² cancels and what remains of the noise
/// scales with the candidates' difference, which is what lets two candidates be told apart far below the
/// noise floor. The spheres share their patch layout and the same rays cross matching patches of every
/// sphere, so the terms are summed over the spheres per patch and the variance taken of that sum over the
/// N patches: var_p(Σ_s δ_s,p / (2 m_s² ε̄_s²)) / N. Spheres where either error is not finite and positive
/// are left out, as in the cost; so are spheres whose patch count differs from the first's, and those
/// `spheres` marks false (the distances the cost leaves out; empty: none).
inline double cost_difference_standard_error(const ReferenceIrradiance& ref, const std::vector<std::vector<double>>& a,
                                             const std::vector<std::vector<double>>& b,
                                             const std::vector<bool>& spheres = {}) {
  std::vector<double> per_patch;
  for (std::size_t s = 0; s < ref.sphere.size() && s < a.size() && s < b.size(); ++s) {
    if (s < spheres.size() && !spheres[s]) continue;
    const std::vector<double>& e = ref.sphere[s].irradiance;
    const std::size_t n = e.size();
    if (n < 2 || a[s].size() != n || b[s].size() != n) continue;
    if (per_patch.empty()) per_patch.assign(n, 0.0);
    if (per_patch.size() != n) continue;
    double mean_ref = 0, sa = 0, sb = 0;
    for (std::size_t p = 0; p < n; ++p) {
      mean_ref += e[p];
      sa += (a[s][p] - e[p]) * (a[s][p] - e[p]);
      sb += (b[s][p] - e[p]) * (b[s][p] - e[p]);
    }
    mean_ref /= double(n);
    const double m2 = mean_ref * mean_ref, ea2 = sa / double(n) / m2, eb2 = sb / double(n) / m2;
    if (!(ea2 > 0) || !(eb2 > 0) || !std::isfinite(ea2 + eb2)) continue;
    const double scale = 2 * m2 * 0.5 * (ea2 + eb2);
    for (std::size_t p = 0; p < n; ++p) {
      const double ra = (a[s][p] - e[p]) * (a[s][p] - e[p]), rb = (b[s][p] - e[p]) * (b[s][p] - e[p]);
      per_patch[p] += (ra - rb) / scale;
    }
  }
  const std::size_t n = per_patch.size();
  if (n < 2) return 0.0;
  double mean = 0, sq = 0;
  for (double d : per_patch) mean += d / double(n);
  for (double d : per_patch) sq += (d - mean) * (d - mean);
  return std::sqrt(sq / double(n - 1) / double(n));
}

/// The map bytes (in memory) above which fit_map_resolutions trades a level's finer maps for coarser ones
/// the held-out rays cannot tell apart from them (the one-standard-error rule): 1 MiB, an eighth of the
/// 8 MiB a 512-APL bundle from 1 M rays is given.
inline constexpr double kParsimonyBytes = 1024.0 * 1024.0;

/// The memory fit_map_resolutions may keep a level's smoothed maps in, to reuse them across the modes of one
/// kernel width: 128 MiB, two widths of a 512-APL level at R 128 (a 1 M-ray LED strip: 43.1 → 36.4 s,
/// 914 → 1 046 MB peak resident; with three, 37.1 s and 1 111 MB).
inline constexpr double kAppliedBytes = 128.0 * 1024.0 * 1024.0;

/// The memory fit_map_resolutions may keep the lookups of one level at one resolution in
/// (detail::LevelLookups), so that its candidates there are graded by their blends alone: 128 MiB, a
/// 512-APL level at the 12 288 points of R 32 patches (the fit's for up to 10⁶ rays: fit_patch_resolution).
/// A level with more points and APLs keeps the lookups of as many points as this holds (10⁷ rays: the
/// 49 152 points of R 64 patches, a quarter of them for 512 APLs, half for 256).
inline constexpr double kLookupBytes = 128.0 * 1024.0 * 1024.0;

/// The error beyond which the kernel guard of fit_map_resolutions does not protect a distance (relative RMSE).
inline constexpr double kUnusableError = 0.25;

/// Chooses each level's map resolution, from its own down to `min_resolution`, and kernel (none, or one of
/// fit_kernels(R)), by the error against `ref` (held-out rays: see above), and fits the levels of `set`.
/// `set_rays`: the number of rays `set` was built from (0: unknown, and then no kernel is tried).
inline ResolutionChoice fit_map_resolutions(AplSet& set, const ReferenceIrradiance& ref, const AplErrorOptions& options,
                                            int min_resolution = 4, std::uint64_t set_rays = 0) {
  ResolutionChoice choice;
  AplErrorOptions o = options;
  o.min_timing_seconds = 0;
  const auto kernel_for = [](int R, double kappa) { return SphereMapKernel::shared(R, kappa); };
  HarmonicEstimateCache spectra;  // every level's sum is the same rays': one expansion for all
  for (std::size_t k = 0; k < set.levels.size(); ++k) {
    const AplLevel built = set.levels[k];
    const bool masked = built.has_masks();
    std::vector<FitCandidate> tried;
    FitCandidate best{built.map_resolution, 0.0, INFINITY};
    // Every eligible candidate (past the kernel guards) with its model values, for the one-standard-error
    // rule below, and its gain (empty for plain), to smooth the level with once chosen; the best is one
    // of them.
    struct Eligible {
      FitCandidate candidate;
      std::vector<std::vector<double>> values;  // per sphere and patch
      SphereMap gain;
    };
    std::vector<Eligible> eligible;
    std::vector<std::vector<double>> last_values;  // the model values of the candidate graded last
    std::size_t best_at = 0;
    // The distances the cost sums over (see above): every one, except for level 0, where the first
    // grade (the built maps unsmoothed) sets them.
    std::vector<bool> serves;
    const auto admit = [&](SphereMap gain) {
      eligible.push_back({tried.back(), std::move(last_values), std::move(gain)});
      if (tried.back().cost < best.cost) best = tried.back(), best_at = eligible.size() - 1;
    };
    // The lookups of the level at the current R, of as many points as kLookupBytes holds: every candidate
    // there has its layout.
    std::unique_ptr<const detail::LevelLookups> lookups;
    const auto grade = [&](int R, double kappa, KernelMode mode, std::vector<double>& errors) {
      LevelErrors row = lookups ? lookups->evaluate(set, k, ref, o) : evaluate_level(set, k, ref, o);
      last_values = std::move(row.irradiance);
      errors.clear();
      for (const IrradianceErrors& e : row.errors) errors.push_back(e.relative_rmse);
      if (serves.empty()) {
        for (double e : errors) serves.push_back(k > 0 || (std::isfinite(e) && e <= kUnusableError));
        if (std::find(serves.begin(), serves.end(), true) == serves.end()) serves.assign(errors.size(), true);
      }
      double cost = 0;
      for (std::size_t s = 0; s < errors.size(); ++s)
        if ((s >= serves.size() || serves[s]) && std::isfinite(errors[s]) && errors[s] > 0) cost += std::log(errors[s]);
      tried.push_back({R, kappa, cost, mode});
      return cost;
    };
    double plain_before = INFINITY;
    std::vector<double> plain_errors, kernel_errors;
    for (int R = built.map_resolution; R >= std::max(1, min_resolution); R /= 2) {
      const AplLevel at_r = downsampled_level(built, R);
      const SphereMap sum_at_r = level_sum(at_r);
      set.levels[k] = at_r;
      lookups.reset();  // the last resolution's, freed before these are taken
      // A masked level (point sources behind apertures, a few APLs) is graded point by point through
      // irradiance(), and only as plain masked maps: a kernel would blur the intensity the mask's border
      // divides by its coverage.
      if (!masked) lookups = std::make_unique<const detail::LevelLookups>(set, k, ref, o, kLookupBytes);
      const double plain = grade(R, 0.0, KernelMode::plain, plain_errors);
      admit(SphereMap());
      // The cost of the last two-scale candidate admitted at this R, and whether a wider one may still win.
      double two_scale_before = INFINITY, spectral_before = INFINITY, per_order_before = INFINITY;
      bool two_scale_improving = true, spectral_improving = true;
      bool per_order_improving = glm::length(mean_direction(sum_at_r)) >= kMinPerOrderResultant;
      // K·f of every map, per kernel width at this R, kept for the other modes of that width (1.5 and 3
      // texel widths serve six or seven candidates each): the widths used last, as many as kAppliedBytes
      // holds, at most three (a width smoothed once or twice per R, not once per candidate; the same bits).
      std::vector<std::pair<double, std::vector<SphereMap>>> applied;  // least recently used first
      const std::size_t applied_kept = std::size_t(
          std::clamp(kAppliedBytes / std::max(1.0, double(at_r.map_bytes())), 1.0, 3.0));
      const auto applied_for = [&](const SphereMapKernel& kern) -> const std::vector<SphereMap>& {
        for (std::size_t i = 0; i < applied.size(); ++i)
          if (applied[i].first == kern.kappa()) {
            std::rotate(applied.begin() + std::ptrdiff_t(i), applied.begin() + std::ptrdiff_t(i) + 1, applied.end());
            return applied.back().second;
          }
        if (applied.size() >= applied_kept) applied.erase(applied.begin());
        applied.emplace_back(kern.kappa(), kernel_applied_maps(at_r, kern, o.threads));
        return applied.back().second;
      };
      for (const FitKernel& kernel : set_rays > 0 && !at_r.apls.empty() && !masked ? fit_kernels(R) : std::vector<FitKernel>{}) {
        const double kappa = kernel.kappa;
        // Two-scale keeps the level's sum sharp at a distance, so only where the maps are fine enough to
        // hold it: at a coarser R it traded the far field for the near field, and the fitting rays could not
        // see the loss (in a trial allowing it at every R, a cos^20 spot's 512-APL level at R 64 was
        // 0.9–1.0 % at d ≤ 1 and 4.4 % at d = 10 against 3.0 % for the far-field point, yet graded within the
        // fit's standard error of the R 128 candidates: apl_sets.md).
        // On one map it is the sharpened kernel at σ/2, already a candidate.
        if (kernel.mode == KernelMode::two_scale && (R != built.map_resolution || built.size() <= 1)) continue;
        // Two-scale is tried from its narrowest width up, and a wider one only while widening has helped:
        // the error is U-shaped in the width (bias grows as noise falls), so once a width graded worse
        // than the one before, or was refused by a guard (a wider kernel lowers a peak more), a wider one
        // would only cost a level's smoothing and grading (the box with holes: σ 6.7° graded far worse
        // than 3.4° at every level, so 10.1° is not tried).
        if (kernel.mode == KernelMode::two_scale && !two_scale_improving) continue;
        if (kernel.mode == KernelMode::two_scale) two_scale_improving = false;  // until admitted and better
        // Spectral likewise: at the built resolution (an expansion at R 128 costs 0.24 s on two cores, once
        // per fit for levels whose sums agree to rounding),
        // widened while that helps; on one map the width only sets the estimate's reach, so one width.
        if (kernel.mode == KernelMode::spectral && (R != built.map_resolution || !spectral_improving)) continue;
        if (kernel.mode == KernelMode::spectral) spectral_improving = false;
        if (kernel.mode == KernelMode::spectral_per_order && (R != built.map_resolution || !per_order_improving)) continue;
        if (kernel.mode == KernelMode::spectral_per_order) per_order_improving = false;
        // A kernel may not flatten a peak the rays resolve: its bias is largest at a narrow lobe, where a
        // patch-mean reference is flattened too and so cannot see it (a cos^50 spot: σ 1.7° lowered the
        // peak 4 %, against a 2.5 % allowance, and doubled the far field's error at d = 10). Kept with the
        // centred reference, which is only as sharp as its pilot.
        // The gain is the level sum's, taken once for the guard and the smoothing.
        const std::shared_ptr<const SphereMapKernel> held = kernel_for(R, kappa);
        const SphereMapKernel& kern = *held;
        const bool plain_mode = kernel.mode == KernelMode::plain;
        const SphereMap gain = plain_mode ? SphereMap() : kern.gain(sum_at_r, kernel.mode, &spectra);
        const auto [lowering, allowance] = kernel_peak_change(
            sum_at_r, plain_mode ? kern.apply(sum_at_r) : kern.apply_with_gain(sum_at_r, gain), set_rays);
        if (lowering > allowance) continue;
        set.levels[k] = level_from_applied(at_r, applied_for(kern), kern, kernel.mode, gain, o.threads);
        grade(R, kappa, kernel.mode, kernel_errors);
        // A kernel must not give away any distance against the same maps unsmoothed: its bias is largest at
        // a narrow peak, which patches coarser than the peak see only in part, at some distances
        // (a cos^50 spot: σ 1.7° won the geometric mean by the near field and doubled the error at d ≥ 5).
        // Distances where the level is off by more than 25 % unsmoothed are not protected: no error target
        // uses it there (a one-APL level near a spot: 340 % either way), and a sharper far field, right at
        // d ≥ 5, is worse there by what the point model misses.
        bool no_worse = true;
        for (std::size_t s = 0; s < kernel_errors.size() && s < plain_errors.size(); ++s)
          if (std::isfinite(plain_errors[s]) && plain_errors[s] <= kUnusableError && !(kernel_errors[s] <= plain_errors[s]))
            no_worse = false;
        if (!no_worse) continue;
        if (kernel.mode == KernelMode::two_scale) {
          two_scale_improving = tried.back().cost < two_scale_before;
          two_scale_before = tried.back().cost;
        }
        if (kernel.mode == KernelMode::spectral) {
          spectral_improving = built.size() > 1 && tried.back().cost < spectral_before;
          spectral_before = tried.back().cost;
        }
        if (kernel.mode == KernelMode::spectral_per_order) {
          per_order_improving = built.size() > 1 && tried.back().cost < per_order_before;
          per_order_before = tried.back().cost;
        }
        admit(gain);
      }
      // Past the minimum: coarser maps trade noise for blur, and once halving made them worse and the best
      // so far is better still, further halving only blurs more (the error is U-shaped in R).
      if (R % 2 != 0 || (plain > plain_before && best.cost < plain)) break;
      plain_before = plain;
    }
    // One-standard-error rule (Breiman et al. 1984 §3.4.3; Hastie et al., ESL §7.10): the coarsest
    // resolution with a candidate whose cost is within one standard error of the best's
    // (cost_difference_standard_error), and its best candidate there. Finer maps cost four times the
    // bytes and memory per halving; where the held-out rays cannot tell them apart (an LED strip's middle
    // levels) they are not worth it.
    // The rule is for bytes, so a level whose maps hold at most kParsimonyBytes at the best's resolution
    // keeps the best: that the held-out rays cannot tell two candidates apart is no evidence that the
    // coarser is as good (in a trial applying the rule to every level, a cos^20 spot's 8-APL level went to
    // R 64 and was 4.3 % off at d = 10 against 3.1 %; the suite's far-field test refused it).
    const double scale = double(best.resolution) / double(std::max(1, built.map_resolution));
    if (!eligible.empty() && double(built.map_bytes()) * scale * scale > kParsimonyBytes) {
      const std::vector<std::vector<double>>& best_values = eligible[best_at].values;
      std::size_t simpler = best_at;
      for (std::size_t i = 0; i < eligible.size(); ++i) {
        const FitCandidate& c = eligible[i].candidate;
        const FitCandidate& s = eligible[simpler].candidate;
        if (c.resolution > s.resolution) continue;
        if (!(c.cost <= best.cost + cost_difference_standard_error(ref, best_values, eligible[i].values, serves)))
          continue;
        if (c.resolution < s.resolution || c.cost < s.cost) simpler = i;
      }
      // Its best candidate there, whether or not that one passed the test: a candidate closer to the best
      // has a smaller standard error of the difference, so a better one at the same resolution can fail
      // where a worse one passes (an LED strip's 256-APL level, once a spectral candidate at R 128 was
      // best, went to R 32 unsmoothed, 5.3 % off at d = 1, where R 32 sharpened was 4.3 %).
      for (std::size_t i = 0; i < eligible.size(); ++i)
        if (eligible[i].candidate.resolution == eligible[simpler].candidate.resolution &&
            eligible[i].candidate.cost < eligible[simpler].candidate.cost)
          simpler = i;
      best = eligible[simpler].candidate;
      best_at = simpler;
    }
    set.levels[k] = downsampled_level(built, best.resolution);
    // Smoothed with the gain the candidate was graded with (the level sum's at that resolution). Smoothed
    // again rather than kept from its grading: keeping the best candidate so far would hold one more
    // level's maps (64 MB at R 128 × 512 APLs) to save one smoothing, where grading smoothed once per
    // kernel width tried.
    if (best.kappa > 0)
      set.levels[k] = smoothed_level_with_gain(set.levels[k], *kernel_for(best.resolution, best.kappa), best.mode,
                                               eligible.at(best_at).gain, o.threads);
    choice.resolution.push_back(best.resolution);
    choice.kappa.push_back(best.kappa);
    choice.mode.push_back(best.kappa > 0 ? best.mode : KernelMode::plain);
    choice.tried.push_back(std::move(tried));
  }
  return choice;
}

/// The pilot of centred_reference for a set: its level nearest 64 APLs (enough to follow the near field at
/// d ≥ 1, cheap to evaluate at k×k points), its maps smoothed by the sharpened kernel (bias O(κ⁻²): the
/// lobe's shape within a patch is kept, the texel noise mostly averaged) of width `sigma` (rad), or with
/// sigma = 0 of 1.5 texel widths of the level's maps where the kernels reach (the fit's pilot: R 128 maps,
/// 3/8 of an R 32 fit patch). For sigma > 0 the maps are first halved (flux-exact) while they are finer
/// than the kernels take (R > 128, or a kernel of more than a quarter of SphereMapKernel::kMaxWeights
/// weights). Maps coarser than R 32, or that cannot be halved to 128 (odd R), are left unsmoothed: such a
/// pilot is noisy, and the shape check (checked_centred_reference) mostly refuses it. Throws
/// std::invalid_argument for a set without levels.
inline AplSet centring_pilot(const AplSet& set, double sigma) {
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
      pilot.levels[0] = smoothed_level(pilot.levels[0], *SphereMapKernel::shared(R, 1.0 / (sigma * sigma)), 0,
                                       KernelMode::sharpened);
  } else if (R >= 32 && R <= SphereMapKernel::kMaxResolution) {
    pilot.levels[0] = smoothed_level(pilot.levels[0], *SphereMapKernel::shared(R, 1.0 / ((1.5 * texel(R)) * (1.5 * texel(R)))),
                                     0, KernelMode::sharpened);
  }
  return pilot;
}

/// The level of `set` with the most masked APLs (a point-source set's finest: one per source; the first
/// of equals), or null when none has a mask.
inline const AplLevel* most_masked_level(const AplSet& set) {
  const AplLevel* best = nullptr;
  for (const AplLevel& l : set.levels)
    if (l.masked_apl_count() > (best ? best->masked_apl_count() : 0)) best = &l;
  return best;
}

namespace detail {
/// Two masked APLs stand for one point source when they lie within 1/1000 of the bounding radius of each
/// other (PointSourceOptions::tolerance): pilot_with_known_borders and border_allowance match by it.
/// The masked APL of `level` that stands for the same source as `a`, or null.
inline const Apl* same_source(const Apl& a, const AplLevel& level, double bounding_radius) {
  const Apl* match = nullptr;
  for (const Apl& b : level.apls)
    if (b.mask && (!match || glm::length(b.position - a.position) < glm::length(match->position - a.position))) match = &b;
  return match && double(glm::length(match->position - a.position)) <= 1e-3 * bounding_radius ? match : nullptr;
}
}  // namespace detail

/// A masked pilot (centring_pilot) whose every mask also takes the caps of the same source's mask in
/// `lit`, a set built from other rays of the same luminaire (the graded set, in the held-out
/// evaluators): each masked APL of the pilot's level joins the caps of the masked APL of `lit` nearest it,
/// when that lies within 1/1000 of the bounding radius (PointSourceOptions::tolerance: the same source),
/// and its coverage is computed afresh. Why: a beam mask is the hull of the directions of real rays
/// through an aperture, so it lies inside the true beam (convex apertures; apl/point_sources.h), and is
/// short of the beam's border by a sliver that shrinks as the rays grow (about (2k/3)·ln n / n of a
/// k-sided hole). A pilot from a quarter of the rays has the wider sliver, and a patch centre the graded
/// level rightly lights there was called dark by it: in the box with holes, one patch of 512 made the
/// estimate 17.7 % where the level is 3.0 % off at points (before this join; docs/apl_sets.md, "What
/// the table stores").
/// Joined, the pilot calls lit every direction either set's rays prove lit, which shares no noise with
/// the graded level (that a direction inside a hull of real rays is lit is a fact, not an estimate); what
/// it cannot see is the graded level's own sliver beyond both hulls. Only for `lit` built from rays of the
/// luminaire the pilot's rays come from: a set's masks are taken as true. A pilot without masks is
/// returned as it is.
inline AplSet pilot_with_known_borders(AplSet pilot, const AplSet& lit) {
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

/// Beam masks as evidence: a level whose masks are hulls of rays (a set built from them), and the flux one
/// of those rays carries (lm or W: the luminaire's flux over the rays the set was built from).
struct MaskEvidence {
  const AplLevel* level = nullptr;
  double flux_per_ray = 0;
};

namespace detail {
/// A cap of a beam mask with its hull's vertices as unit directions (read once per cap).
struct CapVertices {
  const DirectionMask::Cap* cap = nullptr;
  std::vector<glm::dvec3> vertex;
};
inline std::vector<CapVertices> cap_vertices(const DirectionMask& mask) {
  std::vector<CapVertices> out;
  for (const DirectionMask::Cap& c : mask.caps()) {
    CapVertices v;
    v.cap = &c;
    for (const glm::dvec2& q : c.hull) v.vertex.push_back(glm::normalize(c.axis + q.x * c.e1 + q.y * c.e2));
    out.push_back(std::move(v));
  }
  return out;
}

/// The solid angle (sr) the hull of a cap would gain with direction w: the fan of triangles from w's
/// chart point q to the edges q sees. The gnomonic chart maps great circles to lines, so each is the
/// spherical triangle (w, a, b) of the vertices' directions, whose solid angle is exact (Van Oosterom and
/// Strackee 1983: tan(Ω/2) = |a·(b × c)| / (1 + a·b + b·c + c·a)). Infinite when w is not in the cap's
/// chart half-sphere.
inline double cap_gain(const CapVertices& cv, const glm::dvec3& w) {
  const DirectionMask::Cap& c = *cv.cap;
  const double z = glm::dot(w, c.axis);
  if (!(z > 0)) return INFINITY;
  const glm::dvec2 q(glm::dot(w, c.e1) / z, glm::dot(w, c.e2) / z);
  double omega = 0;
  const std::size_t n = c.hull.size();
  for (std::size_t k = 0; k < n; ++k) {
    const glm::dvec2 a = c.hull[k], b = c.hull[(k + 1) % n];
    const double cross = (b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x);
    if (cross >= 0) continue;  // the edge does not face q
    const glm::dvec3 &A = cv.vertex[k], &B = cv.vertex[(k + 1) % n];
    omega += 2 * std::atan2(std::abs(glm::dot(w, glm::cross(A, B))), 1 + glm::dot(w, A) + glm::dot(A, B) + glm::dot(B, w));
  }
  return omega;
}

/// Whether w lies within `margin` rad of cap c's reach: beyond it, a hull of rays would have to grow by
/// a fan of at least that width to hold w (border_allowance takes such a direction as dark).
inline bool cap_near(const DirectionMask::Cap& c, const glm::dvec3& w, double margin) {
  return glm::dot(w, c.axis) >= std::cos(std::min(c.reach + margin, 0.5 * kPi));
}

/// The hull vertex nearest w among the caps within `margin` of it (cap_near); w itself when none is.
inline glm::dvec3 nearest_hull_vertex(const std::vector<CapVertices>& caps, const glm::dvec3& w, double margin) {
  glm::dvec3 best = w;
  double best_cos = -2;
  for (const CapVertices& cv : caps)
    if (cap_near(*cv.cap, w, margin))
      for (const glm::dvec3& d : cv.vertex) {
        const double cs = glm::dot(d, w);
        if (cs > best_cos) best_cos = cs, best = d;
      }
  return best;
}

}  // namespace detail

/// What a patch centre outside every mask may still receive from a masked APL, the border allowance of
/// centred spheres (SphereReference::border). A mask is the hull of the directions of the rays through an
/// aperture, inside the true beam by a sliver (pilot_with_known_borders). Direction w outside a hull H of
/// rays of density λ = I(w) / flux_per_ray (rays per sr) is lit only if the rays left empty the region
/// hull(H ∪ w) \ H, of solid angle Ω(w) (a convex aperture's beam holds both): under a Poisson count that
/// happens with probability exp(−λ Ω), and with several independent hulls of the same beam (the pilot's
/// rays, the graded set's) with the product. Taken as the probability p that w is lit (a flat prior on
/// where the border lies beyond the hull), a centre whose model and pilot are both dark there may be off by
/// L = I(w)·cos/r² with probability p: the allowance is Σ p·L² over the pilot's masked APLs (the nearest
/// cap of each hull). It is the expected square of what
/// no mask can tell; it widens the upper bound and what counts as resolved (compare_irradiance), never
/// ε̂: which patch centre of a sphere
/// falls in a sliver is a matter of chance, and ε̂ stays the estimate of the centres as they are. Over
/// 20 rayings of the box with holes, no upper bound is below 3/4 of the truth; in a trial without the
/// allowance, 6 were, each a sphere with a centre the graded level wrongly calls dark and no mask holds
/// (docs/apl_sets.md, "What the table stores"). `evidence` gives each hull set with its flux per ray; APLs are matched to
/// the pilot's by position within 1/1000 of the bounding radius. I is the pilot's intensity at its hull
/// vertex nearest w (map over coverage), for λ and L alike; λ takes the rays as of equal flux (the mean:
/// weights that do not depend on direction; rays of no flux, which no hull holds, make it a little
/// high). Only the centred spheres get it. Patches are spread over `threads` (AplErrorOptions::threads).
inline void border_allowance(ReferenceIrradiance& ref, const AplSet& pilot, const std::vector<MaskEvidence>& evidence,
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
      const Apl* found = ev.level && ev.flux_per_ray > 0 ? detail::same_source(a, *ev.level, pilot.bounds.radius) : nullptr;
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
      const glm::vec3 m = level.frame.map_direction(glm::vec3(detail::nearest_hull_vertex(beams[i].own, w, kBorderReach)));
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

/// The evidence of border_allowance for a pilot `own` (centring_pilot of a set built from `own_rays` rays,
/// before pilot_with_known_borders) and the set `lit` its borders joined (built from `lit_rays`; may be
/// null): each one's masked level with the flux one of its rays carries, the luminaire's flux (the
/// pilot's: a part of the rays scaled to the whole, rays/holdout.h) over its ray count. Empty without a
/// masked pilot.
inline std::vector<MaskEvidence> mask_evidence(const AplSet& own, std::uint64_t own_rays, const AplSet* lit,
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

/// The width (rad) of the pilot that centres a grading reference on patches of resolution R_patch
/// (centring_pilot): 3/8 of a patch's width √(4π/N). Narrower, the pilot's own noise swamps the
/// reference's: with σ = 1.5 texels of R 128 maps (3/16 of an R 16 patch) and 250 000 rays behind each,
/// every sphere centred (a trial), a Lambertian disk's 512-APL level, 1.6–1.9 % off at points, was
/// estimated at 5–8 %. At 3/8 the spots' centred estimates follow their point errors
/// (tests/test_apl_honest_error.cpp, HonestErrorSuite). The fit's pilot (sigma 0) has the same ratio to
/// the fit's R 32 patches.
inline double centring_pilot_sigma(int patch_resolution) {
  return 0.375 * std::sqrt(4.0 * kPi / (2.0 * double(patch_resolution) * double(patch_resolution)));
}

/// Level 0 of `pilot` on the spheres and patches of `like`, averaged over k × k points per patch (k = 1:
/// the patch centres), per sphere: the shapes centred_reference and checked_centred_reference move by.
inline std::vector<std::vector<double>> pilot_on_patches(const AplSet& pilot, const ReferenceIrradiance& like,
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

namespace detail {
/// Points per patch side a masked pilot is read at on spheres `ms` (centred_reference, and the quarters
/// of checked_centred_reference): `most`, fewer while the spheres' patches × k² exceed 2^22 (4 194 304)
/// points, at least 2. Its borders need many: the lit share of a
/// patch to 1/k².
inline int masked_pilot_subsamples(const MeasurementSpheres& ms, int most) {
  const double patches = double(ms.sphere_count()) * 2.0 * double(ms.patch_resolution()) * double(ms.patch_resolution());
  int k = most;
  while (k > 2 && patches * double(k) * double(k) > double(1u << 22)) --k;
  return k;
}
/// Beyond this ratio P(c) / P̄ a masked patch is moved by adding instead: a centre lit where the pilot
/// lights under 1/16 of its patch (a sliver's tip) would scale the patch's noise by more than 16.
inline constexpr double kMaxCentringScale = 16;
/// Moves patch p of `sr` from its mean to its centre by a pilot's value there (`centre`) and its mean over
/// the patch (`mean`). Plain pilots add the difference, E_c = max(0, E + P(c) − P̄) (centred_reference).
/// A masked pilot's shape within a patch is a border times a smooth intensity, so it scales instead:
/// E_c = E · P(c) / P̄, with the variance × (P(c) / P̄)² and the halves scaled alike. A border patch
/// lit over a fraction f by the pilot and at its centre is moved by about E·(1/f − 1), which the
/// pilot's own intensity noise (an R 8 map from a quarter of the rays, a few % a texel) no longer
/// enters: added, its intensity error times (1 − f) went into every border patch, and the box's masked
/// level, 3.0 % off at points at d = 1, was estimated at 5.1 % in a trial (scaled: 7.7 %, unresolved,
/// HonestErrorSuite/4). A patch the pilot leaves dark throughout keeps its mean;
/// one whose ratio exceeds kMaxCentringScale is moved by adding.
/// The factor a masked pilot scales a patch by, or −1 where it adds (beyond kMaxCentringScale) or leaves
/// the patch (dark throughout in the pilot: mean 0).
inline double masked_scale(double centre, double mean) {
  return mean > 0 && centre / mean <= kMaxCentringScale ? centre / mean : -1;
}
/// Patch value e moved to its centre (centre_patch), without moving it.
inline double centred_value(double e, double centre, double mean, bool masked) {
  if (masked) {
    if (!(mean > 0)) return e;  // dark throughout in the pilot: the mean stays
    const double g = masked_scale(centre, mean);
    if (g >= 0) return e * g;
  }
  return std::max(0.0, e + centre - mean);
}
inline void centre_patch(SphereReference& sr, std::size_t p, double centre, double mean, bool masked) {
  const double g = masked ? masked_scale(centre, mean) : -1;
  if (g >= 0) {
    sr.irradiance[p] *= g;
    sr.variance[p] *= g * g;
    if (p < sr.half_even.size()) sr.half_even[p] *= g;
    if (p < sr.half_odd.size()) sr.half_odd[p] *= g;
  } else {
    sr.irradiance[p] = centred_value(sr.irradiance[p], centre, mean, masked);
  }
}

}  // namespace detail

/// The reference moved from patch means to patch centres, where fit_map_resolutions evaluates its
/// candidates: E_c = max(0, E + P(centre) − P̄), with P a pilot model (level 0 of `pilot`, e.g.
/// centring_pilot of a set built from other rays) and P̄ its mean over the patch (k × k sub-points).
/// Why: a patch mean sits below a narrow lobe's peak and above its foot. A cos^50 spot's exact patch means on
/// R 32 patches are 26 % (eq. 5.1) from its values at the patch centres at d = 10, five times the error of a
/// good level, so the fit preferred candidates blurred like a patch: it kept R 64 for the finest level of
/// that spot (11.3 % off at d = 10 against the exact irradiance; R 128, chosen against centred references,
/// 4.4 %). A 5-point Laplacian of the patch means (the second-order correction), tried and not kept,
/// removed only half of the bias (24 → 14 % with 4 M rays): at h/σ ≈ 0.5 the higher orders are as large. Centred by the pilot, the
/// reference is within 1.15× its noise floor of the exact centre values (tests/test_apl_honest_error.cpp,
/// FitReference). The pilot's shape within a patch is the same for every candidate and, made from other
/// rays, independent of them, so each candidate's own point noise is still seen in full; what remains is
/// the pilot's error in that shape. The variance and
/// halves are left as they are; a patch the centring would take below 0 is set to 0 (irradiance is never
/// negative), which can lift a dark patch by a little. A masked pilot scales instead of adding
/// (detail::centre_patch), with the variance and halves scaled alike. The pilot must not share rays with the candidates
/// (evaluate_held_out_fitted builds it from the fitting rays): a pilot made from a candidate's own rays
/// would cancel that candidate's noise within each patch, and the fit would favour whatever resembles
/// it (a masked pilot's borders may join the candidates' masks: pilot_with_known_borders). k = 0: 4,
/// or 16 for a masked pilot. Throws std::invalid_argument unless k is 0 or 2 ≤ k ≤ 16.
inline ReferenceIrradiance centred_reference(const ReferenceIrradiance& ref, const AplSet& pilot,
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
    for (std::size_t p = 0; p < sr.irradiance.size(); ++p) detail::centre_patch(sr, p, at_centre[s][p], mean[s][p], masked);
    if (masked) detail::refresh_noise_floors(sr);
    sr.centred = true;
  }
  return out;
}

/// centred_reference for grading, checked sphere by sphere against the rays: the pilot's shape within each
/// patch is compared with that of `fine`, the same rays gathered on patches of twice the resolution (each
/// patch's four quarters). Where the pilot is right, the quarters' residuals r_ij = e_ij − p_ij scatter
/// about their patch's mean by the rays' noise alone: E Σ_j (r_ij − r̄_i)² = ¾ Σ_j v_ij. A pilot that
/// blurs what the rays resolve (a sharp shadow border: the pilot, made of APLs like the graded level,
/// shares its blur) leaves more, and centring by it would move the reference towards that blur and
/// flatter every level like it. A sphere is centred only where the pilot's excess (noise removed), taken at
/// its upper bound (two standard errors above the estimate, from the scatter of the per-patch terms), is
/// under half the move it would make; else it keeps its patch means (SphereReference::centred false), and
/// its errors are against them. (Without the bound, in a trial, a 200 k-ray rectangle's sphere at d = 0.5, its point
/// estimate 0.44 of the move, was centred by a wrong shape: 14.6 % estimated against 2.2 % at points.)
/// Per sphere, `centring_shift` is the RMS of the move and `pilot_shape_error` that bound over the
/// quarters, both relative to the mean irradiance. Measured (tests/test_apl_honest_error.cpp,
/// HonestErrorSuite, 1 M rays, R 16 patches): the spots' spheres from d = 0.75 pass (bound 0.17–0.47 of
/// the move, which is 8–69 % of the mean: a cos^50 spot's 512-APL level, 6.3 % off at points at d = 10,
/// is estimated at 8.6 % where it is 74.5 % off the exact patch means); the point sources in a box with
/// holes fail at every d (1.1–1.45: centred anyway, in a trial, its 512-APL level, 41–48 % off at points,
/// was estimated at 21–27 %; against patch means it is estimated at 32–38 %).
inline ReferenceIrradiance checked_centred_reference(const ReferenceIrradiance& ref, const ReferenceIrradiance& fine,
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
    for (std::size_t p = 0; p < sr.irradiance.size(); ++p) detail::centre_patch(sr, p, centre[s][p], pilot_mean[p], masked);
    if (masked) detail::refresh_noise_floors(sr);
  }
  return out;
}

/// evaluate_held_out with the map resolutions fitted first (fit_map_resolutions). The odd rays are split
/// again: rays 1, 5, 9, … (flux ×4, on patches half the size) choose the resolutions and rays 3, 7, 11, …
/// (flux ×4) grade the result, so the choice does not flatter the figures it is judged by. `choice`, when given, receives
/// the resolutions, to apply to a set built from all the rays (downsampled_level).
template <class Build>
AplErrorReport evaluate_held_out_fitted(RaySource& rays, Build&& build, const AplErrorOptions& options = {},
                                        ResolutionChoice* choice = nullptr, int min_resolution = 4) {
  AplSet set;
  std::uint64_t train_rays = 0;
  {
    RayHalf train(rays, 0);
    set = build(static_cast<RaySource&>(train));
    train_rays = train.info().ray_count;
  }
  if (set.levels.empty()) throw std::invalid_argument("apl_error: the set has no level");
  RayHalf odd(rays, 1);
  ResolutionChoice c;
  AplSet grading_pilot, own_grading_pilot;
  std::uint64_t fit_rays = 0;
  {
    RayHalf fit(odd, 0);
    AplErrorOptions quiet = options;
    quiet.progress = nullptr;
    // Finer patches for the choice: a patch mean hides detail finer than the patch, so the grading
    // resolution would otherwise cap the resolution chosen (a cos^20 spot: R 16 → 32 and its point error
    // at d = 1 from 19 % to 7 % with 1 M rays). At least twice the grading resolution, finer while the
    // fitting rays give ≥ 32 per patch on average, at most 64 (8192 patches: the cost of grading every
    // candidate). Candidates are ranked on one reference, so its noise mostly cancels in the ranking.
    quiet.patch_resolution = fit_patch_resolution(options.patch_resolution, fit.info().ray_count);
    AplSet far = set;
    far.levels.resize(1);
    // The fit grades single points (a renderer's queries), whatever the report averages.
    quiet.patch_subsamples = 1;
    // Both fit references at the patch centres (centred_reference), by the shape of a pilot made from the
    // fitting rays: independent of the candidates (built from the even rays), so it cannot favour one.
    AplSet pilot;
    {
      const AplSet from_fit = build(static_cast<RaySource&>(fit));
      fit_rays = fit.info().ray_count;
      // A masked pilot takes the graded set's beam borders too (pilot_with_known_borders).
      pilot = pilot_with_known_borders(centring_pilot(from_fit), set);
      if (centring_applies(options)) {
        own_grading_pilot = centring_pilot(from_fit, centring_pilot_sigma(options.patch_resolution));
        grading_pilot = pilot_with_known_borders(own_grading_pilot, set);
      }
    }
    const ReferenceIrradiance fit_ref = centred_reference(gather_reference(fit, set.bounds, quiet), pilot, quiet);
    c = fit_map_resolutions(set, fit_ref, quiet, min_resolution, train_rays);
    AplErrorOptions far_options = quiet;
    far_options.relative_distances = {5, 10};
    far_options.patch_resolution = 64;
    const ReferenceIrradiance far_ref = centred_reference(gather_reference(fit, set.bounds, far_options), pilot, far_options);
    const ResolutionChoice far_choice = fit_map_resolutions(far, far_ref, far_options, min_resolution, train_rays);
    c.far_field_resolution = far_choice.resolution.at(0);
    c.far_field_kappa = far_choice.kappa.at(0);
    c.far_field_mode = far_choice.mode.at(0);
  }
  // The grading reference is centred by a pilot from the same rays, 1, 5, 9, …: neither the graded set's
  // maps' nor the grading rays' (they only chose the graded set's resolutions and kernels, a discrete
  // choice), so its shape's noise is independent of both; wider, for the grading's coarser patches.
  RayHalf test(odd, 1);
  AplErrorReport report =
      evaluate_apl_errors(set, test, options, grading_pilot.levels.empty() ? nullptr : &grading_pilot,
                          mask_evidence(own_grading_pilot, fit_rays, &set, train_rays));
  if (choice) *choice = std::move(c);
  return report;
}

/// A level's error table from its row: (d, relative RMSE) for every sphere where the error is defined.
inline ErrorTable error_table(const LevelErrors& row, const ReferenceIrradiance& ref) {
  ErrorTable t;
  for (std::size_t s = 0; s < row.errors.size() && s < ref.sphere.size(); ++s) {
    // The noise-removed point error where the reference has a variance, at its upper bound when the
    // reference cannot resolve it (a level is never stored as better than the rays can tell).
    const IrradianceErrors& x = row.errors[s];
    const double e = std::isfinite(x.relative_rmse_noise_removed)
                         ? (x.resolved ? x.relative_rmse_noise_removed : x.noise_removed_upper)
                         : x.relative_rmse;
    if (!std::isfinite(e) || e < 0) continue;
    t.relative_distance.push_back(ref.sphere[s].relative_distance);
    t.relative_rmse.push_back(e);
  }
  return t;
}

/// Fills AplLevel::error of every level of `set` from `report` (which must have been made from this set:
/// same level count and APL counts, else std::invalid_argument), so write_bundle stores the tables and
/// choose_level_for_error (apl/lod.h) can use them.
inline void store_error_tables(AplSet& set, const AplErrorReport& report) {
  if (report.levels.size() != set.levels.size())
    throw std::invalid_argument("store_error_tables: the report has " + std::to_string(report.levels.size()) +
                                " levels, the set " + std::to_string(set.levels.size()));
  for (std::size_t k = 0; k < set.levels.size(); ++k)
    if (report.levels[k].level != int(k) || report.levels[k].apls != set.levels[k].size())
      throw std::invalid_argument("store_error_tables: level " + std::to_string(k) +
                                  " of the report does not match the set's");
  for (std::size_t k = 0; k < set.levels.size(); ++k)
    set.levels[k].error = error_table(report.levels[k], report.reference);
}

/// Applies a held-out fit to a set built from every ray: each level's maps downsampled to the chosen
/// resolution (when `choice` is given and not finer than the level's) and the report's error tables
/// stored. False, and the set untouched, when the report's levels are not the set's (half the rays of a
/// tiny rayset can give other levels).
inline bool apply_held_out_fit(AplSet& set, const AplErrorReport& report, const ResolutionChoice* choice = nullptr) {
  bool same = report.levels.size() == set.levels.size();
  // The same APL counts, and masked where the graded levels were (a half set may find point sources
  // where the whole set, with a stray ray, does not).
  for (std::size_t k = 0; same && k < set.levels.size(); ++k)
    same = report.levels[k].apls == set.levels[k].size() && report.levels[k].masked == set.levels[k].has_masks();
  if (!same) return false;
  HarmonicEstimateCache spectra;
  if (choice)
    for (std::size_t k = 0; k < set.levels.size() && k < choice->resolution.size(); ++k)
      if (choice->resolution[k] <= set.levels[k].map_resolution)
        set.levels[k] = fitted_level(set.levels[k], choice->resolution[k],
                                     k < choice->kappa.size() ? choice->kappa[k] : 0.0,
                                     k < choice->mode.size() ? choice->mode[k] : KernelMode::plain, &spectra);
  store_error_tables(set, report);
  return true;
}

/// What `lumx build` ships: `build(rays)` on every ray, each level's maps downsampled to the resolution
/// fitted on held-out rays (evaluate_held_out_fitted, whose half set `build_half` makes: give it maps at
/// the resolutions `build` will have, e.g. apl/builder.h's half_rays_build_options, or the fit cannot
/// choose them), and the held-out error tables stored in it (apply_held_out_fit; without tables when half
/// the rays give other levels). `report`, when given, receives the held-out report; `fitted` whether the
/// fit was applied.
template <class BuildHalf, class Build>
AplSet build_with_held_out_errors(RaySource& rays, BuildHalf&& build_half, Build&& build,
                                  const AplErrorOptions& options = {}, AplErrorReport* report = nullptr,
                                  bool* fitted = nullptr) {
  ResolutionChoice choice;
  AplErrorReport r = evaluate_held_out_fitted(rays, build_half, options, &choice);
  AplSet set = build(rays);
  const bool applied = apply_held_out_fit(set, r, &choice);
  if (fitted) *fitted = applied;
  if (report) *report = std::move(r);
  return set;
}

LUMX_NAMESPACE_END
