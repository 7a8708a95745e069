// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// the map resolutions and kernels fitted on held-out rays (apl/map_fit.h).
#include "apl/error_detail.h"

LUMX_NAMESPACE_BEGIN

int fit_patch_resolution(int patch_resolution, std::uint64_t rays) {
  const int low = std::min(1024, 2 * patch_resolution), high = std::max(low, 64);
  int R = low;
  while (R * 2 <= high && 2.0 * (2.0 * R) * (2.0 * R) * 32.0 <= double(rays)) R *= 2;
  return R;
}

AplLevel downsampled_level(const AplLevel& level, int R) {
  AplLevel out = level;
  if (R == level.map_resolution) return out;
  for (Apl& a : out.apls) {
    while (a.map.resolution() > R) a.map = a.map.downsampled();
    if (a.map.resolution() != R)
      throw std::invalid_argument("downsampled_level: " + std::to_string(R) + " is not a power-of-two fraction of " +
                                  std::to_string(level.map_resolution));
  }
  out.map_resolution = R;
  // A mask's coverage computed afresh at R, as a reader loading the level at R computes it (averaging the
  // children's would sample each texel finer than that, and the bundle would read back other values).
  if (out.has_masks()) refresh_coverages(out);
  return out;
}

SphereMap level_sum(const AplLevel& level) {
  SphereMap total(level.map_resolution, 1);
  for (const Apl& a : level.apls) accumulate_channels(total, a.map);
  return total;
}

std::vector<SphereMap> kernel_applied_maps(const AplLevel& level, const SphereMapKernel& kernel, unsigned threads) {
  std::vector<SphereMap> out(level.apls.size());
  detail::parallel_jobs(
      out.size(), threads, [&](std::size_t i) { out[i] = kernel.apply(level.apls[i].map); }, kMapsPerThread);
  return out;
}

AplLevel level_from_applied(const AplLevel& level, std::vector<SphereMap> applied, const SphereMapKernel& kernel,
                            KernelMode mode, const SphereMap& gain, unsigned threads) {
  if (applied.size() != level.apls.size())
    throw std::invalid_argument("level_from_applied: " + std::to_string(applied.size()) + " smoothed maps for " +
                                std::to_string(level.apls.size()) + " APLs");
  // Every field but the maps, which are written below (copying the input's maps first would cost a
  // level's map bytes, 64 MB at R 128 × 512 APLs, per candidate).
  AplLevel out;
  out.map_resolution = level.map_resolution;
  out.frame = level.frame;
  out.error = level.error;
  out.apls.resize(level.apls.size());
  for (std::size_t i = 0; i < level.apls.size(); ++i) {
    out.apls[i].position = level.apls[i].position;
    out.apls[i].flux = level.apls[i].flux;
    out.apls[i].parent = level.apls[i].parent;
    out.apls[i].mask = level.apls[i].mask;
    out.apls[i].coverage = level.apls[i].coverage;
  }
  const bool with_gain = mode != KernelMode::plain;
  detail::parallel_jobs(
      out.apls.size(), threads,
      [&](std::size_t i) {
        out.apls[i].map =
            with_gain ? kernel.with_gain(level.apls[i].map, std::move(applied[i]), gain) : std::move(applied[i]);
      },
      kMapsPerThread);
  return out;
}

AplLevel smoothed_level_with_gain(const AplLevel& level, const SphereMapKernel& kernel, KernelMode mode,
                                  const SphereMap& gain, unsigned threads) {
  return level_from_applied(level, kernel_applied_maps(level, kernel, threads), kernel, mode, gain, threads);
}

AplLevel smoothed_level(const AplLevel& level, const SphereMapKernel& kernel, unsigned threads, KernelMode mode,
                        HarmonicEstimateCache* cache) {
  const SphereMap gain =
      mode != KernelMode::plain && !level.apls.empty() ? kernel.gain(level_sum(level), mode, cache) : SphereMap();
  return smoothed_level_with_gain(level, kernel, mode, gain, threads);
}

AplLevel fitted_level(const AplLevel& level, int R, double kappa, KernelMode mode, HarmonicEstimateCache* cache) {
  AplLevel out = downsampled_level(level, R);
  // A masked level is never smoothed (fit_map_resolutions grades it plain): a kernel chosen for another
  // kind of level (a half set with other sources) is not applied to it.
  if (kappa > 0 && !out.has_masks()) out = smoothed_level(out, *SphereMapKernel::shared(R, kappa), 0, mode, cache);
  return out;
}

std::vector<double> fit_kernel_kappas(int R) {
  if (R < 32 || R > SphereMapKernel::kMaxResolution) return {};
  const double texel = std::sqrt(4.0 * kPi / (2.0 * double(R) * double(R)));
  std::vector<double> out;
  for (double widths : {0.75, 1.5}) out.push_back(1.0 / ((widths * texel) * (widths * texel)));
  return out;
}

std::vector<FitKernel> fit_kernels(int R) {
  std::vector<FitKernel> out;
  for (double kappa : fit_kernel_kappas(R)) out.push_back({kappa, KernelMode::plain});
  if (R < 32 || R > SphereMapKernel::kMaxResolution) return out;
  const double texel = std::sqrt(4.0 * kPi / (2.0 * double(R) * double(R)));
  const auto kappa_of = [&](double widths) { return 1.0 / ((widths * texel) * (widths * texel)); };
  for (double widths : {0.75, 1.5, 3.0}) out.push_back({kappa_of(widths), KernelMode::sharpened});
  for (double widths : {1.5, 3.0}) out.push_back({kappa_of(widths), KernelMode::local_linear});
  for (double widths : {1.5, 3.0}) out.push_back({kappa_of(widths), KernelMode::extrapolated});
  for (double widths : {1.5, 3.0, 4.5}) out.push_back({kappa_of(widths), KernelMode::two_scale});
  // Spectral and spectral per order width by width: both smooth each map by the same kernel, so the second
  // finds the first's K·f still kept (fit_map_resolutions keeps the last one to three widths used).
  for (double widths : {1.5, 3.0, 4.5}) {
    out.push_back({kappa_of(widths), KernelMode::spectral});
    out.push_back({kappa_of(widths), KernelMode::spectral_per_order});
  }
  return out;
}

std::pair<double, double> kernel_peak_change(const SphereMap& sum, const SphereMap& smooth, std::uint64_t set_rays) {
  if (set_rays == 0) return {1.0, 0.0};
  std::vector<std::uint32_t> order(sum.texel_count());
  for (std::size_t t = 0; t < order.size(); ++t) order[t] = std::uint32_t(t);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return smooth.data()[a] > smooth.data()[b] || (smooth.data()[a] == smooth.data()[b] && a < b);
  });
  double total = 0;
  for (std::size_t t = 0; t < sum.texel_count(); ++t) total += double(sum.data()[t]);
  if (!(total > 0)) return {0.0, 0.0};
  double plain = 0, smoothed = 0;
  for (std::uint32_t t : order) {
    if (smoothed >= 0.05 * total) break;
    plain += double(sum.data()[t]);
    smoothed += double(smooth.data()[t]);
  }
  if (!(plain > 0)) return {0.0, 0.0};
  const double rays_there = double(set_rays) * plain / total;
  return {(plain - smoothed) / plain, 2.0 / std::sqrt(std::max(1.0, rays_there))};
}

std::pair<double, double> kernel_peak_change(const AplLevel& level, const SphereMapKernel& kernel,
                                             std::uint64_t set_rays, KernelMode mode) {
  if (level.apls.empty() || set_rays == 0) return {1.0, 0.0};
  const SphereMap sum = level_sum(level);
  return kernel_peak_change(sum, kernel.apply(sum, mode), set_rays);
}

double cost_difference_standard_error(const ReferenceIrradiance& ref, const std::vector<std::vector<double>>& a,
                                      const std::vector<std::vector<double>>& b, const std::vector<bool>& spheres) {
  std::vector<double> per_patch;
  for (std::size_t s = 0; s < ref.sphere.size() && s < a.size() && s < b.size(); ++s) {
    if (s < spheres.size() && !spheres[s]) continue;
    const std::vector<double>& e = ref.sphere[s].irradiance;
    const std::size_t n = e.size();
    if (n < 2 || a[s].size() != n || b[s].size() != n) continue;
    if (per_patch.empty()) per_patch.assign(n, 0.0);
    if (per_patch.size() != n) continue;
    double mean_ref = 0, sa = 0, sb = 0;
    for (std::size_t p = 0; p < n; ++p) {
      mean_ref += e[p];
      sa += (a[s][p] - e[p]) * (a[s][p] - e[p]);
      sb += (b[s][p] - e[p]) * (b[s][p] - e[p]);
    }
    mean_ref /= double(n);
    const double m2 = mean_ref * mean_ref, ea2 = sa / double(n) / m2, eb2 = sb / double(n) / m2;
    if (!(ea2 > 0) || !(eb2 > 0) || !std::isfinite(ea2 + eb2)) continue;
    const double scale = 2 * m2 * 0.5 * (ea2 + eb2);
    for (std::size_t p = 0; p < n; ++p) {
      const double ra = (a[s][p] - e[p]) * (a[s][p] - e[p]), rb = (b[s][p] - e[p]) * (b[s][p] - e[p]);
      per_patch[p] += (ra - rb) / scale;
    }
  }
  const std::size_t n = per_patch.size();
  if (n < 2) return 0.0;
  double mean = 0, sq = 0;
  for (double d : per_patch) mean += d / double(n);
  for (double d : per_patch) sq += (d - mean) * (d - mean);
  return std::sqrt(sq / double(n - 1) / double(n));
}

ResolutionChoice fit_map_resolutions(AplSet& set, const ReferenceIrradiance& ref, const AplErrorOptions& options,
                                     int min_resolution, std::uint64_t set_rays) {
  ResolutionChoice choice;
  AplErrorOptions o = options;
  o.min_timing_seconds = 0;
  const auto kernel_for = [](int R, double kappa) { return SphereMapKernel::shared(R, kappa); };
  HarmonicEstimateCache spectra;  // every level's sum is the same rays': one expansion for all
  for (std::size_t k = 0; k < set.levels.size(); ++k) {
    const AplLevel built = set.levels[k];
    const bool masked = built.has_masks();
    std::vector<FitCandidate> tried;
    FitCandidate best{built.map_resolution, 0.0, INFINITY};
    // Every eligible candidate (past the kernel guards) with its model values, for the one-standard-error
    // rule below, and its gain (empty for plain), to smooth the level with once chosen; the best is one
    // of them.
    struct Eligible {
      FitCandidate candidate;
      std::vector<std::vector<double>> values;  // per sphere and patch
      SphereMap gain;
    };
    std::vector<Eligible> eligible;
    std::vector<std::vector<double>> last_values;  // the model values of the candidate graded last
    std::size_t best_at = 0;
    // The distances the cost sums over (see above): every one, except for level 0, where the first
    // grade (the built maps unsmoothed) sets them.
    std::vector<bool> serves;
    const auto admit = [&](SphereMap gain) {
      eligible.push_back({tried.back(), std::move(last_values), std::move(gain)});
      if (tried.back().cost < best.cost) best = tried.back(), best_at = eligible.size() - 1;
    };
    // The lookups of the level at the current R, of as many points as kLookupBytes holds: every candidate
    // there has its layout.
    std::unique_ptr<const detail::LevelLookups> lookups;
    const auto grade = [&](int R, double kappa, KernelMode mode, std::vector<double>& errors) {
      LevelErrors row = lookups ? lookups->evaluate(set, k, ref, o) : evaluate_level(set, k, ref, o);
      last_values = std::move(row.irradiance);
      errors.clear();
      for (const IrradianceErrors& e : row.errors) errors.push_back(e.relative_rmse);
      if (serves.empty()) {
        for (double e : errors) serves.push_back(k > 0 || (std::isfinite(e) && e <= kUnusableError));
        if (std::find(serves.begin(), serves.end(), true) == serves.end()) serves.assign(errors.size(), true);
      }
      double cost = 0;
      for (std::size_t s = 0; s < errors.size(); ++s)
        if ((s >= serves.size() || serves[s]) && std::isfinite(errors[s]) && errors[s] > 0) cost += std::log(errors[s]);
      tried.push_back({R, kappa, cost, mode});
      return cost;
    };
    double plain_before = INFINITY;
    std::vector<double> plain_errors, kernel_errors;
    for (int R = built.map_resolution; R >= std::max(1, min_resolution); R /= 2) {
      const AplLevel at_r = downsampled_level(built, R);
      const SphereMap sum_at_r = level_sum(at_r);
      set.levels[k] = at_r;
      lookups.reset();  // the last resolution's, freed before these are taken
      // A masked level (point sources behind apertures, a few APLs) is graded point by point through
      // irradiance(), and only as plain masked maps: a kernel would blur the intensity the mask's border
      // divides by its coverage.
      if (!masked) lookups = std::make_unique<const detail::LevelLookups>(set, k, ref, o, kLookupBytes);
      const double plain = grade(R, 0.0, KernelMode::plain, plain_errors);
      admit(SphereMap());
      // The cost of the last two-scale candidate admitted at this R, and whether a wider one may still win.
      double two_scale_before = INFINITY, spectral_before = INFINITY, per_order_before = INFINITY;
      bool two_scale_improving = true, spectral_improving = true;
      bool per_order_improving = glm::length(mean_direction(sum_at_r)) >= kMinPerOrderResultant;
      // K·f of every map, per kernel width at this R, kept for the other modes of that width (1.5 and 3
      // texel widths serve six or seven candidates each): the widths used last, as many as kAppliedBytes
      // holds, at most three (a width smoothed once or twice per R, not once per candidate; the same bits).
      std::vector<std::pair<double, std::vector<SphereMap>>> applied;  // least recently used first
      const std::size_t applied_kept =
          std::size_t(std::clamp(kAppliedBytes / std::max(1.0, double(at_r.map_bytes())), 1.0, 3.0));
      const auto applied_for = [&](const SphereMapKernel& kern) -> const std::vector<SphereMap>& {
        for (std::size_t i = 0; i < applied.size(); ++i)
          if (applied[i].first == kern.kappa()) {
            std::rotate(applied.begin() + std::ptrdiff_t(i), applied.begin() + std::ptrdiff_t(i) + 1, applied.end());
            return applied.back().second;
          }
        if (applied.size() >= applied_kept) applied.erase(applied.begin());
        applied.emplace_back(kern.kappa(), kernel_applied_maps(at_r, kern, o.threads));
        return applied.back().second;
      };
      for (const FitKernel& kernel :
           set_rays > 0 && !at_r.apls.empty() && !masked ? fit_kernels(R) : std::vector<FitKernel>{}) {
        const double kappa = kernel.kappa;
        // Two-scale keeps the level's sum sharp at a distance, so only where the maps are fine enough to
        // hold it: at a coarser R it traded the far field for the near field, and the fitting rays could not
        // see the loss (in a trial allowing it at every R, a cos^20 spot's 512-APL level at R 64 was
        // 0.9–1.0 % at d ≤ 1 and 4.4 % at d = 10 against 3.0 % for the far-field point, yet graded within the
        // fit's standard error of the R 128 candidates: apl_sets.md).
        // On one map it is the sharpened kernel at σ/2, already a candidate.
        if (kernel.mode == KernelMode::two_scale && (R != built.map_resolution || built.size() <= 1)) continue;
        // Two-scale is tried from its narrowest width up, and a wider one only while widening has helped:
        // the error is U-shaped in the width (bias grows as noise falls), so once a width graded worse
        // than the one before, or was refused by a guard (a wider kernel lowers a peak more), a wider one
        // would only cost a level's smoothing and grading (the box with holes: σ 6.7° graded far worse
        // than 3.4° at every level, so 10.1° is not tried).
        if (kernel.mode == KernelMode::two_scale && !two_scale_improving) continue;
        if (kernel.mode == KernelMode::two_scale) two_scale_improving = false;  // until admitted and better
        // Spectral likewise: at the built resolution (an expansion at R 128 costs 0.24 s on two cores, once
        // per fit for levels whose sums agree to rounding),
        // widened while that helps; on one map the width only sets the estimate's reach, so one width.
        if (kernel.mode == KernelMode::spectral && (R != built.map_resolution || !spectral_improving)) continue;
        if (kernel.mode == KernelMode::spectral) spectral_improving = false;
        if (kernel.mode == KernelMode::spectral_per_order && (R != built.map_resolution || !per_order_improving))
          continue;
        if (kernel.mode == KernelMode::spectral_per_order) per_order_improving = false;
        // A kernel may not flatten a peak the rays resolve: its bias is largest at a narrow lobe, where a
        // patch-mean reference is flattened too and so cannot see it (a cos^50 spot: σ 1.7° lowered the
        // peak 4 %, against a 2.5 % allowance, and doubled the far field's error at d = 10). Kept with the
        // centred reference, which is only as sharp as its pilot.
        // The gain is the level sum's, taken once for the guard and the smoothing.
        const std::shared_ptr<const SphereMapKernel> held = kernel_for(R, kappa);
        const SphereMapKernel& kern = *held;
        const bool plain_mode = kernel.mode == KernelMode::plain;
        const SphereMap gain = plain_mode ? SphereMap() : kern.gain(sum_at_r, kernel.mode, &spectra);
        const auto [lowering, allowance] = kernel_peak_change(
            sum_at_r, plain_mode ? kern.apply(sum_at_r) : kern.apply_with_gain(sum_at_r, gain), set_rays);
        if (lowering > allowance) continue;
        set.levels[k] = level_from_applied(at_r, applied_for(kern), kern, kernel.mode, gain, o.threads);
        grade(R, kappa, kernel.mode, kernel_errors);
        // A kernel must not give away any distance against the same maps unsmoothed: its bias is largest at
        // a narrow peak, which patches coarser than the peak see only in part, at some distances
        // (a cos^50 spot: σ 1.7° won the geometric mean by the near field and doubled the error at d ≥ 5).
        // Distances where the level is off by more than 25 % unsmoothed are not protected: no error target
        // uses it there (a one-APL level near a spot: 340 % either way), and a sharper far field, right at
        // d ≥ 5, is worse there by what the point model misses.
        bool no_worse = true;
        for (std::size_t s = 0; s < kernel_errors.size() && s < plain_errors.size(); ++s)
          if (std::isfinite(plain_errors[s]) && plain_errors[s] <= kUnusableError &&
              !(kernel_errors[s] <= plain_errors[s]))
            no_worse = false;
        if (!no_worse) continue;
        if (kernel.mode == KernelMode::two_scale) {
          two_scale_improving = tried.back().cost < two_scale_before;
          two_scale_before = tried.back().cost;
        }
        if (kernel.mode == KernelMode::spectral) {
          spectral_improving = built.size() > 1 && tried.back().cost < spectral_before;
          spectral_before = tried.back().cost;
        }
        if (kernel.mode == KernelMode::spectral_per_order) {
          per_order_improving = built.size() > 1 && tried.back().cost < per_order_before;
          per_order_before = tried.back().cost;
        }
        admit(gain);
      }
      // Past the minimum: coarser maps trade noise for blur, and once halving made them worse and the best
      // so far is better still, further halving only blurs more (the error is U-shaped in R).
      if (R % 2 != 0 || (plain > plain_before && best.cost < plain)) break;
      plain_before = plain;
    }
    // One-standard-error rule (Breiman et al. 1984 §3.4.3; Hastie et al., ESL §7.10): the coarsest
    // resolution with a candidate whose cost is within one standard error of the best's
    // (cost_difference_standard_error), and its best candidate there. Finer maps cost four times the
    // bytes and memory per halving; where the held-out rays cannot tell them apart (an LED strip's middle
    // levels) they are not worth it.
    // The rule is for bytes, so a level whose maps hold at most kParsimonyBytes at the best's resolution
    // keeps the best: that the held-out rays cannot tell two candidates apart is no evidence that the
    // coarser is as good (in a trial applying the rule to every level, a cos^20 spot's 8-APL level went to
    // R 64 and was 4.3 % off at d = 10 against 3.1 %; the suite's far-field test refused it).
    const double scale = double(best.resolution) / double(std::max(1, built.map_resolution));
    if (!eligible.empty() && double(built.map_bytes()) * scale * scale > kParsimonyBytes) {
      const std::vector<std::vector<double>>& best_values = eligible[best_at].values;
      std::size_t simpler = best_at;
      for (std::size_t i = 0; i < eligible.size(); ++i) {
        const FitCandidate& c = eligible[i].candidate;
        const FitCandidate& s = eligible[simpler].candidate;
        if (c.resolution > s.resolution) continue;
        if (!(c.cost <= best.cost + cost_difference_standard_error(ref, best_values, eligible[i].values, serves)))
          continue;
        if (c.resolution < s.resolution || c.cost < s.cost) simpler = i;
      }
      // Its best candidate there, whether or not that one passed the test: a candidate closer to the best
      // has a smaller standard error of the difference, so a better one at the same resolution can fail
      // where a worse one passes (an LED strip's 256-APL level, once a spectral candidate at R 128 was
      // best, went to R 32 unsmoothed, 5.3 % off at d = 1, where R 32 sharpened was 4.3 %).
      for (std::size_t i = 0; i < eligible.size(); ++i)
        if (eligible[i].candidate.resolution == eligible[simpler].candidate.resolution &&
            eligible[i].candidate.cost < eligible[simpler].candidate.cost)
          simpler = i;
      best = eligible[simpler].candidate;
      best_at = simpler;
    }
    set.levels[k] = downsampled_level(built, best.resolution);
    // Smoothed with the gain the candidate was graded with (the level sum's at that resolution). Smoothed
    // again rather than kept from its grading: keeping the best candidate so far would hold one more
    // level's maps (64 MB at R 128 × 512 APLs) to save one smoothing, where grading smoothed once per
    // kernel width tried.
    if (best.kappa > 0)
      set.levels[k] = smoothed_level_with_gain(set.levels[k], *kernel_for(best.resolution, best.kappa), best.mode,
                                               eligible.at(best_at).gain, o.threads);
    choice.resolution.push_back(best.resolution);
    choice.kappa.push_back(best.kappa);
    choice.mode.push_back(best.kappa > 0 ? best.mode : KernelMode::plain);
    choice.tried.push_back(std::move(tried));
  }
  return choice;
}

const AplLevel* most_masked_level(const AplSet& set) {
  const AplLevel* best = nullptr;
  for (const AplLevel& l : set.levels)
    if (l.masked_apl_count() > (best ? best->masked_apl_count() : 0)) best = &l;
  return best;
}

AplErrorReport evaluate_held_out_fitted(RaySource& rays, const AplSetBuilder& build, const AplErrorOptions& options,
                                        ResolutionChoice* choice, int min_resolution) {
  AplSet set;
  std::uint64_t train_rays = 0;
  {
    RayHalf train(rays, 0);
    set = build(static_cast<RaySource&>(train));
    train_rays = train.info().ray_count;
  }
  if (set.levels.empty()) throw std::invalid_argument("apl_error: the set has no level");
  RayHalf odd(rays, 1);
  ResolutionChoice c;
  AplSet grading_pilot, own_grading_pilot;
  std::uint64_t fit_rays = 0;
  {
    RayHalf fit(odd, 0);
    AplErrorOptions quiet = options;
    quiet.progress = nullptr;
    // Finer patches for the choice: a patch mean hides detail finer than the patch, so the grading
    // resolution would otherwise cap the resolution chosen (a cos^20 spot: R 16 → 32 and its point error
    // at d = 1 from 19 % to 7 % with 1 M rays). At least twice the grading resolution, finer while the
    // fitting rays give ≥ 32 per patch on average, at most 64 (8192 patches: the cost of grading every
    // candidate). Candidates are ranked on one reference, so its noise mostly cancels in the ranking.
    quiet.patch_resolution = fit_patch_resolution(options.patch_resolution, fit.info().ray_count);
    AplSet far = set;
    far.levels.resize(1);
    // The fit grades single points (a renderer's queries), whatever the report averages.
    quiet.patch_subsamples = 1;
    // Both fit references at the patch centres (centred_reference), by the shape of a pilot made from the
    // fitting rays: independent of the candidates (built from the even rays), so it cannot favour one.
    AplSet pilot;
    {
      const AplSet from_fit = build(static_cast<RaySource&>(fit));
      fit_rays = fit.info().ray_count;
      // A masked pilot takes the graded set's beam borders too (pilot_with_known_borders).
      pilot = pilot_with_known_borders(centring_pilot(from_fit), set);
      if (centring_applies(options)) {
        own_grading_pilot = centring_pilot(from_fit, centring_pilot_sigma(options.patch_resolution));
        grading_pilot = pilot_with_known_borders(own_grading_pilot, set);
      }
    }
    const ReferenceIrradiance fit_ref = centred_reference(gather_reference(fit, set.bounds, quiet), pilot, quiet);
    c = fit_map_resolutions(set, fit_ref, quiet, min_resolution, train_rays);
    AplErrorOptions far_options = quiet;
    far_options.relative_distances = {5, 10};
    far_options.patch_resolution = 64;
    const ReferenceIrradiance far_ref =
        centred_reference(gather_reference(fit, set.bounds, far_options), pilot, far_options);
    const ResolutionChoice far_choice = fit_map_resolutions(far, far_ref, far_options, min_resolution, train_rays);
    c.far_field_resolution = far_choice.resolution.at(0);
    c.far_field_kappa = far_choice.kappa.at(0);
    c.far_field_mode = far_choice.mode.at(0);
  }
  // The grading reference is centred by a pilot from the same rays, 1, 5, 9, …: neither the graded set's
  // maps' nor the grading rays' (they only chose the graded set's resolutions and kernels, a discrete
  // choice), so its shape's noise is independent of both; wider, for the grading's coarser patches.
  RayHalf test(odd, 1);
  AplErrorReport report =
      evaluate_apl_errors(set, test, options, grading_pilot.levels.empty() ? nullptr : &grading_pilot,
                          mask_evidence(own_grading_pilot, fit_rays, &set, train_rays));
  if (choice) *choice = std::move(c);
  return report;
}

bool apply_held_out_fit(AplSet& set, const AplErrorReport& report, const ResolutionChoice* choice) {
  bool same = report.levels.size() == set.levels.size();
  // The same APL counts, and masked where the graded levels were (a half set may find point sources
  // where the whole set, with a stray ray, does not).
  for (std::size_t k = 0; same && k < set.levels.size(); ++k)
    same = report.levels[k].apls == set.levels[k].size() && report.levels[k].masked == set.levels[k].has_masks();
  if (!same) return false;
  HarmonicEstimateCache spectra;
  if (choice)
    for (std::size_t k = 0; k < set.levels.size() && k < choice->resolution.size(); ++k)
      if (choice->resolution[k] <= set.levels[k].map_resolution)
        set.levels[k] =
            fitted_level(set.levels[k], choice->resolution[k], k < choice->kappa.size() ? choice->kappa[k] : 0.0,
                         k < choice->mode.size() ? choice->mode[k] : KernelMode::plain, &spectra);
  store_error_tables(set, report);
  return true;
}

AplSet build_with_held_out_errors(RaySource& rays, const AplSetBuilder& build_half, const AplSetBuilder& build,
                                  const AplErrorOptions& options, AplErrorReport* report, bool* fitted) {
  ResolutionChoice choice;
  AplErrorReport r = evaluate_held_out_fitted(rays, build_half, options, &choice);
  AplSet set = build(rays);
  const bool applied = apply_held_out_fit(set, r, &choice);
  if (fitted) *fitted = applied;
  if (report) *report = std::move(r);
  return set;
}

LUMX_NAMESPACE_END
