// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/model/apl_model.h — one level of an APL set as a LightModel (registered as "apl";
// [VelazquezArmendariz2014] §4.3–4.5, docs/references.md): irradiance and intensity as apl/evaluation.h computes them, emission sampling as
// apl/sampling.h's AplEmissionSampler draws it (an APL by flux, a direction by its dilated map), so the
// seam returns the same numbers as the APL queries it wraps.
#pragma once

#include <lumx/apl/apl_set.h>
#include <lumx/model/light_model.h>

#include <cstddef>
#include <memory>

LUMX_NAMESPACE_BEGIN

class AplEmissionSampler;

class AplLevelModel final : public LightModel {
 public:
  /// Level `level` of `set` (shared: several levels' models may hold one set). Throws std::invalid_argument
  /// for a level that does not exist or is empty.
  AplLevelModel(std::shared_ptr<const AplSet> set, std::size_t level);
  ~AplLevelModel() override;

  const AplSet& set() const { return *set_; }
  std::size_t level_index() const { return level_; }
  const AplLevel& level() const { return set_->levels[level_]; }

  std::string type() const override { return "apl"; }
  std::string description() const override;
  PhotometricQuantity quantity() const override { return set_->quantity; }
  ChannelLayout channels() const override { return set_->channels; }
  BoundingSphere bounds() const override { return set_->bounds; }
  glm::dvec3 flux() const override;
  glm::dvec3 intensity(const glm::dvec3& w) const override;
  glm::dvec3 irradiance(const glm::dvec3& x, const glm::dvec3& n, const Visibility* visibility = nullptr) const override;
  PositionMeasure position_measure() const override { return PositionMeasure::discrete; }
  ModelEmission sample_emission(const std::array<double, 4>& u) const override;
  EmissionDensity emission_pdf(std::size_t element, const glm::dvec3& position, const glm::dvec3& direction) const override;
  std::size_t bytes() const override;

 private:
  std::shared_ptr<const AplSet> set_;
  std::size_t level_;
  std::unique_ptr<AplEmissionSampler> sampler_;
};

LUMX_NAMESPACE_END
