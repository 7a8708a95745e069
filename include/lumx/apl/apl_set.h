// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/apl/apl_set.h — the in-memory model of an APL set: anisotropic point lights in levels of detail.
//
// An anisotropic point light (APL) is a point at a fixed position that emits with a direction-dependent
// intensity, stored as an equal-area sphere map (dissertation 000 §4.3; algorithms.md §2). A luminaire's
// APL set has several levels (e.g. 1, 8, 64, 256, 512 APLs). Each level is a cut of one agglomerative
// cluster tree, so every APL of level k has a parent in level k−1 and the parents' fluxes are the sums of
// their children's (000 §6.1). Level 1 is the classic far-field point source.
//
// This header is the data model only; queries live in apl/evaluation.h, apl/sampling.h and apl/lod.h,
// and the file form in io/bundle_io.h (the OpenVDB split of model and I/O).
#pragma once

#include <lumx/core/units.h>
#include <lumx/math/bounding_sphere.h>
#include <lumx/math/direction_mask.h>
#include <lumx/math/sphere_map.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// One anisotropic point light.
///
/// A masked APL (a point source behind apertures: apl/point_sources.h) also carries the directions its
/// light leaves in as geometry, a DirectionMask in the photometric frame. Its intensity is then
///   I(ω) = B[map](m) / max(c_min, B[coverage](m))  for ω inside the mask, 0 outside,
/// with m the map-frame direction, B the bilinear lookup and `coverage` each texel's lit fraction
/// (DirectionMask::normalised_lookup): the border is the mask's, located by the rays far more finely than
/// a texel, and the map carries only the intensity inside it (docs/apl_sets.md, "Beam masks").
struct Apl {
  glm::vec3 position{0.0f};  ///< m, in the luminaire's photometric frame
  glm::dvec3 flux{0.0};      ///< lm or W per channel (one-channel sets repeat Y); equals map.integral()
  int parent = -1;           ///< index of the APL in the previous (coarser) level; −1 in the first level
  SphereMap map;             ///< intensity, cd or W/sr per channel, in its level's MapFrame
  std::shared_ptr<const DirectionMask> mask;  ///< the directions it lights; null: every direction
  SphereMap coverage;  ///< with a mask: its lit fraction of each texel of `map` (one channel, same R and frame)
};

/// Coverage below this is raised to it in a masked lookup (DirectionMask::normalised_lookup): a sliver of
/// a texel that the bilinear weights barely reach would otherwise divide noise by almost nothing.
inline constexpr float kMinMaskCoverage = 1.0f / 16;
/// Sub-directions per texel side of a mask's coverage at map resolution R: 1024 / R (8 at R 128, 256 at
/// R 4), at least 8, so that a border is sampled on the same 2048 × 1024 grid of the sphere at every R up
/// to 128. That grid nests: the coverage at R/2 is the mean of its four children's at R, so a level the fit
/// coarsens reads its border as finely as the built one (8 × 8 sub-directions at R 4 find a border
/// texel's lit fraction only to ±1/16 of a texel 0.3 rad wide).
inline int mask_coverage_subsamples(int resolution) { return std::clamp(1024 / std::max(1, resolution), 8, 256); }

/// Relative RMSE of a level's irradiance against a reference, on spheres of relative distance d
/// (000 §5.3, eq. 5.1). Filled by the builder; read by the error-target level choice.
struct ErrorTable {
  std::vector<double> relative_distance;  ///< d = |x − c| / D, increasing
  std::vector<double> relative_rmse;      ///< one per distance
  bool empty() const { return relative_distance.empty(); }
};

/// The rotation from the luminaire's photometric frame to the frame its maps are drawn in. An equal-area
/// square map has kinks where its wedges meet (math/sphere_map.h: the poles and the squares' diagonals),
/// and a lobe centred on one is read through them: noise-free, a cos^50 lobe along a pole is 4.7 % off
/// (eq. 5.1) from R 128 texels read bilinearly, against 1.4 % inside a wedge (apl_sets.md). The builder
/// turns a set's maps so that its rays' mean direction falls inside a wedge (map_frame_for); sets from
/// far-field photometry keep the identity.
struct MapFrame {
  glm::mat3 to_map{1.0f};  ///< world → map; orthonormal, determinant +1 (glm is column-major)

  glm::vec3 map_direction(const glm::vec3& w) const { return to_map * w; }
  glm::vec3 world_direction(const glm::vec3& m) const { return glm::transpose(to_map) * m; }
  bool is_identity() const { return to_map == glm::mat3(1.0f); }
  /// Row r of to_map (glm stores columns): the map's axis r in the photometric frame, as files store it.
  glm::vec3 row(int r) const { return {to_map[0][r], to_map[1][r], to_map[2][r]}; }
  /// Largest |(RᵀR − I)_ij| and the determinant: how far from a proper rotation the matrix is.
  std::pair<float, float> deviation() const {
    const glm::mat3 p = glm::transpose(to_map) * to_map;
    float worst = 0;
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) worst = std::max(worst, std::abs(p[c][r] - (c == r ? 1.0f : 0.0f)));
    return {worst, glm::determinant(to_map)};
  }
};

/// The direction a set's maps are turned to: polar angle 45° on the +x meridian of the upper square, the
/// middle of a wedge of the concentric map, away from its centre, its diagonals and its border.
inline glm::vec3 map_frame_target() { return glm::vec3(std::sqrt(0.5f), 0.0f, std::sqrt(0.5f)); }

/// The frame that turns unit direction `mean` onto map_frame_target() by the shortest rotation (Rodrigues),
/// or the identity when `mean` is not a usable direction (zero, not finite).
inline MapFrame map_frame_for(const glm::dvec3& mean) {
  MapFrame f;
  const double len = glm::length(mean);
  if (!(len > 0) || !std::isfinite(len)) return f;
  const glm::dvec3 a = mean / len, b(map_frame_target());
  const glm::dvec3 axis = glm::cross(a, b);
  const double s = glm::length(axis), c = glm::dot(a, b);
  glm::dvec3 k;
  if (s > 1e-9) {
    k = axis / s;
  } else if (c > 0) {
    return f;  // already there
  } else {     // opposite: half a turn about any axis perpendicular to b
    k = glm::normalize(glm::cross(b, std::abs(b.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
  }
  // R = I cos θ + sin θ [k]× + (1 − cos θ) k kᵀ, with cos θ = a·b and sin θ = |a × b|.
  const double cs = s > 1e-9 ? c : -1.0, sn = s > 1e-9 ? s : 0.0;
  glm::dmat3 r(0.0);
  const glm::dmat3 kx(0, k.z, -k.y, -k.z, 0, k.x, k.y, -k.x, 0);  // columns of the cross-product matrix
  r = glm::dmat3(cs) + sn * kx + (1 - cs) * glm::outerProduct(k, k);
  f.to_map = glm::mat3(r);
  return f;
}

struct AplLevel {
  int map_resolution = 0;  ///< R of every map in this level (image 2R × R)
  MapFrame frame;          ///< the frame every map of this level is drawn in
  std::vector<Apl> apls;
  ErrorTable error;

  std::size_t size() const { return apls.size(); }
  /// Total flux per channel: Σ APL flux.
  glm::dvec3 flux() const {
    glm::dvec3 f(0.0);
    for (const Apl& a : apls) f += a.flux;
    return f;
  }
  /// Bytes of map data held in memory.
  std::size_t map_bytes() const {
    std::size_t b = 0;
    for (const Apl& a : apls) b += a.map.bytes() + (a.mask ? a.coverage.bytes() : 0);
    return b;
  }
  /// Whether some APL of the level carries a mask.
  bool has_masks() const {
    for (const Apl& a : apls)
      if (a.mask) return true;
    return false;
  }
  /// APLs of the level with a mask (one per point source in a point-source set's finest level).
  std::size_t masked_apl_count() const {
    return std::size_t(std::count_if(apls.begin(), apls.end(), [](const Apl& a) { return bool(a.mask); }));
  }
};

/// Recomputes a masked APL's coverage at its map's resolution in `frame` (clears it without a mask):
/// wherever a map changes resolution (a fit, a partial load) its coverage must follow.
inline void refresh_coverage(Apl& a, const MapFrame& frame) {
  if (!a.mask) {
    a.coverage = SphereMap();
    return;
  }
  a.coverage = a.mask->coverage(a.map.resolution(), glm::transpose(frame.to_map), mask_coverage_subsamples(a.map.resolution()));
}
/// refresh_coverage for every APL of the level, each distinct mask's coverage computed once and shared
/// (the APLs of one source share its mask).
inline void refresh_coverages(AplLevel& level) {
  std::vector<const Apl*> done;
  for (Apl& a : level.apls) {
    if (!a.mask) {
      a.coverage = SphereMap();
      continue;
    }
    const Apl* same = nullptr;
    for (const Apl* d : done)
      if (d->mask == a.mask && d->map.resolution() == a.map.resolution()) same = d;
    if (same) {
      a.coverage = same->coverage;
    } else {
      a.coverage = SphereMap();
      refresh_coverage(a, level.frame);
      done.push_back(&a);
    }
  }
}

/// Limits every bundle reader applies by default (io/bundle_io.h BundleLimits), which the builder keeps
/// to so that what it writes can be read: caps per mask, vertices per cap, and the containment tests
/// the coverage of a whole set's masks takes at the levels' resolutions.
inline constexpr std::size_t kMaxMaskCaps = 256;
inline constexpr std::size_t kMaxMaskHullVertices = 4096;
inline constexpr double kMaxMaskTests = 2147483648.0;  // 2^31: a few seconds

/// A luminaire's APL set: levels ordered by increasing APL count, plus what a reader needs to use it.
struct AplSet {
  PhotometricQuantity quantity = PhotometricQuantity::photometric;
  ChannelLayout channels = ChannelLayout::luminance;
  BoundingSphere bounds;                           ///< encloses the luminaire (for the LOD distance)
  std::map<std::string, std::string> provenance;   ///< free-form: source file, generator, seed, ...
  std::vector<AplLevel> levels;

  /// Relative distance of x from the luminaire, d = |x − c| / D with D the bounding diameter (000 Fig. 6.1).
  double relative_distance(const glm::dvec3& x) const {
    const double diameter = 2.0 * bounds.radius;
    return diameter > 0 ? glm::length(x - bounds.center) / diameter : INFINITY;
  }
};

/// Recomputes every APL's flux from its map (Σ texel × solid angle), the value the manifest stores.
inline void update_fluxes(AplSet& set) {
  for (AplLevel& level : set.levels)
    for (Apl& a : level.apls) a.flux = a.map.integral();
}

/// The smallest sphere-like bound we can compute cheaply: the centre of the APL positions' box and the
/// largest distance to it. Builders that know the geometry should set a tighter one themselves.
inline BoundingSphere bounding_sphere_of(const AplSet& set) {
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const AplLevel& l : set.levels)
    for (const Apl& a : l.apls) {
      lo = glm::min(lo, glm::dvec3(a.position));
      hi = glm::max(hi, glm::dvec3(a.position));
    }
  BoundingSphere s;
  if (!(lo.x <= hi.x)) return s;
  s.center = 0.5 * (lo + hi);
  for (const AplLevel& l : set.levels)
    for (const Apl& a : l.apls) s.radius = std::max(s.radius, glm::length(glm::dvec3(a.position) - s.center));
  return s;
}

/// Consistency rules of a set; each violation is one message naming the level, APL and field.
///   - at least one level; levels strictly increasing in APL count; no empty level;
///   - every map has the level's resolution and the set's channel count; values finite and ≥ 0;
///   - positions, the bounding sphere and fluxes finite, fluxes ≥ 0; error tables well formed;
///   - parent indices valid (−1 in level 0, in range afterwards);
///   - each APL's flux equals its map's integral within `flux_tolerance` relative (plus 1e-6 of the level's
///     flux, for APLs with next to no flux);
///   - each parent's flux equals the sum of its children's, with the same tolerance (cuts of one tree).
std::vector<std::string> check_apl_set(const AplSet& set, double flux_tolerance = 1e-3);

LUMX_NAMESPACE_END
