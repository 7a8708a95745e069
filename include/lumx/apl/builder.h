// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/apl/builder.h — raysets in, APL sets out (dissertation 000 §4.3, §4.6).
//
//   1. Seeds: `seed_rays` rays spread evenly through the file (every (N/S)-th ray with flux > 0; files
//      are often sorted by position or emitter, so "the first S" would seed one corner of the source).
//      1b. Rays as lines (AplBuildOptions::place_at_convergence, the default): a ray's start point is
//      only where it was recorded, anywhere along its line. The seeds' convergence point c0 (LineFit:
//      least squares over their lines) is fitted; when it is inside the luminaire's bound and three tests
//      pass (the lines meet, clustering by line does not shift the rays much more, the lines do not meet
//      in one point; see the code), each ray is represented by the point of its line nearest c0, so rays
//      recorded on a surface around a smaller emitter are clustered by where they come from
//      (Cyl1M_Faberge's rays lie on the caps of a cylinder but pass within ~1 mm of its centre).
//   2. Tree: agglomerative clustering of the seeds' points with eq. 4.1 (apl/clustering.h).
//   3. Levels: cuts of the tree with 1, 8, 64, ... clusters; an APL sits at the centre of its seeds'
//      bounding box (000 §4.3); parents are the enclosing clusters of the previous cut. Every map is drawn
//      in one MapFrame (apl_set.h): for a beam, one that turns the seeds' flux-weighted mean direction
//      into the middle of a wedge of the equal-area map, so that the beam is not read across the map's
//      kinks; otherwise the photometric frame (kMinMapFrameResultant).
//   4. Assignment: every ray of the file goes to the nearest APL centre of the finest level, and to that
//      APL's ancestors in the coarser levels, so a parent's map is exactly the sum of its children's and
//      the flux of every level is the rayset's flux. (Assigning each level by its own nearest centre
//      would break that: a ray could fall to an APL whose parent is not the APL it fell to one level up.)
//   5. Maps: each ray adds its flux, as intensity flux / texel solid angle, to its APL's map at its
//      direction (the ray is "moved" to the APL, keeping its direction). Sums are kept in 64-bit fixed
//      point, so they do not depend on the order rays arrive in, and converted to float at the end.
//   6. With place_at_convergence, each APL then moves to the least-squares point of its own rays' lines
//      (along directions the map cannot resolve, its parent's coordinate: a truncated solve; see the
//      code), which minimises the flux-weighted squared shift across each ray that step 5 implies.
//
//   7. With place_at_convergence, when every ray's line passes through one of a few of those positions
//      (point sources behind apertures), the set is rebuilt as one masked APL per source and cuts of a
//      tree over the sources (apl/point_sources.h): their borders as geometry.
//
// Map resolution per level (when not fixed by the caller): a histogram of m rays over T texels has a
// relative noise of about 1/√(m/T) per texel. A shading point sums every APL of the level, so in the mid
// and far field the noise that matters is that of all N rays over T texels, while near the luminaire one
// APL's own N/n rays dominate. The rule: R is the largest power of two with
// 2R² ≤ N / (rays_per_texel · n^apl_exponent), clamped to [min_resolution, max_resolution].
// apl_exponent = 1 is the per-APL budget, 0 the level's. Measured on the real TM-25 files (lumx eval,
// patch-averaged relative RMSE; `lumx build --resolution-exponent E FILE OUT`) the level's budget (0, the
// default) wins at d ≥ 1: on the 100 k-ray OSRAM LED the per-APL budget gives R = 4 at 512 APLs and 44 %
// error at every d, the geometric mean (0.5) R = 16 and 6.1 % at d = 1, the level's budget R = 64 and
// 3.1 %; on Cyl1M_Faberge, whose APLs share one small emitter, 23 % (R = 16) against 4.5 % (R = 64). The sparse per-APL maps
// this leaves near the luminaire are what the optional flux-exact smoothing (map_smoothing_rays) is for.
#pragma once

#include <lumx/apl/apl_set.h>
#include <lumx/apl/clustering.h>
#include <lumx/apl/point_sources.h>
#include <lumx/math/line_fit.h>
#include <lumx/rays/rayset.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

struct AplBuildOptions {
  std::vector<std::size_t> level_counts = {1, 8, 64, 256, 512};  ///< APLs per level, increasing
  std::size_t seed_rays = 250000;   ///< rays the tree is built from
  int cluster_window = 16;          ///< PLOC search radius
  int map_resolution = 0;           ///< fixed R for every level; 0 = by the rule above
  int min_resolution = 4, max_resolution = 128;
  double rays_per_texel = 8;        ///< the rule's target mean rays per texel
  /// The ray count the rule counts (0: the rays read). A set built from part of a rayset for the held-out
  /// fit counts the whole (half_rays_build_options), so that its maps get the whole set's resolutions.
  std::uint64_t resolution_rays = 0;
  double apl_exponent = 0;          ///< the rule's n^apl_exponent: 0 = the level's rays, 1 = one APL's
  std::size_t chunk_rays = 1 << 16; ///< rays per read
  unsigned threads = 1;             ///< threads for the assignment pass (results do not depend on it)
  /// Treat rays as lines (see build_apl_set, step 1b and 6): cluster them by the point of each line
  /// nearest the rayset's convergence point, and place each APL at its rays' least-squares convergence
  /// point, instead of clustering start points and placing APLs at their box centres (000 §4.3). On by
  /// default: a measured rayset's start points lie on the recording surface, not on the emitter.
  bool place_at_convergence = true;
  /// With place_at_convergence: step 1b's choice between clustering start points and the lines' points,
  /// by its tests (automatic) or forced, e.g. to chart what the tests decide (lumx build --cluster-by).
  enum class LineClustering { automatic, start_points, lines };
  LineClustering line_clustering = LineClustering::automatic;
  /// Flux-exact pull-push smoothing of each map (math/sphere_map_smoothing.h) with this many rays per texel
  /// as the threshold of a reliable texel; 0 = off. Needs power-of-two resolutions.
  double map_smoothing_rays = 0;
  /// Turn the maps so that the seeds' mean direction falls inside a wedge of the map (MapFrame, step 3);
  /// false keeps the photometric frame.
  bool orient_maps = true;
  /// Step 7 (with place_at_convergence): when every ray's line passes through one of a few points, the
  /// set of those point sources as masked APLs (apl/point_sources.h); map_smoothing_rays is then not used.
  PointSourceOptions point_sources;
  /// Called with the fraction done (0..1) and a phase name, at most a few hundred times.
  std::function<void(double, const char*)> progress;
};

struct AplBuildReport {
  std::uint64_t rays = 0, seeds = 0, zero_flux_rays = 0;
  std::size_t moved_to_convergence = 0;   ///< APLs placed at their rays' convergence point
  /// Step 1b: per level, the seeds' mean squared shift across the rays (m²) when clustered by start point
  /// and by the point of their line nearest the convergence point (each cluster's point from a truncated
  /// solve anchored on its own box centre); empty when not compared.
  std::vector<double> shift_by_start, shift_by_line;
  /// Step 1b: RMS distance of the seeds' lines from their convergence point / of their start points, and
  /// the same with the directions shuffled among the seeds (slide when the first ≤ 0.9 × the second).
  double line_convergence = 1, line_convergence_shuffled = 1;
  bool slid_to_convergence = false;       ///< step 1b chose the lines' points
  std::vector<int> map_resolution;        ///< per level
  std::vector<std::size_t> apl_count;     ///< per level (may be below the request for tiny raysets)
  double seconds_seed = 0, seconds_tree = 0, seconds_assign = 0;
  /// Step 7: the point sources found (0: none, the set is the clustered one) and, with none, why.
  std::size_t point_sources = 0;
  std::string point_source_note;
};

/// The mean resultant length |Σ flux·ω| / Σ flux from which the builder turns the maps (a beam): 0.9, a
/// cos^m lobe with m ≥ 8 ((m+1)/(m+2)). The kink a turned frame avoids costs a narrow lobe most
/// (noise-free at R 128, a cos^20 lobe on the pole is 1.46 % off against 0.54 % mid-wedge, a cos^50 lobe
/// 4.68 % against 1.37 %), while an emitter that lights a whole hemisphere (Lambertian: 2/3) has its
/// horizon on the map's equator in the photometric frame, between texels; turned, the horizon cuts
/// texels and the Lambertian disk's finest level went from 0.9–1.1 % to 1.6–1.8 % at d ≥ 0.5.
inline constexpr double kMinMapFrameResultant = 0.9;

/// The map resolution the rule gives for `rays` rays shared by `apls` APLs.
inline int map_resolution_for(double rays, double apls, const AplBuildOptions& o) {
  const double texels = rays / (std::max(1e-9, o.rays_per_texel) * std::pow(std::max(1.0, apls), o.apl_exponent));  // 2R² ≤ this
  int R = o.min_resolution;
  while (R * 2 <= o.max_resolution && 2.0 * (2.0 * R) * (2.0 * R) <= texels) R *= 2;
  return std::max(1, std::min(R, o.max_resolution));
}

/// The options for a set built from half of a rayset of `all_rays` rays (the held-out fit, apl/error.h) whose
/// maps get the resolutions the rule gives the whole rayset: the rule counts `all_rays` (resolution_rays), or,
/// when that count is unknown (0), half the rays per texel. The fit only ever coarsens the maps it is given,
/// so a half set built by the plain rule (one step coarser wherever halving the rays crosses a step: 112 000
/// rays give R 64, their 56 000 R 32) could never choose the resolution the shipped set is built at.
inline AplBuildOptions half_rays_build_options(AplBuildOptions o, std::uint64_t all_rays) {
  if (all_rays > 0)
    o.resolution_rays = all_rays;
  else
    o.rays_per_texel /= 2;
  return o;
}

/// Builds an APL set from every ray of `rays` (two passes: seeds, then assignment). Levels that would
/// repeat the previous level's APL count (fewer seeds than requested) are dropped. Throws
/// std::invalid_argument for bad options or a rayset without flux.
AplSet build_apl_set(RaySource& rays, const AplBuildOptions& options = {}, AplBuildReport* report = nullptr);

LUMX_NAMESPACE_END
