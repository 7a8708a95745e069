// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// build_point_source_set (apl/point_sources.h): the five steps of the header's module comment.
#include <lumx/apl/point_sources.h>

#include <lumx/apl/apl_set.h>
#include <lumx/apl/clustering.h>
#include <lumx/math/detail/parallel_jobs.h>
#include <lumx/math/direction_mask.h>
#include <lumx/math/line_fit.h>
#include <lumx/math/sphere_map.h>
#include <lumx/rays/rayset.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace {

// m: the distance from c to the line through o along unit w, and whether c lies behind o (or within
// `tolerance` ahead of it): a ray leaves its source, so the source is behind its start.
bool line_passes(const glm::dvec3& c, const glm::dvec3& o, const glm::dvec3& w, double tolerance, double& distance) {
  const glm::dvec3 v = c - o;
  const double along = glm::dot(v, w);
  distance = glm::length(v - along * w);
  return along <= tolerance && distance <= tolerance;
}

// Reads every ray of `rays` in chunks, calling prepare(n) for a chunk of n rays, per(job, i, chunk) on
// up to `threads` threads for each of its rays (job: one of kRayJobs, each a range of the chunk; i: in
// the chunk), then after(chunk, first_index) on this thread, which returns whether to go on.
constexpr std::size_t kRayJobs = 16;
template <class Prepare, class PerRay, class After>
void for_each_ray_chunk(RaySource& rays, std::size_t chunk_rays, unsigned threads, Prepare&& prepare, PerRay&& per,
                        After&& after) {
  RayChunk chunk;
  std::uint64_t first = 0;
  rays.rewind();
  while (rays.next(chunk, chunk_rays)) {
    const std::size_t n = chunk.size(), jobs = std::min<std::size_t>(n, kRayJobs);
    prepare(n);
    detail::parallel_jobs(jobs, threads, [&](std::size_t j) {
      for (std::size_t i = n * j / jobs; i < n * (j + 1) / jobs; ++i) per(j, i, chunk);
    });
    if (!after(chunk, first)) return;
    first += n;
  }
}

}  // namespace

std::optional<AplSet> build_point_source_set(RaySource& rays, const std::vector<glm::vec3>& candidates,
                                             const BoundingSphere& bounds, const std::vector<std::size_t>& level_counts,
                                             const std::function<int(std::size_t)>& resolution, const MapFrame& frame,
                                             const PointSourceOptions& options, std::size_t chunk_rays, unsigned threads,
                                             PointSourceReport* report) {
  PointSourceReport local;
  PointSourceReport& rep = report ? *report : local;
  rep = PointSourceReport{};
  auto none = [&](const std::string& why) -> std::optional<AplSet> {
    rep.why = why;
    return std::nullopt;
  };
  if (!options.enabled) return none("not looked for");
  if (level_counts.empty() || chunk_rays == 0) return none("no level requested");
  const double eps = options.tolerance * bounds.radius;
  if (!(eps > 0) || !std::isfinite(eps)) return none("the bounding sphere has no size");
  // The candidates, each within 2·eps of an earlier one dropped (many APLs sit on one source).
  std::vector<glm::dvec3> points;
  for (const glm::vec3& c : candidates) {
    if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) continue;
    bool seen = false;
    for (const glm::dvec3& q : points) seen = seen || glm::length(q - glm::dvec3(c)) <= 2 * eps;
    if (!seen) points.emplace_back(c);
  }
  const std::size_t P = points.size();
  if (P == 0) return none("no candidate point");

  // ---- 1. the lines through each candidate; stops at the first ray (with flux) through none
  // Counts per job (integers: their sum does not depend on the order), so memory is kRayJobs × P counts
  // whatever the chunk; the first ray through none stops the pass.
  std::vector<std::uint64_t> through(P, 0), job_through(kRayJobs * P, 0);
  std::vector<std::uint8_t> passes_none;
  std::uint64_t missing = UINT64_MAX;
  // Small chunks: an extended emitter's first ray through no candidate ends the pass after 4 096 rays.
  for_each_ray_chunk(
      rays, std::min<std::size_t>(chunk_rays, 4096), threads,
      [&](std::size_t n) {
        if (passes_none.size() < n) passes_none.resize(n);
      },
      [&](std::size_t job, std::size_t i, const RayChunk& c) {
        passes_none[i] = 0;
        if (!(c.flux[i] > 0)) return;  // a ray without flux needs no source
        const glm::dvec3 o(c.position(i)), w(c.direction(i));
        bool any = false;
        std::uint64_t* counts = job_through.data() + job * P;
        for (std::size_t p = 0; p < P; ++p) {
          double d;
          if (line_passes(points[p], o, w, eps, d)) ++counts[p], any = true;
        }
        passes_none[i] = !any;
      },
      [&](const RayChunk& c, std::uint64_t first) {
        for (std::size_t i = 0; i < c.size(); ++i)
          if (passes_none[i]) {
            missing = first + i;
            return false;
          }
        return true;
      });
  for (std::size_t j = 0; j < kRayJobs; ++j)
    for (std::size_t p = 0; p < P; ++p) through[p] += job_through[j * P + p];
  if (missing != UINT64_MAX)
    return none("ray " + std::to_string(missing) + "'s line passes none of the " + std::to_string(P) +
                " candidate points");
  // Most lines first (ties: the earlier candidate); a candidate within 4·eps of one kept is that source
  // seen off its centre (a point 1.5·eps from a source passes most of its lines within eps) and is dropped.
  std::vector<std::size_t> order(P);
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return through[a] > through[b]; });
  std::vector<glm::dvec3> sources;
  for (std::size_t p : order) {
    if (through[p] < options.min_rays) break;
    bool near = false;
    for (const glm::dvec3& q : sources) near = near || glm::length(q - points[p]) <= 4 * eps;
    if (!near) sources.push_back(points[p]);
  }
  if (sources.empty()) return none("no point has " + std::to_string(options.min_rays) + " lines through it");
  if (sources.size() > options.max_sources)
    return none(std::to_string(sources.size()) + " points have lines through them (at most " +
                std::to_string(options.max_sources) + ")");

  // ---- 2. every ray to the source its line passes nearest (the first of equals), its line, direction
  // and flux gathered per source, the flux binned at every level's map resolution. A point a few eps
  // from a source passes some of its lines too (those within eps/δ rad of its direction from the
  // source), so a point kept in step 1 can be the nearest of few lines or none: such points are dropped
  // and the rays gathered again, until every source is the nearest of min_rays lines.
  const auto counts_for = [&](std::size_t sources_found) {  // APLs per level: at most one per source
    std::vector<std::size_t> counts;
    for (std::size_t c : level_counts) {
      const std::size_t n = std::min(c, sources_found);
      if (counts.empty() || n > counts.back()) counts.push_back(n);
    }
    return counts;
  };
  constexpr std::uint32_t kNoSource = UINT32_MAX;
  std::vector<std::uint32_t> chunk_source;
  std::vector<LineFit> lines;
  std::vector<std::vector<glm::dvec3>> directions;
  std::vector<int> resolutions;                      // the levels' distinct map resolutions
  std::vector<std::vector<std::vector<double>>> binned;  // per source and resolution, Σ flux per texel
  const auto gather = [&] {
    const std::size_t n_src = sources.size();
    resolutions.clear();
    for (std::size_t c : counts_for(n_src))
      if (std::find(resolutions.begin(), resolutions.end(), resolution(c)) == resolutions.end())
        resolutions.push_back(resolution(c));
    lines.assign(n_src, LineFit{});
    directions.assign(n_src, {});
    binned.assign(n_src, std::vector<std::vector<double>>(resolutions.size()));
    for (auto& per_source : binned)
      for (std::size_t r = 0; r < resolutions.size(); ++r)
        per_source[r].assign(2 * std::size_t(resolutions[r]) * std::size_t(resolutions[r]), 0.0);
    for_each_ray_chunk(
        rays, chunk_rays, threads,
        [&](std::size_t n) {
          if (chunk_source.size() < n) chunk_source.resize(n);
        },
        [&](std::size_t, std::size_t i, const RayChunk& c) {
          chunk_source[i] = kNoSource;
          if (!(c.flux[i] > 0)) return;
          const glm::dvec3 o(c.position(i)), w(c.direction(i));
          double best = INFINITY;
          for (std::size_t q = 0; q < n_src; ++q) {
            double d;
            if (line_passes(sources[q], o, w, eps, d) && d < best) best = d, chunk_source[i] = std::uint32_t(q);
          }
        },
        [&](const RayChunk& c, std::uint64_t first) {  // in file order: the sums do not depend on threads
          for (std::size_t i = 0; i < c.size(); ++i) {
            if (!(c.flux[i] > 0)) continue;
            const std::uint32_t q = chunk_source[i];
            if (q == kNoSource) {
              missing = first + i;
              return false;
            }
            lines[q].add(c.position(i), c.direction(i), c.flux[i]);
            directions[q].push_back(glm::normalize(glm::dvec3(c.direction(i))));
            const glm::vec3 m = frame.map_direction(c.direction(i));
            for (std::size_t r = 0; r < resolutions.size(); ++r) {
              int x, y;
              sphere_map::texel_of(m, resolutions[r], x, y);
              binned[q][r][std::size_t(y) * 2 * std::size_t(resolutions[r]) + std::size_t(x)] += double(c.flux[i]);
            }
          }
          return true;
        });
  };
  while (true) {  // each round drops a point at least, so at most max_sources rounds
    gather();
    if (missing != UINT64_MAX)
      return none("ray " + std::to_string(missing) + "'s line passes none of the " + std::to_string(sources.size()) +
                  " sources");
    std::vector<glm::dvec3> kept;
    for (std::size_t q = 0; q < sources.size(); ++q)
      if (directions[q].size() >= options.min_rays) kept.push_back(sources[q]);
    if (kept.size() == sources.size()) break;
    if (kept.empty()) return none("no set of points is each the nearest of " + std::to_string(options.min_rays) + " lines");
    sources = std::move(kept);
  }
  const std::size_t S = sources.size();

  // ---- 3. each source at its rays' least-squares point (kept where that stays within eps), its mask
  std::vector<std::shared_ptr<const DirectionMask>> masks(S);
  for (std::size_t s = 0; s < S; ++s) {
    const glm::dvec3 x = lines[s].solve(sources[s], 1e-9);
    if (glm::length(x - sources[s]) <= eps) sources[s] = x;
    std::string why;
    std::optional<DirectionMask> m = DirectionMask::from_directions(directions[s], {}, &why);
    if (!m) return none("source " + std::to_string(s) + ": " + why);
    masks[s] = std::make_shared<const DirectionMask>(std::move(*m));
  }
  std::vector<std::vector<glm::dvec3>>().swap(directions);

  // ---- 4. levels: cuts of a tree over the sources, at most one APL per source
  const std::vector<std::size_t> counts = counts_for(S);
  std::vector<std::vector<std::uint32_t>> apl_of(counts.size(), std::vector<std::uint32_t>(S));  // per level, source → APL
  {
    std::vector<glm::vec3> pos;
    std::vector<float> flux;
    for (std::size_t s = 0; s < S; ++s) pos.emplace_back(sources[s]), flux.push_back(float(lines[s].weight));
    // A tree only where some level has fewer APLs than sources (one source needs none).
    const ClusterTree tree = counts.front() < S ? build_cluster_tree(pos, flux, ClusterOptions{}) : ClusterTree{};
    const std::vector<std::vector<int>> cuts = counts.front() < S ? cut_cluster_tree(tree, counts) : std::vector<std::vector<int>>{};
    for (std::size_t k = 0; k < counts.size(); ++k) {
      if (counts[k] == S) {  // one APL per source, in the sources' order
        for (std::size_t s = 0; s < S; ++s) apl_of[k][s] = std::uint32_t(s);
        continue;
      }
      if (k >= cuts.size() || cuts[k].size() != counts[k]) return none("the sources' tree gives no cut of " + std::to_string(counts[k]));
      for (std::size_t i = 0; i < cuts[k].size(); ++i) {
        std::vector<int> stack{cuts[k][i]};  // label the sources below the cut node
        while (!stack.empty()) {
          const int node = stack.back();
          stack.pop_back();
          if (tree.is_seed(node)) {
            apl_of[k][std::size_t(node)] = std::uint32_t(i);
          } else {
            stack.push_back(tree.left[std::size_t(node)]);
            stack.push_back(tree.right[std::size_t(node)]);
          }
        }
      }
    }
  }
  // ---- 5. each APL: its sources' binned flux as intensity (step 5 of the builder), its place, its mask
  AplSet set;
  set.bounds = bounds;
  double tests = 0;  // the masks' coverage work, against what a bundle reader accepts by default
  for (std::size_t k = 0; k < counts.size(); ++k) {
    AplLevel level;
    level.frame = frame;
    level.map_resolution = resolution(counts[k]);
    const int R = level.map_resolution;
    const std::size_t r = std::size_t(std::find(resolutions.begin(), resolutions.end(), R) - resolutions.begin());
    const double to_intensity = 1.0 / sphere_map::texel_solid_angle(R);
    level.apls.resize(counts[k]);
    std::vector<std::vector<std::size_t>> members(counts[k]);
    for (std::size_t s = 0; s < S; ++s) members[apl_of[k][s]].push_back(s);
    for (std::size_t a = 0; a < counts[k]; ++a) {
      Apl& apl = level.apls[a];
      const std::vector<std::size_t>& mine = members[a];
      if (mine.empty()) continue;  // check_apl_set reports it; a cut of the tree has none
      apl.parent = k == 0 ? -1 : int(apl_of[k - 1][mine.front()]);
      std::vector<double> sum(binned[mine.front()][r]);
      for (std::size_t j = 1; j < mine.size(); ++j)
        for (std::size_t t = 0; t < sum.size(); ++t) sum[t] += binned[mine[j]][r][t];
      apl.map = SphereMap(R, 1);
      double flux = 0;
      for (std::size_t t = 0; t < sum.size(); ++t) apl.map.values()[t] = float(sum[t] * to_intensity), flux += sum[t];
      apl.flux = glm::dvec3(flux);
      if (mine.size() == 1) {
        apl.position = glm::vec3(sources[mine.front()]);
        apl.mask = masks[mine.front()];
        const DirectionMask& m = *apl.mask;
        if (m.caps().size() > kMaxMaskCaps) return none("a source's mask has " + std::to_string(m.caps().size()) + " caps");
        for (const DirectionMask::Cap& c : m.caps())
          if (c.hull.size() > kMaxMaskHullVertices)
            return none("a source's mask has a hull of " + std::to_string(c.hull.size()) + " vertices");
        tests += m.coverage_tests(R, mask_coverage_subsamples(R)) + 2.0 * R * R;
        continue;
      }
      LineFit all;
      glm::dvec3 mean(0.0);
      for (std::size_t s : mine) all.add(lines[s]), mean += lines[s].weight * sources[s];
      mean = all.weight > 0 ? mean / all.weight : sources[mine.front()];
      const glm::dvec3 x = all.solve(mean, sphere_map::texel_solid_angle(R));
      apl.position = glm::vec3(glm::length(x - bounds.center) <= 1.001 * bounds.radius + 1e-9 ? x : mean);
    }
    set.levels.push_back(std::move(level));
  }
  if (tests > kMaxMaskTests)
    return none("the masks' coverage would take " + std::to_string(tests) + " tests (at most " +
                std::to_string(kMaxMaskTests) + ")");
  for (AplLevel& level : set.levels) refresh_coverages(level);
  rep.sources = S;
  return set;
}

LUMX_NAMESPACE_END
