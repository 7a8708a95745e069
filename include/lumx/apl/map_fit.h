// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/apl/map_fit.h — the map resolution and smoothing kernel of each level of an APL set, chosen by its
// error at points against held-out rays (apl/error.h), and what `lumx build` ships from the choice.
#pragma once

#include <lumx/apl/error.h>
#include <lumx/math/sphere_map_harmonics.h>
#include <lumx/math/sphere_map_kernel.h>

#include <cstdint>
#include <utility>
#include <vector>

LUMX_NAMESPACE_BEGIN

// ---- Map resolution by held-out error
// A map of m rays over T texels has a relative noise of about 1/√(m/T) per texel, and a renderer's point
// query sees it; coarser texels trade that noise for blur. Which wins depends on the luminaire, the level
// and the ray count, so it is measured: each level's maps are box-downsampled (flux-exact on equal-area
// maps) by halving from the built resolution, and smoothed by a few kernels; every candidate is graded at
// the points of the measurement spheres against held-out rays moved to the patch centres
// (centred_reference), and the one with the least Σ_d log ε(d) (the geometric mean over the distances, so
// that each distance counts by its relative change) is the best. For level 0, the far-field point, the sum
// runs over the distances where a point can serve: those where its maps as built are within 25 % there,
// or every distance when there are none. The coarsest candidate within one standard error of the best is
// kept (the one-standard-error rule). The noise variance of the reference is the same for every
// candidate, so the raw ε ranks them. The choice is made on a set built from half the rays; a set from
// all of them has half the noise variance and might afford one step finer: the choice is the
// conservative one. docs/apl_sets.md tabulates what the rule chooses.

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
  std::vector<int> resolution;                   ///< per level
  std::vector<double> kappa;                     ///< per level: the kernel's κ (0: none)
  std::vector<KernelMode> mode;                  ///< per level: how the kernel smooths
  std::vector<std::vector<FitCandidate>> tried;  ///< per level
  /// The resolution of level 0's maps for the far field alone (IES/EULUMDAT export), fitted at d = 5 and
  /// 10 on patches of R 64 (3° wide): a far field needs angular detail the near field's compromise can
  /// give away (evaluate_held_out_fitted). 0 when not fitted.
  int far_field_resolution = 0;
  double far_field_kappa = 0;                     ///< and its kernel (0: none)
  KernelMode far_field_mode = KernelMode::plain;  ///< and how it smooths
};

/// The patch resolution fit_map_resolutions grades on in evaluate_held_out_fitted, for `rays` fitting rays
/// (0: unknown) and the report's patch resolution (see there).
int fit_patch_resolution(int patch_resolution, std::uint64_t rays);

/// The level's maps box-downsampled to resolution R (a power-of-two fraction of theirs; else throws).
AplLevel downsampled_level(const AplLevel& level, int R);

/// A level's maps summed over its APLs and channels (one channel at its resolution): its far field.
SphereMap level_sum(const AplLevel& level);

/// K·f of every map of `level` (`kernel`'s resolution), on up to `threads` threads (0: the hardware's): what
/// every mode of one kernel starts from (SphereMapKernel::with_gain). Each map is smoothed alone, so the
/// result does not depend on the thread count.
std::vector<SphereMap> kernel_applied_maps(const AplLevel& level, const SphereMapKernel& kernel, unsigned threads = 0);

/// The level's maps as `kernel` in `mode` smooths them, from their K·f already taken (`applied`,
/// kernel_applied_maps) and `gain` from the level's sum (kernel.gain(level_sum(level), mode); not read in
/// plain mode): the same bits as smoothing each map afresh.
AplLevel level_from_applied(const AplLevel& level, std::vector<SphereMap> applied, const SphereMapKernel& kernel,
                            KernelMode mode, const SphereMap& gain, unsigned threads = 0);

/// The level's maps smoothed by `kernel` (whose resolution must be theirs) in `mode` with `gain` already
/// taken from the level's sum (kernel.gain(level_sum(level), mode); not read in plain mode), on up to
/// `threads` threads (0: the hardware's). Each map is smoothed alone, so the result does not depend on the
/// thread count.
AplLevel smoothed_level_with_gain(const AplLevel& level, const SphereMapKernel& kernel, KernelMode mode,
                                  const SphereMap& gain, unsigned threads = 0);

/// The level's maps smoothed by `kernel` in `mode`. Any mode but plain takes one gain from the level's sum
/// (its far field) for every map (SphereMapKernel::apply_with_gain), so the sparse maps sum to the sum's
/// estimate.
AplLevel smoothed_level(const AplLevel& level, const SphereMapKernel& kernel, unsigned threads = 0,
                        KernelMode mode = KernelMode::plain, HarmonicEstimateCache* cache = nullptr);

/// The fitted maps of a level: downsampled to R, then smoothed by the kernel of κ in `mode` when κ > 0.
/// `cache`: where a spectral kernel's expansions are kept for the next level (one per set).
AplLevel fitted_level(const AplLevel& level, int R, double kappa, KernelMode mode = KernelMode::plain,
                      HarmonicEstimateCache* cache = nullptr);

/// How much a kernel lowers a level's brightest directions, relative, and how much their mean may move by
/// its own noise. The level's maps are summed (its far field); the brightest directions are the texels of
/// the smoothed sum, brightest first, that hold 5 % of its flux (chosen on the smoothed map, so that texels
/// bright by noise alone are not picked and then "lowered" back to their mean); the lowering is of the
/// plain sum's mean over them, and the allowance 2/√n, n = set_rays · (their share of the plain flux)
/// (the rays that fell there, for rays of equal flux). Returns {lowering, allowance}. Here from the level's
/// plain sum and that sum smoothed.
std::pair<double, double> kernel_peak_change(const SphereMap& sum, const SphereMap& smooth, std::uint64_t set_rays);

/// kernel_peak_change of a level smoothed by `kernel` in `mode`.
std::pair<double, double> kernel_peak_change(const AplLevel& level, const SphereMapKernel& kernel,
                                             std::uint64_t set_rays, KernelMode mode = KernelMode::plain);

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
double cost_difference_standard_error(const ReferenceIrradiance& ref, const std::vector<std::vector<double>>& a,
                                      const std::vector<std::vector<double>>& b, const std::vector<bool>& spheres = {});

/// Chooses each level's map resolution, from its own down to `min_resolution`, and kernel (none, or one of
/// fit_kernels(R)), by the error against `ref` (held-out rays: see above), and fits the levels of `set`.
/// `set_rays`: the number of rays `set` was built from (0: unknown, and then no kernel is tried).
ResolutionChoice fit_map_resolutions(AplSet& set, const ReferenceIrradiance& ref, const AplErrorOptions& options,
                                     int min_resolution = 4, std::uint64_t set_rays = 0);

/// evaluate_held_out with the map resolutions fitted first (fit_map_resolutions). The odd rays are split
/// again: rays 1, 5, 9, … (flux ×4, on patches half the size) choose the resolutions and rays 3, 7, 11, …
/// (flux ×4) grade the result, so the choice does not flatter the figures it is judged by. `choice`, when given,
/// receives the resolutions, to apply to a set built from all the rays (downsampled_level).
AplErrorReport evaluate_held_out_fitted(RaySource& rays, const AplSetBuilder& build,
                                        const AplErrorOptions& options = {}, ResolutionChoice* choice = nullptr,
                                        int min_resolution = 4);

/// Applies a held-out fit to a set built from every ray: each level's maps downsampled to the chosen
/// resolution (when `choice` is given and not finer than the level's) and the report's error tables
/// stored. False, and the set untouched, when the report's levels are not the set's (half the rays of a
/// tiny rayset can give other levels).
bool apply_held_out_fit(AplSet& set, const AplErrorReport& report, const ResolutionChoice* choice = nullptr);

/// What `lumx build` ships: `build(rays)` on every ray, each level's maps downsampled to the resolution
/// fitted on held-out rays (evaluate_held_out_fitted, whose half set `build_half` makes: give it maps at
/// the resolutions `build` will have, e.g. apl/builder.h's half_rays_build_options, or the fit cannot
/// choose them), and the held-out error tables stored in it (apply_held_out_fit; without tables when half
/// the rays give other levels). `report`, when given, receives the held-out report; `fitted` whether the
/// fit was applied.
AplSet build_with_held_out_errors(RaySource& rays, const AplSetBuilder& build_half, const AplSetBuilder& build,
                                  const AplErrorOptions& options = {}, AplErrorReport* report = nullptr,
                                  bool* fitted = nullptr);

LUMX_NAMESPACE_END
