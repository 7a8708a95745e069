// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/rays/intensity_preview.h — a rayset's intensity distribution as a preview image: the rays' directions
// binned on an equal-area sphere map (the histogram estimator, 000 §4.3), then filtered by multi-resolution
// pull-push with stable/unstable texels, shadow-border classification and bilateral upsampling
// (math/pull_push.h, seed 002 §5), so that a bake's first passes already show a meaningful distribution.
#pragma once

#include <lumx/math/pull_push.h>
#include <lumx/math/sphere_map.h>
#include <lumx/rays/rayset.h>

#include <cstdint>
#include <vector>

LUMX_NAMESPACE_BEGIN

struct IntensityPreview {
  SphereMap histogram;                ///< Σ flux / texel solid angle: cd (or W/sr), 1 channel
  SphereMap filtered;                 ///< the same after pull-push, same flux
  std::vector<double> count;          ///< rays per texel
  std::vector<PullPushTexel> kind;    ///< what the filter did per texel
  std::uint64_t rays = 0;             ///< rays binned
};

/// Streams `rays` once (from the start) into maps of square resolution R (a power of two) and filters them.
/// Throws std::invalid_argument for a bad R or a ray with a non-finite or zero direction or a negative or
/// non-finite flux (its index in the message).
inline IntensityPreview intensity_preview(RaySource& rays, int R, const PullPushOptions& options = {}) {
  IntensityPreview p;
  p.histogram = SphereMap(R, 1);
  p.count.assign(p.histogram.texel_count(), 0.0);
  std::vector<double> flux(p.histogram.texel_count(), 0.0);
  rays.rewind();
  RayChunk chunk;
  while (rays.next(chunk, 1 << 16)) {
    for (std::size_t i = 0; i < chunk.size(); ++i, ++p.rays) {
      const glm::vec3 d = chunk.direction(i);
      const float len = glm::length(d);
      if (!(len > 0) || !std::isfinite(len) || !(chunk.flux[i] >= 0) || !std::isfinite(chunk.flux[i]))
        throw std::invalid_argument("intensity_preview: ray " + std::to_string(p.rays) +
                                    " has a zero or non-finite direction or a negative or non-finite flux");
      int x, y;
      p.histogram.texel_of(d / len, x, y);
      const std::size_t t = std::size_t(y) * std::size_t(p.histogram.width()) + std::size_t(x);
      flux[t] += chunk.flux[i];
      p.count[t] += 1;
    }
  }
  const double inv_sr = 1.0 / p.histogram.texel_solid_angle();
  const PullPushResult filtered = pull_push(flux, p.count, R, options);
  p.filtered = SphereMap(R, 1);
  for (std::size_t t = 0; t < flux.size(); ++t) {
    p.histogram.data()[t] = float(flux[t] * inv_sr);
    p.filtered.data()[t] = float(filtered.flux[t] * inv_sr);
  }
  p.kind = filtered.kind;
  return p;
}

LUMX_NAMESPACE_END
