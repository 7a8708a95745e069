// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/core/units.h — the quantities lumx's data carry and their units, shared by raysets, APL sets,
// radiance volumes and bundles. Lengths are always metres.
#pragma once

#include <lumx/version.h>

#include <glm/vec3.hpp>

LUMX_NAMESPACE_BEGIN

/// Which quantity a set of rays, maps or voxels holds. Length is always metres.
enum class PhotometricQuantity {
  photometric,  ///< intensity cd, flux lm, irradiance lx (= lm/m²)
  radiometric,  ///< intensity W/sr, flux W, irradiance W/m²
};

inline const char* intensity_unit(PhotometricQuantity q) {
  return q == PhotometricQuantity::photometric ? "cd" : "W/sr";
}
inline const char* flux_unit(PhotometricQuantity q) { return q == PhotometricQuantity::photometric ? "lm" : "W"; }
inline const char* irradiance_unit(PhotometricQuantity q) {
  return q == PhotometricQuantity::photometric ? "lx" : "W/m^2";
}

/// The colour channels of every map in a set: one luminous (or radiant) channel "Y", or linear RGB with
/// Rec. 709 primaries whose luminance Y = 0.2126 R + 0.7152 G + 0.0722 B carries the unit (so an RGB set
/// in cd has Y in cd). Renderers read RGB; photometric exports use Y.
enum class ChannelLayout { luminance, rgb };

inline int channel_count(ChannelLayout c) { return c == ChannelLayout::rgb ? 3 : 1; }

/// The scalar a channel triple stands for: Y itself for one channel, Rec. 709 luminance for RGB.
inline double luminance_of(ChannelLayout layout, const glm::dvec3& v) {
  return layout == ChannelLayout::rgb ? 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z : v.x;
}

LUMX_NAMESPACE_END
