// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// build_apl_set (apl/builder.h): the steps of the header's module comment, in order.
#include <lumx/apl/builder.h>

#include <lumx/apl/apl_set.h>
#include <lumx/apl/clustering.h>
#include <lumx/apl/point_sources.h>
#include <lumx/math/detail/point_kdtree.h>
#include <lumx/math/line_fit.h>
#include <lumx/math/sphere_map.h>
#include <lumx/math/sphere_map_smoothing.h>
#include <lumx/rays/rayset.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace {

// A ray the builder can use: finite position, non-negative finite flux, unit direction (±1e-3).
bool usable_ray(float flux, const glm::vec3& p, const glm::vec3& w) {
  return flux >= 0 && std::isfinite(flux) && std::isfinite(p.x + p.y + p.z) && std::isfinite(w.x + w.y + w.z) &&
         std::abs(glm::dot(w, w) - 1.0f) <= 1e-3f;
}

// The error for a ray the builder cannot use.
std::string bad_ray_message(std::uint64_t index) {
  return "build_apl_set: ray " + std::to_string(index) +
         " has a non-finite position, a negative or non-finite flux, or a direction that is not a unit vector";
}

}  // namespace

AplSet build_apl_set(RaySource& rays, const AplBuildOptions& options, AplBuildReport* report) {
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  if (options.level_counts.empty()) throw std::invalid_argument("build_apl_set: no level requested");
  for (std::size_t k = 0; k < options.level_counts.size(); ++k)
    if (options.level_counts[k] < 1 || (k > 0 && options.level_counts[k] <= options.level_counts[k - 1]))
      throw std::invalid_argument("build_apl_set: level_counts must be positive and increasing");
  if (options.seed_rays < 1) throw std::invalid_argument("build_apl_set: seed_rays must be ≥ 1");
  if (options.map_resolution < 0 || options.map_resolution > sphere_map::kMaxResolution)
    throw std::invalid_argument("build_apl_set: map_resolution outside [0, 4096]");
  if (options.min_resolution < 1 || options.max_resolution < options.min_resolution ||
      options.max_resolution > sphere_map::kMaxResolution)
    throw std::invalid_argument("build_apl_set: need 1 ≤ min_resolution ≤ max_resolution ≤ 4096");
  AplBuildReport local;
  AplBuildReport& rep = report ? *report : local;
  rep = AplBuildReport{};
  const RaysetInfo& info = rays.info();
  BoundingSphere set_bounds;
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
  const double rule_rays = double(options.resolution_rays > 0 ? options.resolution_rays : total);
  const std::uint64_t want = std::min<std::uint64_t>(options.seed_rays, total);
  std::vector<glm::vec3> seed_pos, seed_dir;
  std::vector<float> seed_flux;
  seed_pos.reserve(std::size_t(want));
  seed_flux.reserve(std::size_t(want));
  if (options.place_at_convergence) seed_dir.reserve(std::size_t(want));
  rays.rewind();
  std::uint64_t index = 0;
  float max_flux = 0;  // for the fixed-point unit of step 5, gathered in this pass over every ray
  glm::dvec3 seed_flux_direction(0.0);  // Σ flux · direction over the seeds, for the map frame (step 3)
  double seed_flux_sum = 0;
  while (rays.next(chunk, options.chunk_rays)) {
    for (float f : chunk.flux) max_flux = std::max(max_flux, std::isfinite(f) ? f : 0.0f);
    for (std::size_t i = 0; i < chunk.size(); ++i, ++index) {
      // Ray `index` is a seed when ⌊(index+1)·S/N⌋ > ⌊index·S/N⌋: exactly S seeds, evenly spaced.
      if ((index + 1) * want / total == index * want / total) continue;
      // Seeds are checked here (the tree and step 1b need them sound); every ray is in step 4.
      if (!usable_ray(chunk.flux[i], chunk.position(i), chunk.direction(i)))
        throw std::invalid_argument(bad_ray_message(index));
      if (!(chunk.flux[i] > 0)) continue;  // no light, no APL
      seed_pos.push_back(chunk.position(i));
      seed_flux.push_back(chunk.flux[i]);
      seed_flux_direction += double(chunk.flux[i]) * glm::dvec3(chunk.direction(i));
      seed_flux_sum += double(chunk.flux[i]);
      if (options.place_at_convergence) seed_dir.push_back(chunk.direction(i));
    }
    progress(0.1 * double(index) / double(total), "seeds");
  }
  if (seed_pos.empty()) throw std::invalid_argument("build_apl_set: no seed ray carries flux");
  rep.seeds = seed_pos.size();
  // The luminaire's bound: the box of the seeds' start points as recorded.
  glm::dvec3 box_lo(seed_pos[0]), box_hi(seed_pos[0]);
  for (const glm::vec3& p : seed_pos) {
    box_lo = glm::min(box_lo, glm::dvec3(p));
    box_hi = glm::max(box_hi, glm::dvec3(p));
  }
  set_bounds.center = 0.5 * (box_lo + box_hi);
  set_bounds.radius = 0.5 * glm::length(box_hi - box_lo);
  const auto t1 = Clock::now();
  rep.seconds_seed = seconds(t0, t1);

  // ---- 2.–3. tree and nested cuts
  ClusterOptions co;
  co.window = options.cluster_window;
  auto make_cuts = [&](const ClusterTree& t) {
    std::vector<std::vector<int>> c = cut_cluster_tree(t, options.level_counts);
    for (std::size_t k = c.size(); k-- > 1;)  // drop levels that did not grow (tiny raysets)
      if (c[k].size() <= c[k - 1].size()) c.erase(c.begin() + std::ptrdiff_t(k));
    return c;
  };
  ClusterTree tree = build_cluster_tree(seed_pos, seed_flux, co);
  std::vector<std::vector<int>> cuts = make_cuts(tree);
  // Step 1b: cluster the rays by the points of their lines nearest the seeds' convergence point c0
  // instead of by start point, when all of these hold:
  //   - the lines meet: their RMS distance from c0 (across them) relative to the start points' RMS
  //     distance from it is below the same ratio with the directions shuffled among the seeds (start
  //     point and direction made independent), by more than chance: a factor min(0.97, 1 − 10/√n) for n
  //     seeds. A flat emitter of any angular distribution, a beam from an aperture or identical emitters
  //     give ≈ 1 (their lines say no more about where the light comes from than the start points); rays
  //     recorded on a surface around a smaller emitter give far less;
  //   - at no level does it shift the rays (across them) more than 4× as much as start points do, by the
  //     measure step 6 minimises (LineFit over the seeds moved to their APLs). This keeps emitters that
  //     merely point away from a common centre apart; the shift is a proxy for the error, not the error;
  //   - the lines do not all meet in one point (the slid seeds' box is not below 1e-4 of the seeds'):
  //     then every clustering by line is degenerate, while start points still split the light by
  //     direction, and step 6 puts every APL at that point anyway.
  // The report carries the figures (line_convergence, line_convergence_shuffled, shift_by_*).
  bool slide = false;
  glm::dvec3 c0 = set_bounds.center;
  if (options.place_at_convergence) {
    LineFit seed_lines;
    for (std::size_t i = 0; i < seed_pos.size(); ++i) seed_lines.add(seed_pos[i], seed_dir[i], seed_flux[i]);
    const glm::dvec3 x = seed_lines.solve(set_bounds.center, 1e-3);
    auto shift_cost = [&](const ClusterTree& t, const std::vector<std::vector<int>>& c) {
      std::vector<double> per_level;
      std::vector<int> label(t.size());
      for (std::size_t k = 0; k < c.size(); ++k) {
        // Label every node below a cut node with that cluster (top-down: parents have larger ids).
        std::fill(label.begin(), label.end(), -1);
        for (std::size_t i = 0; i < c[k].size(); ++i) label[std::size_t(c[k][i])] = int(i);
        for (std::size_t n = t.size(); n-- > 0;)
          if (label[n] >= 0 && !t.is_seed(int(n))) {
            label[std::size_t(t.left[n])] = label[n];
            label[std::size_t(t.right[n])] = label[n];
          }
        const int R = options.map_resolution > 0 ? options.map_resolution
                                                 : map_resolution_for(rule_rays, double(c[k].size()), options);
        std::vector<LineFit> fit(c[k].size());
        for (std::size_t i = 0; i < seed_pos.size(); ++i)
          if (label[i] >= 0) fit[std::size_t(label[i])].add(seed_pos[i], seed_dir[i], seed_flux[i]);
        double level_cost = 0, level_weight = 0;
        for (std::size_t i = 0; i < fit.size(); ++i) {
          const glm::dvec3 xi = fit[i].solve(glm::dvec3(t.center(c[k][i])), sphere_map::texel_solid_angle(R));
          level_cost += fit[i].weight * fit[i].mean_line_distance2(xi);
          level_weight += fit[i].weight;
        }
        per_level.push_back(level_weight > 0 ? level_cost / level_weight : 0);
      }
      return per_level;
    };
    const double across = seed_lines.mean_line_distance2(x), start = seed_lines.mean_start_distance2(x);
    rep.line_convergence = start > 0 ? std::sqrt(across / start) : 1.0;
    // The same with directions shuffled: seed i paired with direction π(i) = i·P mod n, P coprime to n.
    LineFit shuffled;
    {
      const std::size_t n = seed_pos.size();
      std::uint64_t P = 2654435761u % std::max<std::size_t>(n, 1);
      while (n > 1 && std::gcd(P, std::uint64_t(n)) != 1) ++P;
      for (std::size_t i = 0; i < n; ++i)
        shuffled.add(seed_pos[i], seed_dir[std::size_t((std::uint64_t(i) * P) % n)], seed_flux[i]);
      const glm::dvec3 xs = shuffled.solve(set_bounds.center, 1e-3);
      const double a2 = shuffled.mean_line_distance2(xs), s2 = shuffled.mean_start_distance2(xs);
      rep.line_convergence_shuffled = s2 > 0 ? std::sqrt(a2 / s2) : 1.0;
    }
    // Shuffled, the ratio scatters by about 1/√n around its mean, so a departure of 10/√n, and at least
    // 3 %, is correlation, not chance.
    const double significant = std::min(0.97, 1.0 - 10.0 / std::sqrt(double(seed_pos.size())));
    using LC = AplBuildOptions::LineClustering;
    const bool inside = glm::length(x - set_bounds.center) <= 1.001 * set_bounds.radius + 1e-9 && start > 0;
    if (inside && options.line_clustering != LC::start_points &&
        (options.line_clustering == LC::lines || rep.line_convergence <= significant * rep.line_convergence_shuffled)) {
      std::vector<glm::vec3> slid(seed_pos.size());
      glm::dvec3 slid_lo(slide_to_nearest(seed_pos[0], seed_dir[0], x)), slid_hi = slid_lo;
      for (std::size_t i = 0; i < seed_pos.size(); ++i) {
        slid[i] = slide_to_nearest(seed_pos[i], seed_dir[i], x);
        slid_lo = glm::min(slid_lo, glm::dvec3(slid[i]));
        slid_hi = glm::max(slid_hi, glm::dvec3(slid[i]));
      }
      ClusterTree slid_tree = build_cluster_tree(slid, seed_flux, co);
      std::vector<std::vector<int>> slid_cuts = make_cuts(slid_tree);
      rep.shift_by_start = shift_cost(tree, cuts);
      rep.shift_by_line = shift_cost(slid_tree, slid_cuts);
      bool better = rep.shift_by_line.size() == rep.shift_by_start.size() &&
                    glm::length(slid_hi - slid_lo) >= 1e-4 * 2.0 * set_bounds.radius;
      for (std::size_t k = 0; better && k < rep.shift_by_line.size(); ++k)
        better = rep.shift_by_line[k] <= 4 * rep.shift_by_start[k];
      if (better || options.line_clustering == LC::lines) {
        slide = true;
        c0 = x;
        tree = std::move(slid_tree);
        cuts = std::move(slid_cuts);
        seed_pos = std::move(slid);
      }
    }
    rep.slid_to_convergence = slide;
    std::vector<glm::vec3>().swap(seed_dir);
  }
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

  // The maps' frame (step 3): a beam's flux-weighted mean direction (its seeds' mean resultant length at
  // least kMinMapFrameResultant) turned into a wedge of the map; broader light keeps the photometric
  // frame.
  const MapFrame frame = options.orient_maps && glm::length(seed_flux_direction) >=
                                                    kMinMapFrameResultant * seed_flux_sum
                             ? map_frame_for(seed_flux_direction)
                             : MapFrame{};
  // Resolution per level by the rule above.
  for (std::size_t k = 0; k < nl; ++k) {
    AplLevel level;
    level.frame = frame;
    level.map_resolution = options.map_resolution > 0
                               ? options.map_resolution
                               : map_resolution_for(rule_rays, double(cuts[k].size()), options);
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
  // One unit = max_flux · max(2^-40, N · 2^-62): all N rays at the largest flux, in one texel, still sum
  // below 2^62, and a ray's flux is kept to 2^-40 of the largest one (finer only for N < 2^22).
  const double unit = double(max_flux) * std::max(std::ldexp(1.0, -40), double(total) * std::ldexp(1.0, -62));
  std::vector<std::vector<std::int64_t>> sums(nl);
  std::vector<int> texels(nl);
  for (std::size_t k = 0; k < nl; ++k) {
    const int R = set.levels[k].map_resolution;
    texels[k] = 2 * R * R;
    sums[k].assign(std::size_t(texels[k]) * set.levels[k].apls.size(), 0);
  }
  // Rays per texel, for the optional smoothing (its reliability threshold counts rays, not flux).
  const bool smoothing = options.map_smoothing_rays > 0;
  std::vector<std::vector<std::uint32_t>> counts(smoothing ? nl : 0);
  for (std::size_t k = 0; k < counts.size(); ++k) {
    const int R = set.levels[k].map_resolution;
    if ((R & (R - 1)) != 0) throw std::invalid_argument("build_apl_set: map smoothing needs power-of-two resolutions");
    counts[k].assign(sums[k].size(), 0);
  }
  std::vector<LineFit> lines_of(options.place_at_convergence ? finest.size() : 0);  // per finest APL
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
      if (!usable_ray(f, p, w)) {
        error = bad_ray_message(done + i);
        return;
      }
      quanta[i] = f == 0 ? 0 : std::int64_t(std::llround(double(f) / unit));
      fine_of[i] = f == 0 ? -1 : std::int32_t(nearest.nearest(slide ? slide_to_nearest(p, w, c0) : p));
      for (std::size_t k = 0; k < nl; ++k) {
        int x, y;
        sphere_map::texel_of(frame.map_direction(w), set.levels[k].map_resolution, x, y);
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
        const std::size_t t = apl * std::size_t(texels[k]) + std::size_t(texel_of_ray[i * nl + k]);
        sums[k][t] += quanta[i];
        if (smoothing && counts[k][t] < UINT32_MAX) ++counts[k][t];
      }
      if (options.place_at_convergence)
        lines_of[std::size_t(fine_of[i])].add(chunk.position(i), chunk.direction(i), chunk.flux[i]);
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
      if (smoothing) {
        // The prior: the parent's smoothed map at this resolution; else (a coarser parent) the bilinear shape.
        const std::size_t T = std::size_t(texels[k]);
        std::vector<double> f(s, s + T);
        const std::uint32_t* c = counts[k].data() + a * T;
        std::vector<double> prior;
        if (k > 0) {  // the parent's map, box-downsampled to R when it is finer (flux-exact)
          SphereMap pm = set.levels[k - 1].apls[std::size_t(apl.parent)].map;
          while (pm.resolution() > R && pm.resolution() % 2 == 0) pm = pm.downsampled();
          if (pm.resolution() == R) prior.assign(pm.values().begin(), pm.values().begin() + std::ptrdiff_t(T));
        }
        const std::vector<double> g = smooth_sparse_map(f, std::vector<std::uint32_t>(c, c + T), R,
                                                        options.map_smoothing_rays, prior.empty() ? nullptr : &prior);
        for (std::size_t t = 0; t < T; ++t) apl.map.values()[t] = float(g[t] * to_intensity);
      }
    }
    std::vector<std::int64_t>().swap(sums[k]);
    if (smoothing) std::vector<std::uint32_t>().swap(counts[k]);
  }
  set.bounds = set_bounds;
  if (options.place_at_convergence) {
    // Each APL moves to the point x minimising its rays' flux-weighted squared distance to x measured
    // across the ray, Σ Φ |(I − ωωᵀ)(x − p)|²: the lateral shift every ray suffers when it is moved to the
    // APL. For rays leaving a surface in all directions the minimum is near the surface; for rays
    // recorded on a surface around a smaller emitter it is the emitter. Along the axis of a cone of
    // half-angle α the minimum is weakly held (the projectors' mean has an eigenvalue ≈ α²/2), and it
    // sits at the cone's waist, which a map whose texels are wider than the cone cannot express: each
    // APL's blurred lobe would then light a smaller, brighter spot than its rays do. So LineFit::solve takes the components whose
    // eigenvalue is below Ω, the level's texel solid angle (a cone narrower than ≈ 1.4 texels), from the
    // parent, placed first (the root's anchor is its seeds' box centre). A point outside the luminaire's
    // bound is not used.
    for (std::size_t k = 0; k < nl; ++k) {
      const double lambda = sphere_map::texel_solid_angle(set.levels[k].map_resolution);
      std::vector<LineFit> fit(set.levels[k].size());
      for (std::size_t i = 0; i < finest.size(); ++i) fit[std::size_t(up[k][i])].add(lines_of[i]);
      for (std::size_t a = 0; a < fit.size(); ++a) {
        Apl& apl = set.levels[k].apls[a];
        if (!(fit[a].weight > 0)) continue;
        const glm::dvec3 anchor =
            k == 0 ? glm::dvec3(apl.position) : glm::dvec3(set.levels[k - 1].apls[std::size_t(apl.parent)].position);
        const glm::dvec3 x = fit[a].solve(anchor, lambda);  // lambda: the minimum eigenvalue used
        if (!(glm::length(x - set.bounds.center) <= 1.001 * set.bounds.radius + 1e-9)) continue;
        apl.position = glm::vec3(x);
        ++rep.moved_to_convergence;
      }
    }
  }
  // ---- 7. point sources behind apertures: masked APLs at the points every line passes through
  if (options.place_at_convergence && options.point_sources.enabled) {
    // Candidates: each finest cluster's least-squares point of its lines solved in full (whatever the
    // maps' resolution truncated in step 6: a cluster of one source's rays meets at that source), then
    // the finest level's positions.
    std::vector<glm::vec3> candidates;
    for (std::size_t i = 0; i < lines_of.size(); ++i)
      if (lines_of[i].weight > 0)
        candidates.push_back(glm::vec3(lines_of[i].solve(glm::dvec3(set.levels.back().apls[i].position), 1e-9)));
    for (const Apl& a : set.levels.back().apls) candidates.push_back(a.position);
    const auto resolution = [&](std::size_t apls) {
      return options.map_resolution > 0 ? options.map_resolution : map_resolution_for(rule_rays, double(apls), options);
    };
    PointSourceReport found;
    std::optional<AplSet> points = build_point_source_set(rays, candidates, set.bounds, options.level_counts, resolution,
                                                          frame, options.point_sources, options.chunk_rays, threads, &found);
    rep.point_sources = found.sources;
    rep.point_source_note = found.why;
    if (points) {
      points->quantity = set.quantity;
      points->channels = set.channels;
      points->provenance = set.provenance;
      points->provenance["builder"] = "lumx build_apl_set (point sources behind apertures: " +
                                      std::to_string(found.sources) + ", masked)";
      set = std::move(*points);
      rep.map_resolution.clear();
      rep.apl_count.clear();
      for (const AplLevel& l : set.levels) rep.map_resolution.push_back(l.map_resolution), rep.apl_count.push_back(l.size());
    }
  }
  const auto t3 = Clock::now();
  rep.seconds_assign = seconds(t2, t3);
  progress(1.0, "done");
  return set;
}

LUMX_NAMESPACE_END
