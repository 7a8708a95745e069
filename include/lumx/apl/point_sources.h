// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/apl/point_sources.h — a rayset whose every line passes through one of a few points: point sources
// behind apertures, built as masked APLs (the builder's last step, apl/builder.h step 7).
//
// Point sources in an opaque box with holes (an LED behind a shutter, a lamp behind a louvre) light sets
// of directions with perfectly sharp borders. No texel map reads such a border well at any resolution a
// bundle can afford: noise-free maps at the two sources of the box with holes stay above 10 % off at
// some distance up to R 1024 (docs/apl_sets.md, "What maps can do on the box at all"). And clustering
// puts APLs between the sources, whose rays mix both (step 1b: the lines' points nearest a convergence
// point between the sources). When every ray's line passes through one of a few points, the light is
// that of point sources, so:
//   1. the candidates are the least-squares points of the finest clusters' lines and the finest level's
//      positions (step 6 placed most of its APLs on the sources); a source is a candidate through which
//      at least `min_rays` lines pass within `tolerance` of the bounding radius, on the side the rays
//      leave from (the source is behind, or at, each ray's start), the candidates with most lines first;
//   2. every ray goes to the source its line passes nearest; when one passes none, there are no point
//      sources and the built set stands;
//   3. each source moves to its own rays' least-squares point (LineFit), and its directions become its
//      DirectionMask (math/direction_mask.h); a source whose directions form no mask (light leaving in
//      every direction) leaves the built set standing;
//   4. the levels are cuts of a cluster tree over the sources (eq. 4.1), as many APLs as requested but
//      at most one per source: a box with two sources gets levels of 1 and 2 APLs. An APL of one source
//      sits at it with its mask; an APL of several at their rays' least-squares point with a plain map
//      (the box's one-APL level plain is 126/75/51/53 % off at d = 1/2/5/10, ShippedSetSuite/4; masked
//      by the hull of all its directions it was no better in a trial: one point cannot stand for
//      sources 4 cm apart);
//   5. maps are the rays binned as in the builder (step 5): each source's flux binned once per map
//      resolution as its rays are assigned, an APL's map the sum of its sources'.
// Masked APLs add up exactly as the lights they stand for: APLs at one point with one mask are one light,
// so one APL per source is the level (the placement study in docs/apl_sets.md left 303 of 512 APLs
// empty and equalled the two-APL rows to 0.01 points).
//
// Cost: one pass over the rays to count the lines through each candidate, which ends at the first ray
// that passes none (for any extended emitter, almost always the first: 4 096 rays are read); one that
// assigns each ray to a source and gathers its line, direction and binned flux there, again for each
// round that drops a source. Memory: each ray's direction (24 bytes, while the masks are made) and each
// source's flux at every level's resolution. A set whose masks a bundle reader would refuse by default (apl_set.h: kMaxMaskCaps,
// kMaxMaskHullVertices, kMaxMaskTests) is not made.
#pragma once

#include <lumx/apl/apl_set.h>
#include <lumx/math/bounding_sphere.h>
#include <lumx/rays/rayset.h>

#include <glm/glm.hpp>

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

struct PointSourceOptions {
  bool enabled = true;           ///< look for point sources at all (AplBuildOptions::point_sources)
  /// A line passes through a point when it passes within this fraction of the bounding radius of it:
  /// 1/1000 (75 µm on the 10 cm box with holes, whose lines pass their sources to float rounding:
  /// PointSources.TheBoxWithHolesBecomesOneMaskedAplPerSource finds them within 1 µm).
  double tolerance = 1e-3;
  std::size_t min_rays = 500;    ///< lines a point needs to be a source (a DirectionMask needs ≥ 64 per beam)
  std::size_t max_sources = 64;  ///< more points than this: not "a few point sources"
};

/// What the point-source step found: the sources, or why there are none.
struct PointSourceReport {
  std::size_t sources = 0;  ///< 0: the built set stands
  std::string why;          ///< with no sources: the reason
};

/// The point-source set of `rays` (module comment), or nothing, with the reason in report.why.
/// `candidates`: points that may be sources (the builder's: its finest clusters' points); `bounds`: its bounding sphere; `level_counts`: the
/// requested APLs per level (increasing); `resolution(apls)`: the map resolution of a level of that many
/// APLs; `frame`: the maps' frame. Rays are read `chunk_rays` at a time (each chunk at most that many).
/// Deterministic: rays are classified independently on `threads` threads and summed in file order.
std::optional<AplSet> build_point_source_set(RaySource& rays, const std::vector<glm::vec3>& candidates,
                                             const BoundingSphere& bounds, const std::vector<std::size_t>& level_counts,
                                             const std::function<int(std::size_t)>& resolution, const MapFrame& frame,
                                             const PointSourceOptions& options, std::size_t chunk_rays = 1 << 16,
                                             unsigned threads = 1, PointSourceReport* report = nullptr);

LUMX_NAMESPACE_END
