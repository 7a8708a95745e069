// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include "apl/error_detail.h"
#include <lumx/apl/error.h>
#include <lumx/model/grading.h>
#include <lumx/rays/holdout.h>
#include <lumx/rays/rayset.h>

#include <cmath>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN

namespace {

// The centre of the start points' box and the distance to the farthest start point (one pass).
BoundingSphere start_point_bounds(RaySource& rays, const ExecutionContext& ctx) {
  rays.rewind();
  RayChunk chunk;
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  while (rays.next(chunk, 1 << 16)) {
    ctx.check_cancelled();
    for (std::size_t i = 0; i < chunk.size(); ++i) {
      const glm::dvec3 p(chunk.position(i));
      lo = glm::min(lo, p), hi = glm::max(hi, p);
    }
  }
  if (!(lo.x <= hi.x)) throw std::invalid_argument("grade_model: the rayset has no ray");
  BoundingSphere b;
  b.center = 0.5 * (lo + hi);
  rays.rewind();
  while (rays.next(chunk, 1 << 16))
    for (std::size_t i = 0; i < chunk.size(); ++i) b.radius = std::max(b.radius, glm::length(glm::dvec3(chunk.position(i)) - b.center));
  return b;
}

}  // namespace

ModelGrade grade_model(const LightModel& model, RaySource& rays, const ModelGradeOptions& options) {
  AplErrorOptions o;
  o.relative_distances = options.relative_distances;
  o.patch_resolution = options.patch_resolution;
  o.patch_subsamples = 1;
  o.threads = options.execution.threads;
  o.far_field = false;
  const BoundingSphere bounds = options.bounds ? *options.bounds : start_point_bounds(rays, options.execution);
  options.execution.report(0, "reference");
  const ReferenceIrradiance ref = gather_reference(rays, bounds, o);
  options.execution.check_cancelled();
  options.execution.report(0.5, "model");
  LevelErrors row;
  row.apls = 1;
  row.map_resolution = 1;  // one point a patch: k = 1 whatever the model
  const ChannelLayout channels = model.channels();
  detail::evaluate_rows(ref, o, row, [&](std::size_t, const glm::vec3& x, const glm::vec3& n, std::size_t*) {
    return luminance_of(channels, model.irradiance(glm::dvec3(x), glm::dvec3(n)));
  });
  ModelGrade g;
  g.type = model.type();
  g.description = model.description();
  g.bytes = model.bytes();
  g.ns_per_evaluation = row.ns_per_evaluation;
  g.reference_rays = ref.rays;
  for (std::size_t s = 0; s < ref.sphere.size(); ++s) {
    const IrradianceErrors& e = row.errors[s];
    ModelSphereError m;
    m.relative_distance = ref.sphere[s].relative_distance;
    m.relative_rmse = e.relative_rmse;
    m.noise_removed = e.relative_rmse_noise_removed;
    m.noise_removed_upper = e.noise_removed_upper;
    m.noise_floor = ref.sphere[s].noise_floor;
    m.resolved = e.resolved;
    g.spheres.push_back(m);
  }
  options.execution.report(1, "model");
  return g;
}

ModelGrade grade_held_out(const std::string& type, RaySource& rays, const ModelBuildOptions& build, ModelGradeOptions options) {
  if (!options.bounds) options.bounds = start_point_bounds(rays, options.execution);
  RayHalf even(rays, 0);
  const std::unique_ptr<LightModel> model = build_model(type, even, build);
  options.execution.check_cancelled();
  RayHalf odd(rays, 1);
  return grade_model(*model, odd, options);
}

LUMX_NAMESPACE_END
