// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/apl/builder.h>
#include <lumx/apl/evaluation.h>
#include <lumx/apl/sampling.h>
#include <lumx/model/apl_model.h>
#include <lumx/model/registry.h>

#include "model/builtin_models.h"

#include <stdexcept>

LUMX_NAMESPACE_BEGIN

AplLevelModel::AplLevelModel(std::shared_ptr<const AplSet> set, std::size_t level) : set_(std::move(set)), level_(level) {
  if (!set_) throw std::invalid_argument("AplLevelModel: no set");
  if (level_ >= set_->levels.size())
    throw std::invalid_argument("AplLevelModel: level " + std::to_string(level_) + " does not exist");
  if (set_->levels[level_].apls.empty())
    throw std::invalid_argument("AplLevelModel: level " + std::to_string(level_) + " is empty");
  sampler_ = std::make_unique<AplEmissionSampler>(*set_, level_);
}

AplLevelModel::~AplLevelModel() = default;

std::string AplLevelModel::description() const {
  const AplLevel& l = level();
  std::string s = std::to_string(l.size()) + (l.size() == 1 ? " APL" : " APLs") + ", maps R " +
                  std::to_string(l.map_resolution);
  if (const std::size_t m = l.masked_apl_count(); m > 0) s += ", " + std::to_string(m) + " masked";
  return s;
}

glm::dvec3 AplLevelModel::flux() const { return level().flux(); }

glm::dvec3 AplLevelModel::intensity(const glm::dvec3& w) const { return far_field_intensity(level(), glm::vec3(w)); }

glm::dvec3 AplLevelModel::irradiance(const glm::dvec3& x, const glm::dvec3& n, const Visibility* visibility) const {
  if (!visibility) return lumx::irradiance(*set_, level_, glm::vec3(x), glm::vec3(n)).irradiance;
  return lumx::irradiance(*set_, level_, glm::vec3(x), glm::vec3(n),
                          [&](std::size_t, const glm::vec3& p, const glm::vec3&) {
                            return visibility->visible(glm::dvec3(p), x) ? 1.0f : 0.0f;
                          })
      .irradiance;
}

ModelEmission AplLevelModel::sample_emission(const std::array<double, 4>& u) const {
  // u[3] is not needed: a point light draws no position within its element.
  const EmissionSample s = sampler_->sample(float(u[0]), float(u[1]), float(u[2]));
  ModelEmission e;
  if (!s.valid()) return e;
  e.position = glm::dvec3(s.position);
  e.direction = glm::dvec3(s.direction);
  e.flux = glm::dvec3(s.flux);
  e.pdf_position = s.pdf_apl;
  e.pdf_direction = s.pdf_direction;
  e.element = s.apl;
  return e;
}

EmissionDensity AplLevelModel::emission_pdf(std::size_t element, const glm::dvec3&, const glm::dvec3& direction) const {
  if (element >= level().size()) return {};
  return {sampler_->pdf_apl(element), sampler_->pdf_direction(element, glm::vec3(direction))};
}

std::size_t AplLevelModel::bytes() const {
  // The maps, and the sampler's one float per texel of each APL.
  const std::size_t R = std::size_t(level().map_resolution);
  return level().map_bytes() + level().size() * 2 * R * R * sizeof(float);
}

namespace detail {

ModelType apl_model_type() {
  ModelType t;
  t.name = "apl";
  t.description = "APL level: anisotropic point lights on equal-area sphere maps";
  // Stored by the bundle itself (its "levels", io/bundle_io.h): no section codec.
  t.build = [](RaySource& rays, const ModelBuildOptions& o) -> std::unique_ptr<LightModel> {
    AplBuildOptions b;
    const double apls = o.number("apls", 512);
    if (!(apls >= 1 && apls <= double(1u << 20))) throw std::invalid_argument("option apls must be in [1, 2^20]");
    b.level_counts = {std::size_t(apls)};
    b.map_resolution = int(o.number("map-resolution", 0));
    b.threads = o.execution.thread_count();
    auto set = std::make_shared<AplSet>(build_apl_set(rays, b));
    return std::make_unique<AplLevelModel>(std::move(set), set->levels.size() - 1);
  };
  return t;
}

}  // namespace detail
LUMX_NAMESPACE_END
