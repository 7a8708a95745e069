// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/apl/error.h — how far each level of an APL set is from the luminaire it represents: reference
// irradiance on measurement spheres from rays the set was not built from, the error at single points as a
// renderer queries them, the reference's own noise (estimated and removed), cost per level, and the
// per-level error tables that the LOD error-target rule reads (apl/lod.h).
//
// Method ([VelazquezArmendariz2014] §5.3, "virtual measurement spheres", Figure 5.8):
//   - Spheres. Around the set's bounding sphere (centre c = bounds.center, diameter D = 2·bounds.radius)
//     we place spheres of radius ρ = d·D for relative distances d (default 0.5, 0.75, 1, 2, 5, 10; d = 0.5
//     is the bounding sphere itself, d = 5 the traditional start of the far field).
//   - Patches. Each sphere is cut into N equal-area patches: the texels of an equal-area sphere map of
//     resolution R_patch (math/sphere_map.h), seen from c. Every texel covers 4π/N sr, so every patch covers
//     the area A = 4πρ²/N. R_patch = 16 gives N = 2·16² = 512.
//   - Reference. Every ray (start p, direction ω, flux Φ) is followed to where it leaves each sphere, and
//     Φ is added to the patch that contains the exit point's direction from c. The reference irradiance of
//     patch i is E_ref(i) = Σ Φ / A (lx for lm, W/m² for W): flux through the patch per unit area, the
//     histogram estimate of irradiance on the sphere ([VelazquezArmendariz2014] §5.3).
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
//   relative RMSE ([VelazquezArmendariz2014] eq. 5.1)
//                                 ε = √(Σ_i (E_ref(i) − E(i))² / N) / (Σ_i E_ref(i) / N)
//   normalised distributions      p_i = E_ref(i) / Σ_j E_ref(j),  q_i = E(i) / Σ_j E(j)   (Σ p = Σ q = 1;
//                                 equal-area patches make these probabilities of a patch receiving light)
//   l² distance ([Mas2008] §6)   D_l²(p, q) = √(Σ_i (p_i − q_i)²)                          ∈ [0, √2]
//   Hellinger distance ([Mas2008] §6) D_H(p, q) = √(½ Σ_i (√p_i − √q_i)²)                      ∈ [0, 1]
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
// independent of the ray count; the fit (apl/map_fit.h) also keeps a level's lookups, O(spheres × N × APLs),
// within a memory budget.
#pragma once

#include <lumx/apl/apl_set.h>
#include <lumx/apl/evaluation.h>
#include <lumx/math/sphere_map.h>
#include <lumx/rays/rayset.h>

#include <glm/glm.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
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
  double l2 = NAN;         ///< l² distance of the normalised distributions ([Mas2008] §6)
  double hellinger = NAN;  ///< Hellinger distance of the normalised distributions ([Mas2008] §6)
};

/// Relative RMSE (eq. 5.1), l² and Hellinger distances of `model` against `reference`, patch by patch.
/// Throws std::invalid_argument when the sizes differ. Undefined metrics are NaN: every metric for no
/// patch; the relative RMSE when Σ reference = 0; l² and Hellinger when either sum is 0 or a value is
/// negative (they compare probability distributions).
IrradianceErrors compare_irradiance(const std::vector<double>& reference, const std::vector<double>& model);

/// compare_irradiance, plus the noise-removed relative RMSE from the reference's variance per patch.
/// `border` (optional, per patch, (lx)²: SphereReference::border) widens the upper bound by its mean over
/// m², b: √(max(0, ε² − σ²) + 2u + b); the estimate is resolved only when ε² − σ² > 2u + b.
IrradianceErrors compare_irradiance(const std::vector<double>& reference, const std::vector<double>& model,
                                    const std::vector<double>& variance, const std::vector<double>* border = nullptr);

/// The noise floor of a reference from its two independent halves (each scaled to estimate the whole):
/// √(Σ (a_i − b_i)² / N) / mean((a + b)/2) / 2 — the relative RMSE of the halves against each other,
/// over 2 (see the header comment for the factor). NaN when empty or without light; throws
/// std::invalid_argument when the sizes differ.
double noise_floor(const std::vector<double>& half_a, const std::vector<double>& half_b);

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

/// Streams `rays` once (rewinding first) and gathers the reference irradiance on the spheres around
/// `bounds`. Throws std::invalid_argument for bad options, or for a ray with a non-finite position or
/// direction, a zero direction, or a negative or non-finite flux (the ray's index in the message).
ReferenceIrradiance gather_reference(RaySource& rays, const BoundingSphere& bounds,
                                     const AplErrorOptions& options = {});

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

LevelErrors evaluate_level(const AplSet& set, std::size_t k, const ReferenceIrradiance& ref,
                           const AplErrorOptions& options = {});

/// Irradiance at x (normal n) from level 0's far-field intensity Σ_i I_i(ω) placed at the bounding-sphere
/// centre (the "far field" row; see the header comment). Throws std::out_of_range without levels.
double far_field_irradiance(const AplSet& set, const glm::vec3& x, const glm::vec3& n,
                            const IrradianceOptions& options = {}, std::size_t* clamped = nullptr);

/// The far-field row against the reference.
LevelErrors evaluate_far_field(const AplSet& set, const ReferenceIrradiance& ref, const AplErrorOptions& options = {});

/// Everything `lumx eval --rays` reports.
struct AplErrorReport {
  ReferenceIrradiance reference;
  std::vector<LevelErrors> levels;  ///< one per set level, in order
  LevelErrors far_field;            ///< level == −1; empty errors when AplErrorOptions::far_field is off
};

// ---- Centring: the reference moved from patch means to patch centres by a pilot's shape

/// The pilot of centred_reference for a set: its level nearest 64 APLs (enough to follow the near field at
/// d ≥ 1, cheap to evaluate at k×k points), its maps smoothed by the sharpened kernel (bias O(κ⁻²): the
/// lobe's shape within a patch is kept, the texel noise mostly averaged) of width `sigma` (rad), or with
/// sigma = 0 of 1.5 texel widths of the level's maps where the kernels reach (the fit's pilot: R 128 maps,
/// 3/8 of an R 32 fit patch). For sigma > 0 the maps are first halved (flux-exact) while they are finer
/// than the kernels take (R > 128, or a kernel of more than a quarter of SphereMapKernel::kMaxWeights
/// weights). Maps coarser than R 32, or that cannot be halved to 128 (odd R), are left unsmoothed: such a
/// pilot is noisy, and the shape check (checked_centred_reference) mostly refuses it. Throws
/// std::invalid_argument for a set without levels.
AplSet centring_pilot(const AplSet& set, double sigma = 0);

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
AplSet pilot_with_known_borders(AplSet pilot, const AplSet& lit);

/// Beam masks as evidence: a level whose masks are hulls of rays (a set built from them), and the flux one
/// of those rays carries (lm or W: the luminaire's flux over the rays the set was built from).
struct MaskEvidence {
  const AplLevel* level = nullptr;
  double flux_per_ray = 0;
};

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
/// (docs/apl_sets.md, "What the table stores"). `evidence` gives each hull set with its flux per ray; APLs are matched
/// to the pilot's by position within 1/1000 of the bounding radius. I is the pilot's intensity at its hull vertex
/// nearest w (map over coverage), for λ and L alike; λ takes the rays as of equal flux (the mean: weights that do not
/// depend on direction; rays of no flux, which no hull holds, make it a little high). Only the centred spheres get it.
/// Patches are spread over `threads` (AplErrorOptions::threads).
void border_allowance(ReferenceIrradiance& ref, const AplSet& pilot, const std::vector<MaskEvidence>& evidence,
                      unsigned threads = 1);

/// The evidence of border_allowance for a pilot `own` (centring_pilot of a set built from `own_rays` rays,
/// before pilot_with_known_borders) and the set `lit` its borders joined (built from `lit_rays`; may be
/// null): each one's masked level with the flux one of its rays carries, the luminaire's flux (the
/// pilot's: a part of the rays scaled to the whole, rays/holdout.h) over its ray count. Empty without a
/// masked pilot.
std::vector<MaskEvidence> mask_evidence(const AplSet& own, std::uint64_t own_rays, const AplSet* lit,
                                        std::uint64_t lit_rays);

/// The width (rad) of the pilot that centres a grading reference on patches of resolution R_patch
/// (centring_pilot): 3/8 of a patch's width √(4π/N). Narrower, the pilot's own noise swamps the
/// reference's: with σ = 1.5 texels of R 128 maps (3/16 of an R 16 patch) and 250 000 rays behind each,
/// every sphere centred (a trial), a Lambertian disk's 512-APL level, 1.6–1.9 % off at points, was
/// estimated at 5–8 %. At 3/8 the spots' centred estimates follow their point errors
/// (tests/test_apl_honest_error.cpp, HonestErrorSuite). The fit's pilot (sigma 0) has the same ratio to
/// the fit's R 32 patches.
double centring_pilot_sigma(int patch_resolution);

/// Level 0 of `pilot` on the spheres and patches of `like`, averaged over k × k points per patch (k = 1:
/// the patch centres), per sphere: the shapes centred_reference and checked_centred_reference move by.
std::vector<std::vector<double>> pilot_on_patches(const AplSet& pilot, const ReferenceIrradiance& like,
                                                  const AplErrorOptions& options, int k);

/// The reference moved from patch means to patch centres, where fit_map_resolutions evaluates its
/// candidates: E_c = max(0, E + P(centre) − P̄), with P a pilot model (level 0 of `pilot`, e.g.
/// centring_pilot of a set built from other rays) and P̄ its mean over the patch (k × k sub-points).
/// Why: a patch mean sits below a narrow lobe's peak and above its foot. A cos^50 spot's exact patch means on
/// R 32 patches are 26 % (eq. 5.1) from its values at the patch centres at d = 10, five times the error of a
/// good level, so the fit preferred candidates blurred like a patch: it kept R 64 for the finest level of
/// that spot (11.3 % off at d = 10 against the exact irradiance; R 128, chosen against centred references,
/// 4.4 %). A 5-point Laplacian of the patch means (the second-order correction), tried and not kept,
/// removed only half of the bias (24 → 14 % with 4 M rays): at h/σ ≈ 0.5 the higher orders are as large. Centred by the
/// pilot, the reference is within 1.15× its noise floor of the exact centre values (tests/test_apl_honest_error.cpp,
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
ReferenceIrradiance centred_reference(const ReferenceIrradiance& ref, const AplSet& pilot,
                                      const AplErrorOptions& options, int k = 0);

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
ReferenceIrradiance checked_centred_reference(const ReferenceIrradiance& ref, const ReferenceIrradiance& fine,
                                              const AplSet& pilot, const AplErrorOptions& options);

/// Whether the held-out evaluators centre the reference (checked_centred_reference) for these options:
/// one point per patch (the levels queried at the patch centres) and quarters within the spheres' limit.
inline bool centring_applies(const AplErrorOptions& o) {
  return o.patch_subsamples == 1 && 2 * o.patch_resolution <= 1024;
}

/// Gathers the reference from `rays` (one pass) around `set.bounds` and evaluates every level and the far
/// field. With a `pilot` (centring_pilot of a set built from rays `set` never saw, of width
/// centring_pilot_sigma(options.patch_resolution)) and one point per patch
/// (AplErrorOptions::patch_subsamples == 1), the reference is moved from the patch means to the patch
/// centres (centred_reference), where the levels are queried: graded against patch means, a model right
/// at points is charged with the patch's own curvature (a cos^50 spot's 512-APL level, 6.3 % off at
/// points at d = 10, is 74.5 % off the exact patch means). Averaged queries (k ≠ 1) keep the patch means they are
/// compared with. Throws std::invalid_argument for a set without levels, bad options or a bad ray.
AplErrorReport evaluate_apl_errors(const AplSet& set, RaySource& rays, const AplErrorOptions& options = {},
                                   const AplSet* pilot = nullptr, const std::vector<MaskEvidence>& evidence = {});

/// Builds an APL set from rays (e.g. build_apl_set with fixed options): what the held-out evaluators call
/// on the rays a set is built from.
using AplSetBuilder = std::function<AplSet(RaySource&)>;

/// Grades `set` against `rays` it was not built from (another run, another file). With one point per patch
/// the reference is centred where a pilot's shape passes the check (evaluate_apl_errors): `build_pilot`
/// (RaySource& → AplSet; e.g. one level of 64 APLs, built as the set was) makes the pilot from the even
/// rays and the levels are graded on the odd ones, so the pilot shares no ray with the rays that check
/// and grade. Otherwise (no centring for these options, or no pilot from the even rays: too few, or no
/// flux) every ray grades, uncentred. `lit_borders`: a set built from `lit_border_rays` other rays of this
/// luminaire whose beam masks the pilot's join (pilot_with_known_borders; the held-out evaluators pass
/// the graded set); a masked pilot's centred spheres get the border allowance of its own masks and
/// those (border_allowance).
AplErrorReport evaluate_independent(const AplSet& set, RaySource& rays, const AplSetBuilder& build_pilot,
                                    const AplErrorOptions& options = {}, const AplSet* lit_borders = nullptr,
                                    std::uint64_t lit_border_rays = 0);

/// Honest errors of the sets a builder makes from a rayset: `build(RaySource&) -> AplSet` is called on the
/// even rays of `rays` (flux ×2, rays/holdout.h) and its set graded against the odd rays (flux ×2), which
/// it never saw. The set built from all the rays has
/// half this set's noise variance, so these errors bound its own from above. With one point per patch the
/// reference is centred where a pilot's shape passes the check (evaluate_apl_errors); the odd rays are then
/// split again, as in evaluate_held_out_fitted: a set `build` makes from rays 1, 5, 9, … gives the pilot and
/// rays 3, 7, 11, … grade, so the pilot is independent of both the graded set and the rays that check it.
/// Where no pilot can be built from those rays (too few, or no flux) every odd ray grades, uncentred.
AplErrorReport evaluate_held_out(RaySource& rays, const AplSetBuilder& build, const AplErrorOptions& options = {});

/// A level's error table from its row: (d, relative RMSE) for every sphere where the error is defined.
ErrorTable error_table(const LevelErrors& row, const ReferenceIrradiance& ref);

/// Fills AplLevel::error of every level of `set` from `report` (which must have been made from this set:
/// same level count and APL counts, else std::invalid_argument), so write_bundle stores the tables and
/// choose_level_for_error (apl/lod.h) can use them.
void store_error_tables(AplSet& set, const AplErrorReport& report);

LUMX_NAMESPACE_END
