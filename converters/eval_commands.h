// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/eval_commands.h — `lumx eval`: a bundle's irradiance at user-given points, and its error
// against a rayset on measurement spheres (lumx/apl/error.h) as a table and plots.
#pragma once

#include <lumx/apl/error.h>
#include <lumx/model/grading.h>

#include <string>
#include <vector>

namespace lumx_cli {

struct EvalArgs {
  std::string bundle;
  // --points mode
  std::string points;        ///< text file: "x y z nx ny nz" per line (m), '#' starts a comment
  std::string out;           ///< -o: output file (default stdout)
  int level = -1;            ///< --level K (default: the finest level)
  bool lod = false;          ///< --lod: choose the level per point by eq. 6.2, stochastically
  unsigned long long seed = 1;  ///< --seed: of the per-line random number for --lod
  // --rays mode
  std::string rays;          ///< rayset to compare against
  int patch_resolution = 16; ///< --patches R: N = 2R² patches per sphere
  int subsamples = 1;        ///< --subsamples k: 1 = the patch centre; k×k points averaged (0: per level)
  std::vector<double> distances;  ///< --distances (default 0.5 0.75 1 2 5 10)
  std::string plots_dir;     ///< --plots DIR
  std::string plot_format = "png";  ///< --plot-format png|svg
  bool json = false;         ///< --json: the report as JSON instead of the table
  bool store_errors = false; ///< --store-errors: write the error tables into the bundle
  bool independent = false;  ///< --independent: grade the bundle itself even on the rays it was built from
};

/// The speed-against-error tables of `lumx eval --rays` (also printed by `lumx build`).
std::string format_error_table(const lumx::AplErrorReport& r, const std::string& bundle, const std::string& rays,
                               lumx::PhotometricQuantity q);

/// The table of representations graded through the seam (lumx/model/grading.h): one row a model, ε̂ (its
/// upper bound, '*' when resolved) per distance, bytes and ns per irradiance call.
std::string format_model_grades(const std::vector<lumx::ModelGrade>& grades, const std::string& how);

/// `lumx eval`: exactly one of --points or --rays. Returns the exit status (1 on errors, located).
int run_eval(const EvalArgs& a);

}  // namespace lumx_cli
