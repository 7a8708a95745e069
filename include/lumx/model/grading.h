// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/model/grading.h — how wrong any LightModel is, at points as a renderer queries them, against rays
// it was not built from.
//
// The reference is apl/error.h's: on spheres of radius d·D about the rays' bounding sphere (D its
// diameter), each sphere cut into N = 2·R_patch² equal-area patches, E_ref(patch) = Σ Φ / A of the rays
// whose lines cross it, with the variance of that estimate from the rays themselves. The model is read at
// each patch's centre (one irradiance() call a patch, normal toward the sphere's centre) and compared by
// the relative RMSE of [VelazquezArmendariz2014] eq. 5.1; the reference's noise is removed (ε̂ = √max(0, ε² − σ²)) and ε̂'s
// upper bound and resolution are stated as apl/error.h states them. The patch-mean reference is not
// moved to the patch centres (the APL path's centring needs a pilot of the graded type), so smooth
// emitters' errors are overstated by the curvature of E within a patch.
#pragma once

#include <lumx/core/execution.h>
#include <lumx/math/bounding_sphere.h>
#include <lumx/model/light_model.h>
#include <lumx/model/registry.h>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

class RaySource;

struct ModelGradeOptions {
  /// Relative distances d of the spheres; sorted, positive, distinct.
  std::vector<double> relative_distances = {0.5, 0.75, 1, 2, 5, 10};
  int patch_resolution = 16;  ///< R_patch (1..1024)
  /// The sphere distances are measured in; absent: the bounding sphere of the rays' start points.
  std::optional<BoundingSphere> bounds;
  ExecutionContext execution;
};

/// One sphere's figures (fractions: 0.04 = 4 %).
struct ModelSphereError {
  double relative_distance = 0;
  double relative_rmse = 0;       ///< ε, the reference's noise included
  double noise_removed = 0;       ///< ε̂
  double noise_removed_upper = 0; ///< what ε̂ is known to be below (two standard errors)
  double noise_floor = 0;         ///< σ: the ε an exact model would show
  bool resolved = false;          ///< ε̂ stands out of the reference's noise
};

struct ModelGrade {
  std::string type, description;
  std::size_t bytes = 0;           ///< LightModel::bytes()
  double ns_per_evaluation = 0;    ///< one irradiance() call on one thread, ns
  std::uint64_t reference_rays = 0;
  std::vector<ModelSphereError> spheres;  ///< one per relative distance, increasing
};

/// `model` against every ray of `rays` (an independent realisation, or a held-out half). Throws
/// std::invalid_argument for bad options or rays (apl/error.h's gather_reference), Cancelled when asked.
ModelGrade grade_model(const LightModel& model, RaySource& rays, const ModelGradeOptions& options = {});

/// Builds a model of registered type `type` from the even rays of `rays` (flux ×2, rays/holdout.h) and
/// grades it on the odd ones. The grade is of the half-ray model; a model built from all rays is better by
/// about √2 where the error is noise.
ModelGrade grade_held_out(const std::string& type, RaySource& rays, const ModelBuildOptions& build = {},
                          ModelGradeOptions options = {});

LUMX_NAMESPACE_END
