// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/model/light_model.h — the one interface every light representation implements (an APL level, the
// far field, and any representation registered by name: model/registry.h).
//
// Frames and units: positions in metres and directions as unit vectors, both in the luminaire's
// photometric frame (the frame of its bundle; a renderer places it with its own transform). Flux is in lm
// (photometric) or W (radiometric) per channel, intensity in cd or W/sr, irradiance in lx or W/m². One-
// channel models repeat the luminance in all three components of a glm::dvec3, as the APL set does.
//
// A LightModel is immutable after construction: every query is const and may be called from any number of
// threads at once.
#pragma once

#include <lumx/core/units.h>
#include <lumx/math/bounding_sphere.h>

#include <glm/glm.hpp>

#include <array>
#include <cstddef>
#include <string>

LUMX_NAMESPACE_BEGIN

/// Occlusion between two points, supplied by the caller (a renderer's shadow rays, a room's scene).
class Visibility {
 public:
  virtual ~Visibility() = default;
  /// True when nothing lies strictly between `from` (a point of the light) and `to` (the receiver).
  virtual bool visible(const glm::dvec3& from, const glm::dvec3& to) const = 0;
};

/// What an emission sample's position density is measured against.
enum class PositionMeasure {
  discrete,  ///< the model emits from finitely many points: pdf_position is a probability
  area       ///< the model emits from surfaces: pdf_position is per m²
};

/// One emission sample (light tracing, photon mapping, BDPT). Its flux is the emitted radiometric or
/// photometric quantity over the joint density, so that the mean of `flux` over samples is the model's
/// flux(); pdf_position · pdf_direction is exactly what emission_pdf() returns for the same sample (MIS).
struct ModelEmission {
  glm::dvec3 position{0.0};   ///< m
  glm::dvec3 direction{0.0};  ///< unit
  glm::dvec3 flux{0.0};       ///< lm or W per channel
  double pdf_position = 0;    ///< probability (discrete) or 1/m² (area) of the position
  double pdf_direction = 0;   ///< 1/sr, of the direction given the position
  std::size_t element = 0;    ///< which point or surface element emitted (emission_pdf's key)
  bool valid() const { return pdf_position > 0 && pdf_direction > 0; }
};

/// The two factors of an emission sample's density.
struct EmissionDensity {
  double position = 0;   ///< as ModelEmission::pdf_position
  double direction = 0;  ///< as ModelEmission::pdf_direction
  double joint() const { return position * direction; }
};

/// A light representation as a renderer queries it.
class LightModel {
 public:
  virtual ~LightModel() = default;

  /// The registered type name (model/registry.h), e.g. "apl", "far-field".
  virtual std::string type() const = 0;
  /// One line for listings, e.g. "512 APLs, maps R 64".
  virtual std::string description() const = 0;

  virtual PhotometricQuantity quantity() const = 0;
  virtual ChannelLayout channels() const = 0;
  /// A sphere around everything that emits (relative distances are measured in its diameter).
  virtual BoundingSphere bounds() const = 0;
  /// Total emitted flux, lm or W per channel.
  virtual glm::dvec3 flux() const = 0;

  /// Intensity toward unit direction `w` seen from far away (the far-field limit), cd or W/sr.
  virtual glm::dvec3 intensity(const glm::dvec3& w) const = 0;
  /// Irradiance at `x` on a surface of unit normal `n` (lit from the side n faces), lx or W/m². With
  /// `visibility`, light from each emitting point is counted only where visibility->visible(point, x).
  virtual glm::dvec3 irradiance(const glm::dvec3& x, const glm::dvec3& n,
                                const Visibility* visibility = nullptr) const = 0;

  /// How emission sample positions are measured.
  virtual PositionMeasure position_measure() const = 0;
  /// One emission sample from four uniform numbers in [0, 1); invalid (pdfs 0) when nothing emits there.
  virtual ModelEmission sample_emission(const std::array<double, 4>& u) const = 0;
  /// The density sample_emission() gives a sample of element `element` at `position` toward `direction`.
  virtual EmissionDensity emission_pdf(std::size_t element, const glm::dvec3& position,
                                       const glm::dvec3& direction) const = 0;

  /// Bytes the model holds in memory for its queries.
  virtual std::size_t bytes() const = 0;
};

LUMX_NAMESPACE_END
