// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/bake.h — a luminaire's geometry in, a bundle out, in one call (what `lumx bake` runs): light
// particles traced through the luminaire (tracer.h) in passes, their exits spooled to disk and built into
// APL levels, held-out error tables and a far field (io/bundle_builder.h), their internal segments
// deposited in a radiance volume (SH per voxel, RGB, track-length estimator; volume/radiance_volume.h), the
// luminaire file stored byte for byte, and provenance (dissertation 000 §4.1–4.6).
//
// Passes and the stopping rule. After each pass, when a target error is set, the levels that the particles
// so far would give are graded on held-out particles (evaluate_bundle_levels: built from the even exits,
// graded against odd ones they never saw, the reference's noise removed). The bake stops as soon as the
// finest level's error at the target distance is known to be below the target — its upper bound
// √(ε̂² + 2u), two standard errors above the noise-removed estimate, so noise cannot stop it early — or
// when the particle or time budget is spent. The next pass is sized from the Monte Carlo rate, ε̂² ∝ 1/N:
// N_next = N (ε/E)² with 10 % margin, between 1.5 N and 4 N. The last grading is the one the bundle
// stores, so the error the bake reports is the error its tables show.
//
// Determinism. Particle i depends only on (seed, i) and the spool and volume receive particles in index
// order, fluxes normalised to one particle and divided by the final N only when read. So the bundle's maps,
// volume and far field are bit-identical for any thread count and any pass sizes with the same seed and
// final particle count. Only timings in the provenance differ.
#pragma once

#include <lumx/bake/gltf_reader.h>
#include <lumx/bake/tracer.h>
#include <lumx/io/bundle_builder.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace bake {

/// Where a bake is, for progress displays.
struct BakeProgress {
  int pass = 0;                      ///< 1-based pass being traced or graded; 0 while reading the scene
  const char* phase = "";            ///< "tracing", "grading", "building", "writing", ...
  double fraction = 0;               ///< of the current phase, 0..1
  std::uint64_t particles = 0;       ///< particles traced so far
  std::uint64_t budget = 0;          ///< the particle budget (BakeOptions::particles)
  double particles_per_second = 0;   ///< tracing rate so far
  double error = NAN;                ///< last graded error at the target distance (fraction), NaN before
  double eta_seconds = NAN;          ///< estimated time to the end of the bake, NaN when unknown
  double elapsed_seconds = 0;
};

/// One pass, as recorded in the result and in the bundle's provenance.
struct BakePass {
  std::uint64_t particles = 0;       ///< particles traced after this pass (cumulative)
  std::uint64_t exits = 0;           ///< exits after this pass (cumulative)
  double seconds = 0;                ///< elapsed since the bake began, at the end of the pass (and grading)
  bool graded = false;               ///< the levels were graded after this pass
  double error = NAN;                ///< finest level: upper bound of ε̂ at the target distance (fraction)
  double error_estimate = NAN;       ///< finest level: ε̂ itself
  double far_field_error = NAN;      ///< far-field row: upper bound at the target distance
  std::vector<double> level_error;   ///< per level: upper bound at the target distance
};

struct BakeOptions {
  std::uint64_t particles = 1000000;   ///< the particle budget: at most this many are traced
  double time_limit_seconds = 0;       ///< 0: none; else no pass is started that would end after it
  /// Relative RMSE (a fraction) of the finest level's irradiance at single points at relative distance
  /// `target_distance`, graded on held-out particles; 0 turns the stopping rule off (the whole budget).
  double target_error = 0;
  double target_distance = 1;          ///< d, in diameters of the luminaire's bounding sphere
  /// Particles per pass when > 0 (rounded up to whole tracer chunks); 0: automatic (the first pass
  /// 2^18, then sized by the stopping rule, or doubling without a target).
  std::uint64_t pass_particles = 0;
  std::uint64_t seed = 1;
  int threads = 0;                     ///< 0: every hardware thread; results do not depend on it
  int max_depth = 256;                 ///< scattering events before a particle is counted as depth-capped
  int volume_voxels = 32768;           ///< radiance volume's voxel target (0: no volume)
  int volume_bands = 4;                ///< SH bands per voxel (bands² coefficients)
  std::string rays_out;                ///< when set, the exits are also written there as an IES TM-25 file
  /// Levels, grading, far field, extra attachments and provenance (its `evaluated` and `volume` are set
  /// by the bake; its `progress` is ignored: use `progress` below).
  BundleBuildOptions bundle;
  GltfReadOptions read;                ///< limits and warnings for reading the luminaire
  std::function<void(const BakeProgress&)> progress;
  /// Called after each pass (and its grading) with the pass and the exits so far as a rayset (lm per ray,
  /// normalised to the particles traced so far): e.g. a preview of the intensity distribution
  /// (rays/intensity_preview.h) a luminaire designer watches converge.
  std::function<void(const BakePass&, RaySource& exits)> on_pass;
};

struct BakeResult {
  std::string luminaire_name;
  std::size_t parts = 0, triangles = 0, emitters = 0;
  double emitted_lm = 0;               ///< the emitters' total flux
  TraceCounters counters;              ///< over all passes
  std::vector<BakePass> passes;
  bool target_met = false;
  std::string stopped_by;              ///< "target error", "particle budget" or "time limit"
  double trace_seconds = 0;            ///< reading, scene set-up, tracing and grading, before the build
  BundleBuildResult bundle;            ///< what the bundle build did (levels, error tables, far field)
  std::string input_sha256;            ///< of the luminaire file
};

/// Bakes the glTF luminaire at `luminaire` (.gltf or .glb) into the bundle folder `out` (written
/// atomically: a bundle already there is replaced whole or not at all). Throws lumx::Error, located, for a
/// bad luminaire, bad options and failed writes.
BakeResult bake_luminaire(const std::string& luminaire, const std::string& out, const BakeOptions& options = {});

}  // namespace bake
LUMX_NAMESPACE_END
