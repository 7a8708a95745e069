// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/apl/error_detail.h — the grading and fitting engine's private parts (apl/error.h, apl/map_fit.h): the
// evaluation points and their loop, a level's kept lookups, the centring's per-patch rules, the beam-mask
// geometry of the border allowance, and the fit's tuning constants. Included by src/ and the tests only.
#pragma once

#include <lumx/apl/error.h>
#include <lumx/apl/map_fit.h>
#include <lumx/math/detail/parallel_jobs.h>
#include <lumx/math/direction_mask.h>
#include <lumx/rays/holdout.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

LUMX_NAMESPACE_BEGIN

namespace detail {
/// σ and the halves' σ of a sphere from its patches (gather_reference, and again after centre_patch
/// scales variances).
inline void refresh_noise_floors(SphereReference& sr) {
  double sum = 0, var = 0;
  for (std::size_t p = 0; p < sr.irradiance.size(); ++p) sum += sr.irradiance[p], var += sr.variance[p];
  const double n = double(sr.irradiance.size());
  sr.noise_floor = sum > 0 ? std::sqrt(var / n) / (sum / n) : NAN;
  if (sr.half_even.size() == sr.irradiance.size() && sr.half_odd.size() == sr.irradiance.size())
    sr.split_noise_floor = noise_floor(sr.half_even, sr.half_odd);
}
}  // namespace detail

namespace detail {

/// The evaluation points of every sphere for k × k points per patch, in float as irradiance() takes them:
/// point i = s·P + e (P = N·k²) is at the centre + ρ_s·dirs[e], with normal −dirs[e] (facing the centre).
struct EvaluationPoints {
  std::vector<glm::vec3> x, normal;  ///< per point; per direction e
  std::size_t per_sphere = 0;        ///< P
  EvaluationPoints(const MeasurementSpheres& ms, int k) {
    const std::vector<glm::dvec3> dirs = ms.evaluation_directions(k);
    per_sphere = dirs.size();
    x.resize(ms.sphere_count() * dirs.size());
    normal.resize(dirs.size());
    for (std::size_t e = 0; e < dirs.size(); ++e) normal[e] = glm::vec3(-dirs[e]);
    for (std::size_t s = 0; s < ms.sphere_count(); ++s)
      for (std::size_t e = 0; e < dirs.size(); ++e)
        x[s * dirs.size() + e] = glm::vec3(ms.centre() + ms.radius(s) * dirs[e]);
  }
  const glm::vec3& normal_of(std::size_t i) const { return normal[i % per_sphere]; }
};

/// Evaluates `point_irradiance(i, x, n, clamped)` (a scalar at point i, x, with normal n; `clamped` counts
/// clamped distances, null in the timing repeats; called from several threads at once unless o.threads is
/// 1) at every evaluation point of every sphere (EvaluationPoints), averages the subsamples per patch,
/// compares, and times the loop on one thread.
template <class PointIrradiance>
void evaluate_rows(const ReferenceIrradiance& ref, const AplErrorOptions& o, LevelErrors& row,
                   PointIrradiance&& point_irradiance) {
  const MeasurementSpheres& ms = ref.spheres;
  const std::size_t ns = ms.sphere_count(), np = ms.patch_count();
  row.subsamples = ms.subsamples_for(row.map_resolution, row.apls);
  const std::size_t k2 = std::size_t(row.subsamples) * std::size_t(row.subsamples);
  // Computed before the clock starts.
  const EvaluationPoints points(ms, row.subsamples);
  const std::vector<glm::vec3>& xs = points.x;
  std::vector<double> values(xs.size());
  using Clock = std::chrono::steady_clock;
  double seconds = 0;
  std::size_t timed = 0, clamped = 0;  // point evaluations timed; clamped distances
  if (parallel_threads(xs.size(), o.threads) == 1) {
    const auto t0 = Clock::now();
    for (std::size_t i = 0; i < xs.size(); ++i) values[i] = point_irradiance(i, xs[i], points.normal_of(i), &clamped);
    seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    timed = xs.size();
  } else {
    // Contiguous ranges of points, each with its own count of clamped distances.
    const std::size_t jobs = std::min<std::size_t>(xs.size(), 64);
    std::vector<std::size_t> clamped_in(jobs, 0);
    parallel_jobs(jobs, o.threads, [&](std::size_t j) {
      for (std::size_t i = xs.size() * j / jobs; i < xs.size() * (j + 1) / jobs; ++i)
        values[i] = point_irradiance(i, xs[i], points.normal_of(i), &clamped_in[j]);
    });
    for (std::size_t c : clamped_in) clamped += c;
  }
  // Timed (further) on one thread until min_timing_seconds have passed: batches of 64 points taken with a
  // stride prime to their count, so that every sphere is sampled whatever the batches' number.
  const std::size_t n = xs.size();
  std::size_t stride = n > 0 ? 7919 % n : 1;
  if (n > 0 && std::gcd(stride, n) != 1) stride = 1;
  std::size_t next = 0;
  volatile double sink = 0;
  while (seconds < o.min_timing_seconds && n > 0 && timed < 100000 * n) {
    const auto t1 = Clock::now();
    double s = 0;
    for (int b = 0; b < 64; ++b, next = (next + stride) % n)
      s += point_irradiance(next, xs[next], points.normal_of(next), nullptr);
    sink = sink + s;
    seconds += std::chrono::duration<double>(Clock::now() - t1).count();
    timed += 64;
  }
  row.clamped = clamped;
  row.ns_per_evaluation = timed == 0 ? NAN : 1e9 * seconds / double(timed);
  row.irradiance.assign(ns, std::vector<double>(np, 0.0));
  row.errors.resize(ns);
  for (std::size_t s = 0; s < ns; ++s) {
    for (std::size_t p = 0; p < np; ++p) {
      double sum = 0;
      for (std::size_t j = 0; j < k2; ++j) sum += values[s * points.per_sphere + p * k2 + j];
      row.irradiance[s][p] = sum / double(k2);
    }
    row.errors[s] =
        compare_irradiance(ref.sphere[s].irradiance, row.irradiance[s], ref.sphere[s].variance, &ref.sphere[s].border);
  }
}

}  // namespace detail

namespace detail {
/// The luminance of irradiance() from level k at x (normal n), its clamped distances added to `clamped`:
/// what evaluate_level grades at a point, and the lookups at points they do not hold.
inline double level_luminance_at(const AplSet& set, std::size_t k, const glm::vec3& x, const glm::vec3& n,
                                 const IrradianceOptions& options, std::size_t* clamped) {
  const IrradianceResult r = irradiance(set, k, x, n, options);
  if (clamped) *clamped += r.clamped;
  return luminance_of(set.channels, r.irradiance);
}
}  // namespace detail

namespace detail {
/// Everything irradiance() computes for a level at the evaluation points of a reference before it reads a
/// texel (apl_geometry: which APLs light each point, their footprints as offsets into the maps, their
/// weights), kept so that levels differing from it only in their maps' values (the fit's candidates at
/// one resolution: one level's maps downsampled, then smoothed in turn) are evaluated by the blends
/// alone, to the same bits as evaluate_level. Memory: 20 bytes per point and APL (the fit's 12 288 points,
/// R 32 patches on six spheres, × 512 APLs: 126 MB). Under a memory budget, the lookups of as many points
/// as it holds are kept (the first ones, in evaluation order), and the other points are evaluated as
/// evaluate_level does: the same bits either way.
class LevelLookups {
 public:
  /// The bytes LevelLookups(set, k, ref, o) would hold for every point.
  static double bytes_for(const AplSet& set, std::size_t k, const ReferenceIrradiance& ref) {
    const AplLevel& level = set.levels.at(k);
    const double q = double(ref.spheres.subsamples_for(level.map_resolution, level.size()));
    const double points = double(ref.spheres.sphere_count()) * double(ref.spheres.patch_count()) * q * q;
    return points * bytes_per_point(level.size());
  }

  /// The lookups of level k of `set` at the evaluation points of `ref`, on o.threads threads: of every
  /// point, or of as many of the first points as `max_bytes` holds (bytes_for: at most that much).
  LevelLookups(const AplSet& set, std::size_t k, const ReferenceIrradiance& ref, const AplErrorOptions& o,
               double max_bytes = INFINITY) {
    const AplLevel& level = set.levels.at(k);
    // The lookups read plain maps; a masked level is graded by evaluate_level (fit_map_resolutions).
    if (level.has_masks()) throw std::invalid_argument("LevelLookups: level " + std::to_string(k) + " has masked APLs");
    apls_ = level.size();
    resolution_ = level.map_resolution;
    to_map_ = level.frame.to_map;
    turned_ = !level.frame.is_identity();
    for (const Apl& a : level.apls) {
      positions_.push_back(a.position);
      channels_.push_back(a.map.channels());
    }
    subsamples_ = ref.spheres.subsamples_for(level.map_resolution, apls_);
    const EvaluationPoints points(ref.spheres, subsamples_);
    points_ = points.x;
    const double held = std::floor(std::max(0.0, max_bytes) / bytes_per_point(apls_));
    const std::size_t n = held < double(points.x.size()) ? std::size_t(held) : points.x.size();
    entries_.resize(n * apls_);
    count_.assign(n, 0);
    clamped_.assign(n, 0);
    min_r_ = float(effective_min_distance(set, o.irradiance));
    ignore_normal_ = o.irradiance.ignore_normal;
    const std::size_t jobs = std::min<std::size_t>(n, 64);
    parallel_jobs(jobs, o.threads, [&](std::size_t j) {
      for (std::size_t i = n * j / jobs; i < n * (j + 1) / jobs; ++i) {
        Entry* out = entries_.data() + i * apls_;
        std::size_t count = 0, clamped = 0;
        for (std::size_t a = 0; a < apls_; ++a) {
          glm::vec3 w;
          float cosine, r2;
          if (!apl_geometry(level.apls[a].position, points.x[i], points.normal_of(i), min_r_, ignore_normal_, w, cosine,
                            r2, clamped))
            continue;
          const SphereMap::Footprint f = level.apls[a].map.footprint(turned_ ? to_map_ * w : w);
          Entry& e = out[count++];
          e.apl = std::uint32_t(a);
          // A footprint inside the square: texel (x0, y0) of the map and its right and lower neighbours;
          // across a seam (the squares' edges, whose neighbours are elsewhere) it is taken again.
          const float* p = f.texel[0];
          const std::ptrdiff_t C = level.apls[a].map.channels(), row = std::ptrdiff_t(level.apls[a].map.width()) * C;
          const bool inside = f.texel[1] - p == C && f.texel[2] - p == row && f.texel[3] - p == row + C;
          e.texel = inside ? std::uint32_t(p - level.apls[a].map.data()) : kSeam;
          e.tx = f.tx;
          e.ty = f.ty;
          e.weight = cosine * 1.0f / r2;  // irradiance()'s weight with visibility 1, to the bit
        }
        count_[i] = std::uint32_t(count);
        clamped_[i] = std::uint32_t(clamped);
      }
    });
  }

  /// The points whose lookups are kept (the first ones in evaluation order); of all of them when equal to
  /// the number of evaluation points.
  std::size_t points_looked_up() const { return count_.size(); }

  /// Level k of `set` against `ref` (as evaluate_level, the same bits). Throws std::invalid_argument when
  /// the level is not laid out as the one the lookups were taken from (its APLs, their positions, maps'
  /// resolutions and channels, or its frame, compared bit for bit), the irradiance options or the set's
  /// bounds give another clamp distance or normal rule, or `ref` has other evaluation points. Its
  /// ns_per_evaluation, when timed, is of the blends alone.
  LevelErrors evaluate(const AplSet& set, std::size_t k, const ReferenceIrradiance& ref,
                       const AplErrorOptions& o) const {
    const AplLevel& level = set.levels.at(k);
    check(set, level, ref, o);
    LevelErrors row;
    row.level = int(k);
    row.apls = level.size();
    row.map_resolution = level.map_resolution;
    row.bytes = level.map_bytes();
    evaluate_rows(ref, o, row, [&](std::size_t i, const glm::vec3& x, const glm::vec3& n, std::size_t* clamped) {
      if (i >= count_.size()) return level_luminance_at(set, k, x, n, o.irradiance, clamped);  // beyond the budget
      if (clamped) *clamped += clamped_[i];
      return luminance_of(set.channels, glm::dvec3(sum_at(level, i)));
    });
    return row;
  }

 private:
  static constexpr std::uint32_t kSeam = 0xffffffffu;
  struct Entry {
    std::uint32_t apl;
    std::uint32_t texel;  ///< offset of SphereMap::Footprint::texel[0] in the map's values; kSeam: across a seam
    float tx, ty, weight;
  };
  static double bytes_per_point(std::size_t apls) {
    return double(sizeof(Entry)) * double(apls) + sizeof(glm::vec3) + 2 * sizeof(std::uint32_t);
  }
  // The level's layout: what the lookups depend on besides the maps' values.
  std::size_t apls_ = 0;
  int resolution_ = 0;
  float min_r_ = 0;             ///< the clamp distance (effective_min_distance) the weights were taken with
  bool ignore_normal_ = false;  ///< and IrradianceOptions::ignore_normal
  glm::mat3 to_map_{1.0f};
  bool turned_ = false;  ///< to_map_ is not the identity (most sets: no 3×3 multiply per lookup)
  std::vector<glm::vec3> positions_;
  std::vector<int> channels_;
  std::vector<glm::vec3> points_;  ///< the evaluation points they were taken at
  int subsamples_ = 1;
  std::vector<Entry> entries_;                  ///< point i's at [i·apls, i·apls + count_[i])
  std::vector<std::uint32_t> count_, clamped_;  ///< per point looked up: the first count_.size() points

  template <class T>
  static bool same_bits(const T& a, const T& b) {
    return std::memcmp(&a, &b, sizeof(T)) == 0;
  }

  void check(const AplSet& set, const AplLevel& level, const ReferenceIrradiance& ref, const AplErrorOptions& o) const {
    bool same = level.size() == apls_ && level.map_resolution == resolution_ &&
                same_bits(level.frame.to_map, to_map_) &&
                same_bits(float(effective_min_distance(set, o.irradiance)), min_r_) &&
                o.irradiance.ignore_normal == ignore_normal_ &&
                ref.spheres.subsamples_for(level.map_resolution, apls_) == subsamples_;
    if (same) {
      const EvaluationPoints points(ref.spheres, subsamples_);
      same = points.x.size() == points_.size() &&
             std::memcmp(points.x.data(), points_.data(), points_.size() * sizeof(glm::vec3)) == 0;
    }
    for (std::size_t a = 0; same && a < apls_; ++a)
      same = same_bits(level.apls[a].position, positions_[a]) && level.apls[a].map.resolution() == resolution_ &&
             level.apls[a].map.channels() == channels_[a];
    if (!same)
      throw std::invalid_argument(
          "LevelLookups: the level, its irradiance options or the reference are not the ones they were taken for");
  }

  /// irradiance()'s sum at point i: the blends in APL order, their texels prefetched 32 APLs ahead.
  glm::vec3 sum_at(const AplLevel& level, std::size_t i) const {
    constexpr std::size_t kChunk = 32;
    const Entry* e = entries_.data() + i * apls_;
    const std::size_t n = count_[i];
    glm::vec3 sum(0.0f);
    SphereMap::Footprint f[kChunk];
    for (std::size_t begin = 0; begin < n; begin += kChunk) {
      const std::size_t end = std::min(n, begin + kChunk);
      for (std::size_t j = begin; j < end; ++j) {
        const SphereMap& map = level.apls[e[j].apl].map;
        SphereMap::Footprint& fj = f[j - begin];
        if (e[j].texel != kSeam) {
          const float* p = map.data() + e[j].texel;
          const std::ptrdiff_t C = map.channels(), row = std::ptrdiff_t(map.width()) * C;
          fj.texel[0] = p;
          fj.texel[1] = p + C;
          fj.texel[2] = p + row;
          fj.texel[3] = p + row + C;
          fj.tx = e[j].tx;
          fj.ty = e[j].ty;
        } else {
          float r, r2;
          const glm::vec3 w = apl_direction(positions_[e[j].apl], points_[i], r, r2);
          fj = map.footprint(turned_ ? to_map_ * w : w);  // check(): the level's frame is to_map_
        }
        for (const float* t : fj.texel) __builtin_prefetch(t);
      }
      for (std::size_t j = begin; j < end; ++j) sum += level.apls[e[j].apl].map.blend(f[j - begin]) * e[j].weight;
    }
    return sum;
  }
};
}  // namespace detail

/// Maps per thread at least when a level's maps are smoothed in parallel, so that a level of a few APLs
/// is not split over threads that cost more to start than its maps do to smooth.
inline constexpr std::size_t kMapsPerThread = 8;

/// The kernels the fit tries at resolution R: σ = 0.75 and 1.5 texel widths (a texel is √(4π/2R²) rad
/// across), at R 32 to 128 only: coarser maps keep their bilinear interpolation error whatever their
/// noise (apl_sets.md), and finer ones would hold tens of millions of weights (SphereMapKernel::kMaxResolution).
std::vector<double> fit_kernel_kappas(int R);

/// A kernel the fit tries: κ (1/rad²) and how it smooths.
struct FitKernel {
  double kappa = 0;
  KernelMode mode = KernelMode::plain;
};

/// The kernels the fit tries at resolution R: fit_kernel_kappas(R) as they are; sharpened
/// (SphereMapKernel::sharpening_gain: bias O(κ⁻²), so a spot's lobe keeps its peak) at σ = 0.75, 1.5 and 3
/// texel widths; and local linear (SphereMapKernel::local_linear_gain: no leak across the border of the
/// rays' support, such as a Lambertian emitter's horizon, where the others put most of their error) at
/// σ = 1.5 and 3 texel widths; extrapolated (SphereMapKernel::extrapolated_gain: two orders of blur
/// cancelled where sharpening cancels one, for a lobe a wide kernel would flatten even sharpened) at σ = 1.5
/// and 3 texel widths; and two-scale (SphereMapKernel::two_scale_gain: each map at σ against its own few
/// rays, the level's shape from its sum sharpened at σ/2; fit_map_resolutions tries it at the level's
/// built resolution only, and widens it only while that helps) at σ = 1.5, 3 and 4.5 texel widths (4.5: a
/// cos^20 spot's maps from 1 M rays, about 2 000 rays each, want σ 5° while its sum affords 2.5°; over
/// four seeds its finest level is 1.62–3.18 % at d ≥ 1 with that candidate and 1.87–3.21 % without,
/// apl_sets.md); and spectral (SphereMapKernel::spectral_gain: as two-scale, the level's shape from its
/// sum's harmonic expansion shrunk degree by degree, which no kernel's width can match on a narrow lobe: a
/// cos^20 spot's finest level 2.53/3.23 → 1.98/2.09 % at d = 5/10) at the same widths and on the same terms,
/// one width on a one-APL level; and spectral per order (harmonic_estimate_per_order: the expansion about the
/// sum's mean direction, shrunk per degree and order, which removes the noise a round beam's empty orders
/// hold and so goes below the bound of every per-degree weight, but loses power a beam that is not round
/// holds at orders it cannot see) at the same widths, only where the sum is a beam (mean resultant length
/// at least kMinPerOrderResultant). R 128's kernels are for
/// narrow lobes: a spot read through R 64 texels keeps their blur (a cos^20 spot's far field 4 % off,
/// noise-free), and R 128 with a kernel as wide as R 64's averages the same noise through finer texels
/// (apl_sets.md).
std::vector<FitKernel> fit_kernels(int R);

/// The mean resultant length from which the fit tries spectral per order: a beam, as the builder turns a
/// set's maps from (kMinMapFrameResultant, apl/builder.h; a cos^m lobe with m ≥ 8). A broad emitter's
/// mean direction is no axis of symmetry (a Lambertian panel's rectangle is not round about its normal).
inline constexpr double kMinPerOrderResultant = 0.9;

/// The map bytes (in memory) above which fit_map_resolutions trades a level's finer maps for coarser ones
/// the held-out rays cannot tell apart from them (the one-standard-error rule): 1 MiB, an eighth of the
/// 8 MiB a 512-APL bundle from 1 M rays is given.
inline constexpr double kParsimonyBytes = 1024.0 * 1024.0;

/// The memory fit_map_resolutions may keep a level's smoothed maps in, to reuse them across the modes of one
/// kernel width: 128 MiB, two widths of a 512-APL level at R 128 (a 1 M-ray LED strip: 43.1 → 36.4 s,
/// 914 → 1 046 MB peak resident; with three, 37.1 s and 1 111 MB).
inline constexpr double kAppliedBytes = 128.0 * 1024.0 * 1024.0;

/// The memory fit_map_resolutions may keep the lookups of one level at one resolution in
/// (detail::LevelLookups), so that its candidates there are graded by their blends alone: 128 MiB, a
/// 512-APL level at the 12 288 points of R 32 patches (the fit's for up to 10⁶ rays: fit_patch_resolution).
/// A level with more points and APLs keeps the lookups of as many points as this holds (10⁷ rays: the
/// 49 152 points of R 64 patches, a quarter of them for 512 APLs, half for 256).
inline constexpr double kLookupBytes = 128.0 * 1024.0 * 1024.0;

/// The error beyond which the kernel guard of fit_map_resolutions does not protect a distance (relative RMSE).
inline constexpr double kUnusableError = 0.25;

/// The level of `set` with the most masked APLs (a point-source set's finest: one per source; the first
/// of equals), or null when none has a mask.
const AplLevel* most_masked_level(const AplSet& set);

namespace detail {
/// Two masked APLs stand for one point source when they lie within 1/1000 of the bounding radius of each
/// other (PointSourceOptions::tolerance): pilot_with_known_borders and border_allowance match by it.
/// The masked APL of `level` that stands for the same source as `a`, or null.
inline const Apl* same_source(const Apl& a, const AplLevel& level, double bounding_radius) {
  const Apl* match = nullptr;
  for (const Apl& b : level.apls)
    if (b.mask && (!match || glm::length(b.position - a.position) < glm::length(match->position - a.position)))
      match = &b;
  return match && double(glm::length(match->position - a.position)) <= 1e-3 * bounding_radius ? match : nullptr;
}
}  // namespace detail

namespace detail {
/// A cap of a beam mask with its hull's vertices as unit directions (read once per cap).
struct CapVertices {
  const DirectionMask::Cap* cap = nullptr;
  std::vector<glm::dvec3> vertex;
};
inline std::vector<CapVertices> cap_vertices(const DirectionMask& mask) {
  std::vector<CapVertices> out;
  for (const DirectionMask::Cap& c : mask.caps()) {
    CapVertices v;
    v.cap = &c;
    for (const glm::dvec2& q : c.hull) v.vertex.push_back(glm::normalize(c.axis + q.x * c.e1 + q.y * c.e2));
    out.push_back(std::move(v));
  }
  return out;
}

/// The solid angle (sr) the hull of a cap would gain with direction w: the fan of triangles from w's
/// chart point q to the edges q sees. The gnomonic chart maps great circles to lines, so each is the
/// spherical triangle (w, a, b) of the vertices' directions, whose solid angle is exact (Van Oosterom and
/// Strackee 1983: tan(Ω/2) = |a·(b × c)| / (1 + a·b + b·c + c·a)). Infinite when w is not in the cap's
/// chart half-sphere.
inline double cap_gain(const CapVertices& cv, const glm::dvec3& w) {
  const DirectionMask::Cap& c = *cv.cap;
  const double z = glm::dot(w, c.axis);
  if (!(z > 0)) return INFINITY;
  const glm::dvec2 q(glm::dot(w, c.e1) / z, glm::dot(w, c.e2) / z);
  double omega = 0;
  const std::size_t n = c.hull.size();
  for (std::size_t k = 0; k < n; ++k) {
    const glm::dvec2 a = c.hull[k], b = c.hull[(k + 1) % n];
    const double cross = (b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x);
    if (cross >= 0) continue;  // the edge does not face q
    const glm::dvec3 &A = cv.vertex[k], &B = cv.vertex[(k + 1) % n];
    omega +=
        2 * std::atan2(std::abs(glm::dot(w, glm::cross(A, B))), 1 + glm::dot(w, A) + glm::dot(A, B) + glm::dot(B, w));
  }
  return omega;
}

/// Whether w lies within `margin` rad of cap c's reach: beyond it, a hull of rays would have to grow by
/// a fan of at least that width to hold w (border_allowance takes such a direction as dark).
inline bool cap_near(const DirectionMask::Cap& c, const glm::dvec3& w, double margin) {
  return glm::dot(w, c.axis) >= std::cos(std::min(c.reach + margin, 0.5 * kPi));
}

/// The hull vertex nearest w among the caps within `margin` of it (cap_near); w itself when none is.
inline glm::dvec3 nearest_hull_vertex(const std::vector<CapVertices>& caps, const glm::dvec3& w, double margin) {
  glm::dvec3 best = w;
  double best_cos = -2;
  for (const CapVertices& cv : caps)
    if (cap_near(*cv.cap, w, margin))
      for (const glm::dvec3& d : cv.vertex) {
        const double cs = glm::dot(d, w);
        if (cs > best_cos) best_cos = cs, best = d;
      }
  return best;
}

}  // namespace detail

namespace detail {
/// Points per patch side a masked pilot is read at on spheres `ms` (centred_reference, and the quarters
/// of checked_centred_reference): `most`, fewer while the spheres' patches × k² exceed 2^22 (4 194 304)
/// points, at least 2. Its borders need many: the lit share of a
/// patch to 1/k².
inline int masked_pilot_subsamples(const MeasurementSpheres& ms, int most) {
  const double patches =
      double(ms.sphere_count()) * 2.0 * double(ms.patch_resolution()) * double(ms.patch_resolution());
  int k = most;
  while (k > 2 && patches * double(k) * double(k) > double(1u << 22)) --k;
  return k;
}
/// Beyond this ratio P(c) / P̄ a masked patch is moved by adding instead: a centre lit where the pilot
/// lights under 1/16 of its patch (a sliver's tip) would scale the patch's noise by more than 16.
inline constexpr double kMaxCentringScale = 16;
/// Moves patch p of `sr` from its mean to its centre by a pilot's value there (`centre`) and its mean over
/// the patch (`mean`). Plain pilots add the difference, E_c = max(0, E + P(c) − P̄) (centred_reference).
/// A masked pilot's shape within a patch is a border times a smooth intensity, so it scales instead:
/// E_c = E · P(c) / P̄, with the variance × (P(c) / P̄)² and the halves scaled alike. A border patch
/// lit over a fraction f by the pilot and at its centre is moved by about E·(1/f − 1), which the
/// pilot's own intensity noise (an R 8 map from a quarter of the rays, a few % a texel) no longer
/// enters: added, its intensity error times (1 − f) went into every border patch, and the box's masked
/// level, 3.0 % off at points at d = 1, was estimated at 5.1 % in a trial (scaled: 7.7 %, unresolved,
/// HonestErrorSuite/4). A patch the pilot leaves dark throughout keeps its mean;
/// one whose ratio exceeds kMaxCentringScale is moved by adding.
/// The factor a masked pilot scales a patch by, or −1 where it adds (beyond kMaxCentringScale) or leaves
/// the patch (dark throughout in the pilot: mean 0).
inline double masked_scale(double centre, double mean) {
  return mean > 0 && centre / mean <= kMaxCentringScale ? centre / mean : -1;
}
/// Patch value e moved to its centre (centre_patch), without moving it.
inline double centred_value(double e, double centre, double mean, bool masked) {
  if (masked) {
    if (!(mean > 0)) return e;  // dark throughout in the pilot: the mean stays
    const double g = masked_scale(centre, mean);
    if (g >= 0) return e * g;
  }
  return std::max(0.0, e + centre - mean);
}
inline void centre_patch(SphereReference& sr, std::size_t p, double centre, double mean, bool masked) {
  const double g = masked ? masked_scale(centre, mean) : -1;
  if (g >= 0) {
    sr.irradiance[p] *= g;
    sr.variance[p] *= g * g;
    if (p < sr.half_even.size()) sr.half_even[p] *= g;
    if (p < sr.half_odd.size()) sr.half_odd[p] *= g;
  } else {
    sr.irradiance[p] = centred_value(sr.irradiance[p], centre, mean, masked);
  }
}

}  // namespace detail

LUMX_NAMESPACE_END
