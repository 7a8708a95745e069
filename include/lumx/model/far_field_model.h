// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/model/far_field_model.h — far-field photometry (IES LM-63, EULUMDAT, TM-33) as a LightModel
// (registered as "far-field"): one point at the photometric centre with the table's intensity, what legacy
// tools assume at every distance. Queried through its one-APL set (apl/far_field.h,
// apl_set_from_photometry), so intensity, irradiance and sampling agree with the APL queries; stored in a
// bundle as IES LM-63-2019 text, built from rays by rays/far_field.h.
#pragma once

#include <lumx/model/apl_model.h>
#include <lumx/photometry/photometry.h>

#include <memory>

LUMX_NAMESPACE_BEGIN

class FarFieldModel final : public LightModel {
 public:
  /// Throws lumx::Error when `photometry` cannot be tabulated (apl_set_from_photometry).
  explicit FarFieldModel(Photometry photometry, int map_resolution = 128);

  const Photometry& photometry() const { return photometry_; }
  /// The one-APL level every query reads.
  const AplLevelModel& point() const { return point_; }

  std::string type() const override { return "far-field"; }
  std::string description() const override;
  PhotometricQuantity quantity() const override { return point_.quantity(); }
  ChannelLayout channels() const override { return point_.channels(); }
  BoundingSphere bounds() const override { return point_.bounds(); }
  glm::dvec3 flux() const override { return point_.flux(); }
  glm::dvec3 intensity(const glm::dvec3& w) const override { return point_.intensity(w); }
  glm::dvec3 irradiance(const glm::dvec3& x, const glm::dvec3& n, const Visibility* visibility = nullptr) const override {
    return point_.irradiance(x, n, visibility);
  }
  PositionMeasure position_measure() const override { return PositionMeasure::discrete; }
  ModelEmission sample_emission(const std::array<double, 4>& u) const override { return point_.sample_emission(u); }
  EmissionDensity emission_pdf(std::size_t element, const glm::dvec3& position, const glm::dvec3& direction) const override {
    return point_.emission_pdf(element, position, direction);
  }
  std::size_t bytes() const override { return point_.bytes(); }

 private:
  Photometry photometry_;
  AplLevelModel point_;
};

LUMX_NAMESPACE_END
