// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/apl/evaluation.h — what an APL level shines on a point: intensity and irradiance.
//
// Irradiance at x with normal n from one level (000 §4.5; algorithms.md §3):
//   E(x, n) = Σ_i I_i(ω_i) · max(0, −n·ω_i) / r_i² · V_i(x),   ω_i = (x − p_i)/r_i,  r_i = |x − p_i|
// (ω_i leaves the APL; the receiver's normal faces it, hence the minus sign).
// The luminaire's own occlusion is already in the maps; V is the caller's visibility for other geometry.
// The inverse-square law diverges at an APL's position (hard-cases §3, "point light as r → 0"), so a
// caller-chosen minimum distance bounds r; the default is a millionth of the bounding diameter, far
// below any distance at which a point light is a valid model, and its use is counted, never hidden.
#pragma once

#include <lumx/apl/apl_set.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cstddef>

LUMX_NAMESPACE_BEGIN

namespace detail {
/// The factor a masked APL's bilinear value is multiplied by toward w (map-frame direction m): 0 outside
/// its mask, 1 / max(kMinMaskCoverage, B[coverage](m)) inside (Apl's comment); 1 without a mask.
inline float mask_factor(const Apl& a, const glm::vec3& m, const glm::vec3& w) {
  if (!a.mask) return 1.0f;
  if (!a.mask->contains(glm::dvec3(w))) return 0.0f;
  return 1.0f / std::max(kMinMaskCoverage, a.coverage.lookup(m).x);
}
}  // namespace detail

/// Intensity of one APL of `level` toward unit direction w of the photometric frame (cd or W/sr per
/// channel; bilinear on its map, read in the level's map frame, inside its mask when it has one).
inline glm::vec3 intensity(const AplLevel& level, const Apl& apl, const glm::vec3& w) {
  const glm::vec3 m = level.frame.map_direction(w);
  const float f = detail::mask_factor(apl, m, w);
  return f > 0 ? apl.map.lookup(m) * f : glm::vec3(0.0f);
}

/// Intensity of a whole level toward w in the far-field limit (positions ignored): Σ_i I_i(w).
inline glm::dvec3 far_field_intensity(const AplLevel& level, const glm::vec3& w) {
  const glm::vec3 m = level.frame.map_direction(w);
  glm::dvec3 sum(0.0);
  for (const Apl& a : level.apls) {
    const float f = detail::mask_factor(a, m, w);
    if (f > 0) sum += glm::dvec3(a.map.lookup(m) * f);
  }
  return sum;
}

struct IrradianceOptions {
  /// r is clamped to at least this many metres (0 = 1e-6 × the bounding diameter, or 1e-9 m).
  double min_distance = 0;
  /// Ignore the cosine at the receiver (n is then unused): fluence-like "irradiance on a sphere".
  bool ignore_normal = false;
};

struct IrradianceResult {
  glm::dvec3 irradiance{0.0};  ///< lx or W/m² per channel
  std::size_t clamped = 0;     ///< APLs closer than min_distance (their r was clamped)
};

namespace detail {
inline double effective_min_distance(const AplSet& set, const IrradianceOptions& o) {
  if (o.min_distance > 0) return o.min_distance;
  return set.bounds.radius > 0 ? 2e-6 * set.bounds.radius : 1e-9;
}

/// The unit direction w from an APL at p to x, with r = |x − p| and r2 = r² (at the APL itself w is
/// arbitrary but fixed).
inline glm::vec3 apl_direction(const glm::vec3& p, const glm::vec3& x, float& r, float& r2) {
  const glm::vec3 d = x - p;
  r2 = glm::dot(d, d);
  r = std::sqrt(r2);
  return r > 0 ? d * (1.0f / r) : glm::vec3(0, 0, -1);
}

/// What irradiance() computes of one APL for a point x with normal n before it reads the map: the
/// direction w (apl_direction), r² with r clamped to `min_r` (counted in `clamped`), and the receiver's
/// cosine (−n·w, or 1 with ignore_normal). Returns false where the APL does not light x (cosine ≤ 0);
/// else its contribution is blend(footprint(w in the map's frame)) × cosine × visibility / r².
inline bool apl_geometry(const glm::vec3& p, const glm::vec3& x, const glm::vec3& n, float min_r, bool ignore_normal,
                         glm::vec3& w, float& cosine, float& r2, std::size_t& clamped) {
  float r;
  w = apl_direction(p, x, r, r2);
  if (r < min_r) {
    r2 = min_r * min_r;
    ++clamped;
  }
  cosine = ignore_normal ? 1.0f : -glm::dot(n, w);
  return cosine > 0.0f;
}
}  // namespace detail

/// Irradiance at x (m) on a surface with unit normal n from every APL of `level`; `visibility(apl_index,
/// apl_position, x)` returns the fraction of light that reaches x (1 = unoccluded). It is a template
/// parameter so the common no-occluder case costs nothing.
template <class Visibility>
IrradianceResult irradiance(const AplSet& set, std::size_t level_index, const glm::vec3& x, const glm::vec3& n,
                            Visibility&& visibility, const IrradianceOptions& options = {}) {
  const AplLevel& level = set.levels.at(level_index);
  const float min_r = float(detail::effective_min_distance(set, options));
  IrradianceResult result;
  glm::vec3 sum(0.0f);
  // Two passes per chunk of APLs: first every direction, weight and texel footprint (prefetching the
  // texels), then the blends. With hundreds of maps in DRAM the misses of a chunk overlap instead of
  // being paid one after another (performance.md §3c: the limit is misses in flight, not bandwidth).
  constexpr std::size_t kChunk = 32;
  const glm::mat3 to_map = level.frame.to_map;
  const bool turned = !level.frame.is_identity();  // most sets: skip the 3×3 multiply per APL
  SphereMap::Footprint footprints[kChunk];
  float weights[kChunk];
  std::size_t index[kChunk];
  for (std::size_t begin = 0; begin < level.apls.size(); begin += kChunk) {
    const std::size_t end = std::min(level.apls.size(), begin + kChunk);
    std::size_t count = 0;
    for (std::size_t i = begin; i < end; ++i) {
      const Apl& a = level.apls[i];
      glm::vec3 w;
      float cosine, r2;
      if (!detail::apl_geometry(a.position, x, n, min_r, options.ignore_normal, w, cosine, r2, result.clamped))
        continue;
      const float v = visibility(i, a.position, x);
      if (v <= 0.0f) continue;
      const glm::vec3 m = turned ? to_map * w : w;
      const float masked = detail::mask_factor(a, m, w);  // 1 for the usual APL without a mask
      if (masked <= 0.0f) continue;
      footprints[count] = a.map.footprint(m);
      for (const float* t : footprints[count].texel) __builtin_prefetch(t);
      weights[count] = cosine * v / r2 * masked;
      index[count] = i;
      ++count;
    }
    for (std::size_t k = 0; k < count; ++k) sum += level.apls[index[k]].map.blend(footprints[k]) * weights[k];
  }
  result.irradiance = glm::dvec3(sum);
  return result;
}

/// Irradiance without occluders.
inline IrradianceResult irradiance(const AplSet& set, std::size_t level_index, const glm::vec3& x, const glm::vec3& n,
                                   const IrradianceOptions& options = {}) {
  return irradiance(
      set, level_index, x, n, [](std::size_t, const glm::vec3&, const glm::vec3&) { return 1.0f; }, options);
}

LUMX_NAMESPACE_END
