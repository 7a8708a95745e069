// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/io/bundle_builder.h — from a rayset to a bundle on disk, in one call: APL levels by clustering
// (apl/builder.h), their honest error tables (apl/error.h: a set built the same way from the even rays,
// graded on odd rays it never saw, map resolutions fitted on further held-out rays), the far field as IES
// and EULUMDAT attachments, an optional radiance volume and attachments, and provenance.
//
// `lumx build` and `lumx bake` are this call plus printing; an embedder gets the same bundle from it.
#pragma once

#include <lumx/model/grading.h>
#include <lumx/model/registry.h>
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/map_fit.h>
#include <lumx/io/bundle_io.h>
#include <lumx/photometry/far_field_grid.h>
#include <lumx/rays/rayset.h>
#include <lumx/volume/radiance_volume.h>

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// The held-out grading of the levels a build makes (see evaluate_bundle_levels).
struct HeldOutEvaluation {
  AplErrorReport report;     ///< the even-ray set graded against held-out odd rays, noise removed
  ResolutionChoice choice;   ///< map resolutions fitted on held-out rays (empty when they were fixed)
  bool fitted = false;       ///< resolutions were fitted (AplBuildOptions::map_resolution == 0)
  std::uint64_t rays = 0;    ///< rays of the source it was made from
};

struct BundleBuildOptions {
  AplBuildOptions apl;                ///< levels, seeds, maps, threads, progress of the clustering
  bool evaluate = true;               ///< grade the levels on held-out rays and store error tables
  AplErrorOptions errors;             ///< spheres and patches of that grading
  FarFieldGrid far_field;             ///< IES/EULUMDAT grid; efficacy 0 = the header's Φv / Φe
  const RadianceVolume* volume = nullptr;        ///< stored as the bundle's volume when given
  std::vector<BundleAttachment> attachments;     ///< stored beside the far field
  std::map<std::string, std::string> provenance; ///< added to the set's provenance (overriding)
  std::string source_name;            ///< how provenance names the rays ("source"); default info().file
  /// A grading already made by evaluate_bundle_levels on these same rays with these same options (e.g.
  /// the last pass of a bake): reused instead of graded again.
  const HeldOutEvaluation* evaluated = nullptr;
  /// Further registered representations (model/registry.h; "apl" is the levels above and is skipped):
  /// each built from all the rays with `representation_options` and stored as a model named by its type;
  /// with `evaluate`, each is also built from the even rays and graded on the odd ones (grade_held_out).
  std::vector<std::string> representations;
  ModelBuildOptions representation_options;
  /// Fraction done (0..1) and phase, for the whole call.
  std::function<void(double, const char*)> progress;
};

struct BundleBuildResult {
  AplBuildReport build;                   ///< the clustering's report (timings, line convergence)
  std::vector<std::size_t> apls;          ///< per level
  std::vector<int> built_resolution;      ///< per level, as built
  std::vector<int> resolution;            ///< per level, as stored (after the held-out fit)
  bool evaluated = false;                 ///< a held-out grading was made (or reused)
  bool error_tables_stored = false;       ///< its tables were stored (the half set had the same levels)
  HeldOutEvaluation held_out;             ///< that grading
  bool far_field_attached = false;
  double far_field_lm = 0;                ///< flux of the attached far field (lm)
  int far_field_resolution = 0;           ///< level 0's map resolution it was tabulated from
  double far_field_kernel_sigma_deg = 0;  ///< σ of the kernel its maps were smoothed with (°; 0: none)
  KernelMode far_field_kernel_mode = KernelMode::plain;  ///< how that kernel smoothed (sharpened, local linear, extrapolated, two-scale, spectral, spectral per order)
  std::uint64_t bytes = 0;                ///< the bundle's payload bytes (manifest total)
  double seconds_build = 0, seconds_evaluation = 0, seconds_far_field = 0, seconds_write = 0;
  std::vector<std::string> notes;         ///< what was left out and why (no far field, no error tables)
  std::vector<ModelGrade> representation_grades;  ///< per further representation graded, in order
};

/// The held-out grading build_bundle stores as error tables: a set built with `o.apl` from the even rays
/// (flux ×2), graded against odd rays; with o.apl.map_resolution == 0 the resolutions are first fitted
/// on rays 1, 5, 9, … and the grading uses rays 3, 7, 11, … (apl/error.h). Throws lumx::Error.
HeldOutEvaluation evaluate_bundle_levels(RaySource& rays, const BundleBuildOptions& o);

/// Builds the bundle at `out` (written atomically, io/bundle_io.h) from `rays` and returns what it did.
/// Throws lumx::Error for bad rays or options, and for write failures.
BundleBuildResult build_bundle(RaySource& rays, const std::string& out, const BundleBuildOptions& o);

/// The builder options a bundle was made with, as the JSON stored in its provenance ("build_options"),
/// and back; `lumx eval` rebuilds from half of the source rays with them. The parser throws
/// std::invalid_argument naming the key when the text is not such JSON.
std::string build_options_json(const AplBuildOptions& o);
AplBuildOptions build_options_from_json(const std::string& text);

LUMX_NAMESPACE_END
