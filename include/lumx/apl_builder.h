// lumx/apl_builder.h — raysets in, APL sets out (dissertation 000 §4.3, §4.6).
//
//   1. Seeds: `seed_rays` rays spread evenly through the file (every (N/S)-th ray with flux > 0; files
//      are often sorted by position or emitter, so "the first S" would seed one corner of the source).
//   2. Tree: agglomerative clustering of the seeds' start points with eq. 4.1 (apl_clustering.h).
//   3. Levels: cuts of the tree with 1, 8, 64, ... clusters; an APL sits at the centre of its seeds'
//      bounding box (000 §4.3); parents are the enclosing clusters of the previous cut. Optionally
//      (AplBuildOptions::place_at_convergence), after step 4 an APL whose rays' lines meet near one point
//      inside the luminaire moves there (least squares): a rayset recorded on a surface around a smaller
//      emitter radiates from that emitter, not from the recording surface (Cyl1M_Faberge: 8 APLs on
//      its caps are 13 % off at d = 10, one APL at the centre 2.5 %).
//   4. Assignment: every ray of the file goes to the nearest APL centre of the finest level, and to that
//      APL's ancestors in the coarser levels, so a parent's map is exactly the sum of its children's and
//      the flux of every level is the rayset's flux. (Assigning each level by its own nearest centre
//      would break that: a ray could fall to an APL whose parent is not the APL it fell to one level up.)
//   5. Maps: each ray adds its flux, as intensity flux / texel solid angle, to its APL's map at its
//      direction (the ray is "moved" to the APL, keeping its direction). Sums are kept in 64-bit fixed
//      point, so they do not depend on the order rays arrive in, and converted to float at the end.
//
// Map resolution per level (when not fixed by the caller): a histogram of m rays over T texels has a
// relative noise of about 1/√(m/T) per texel. Near the luminaire one APL dominates a shading point, and
// the noise that matters is one map's; far away all n APLs of the level add up with independent noise,
// and the sum's noise is that of all N rays over T texels. The rule takes the geometric mean of the two
// budgets: R is the largest power of two with 2R² ≤ N / (rays_per_texel · √n), clamped to
// [min_resolution, max_resolution]. On the measured 100 k-ray OSRAM LED this gives R = 64, 32, 16, 16, 16
// for 1, 8, 64, 256, 512 APLs; the per-APL budget (N/n) gave R = 4 at 256 and 512 APLs, whose blur made
// those levels 43 % off at every distance, while R = 16 brings 512 APLs within 1.25× the rays' noise
// floor (tests/test_apl_error.cpp).
#pragma once

#include <lumx/apl_clustering.h>
#include <lumx/apl_set.h>
#include <lumx/detail/point_kdtree.h>
#include <lumx/rayset.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

LUMX_NAMESPACE_BEGIN

struct AplBuildOptions {
  std::vector<std::size_t> level_counts = {1, 8, 64, 256, 512};  ///< APLs per level, increasing
  std::size_t seed_rays = 250000;   ///< rays the tree is built from
  int cluster_window = 16;          ///< PLOC search radius
  int map_resolution = 0;           ///< fixed R for every level; 0 = by the rule above
  int min_resolution = 4, max_resolution = 256;
  double rays_per_texel = 8;        ///< the rule's target mean rays per texel
  std::size_t chunk_rays = 1 << 16; ///< rays per read
  unsigned threads = 1;             ///< threads for the assignment pass (results do not depend on it)
  /// Place each APL where its rays' lines converge (see build_apl_set) instead of at its seeds' box
  /// centre (000 §4.3), when that point is well defined and inside the luminaire's bound. Off by default:
  /// it changes the dissertation's placement, and its effect on every kind of rayset is not yet charted.
  bool place_at_convergence = false;
  /// Called with the fraction done (0..1) and a phase name, at most a few hundred times.
  std::function<void(double, const char*)> progress;
};

struct AplBuildReport {
  std::uint64_t rays = 0, seeds = 0, zero_flux_rays = 0;
  std::size_t moved_to_convergence = 0;   ///< APLs placed at their rays' convergence point
  std::vector<int> map_resolution;        ///< per level
  std::vector<std::size_t> apl_count;     ///< per level (may be below the request for tiny raysets)
  double seconds_seed = 0, seconds_tree = 0, seconds_assign = 0;
};

/// The map resolution the rule gives for `rays` rays shared by `apls` APLs.
inline int map_resolution_for(double rays, double apls, const AplBuildOptions& o) {
  const double texels = rays / (std::max(1e-9, o.rays_per_texel) * std::sqrt(std::max(1.0, apls)));  // 2R² ≤ this
  int R = o.min_resolution;
  while (R * 2 <= o.max_resolution && 2.0 * (2.0 * R) * (2.0 * R) <= texels) R *= 2;
  return std::max(1, std::min(R, o.max_resolution));
}

/// Builds an APL set from every ray of `rays` (two passes: seeds, then assignment). Levels that would
/// repeat the previous level's APL count (fewer seeds than requested) are dropped. Throws
/// std::invalid_argument for bad options or a rayset without flux.
inline AplSet build_apl_set(RaySource& rays, const AplBuildOptions& options = {}, AplBuildReport* report = nullptr) {
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  if (options.level_counts.empty()) throw std::invalid_argument("build_apl_set: no level requested");
  for (std::size_t k = 0; k < options.level_counts.size(); ++k)
    if (options.level_counts[k] < 1 || (k > 0 && options.level_counts[k] <= options.level_counts[k - 1]))
      throw std::invalid_argument("build_apl_set: level_counts must be positive and increasing");
  if (options.seed_rays < 1) throw std::invalid_argument("build_apl_set: seed_rays must be ≥ 1");
  if (options.map_resolution < 0 || options.map_resolution > sphere_map::kMaxResolution)
    throw std::invalid_argument("build_apl_set: map_resolution outside [0, 4096]");
  AplBuildReport local;
  AplBuildReport& rep = report ? *report : local;
  rep = AplBuildReport{};
  const RaysetInfo& info = rays.info();
  auto progress = [&](double f, const char* phase) {
    if (options.progress) options.progress(f, phase);
  };

  // ---- 1. seeds, evenly through the file (a counting pass first when the header has no count)
  const auto t0 = Clock::now();
  RayChunk chunk;
  std::uint64_t total = info.ray_count;
  if (total == 0) {
    rays.rewind();
    while (rays.next(chunk, options.chunk_rays)) total += chunk.size();
  }
  if (total == 0) throw std::invalid_argument("build_apl_set: the rayset has no ray");
  const std::uint64_t want = std::min<std::uint64_t>(options.seed_rays, total);
  std::vector<glm::vec3> seed_pos;
  std::vector<float> seed_flux;
  seed_pos.reserve(std::size_t(want));
  seed_flux.reserve(std::size_t(want));
  rays.rewind();
  std::uint64_t index = 0;
  float max_flux = 0;  // for the fixed-point unit of step 5, gathered in this pass over every ray
  while (rays.next(chunk, options.chunk_rays)) {
    for (float f : chunk.flux) max_flux = std::max(max_flux, std::isfinite(f) ? f : 0.0f);
    for (std::size_t i = 0; i < chunk.size(); ++i, ++index) {
      // Ray `index` is a seed when ⌊(index+1)·S/N⌋ > ⌊index·S/N⌋: exactly S seeds, evenly spaced.
      if ((index + 1) * want / total == index * want / total) continue;
      if (!(chunk.flux[i] > 0)) continue;  // no light, no APL
      seed_pos.push_back(chunk.position(i));
      seed_flux.push_back(chunk.flux[i]);
    }
    progress(0.1 * double(index) / double(total), "seeds");
  }
  if (seed_pos.empty()) throw std::invalid_argument("build_apl_set: no seed ray carries flux");
  rep.seeds = seed_pos.size();
  const auto t1 = Clock::now();
  rep.seconds_seed = seconds(t0, t1);

  // ---- 2.–3. tree and nested cuts
  ClusterOptions co;
  co.window = options.cluster_window;
  const ClusterTree tree = build_cluster_tree(seed_pos, seed_flux, co);
  std::vector<std::vector<int>> cuts = cut_cluster_tree(tree, options.level_counts);
  for (std::size_t k = cuts.size(); k-- > 1;)  // drop levels that did not grow (tiny raysets)
    if (cuts[k].size() <= cuts[k - 1].size()) cuts.erase(cuts.begin() + std::ptrdiff_t(k));
  const auto t2 = Clock::now();
  rep.seconds_tree = seconds(t1, t2);
  progress(0.2, "tree");

  // Node → APL index per level, and each finest-level APL's ancestor in every level.
  const std::size_t nl = cuts.size();
  std::vector<std::vector<int>> apl_of_node(nl, std::vector<int>(tree.size(), -1));
  for (std::size_t k = 0; k < nl; ++k)
    for (std::size_t i = 0; i < cuts[k].size(); ++i) apl_of_node[k][std::size_t(cuts[k][i])] = int(i);
  auto ancestor_in = [&](int node, std::size_t k) {
    while (node >= 0 && apl_of_node[k][std::size_t(node)] < 0) node = tree.parent[std::size_t(node)];
    return node < 0 ? -1 : apl_of_node[k][std::size_t(node)];
  };
  const std::vector<int>& finest = cuts.back();
  std::vector<std::vector<int>> up(nl, std::vector<int>(finest.size()));
  for (std::size_t i = 0; i < finest.size(); ++i)
    for (std::size_t k = 0; k < nl; ++k) up[k][i] = ancestor_in(finest[i], k);

  AplSet set;
  set.quantity = info.quantity;
  set.channels = ChannelLayout::luminance;
  set.provenance["source"] = info.file;
  set.provenance["source_format"] = info.format;
  set.provenance["seed_rays"] = std::to_string(rep.seeds);
  set.provenance["builder"] = "lumx build_apl_set (PLOC, eq. 4.1)";
  std::vector<glm::vec3> centres;
  for (int node : finest) centres.push_back(tree.center(node));
  const detail::PointKdTree nearest(centres);

  // Resolution per level by the rule above.
  for (std::size_t k = 0; k < nl; ++k) {
    AplLevel level;
    level.map_resolution = options.map_resolution > 0
                               ? options.map_resolution
                               : map_resolution_for(double(total), double(cuts[k].size()), options);
    for (std::size_t i = 0; i < cuts[k].size(); ++i) {
      Apl a;
      a.position = tree.center(cuts[k][i]);
      a.parent = k == 0 ? -1 : ancestor_in(cuts[k][i], k - 1);
      level.apls.push_back(std::move(a));
    }
    rep.map_resolution.push_back(level.map_resolution);
    rep.apl_count.push_back(level.apls.size());
    set.levels.push_back(std::move(level));
  }

  // ---- 4.–5. assignment and maps, in 64-bit fixed point (order-independent sums)
  if (!(max_flux > 0)) throw std::invalid_argument("build_apl_set: no ray carries flux");
  // One unit = max_flux · 2^-40: 10^10 rays of the largest flux still fit in 2^63.
  const double unit = double(max_flux) * std::ldexp(1.0, -40);
  std::vector<std::vector<std::int64_t>> sums(nl);
  std::vector<int> texels(nl);
  for (std::size_t k = 0; k < nl; ++k) {
    const int R = set.levels[k].map_resolution;
    texels[k] = 2 * R * R;
    sums[k].assign(std::size_t(texels[k]) * set.levels[k].apls.size(), 0);
  }
  std::vector<glm::dmat3> normal(finest.size(), glm::dmat3(0.0));
  std::vector<glm::dvec3> rhs(finest.size(), glm::dvec3(0.0));
  std::vector<double> weight(finest.size(), 0.0);
  rays.rewind();
  std::uint64_t done = 0;
  // Per ray: the finest APL and, per level, the texel (−1 for a ray without flux). Computed by up to
  // `threads` threads over disjoint ranges of the chunk, then accumulated in ray order by this thread;
  // the sums are integers, so the result is the same for any thread count and chunking.
  const unsigned threads = std::max(1u, options.threads);
  std::vector<std::int32_t> fine_of(options.chunk_rays);
  std::vector<std::int32_t> texel_of_ray(options.chunk_rays * nl);
  std::vector<std::int64_t> quanta(options.chunk_rays);
  std::vector<std::string> errors(threads);
  auto classify = [&](std::size_t begin, std::size_t end, std::string& error) {
    for (std::size_t i = begin; i < end && error.empty(); ++i) {
      const float f = chunk.flux[i];
      const glm::vec3 p = chunk.position(i), w = chunk.direction(i);
      if (!(f >= 0) || !std::isfinite(f) || !std::isfinite(p.x + p.y + p.z) || !std::isfinite(w.x + w.y + w.z) ||
          std::abs(glm::dot(w, w) - 1.0f) > 1e-3f) {
        error = "build_apl_set: ray " + std::to_string(done + i) +
                " has a non-finite position, a negative or non-finite flux, or a direction that is not a unit vector";
        return;
      }
      quanta[i] = f == 0 ? 0 : std::int64_t(std::llround(double(f) / unit));
      fine_of[i] = f == 0 ? -1 : std::int32_t(nearest.nearest(p));
      for (std::size_t k = 0; k < nl; ++k) {
        int x, y;
        sphere_map::texel_of(w, set.levels[k].map_resolution, x, y);
        texel_of_ray[i * nl + k] = y * 2 * set.levels[k].map_resolution + x;
      }
    }
  };
  while (rays.next(chunk, options.chunk_rays)) {
    const std::size_t n = chunk.size();
    if (fine_of.size() < n) {
      fine_of.resize(n);
      texel_of_ray.resize(n * nl);
      quanta.resize(n);
    }
    if (threads == 1 || n < 4096) {
      classify(0, n, errors[0]);
    } else {
      std::vector<std::thread> pool;
      for (unsigned t = 0; t < threads; ++t)
        pool.emplace_back(classify, n * t / threads, n * (t + 1) / threads, std::ref(errors[t]));
      for (std::thread& t : pool) t.join();
    }
    for (const std::string& e : errors)
      if (!e.empty()) throw std::invalid_argument(e);  // the lowest range's first bad ray
    for (std::size_t i = 0; i < n; ++i) {
      if (fine_of[i] < 0) {
        ++rep.zero_flux_rays;
        continue;
      }
      for (std::size_t k = 0; k < nl; ++k) {
        const std::size_t apl = std::size_t(up[k][std::size_t(fine_of[i])]);
        sums[k][apl * std::size_t(texels[k]) + std::size_t(texel_of_ray[i * nl + k])] += quanta[i];
      }
      if (options.place_at_convergence) {
        // Σ Φ (I − ωωᵀ) and Σ Φ (I − ωωᵀ) p: the normal equations of the point nearest to the rays' lines.
        const glm::dvec3 w(chunk.direction(i)), p(chunk.position(i));
        const double f = double(chunk.flux[i]);
        const glm::dmat3 P = glm::dmat3(1.0) - glm::outerProduct(w, w);
        normal[std::size_t(fine_of[i])] += f * P;
        rhs[std::size_t(fine_of[i])] += f * (P * p);
        weight[std::size_t(fine_of[i])] += f;
      }
    }
    done += n;
    progress(0.2 + 0.8 * double(done) / double(total), "assign");
  }
  rep.rays = done;
  for (std::size_t k = 0; k < nl; ++k) {
    AplLevel& level = set.levels[k];
    const int R = level.map_resolution;
    const double to_intensity = unit / sphere_map::texel_solid_angle(R);  // flux per texel → per steradian
    for (std::size_t a = 0; a < level.apls.size(); ++a) {
      Apl& apl = level.apls[a];
      apl.map = SphereMap(R, 1);
      const std::int64_t* s = sums[k].data() + a * std::size_t(texels[k]);
      double flux_units = 0;
      for (int t = 0; t < texels[k]; ++t) {
        apl.map.values()[std::size_t(t)] = float(double(s[t]) * to_intensity);
        flux_units += double(s[t]);
      }
      apl.flux = glm::dvec3(flux_units * unit);
    }
    std::vector<std::int64_t>().swap(sums[k]);
  }
  // The luminaire's bound: the box of the seeds' start points (the tree's root).
  set.bounds.center = glm::dvec3(tree.center(tree.root));
  set.bounds.radius = 0.5 * glm::length(glm::dvec3(tree.hi[std::size_t(tree.root)]) - glm::dvec3(tree.lo[std::size_t(tree.root)]));
  if (options.place_at_convergence) {
    // Each APL moves to the point nearest (least squares, flux-weighted) to its rays' lines, when the
    // directions spread enough to fix it (det of the mean projector ≥ 1e-3; a beam within ~2° does
    // not) and it lies inside the luminaire's bound. For rays leaving a surface in all directions this
    // is near the surface; for rays recorded on a surface around a smaller emitter it is the emitter.
    for (std::size_t k = 0; k < nl; ++k) {
      std::vector<glm::dmat3> A(set.levels[k].size(), glm::dmat3(0.0));
      std::vector<glm::dvec3> b(set.levels[k].size(), glm::dvec3(0.0));
      std::vector<double> W(set.levels[k].size(), 0.0);
      for (std::size_t i = 0; i < finest.size(); ++i) {
        const std::size_t a = std::size_t(up[k][i]);
        A[a] += normal[i];
        b[a] += rhs[i];
        W[a] += weight[i];
      }
      for (std::size_t a = 0; a < A.size(); ++a) {
        if (!(W[a] > 0) || !(glm::determinant(A[a] / W[a]) >= 1e-3)) continue;
        const glm::dvec3 x = glm::inverse(A[a]) * b[a];
        if (!(glm::length(x - set.bounds.center) <= 1.001 * set.bounds.radius + 1e-9)) continue;
        set.levels[k].apls[a].position = glm::vec3(x);
        ++rep.moved_to_convergence;
      }
    }
  }
  const auto t3 = Clock::now();
  rep.seconds_assign = seconds(t2, t3);
  progress(1.0, "done");
  return set;
}

LUMX_NAMESPACE_END
