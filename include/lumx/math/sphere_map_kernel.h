// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/sphere_map_kernel.h — flux-exact smoothing of a sphere map by a von Mises–Fisher kernel.
//
// A map binned from m rays over T texels has a relative noise of about 1/√(m/T) per texel, and a
// renderer's point query sees it. Convolving with the von Mises–Fisher kernel
// K(ω, ω') ∝ exp(κ (ω·ω' − 1)) (the spherical Gaussian: σ ≈ 1/√κ rad along each tangent axis) averages
// each texel with its neighbours within a few σ, for a bias of about Δf / (2κ) (Δ the Laplacian on the
// sphere: for a Lambertian cos θ, −cos θ / κ, 0.25 % at κ = 400) — a kernel density estimate on the
// sphere (seed 004 §4; algorithms.md §8) with the texels as its samples. How wide is measured, not
// assumed: the held-out fit (apl/error.h) tries several κ per level and keeps what the held-out rays
// grade best, so a sharp shadow border backed by many rays keeps a narrow kernel or none.
//
// Discretely, each source texel s hands its value to the texels t with weights
// w_ts = exp(κ(ω_t·ω_s − 1)) / Σ_t' exp(κ(ω_t'·ω_s − 1)), truncated where the kernel is below 10⁻³ of
// its peak (1 − ω_t·ω_s > ln(10³)/κ, 3.7 σ). The weights of each source sum to 1 and texels are equal-area, so
// the map's flux is kept exactly (up to float rounding), whatever κ; a map with one lit texel becomes the
// kernel. Directions are texel centres, so the kernel crosses the equator seam and the squares' diagonals
// as the sphere does, not as the square's coordinates do.
//
// K's bias flattens a narrow lobe (a spot's peak texel −13 % at σ 3.4° for cos^50). The sharpened estimate
// G + α(G − K·G), G = K·f, cancels it to O(κ⁻²) and, with α = 1 + κh²/4, the blur of reading a map too
// (sharpening_strength, sharpening_gain); a level shares one gain so its sparse maps sum to their sum's
// sharpened estimate (apply_with_gain).
#pragma once

#include <lumx/math/sphere_map.h>
#include <lumx/math/sphere_map_harmonics.h>
#include <lumx/version.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// How a kernel K smooths a level's maps: K·f alone; sharpened, G + α(G − K·G) with G = K·f
/// (SphereMapKernel::sharpening_gain); or as the weights of a local linear fit inside the rays' support
/// (SphereMapKernel::local_linear_gain).
/// extrapolated: the blur extrapolated to zero from K·f, K²·f and K³·f (SphereMapKernel::extrapolated_gain:
/// its leading two orders of blur cancelled where sharpening cancels one). two_scale: each map smoothed by K, the level's shape from
/// its sum sharpened at half K's width (SphereMapKernel::two_scale_gain). spectral: each map smoothed by K,
/// the level's shape from its sum's harmonic expansion shrunk degree by degree (SphereMapKernel::spectral_gain).
/// spectral_per_order: as spectral, the expansion taken about the sum's mean direction and shrunk per degree
/// and order (harmonic_estimate_per_order: for round beams).
enum class KernelMode { plain, sharpened, local_linear, extrapolated, two_scale, spectral, spectral_per_order };

/// "", "sharpened", "local linear", "extrapolated", "two-scale", "spectral" or "spectral per order" (for
/// reports and the bundle's provenance).
inline const char* kernel_mode_name(KernelMode mode) {
  switch (mode) {
    case KernelMode::sharpened: return "sharpened";
    case KernelMode::local_linear: return "local linear";
    case KernelMode::extrapolated: return "extrapolated";
    case KernelMode::two_scale: return "two-scale";
    case KernelMode::spectral: return "spectral";
    case KernelMode::spectral_per_order: return "spectral per order";
    default: return "";
  }
}

/// sum (one channel) += the sum of `map`'s channels, texel by texel (same resolution): the one-channel
/// total a level's gains are computed from. Throws std::invalid_argument for another resolution.
inline void accumulate_channels(SphereMap& sum, const SphereMap& map) {
  if (sum.resolution() != map.resolution())
    throw std::invalid_argument("accumulate_channels: a map of resolution " + std::to_string(map.resolution()) +
                                " into one of " + std::to_string(sum.resolution()));
  const int C = map.channels();
  for (std::size_t t = 0; t < sum.texel_count(); ++t)
    for (int c = 0; c < C; ++c) sum.data()[t] += map.data()[t * std::size_t(C) + std::size_t(c)];
}

class SphereMapKernel {
 public:
  /// Largest resolution the kernel is built for. Finding each texel's neighbours is a grid search (cost
  /// ∝ the weights), so the limit is memory: at R 128 a kernel of σ = 3 texel widths holds 1.3·10⁷
  /// weights in 8.8·10⁵ runs (58 MB).
  static constexpr int kMaxResolution = 128;
  /// Kernels shared() keeps: more than the held-out fit uses (0.75, 1.5 and 3 texel widths at each of R 32,
  /// 64 and 128, and the two-scale kernels of 2.25 and 4.5 at the level's built resolution: up to 11, about
  /// 260 MB when that is R 128, of which 4.5 texel widths holds 2.9·10⁷ weights, 126 MB), since a cache that drops
  /// the oldest and is smaller than the cycle of a level's candidates would rebuild every kernel for every
  /// level.
  static constexpr std::size_t kCached = 12;
  /// Most weights a kernel may hold (4 bytes each, and 8 a run of consecutive targets: 15–21 weights a run
  /// at σ 3–4.5 texel widths).
  static constexpr std::size_t kMaxWeights = std::size_t(64) << 20;

  /// The kernel for maps of resolution R (1..kMaxResolution) and concentration κ > 0 (1/rad²).
  SphereMapKernel(int resolution, double kappa);

  /// The kernel for (R, κ) from a small process-wide cache (the last kCached built; thread-safe): building one
  /// costs more than applying it to a few hundred maps.
  static std::shared_ptr<const SphereMapKernel> shared(int resolution, double kappa) {
    static std::mutex mutex;
    static std::vector<std::shared_ptr<const SphereMapKernel>> cache;
    {
      std::lock_guard<std::mutex> lock(mutex);
      for (const auto& k : cache)
        if (k->resolution() == resolution && k->kappa() == kappa) return k;
    }
    auto k = std::make_shared<const SphereMapKernel>(resolution, kappa);
    std::lock_guard<std::mutex> lock(mutex);
    if (cache.size() >= kCached) cache.erase(cache.begin());
    cache.push_back(k);
    return k;
  }

  int resolution() const { return resolution_; }
  double kappa() const { return kappa_; }
  /// The kernel's standard deviation along one tangent axis, 1/√κ (rad).
  double sigma() const { return 1.0 / std::sqrt(kappa_); }
  /// Non-zero weights in all (the cost of apply, per channel).
  std::size_t weight_count() const { return weights_.size(); }
  /// Runs of consecutive targets in all; the kernel holds 4 bytes a weight and 8 a run (R 128 at σ 1.5 texel
  /// widths: 7.8 weights a run, SphereMapKernel.BuildsAtTheLargestResolutionAndKeepsFlux; wider kernels have
  /// longer runs).
  std::size_t run_count() const { return runs_.size(); }

  /// The smoothed map (same resolution and channels; flux kept). Throws for another resolution.
  ///
  /// out_t = Σ_s w_ts in_s, summed in double over s in increasing order: each source texel that holds
  /// anything is scattered to its targets, so a map with few lit texels (an APL's map of a few thousand
  /// rays) costs only those; skipping an empty source skips adding 0, so the sums are those of a gather
  /// over every source, bit for bit.
  SphereMap apply(const SphereMap& in) const {
    if (in.resolution() != resolution_)
      throw std::invalid_argument("SphereMapKernel: a map of resolution " + std::to_string(in.resolution()) +
                                  " for a kernel of " + std::to_string(resolution_));
    const int C = in.channels();
    SphereMap out(resolution_, C);
    const float* src = in.data();
    const std::size_t T = offsets_.size() - 1;
    std::vector<double> sum(T * std::size_t(C), 0.0);
    if (C == 1) {  // every APL map: the same sums without the channel loop
      double* out_sum = sum.data();
      for (std::size_t s = 0; s < T; ++s) {
        if (src[s] == 0.0f) continue;
        const double v = double(src[s]);
        const float* w = weights_.data() + offsets_[s];
        for (std::uint32_t r = run_offsets_[s]; r < run_offsets_[s + 1]; ++r) {
          double* to = out_sum + runs_[r].first;
          const std::uint32_t n = runs_[r].second;
          for (std::uint32_t j = 0; j < n; ++j) to[j] += double(w[j]) * v;  // contiguous, no index loads
          w += n;
        }
      }
    }
    for (std::size_t s = 0; s < T && C != 1; ++s) {
      if (!lit(src, s, C)) continue;
      std::uint32_t i = offsets_[s];
      for (std::uint32_t r = run_offsets_[s]; r < run_offsets_[s + 1]; ++r)
        for (std::uint32_t t = runs_[r].first; t < runs_[r].first + runs_[r].second; ++t, ++i)
          for (int c = 0; c < C; ++c)
            sum[std::size_t(t) * std::size_t(C) + std::size_t(c)] +=
                double(weights_[i]) * double(src[s * std::size_t(C) + std::size_t(c)]);
    }
    float* dst = out.data();
    for (std::size_t i = 0; i < sum.size(); ++i) dst[i] = float(sum[i]);
    return out;
  }

  /// α of sharpening_gain: 1 + κ h²/4, h = √(4π / 2R²) the texel width. Twicing (α = 1) cancels K's own
  /// blur; a map is also blurred where it is read: a texel holds the mean over its width (variance h²/12
  /// per axis) and lookups interpolate bilinearly between texel centres (on average h²/6 more), h²/4 in
  /// all, which is α − 1 times K's variance 1/κ. (A cos^20 spot from 1 M rays, 512 APLs, R 64, σ 3.4°:
  /// 5.7 % at d = 10 with α = 1, 4.3 % with this α; apl_sets.md.)
  double sharpening_strength() const {
    const double h2 = 4.0 * kPi / (2.0 * double(resolution_) * double(resolution_));
    return 1.0 + kappa_ * h2 / 4.0;
  }

  /// The gain that sharpens this kernel for maps that sum to `total` (any channels; their sum is used): with
  /// G = K·total, the estimate G + α(G − K·G) (twicing for α = 1: Stuetzle & Mittal 1979; Silverman 1986
  /// §3.10) cancels K's leading bias Δf/(2κ) and, with α = sharpening_strength(), the blur of the lookup
  /// too, leaving O(κ⁻²) — a narrow lobe keeps its peak under a kernel wide enough to average its flanks'
  /// noise. It is clamped at 0 (empty directions stay dark) and rescaled to G's flux, and the gain is its
  /// ratio to G per texel (0 where G is, at most 1 + α).
  SphereMap sharpening_gain(const SphereMap& total) const {
    SphereMap sum(resolution_, 1);
    accumulate_channels(sum, total);
    const SphereMap once = apply(sum), twice = apply(once);
    const double alpha = sharpening_strength();
    SphereMap gain(resolution_, 1);
    double flux = 0, kept = 0;
    for (std::size_t t = 0; t < gain.texel_count(); ++t) {
      flux += double(once.data()[t]);
      kept += std::max(0.0, (1.0 + alpha) * double(once.data()[t]) - alpha * double(twice.data()[t]));
    }
    const double scale = kept > 0 ? flux / kept : 0.0;
    for (std::size_t t = 0; t < gain.texel_count(); ++t) {
      const double g = double(once.data()[t]);
      const double v = std::max(0.0, (1.0 + alpha) * g - alpha * double(twice.data()[t])) * scale;
      gain.data()[t] = g > 0 ? float(v / g) : 0.0f;
    }
    return gain;
  }

  /// The gain of the third-order estimate for maps that sum to `total` (any channels; their sum is used).
  /// On the sphere at this scale K^j is a heat kernel of variance j/κ per axis, and reading a map adds
  /// b = h²/4 (sharpening_strength), so K^j·f as read is f + (j + β)·(Δf/2κ) + (j + β)²·(Δ²f/8κ²) + …,
  /// β = κb. Richardson extrapolation to zero blur through the three nodes t_j = j + β: the estimate
  /// Σ c_j K^j·f with c_j = Π_{i≠j} t_i / (t_i − t_j) (Lagrange's basis at 0) cancels the first two orders
  /// (for β = 0, 3K − 3K² + K³, iterated twicing: Stuetzle & Mittal 1979). K (von Mises–Fisher, truncated)
  /// and a lookup's blur (a texel mean read bilinearly) are Gaussian to leading order only, so what is left
  /// is of their higher moments as well as O(κ⁻³). Sharpening is
  /// the same construction through two nodes (c = 1 + α, −α). The weights are larger (|c| up to 3 + …),
  /// so its noise is about 1.15× the sharpened estimate's at the same κ (Gaussian kernels: Σ c_i c_j /
  /// (i + j) = 1.22 against 0.92): a wider kernel buys the noise back, which the held-out fit decides.
  /// Clamped at 0, rescaled to G's flux; the gain is the ratio to G = K·total (0 where G is 0).
  SphereMap extrapolated_gain(const SphereMap& total) const {
    SphereMap sum(resolution_, 1);
    accumulate_channels(sum, total);
    const SphereMap k1 = apply(sum), k2 = apply(k1), k3 = apply(k2);
    const double beta = sharpening_strength() - 1.0;
    const double t[3] = {1 + beta, 2 + beta, 3 + beta};
    double c[3];
    for (int j = 0; j < 3; ++j) {
      c[j] = 1;
      for (int i = 0; i < 3; ++i)
        if (i != j) c[j] *= t[i] / (t[i] - t[j]);
    }
    SphereMap gain(resolution_, 1);
    double flux = 0, kept = 0;
    const std::size_t T = gain.texel_count();
    std::vector<double> estimate(T);
    for (std::size_t i = 0; i < T; ++i) {
      flux += double(k1.data()[i]);
      // Where K·f is 0 the gain is 0 (beyond K's reach c₂K² + c₃K³ can be positive): keep it out of the
      // flux the rescaling matches.
      if (!(k1.data()[i] > 0)) continue;
      estimate[i] = std::max(0.0, c[0] * double(k1.data()[i]) + c[1] * double(k2.data()[i]) + c[2] * double(k3.data()[i]));
      kept += estimate[i];
    }
    const double scale = kept > 0 ? flux / kept : 0.0;
    for (std::size_t i = 0; i < T; ++i) {
      const double g = double(k1.data()[i]);
      gain.data()[i] = g > 0 ? float(estimate[i] * scale / g) : 0.0f;
    }
    return gain;
  }

  /// The gain that gives maps summing to `total` the shape of that sum sharpened at half this kernel's
  /// width (κ' = 4κ), while each map is smoothed at the full width. A level's maps split one luminaire's
  /// rays among its APLs: each map has a few thousand of them and needs a wide kernel against its own noise,
  /// while the sum holds every ray and affords a narrow one. With the gain g = S'/K·S (S' the sum sharpened
  /// at κ'), the maps K·m_i·g sum to S' (up to each map's flux rescaling): at a distance, where a point reads
  /// every APL in nearly one direction, the level is as sharp as S'; near the luminaire, where points read
  /// the APLs in different directions, each map departs from the shared shape only as K·m_i/K·S, its own
  /// share smoothed at the wide kernel (a multiplicative correction of a pilot shape: Hjort & Glad 1995).
  /// 0 where K·total is 0.
  SphereMap two_scale_gain(const SphereMap& total) const {
    SphereMap sum(resolution_, 1);
    accumulate_channels(sum, total);
    return pilot_gain(sum, shared(resolution_, 4.0 * kappa_)->apply_sharpened(sum));
  }

  /// The gain that gives maps summing to `total` the shape `shape` (one channel, this resolution) while
  /// each is smoothed by this kernel: shape / K·total per texel, 0 where K·total is 0 (two_scale_gain,
  /// spectral_gain).
  SphereMap pilot_gain(const SphereMap& total, const SphereMap& shape) const {
    if (shape.resolution() != resolution_ || shape.channels() != 1)
      throw std::invalid_argument("SphereMapKernel: the shape must be one channel at the kernel's resolution");
    SphereMap sum(resolution_, 1);
    accumulate_channels(sum, total);
    const SphereMap wide = apply(sum);
    SphereMap gain(resolution_, 1);
    for (std::size_t t = 0; t < gain.texel_count(); ++t) {
      const double g = double(wide.data()[t]);
      gain.data()[t] = g > 0 ? float(double(shape.data()[t]) / g) : 0.0f;
    }
    return gain;
  }

  /// The gain that gives maps summing to `total` the shape of harmonic_estimate(total): the sum's harmonic
  /// expansion with each degree shrunk against the rays' noise (sphere_map_harmonics.h), while each map is
  /// smoothed at this kernel's width. As two_scale_gain, with the sum's estimate no longer a kernel's: a
  /// kernel, sharpened or not, leaves a floor of bias and noise on a narrow lobe that the shrunk expansion
  /// does not (a cos^20 lobe from 10⁶ rays: 3.00 % at the best sharpened width against 1.63 % for the
  /// oracle-weighted expansion; apl_sets.md). For one map (a one-APL level) the result is that estimate,
  /// inside this kernel's reach of the rays. 0 where K·total is 0. `cache`, when given, keeps the
  /// expansion for the next call with the same sum.
  /// With `per_order`, the shape is harmonic_estimate_per_order(total)'s.
  SphereMap spectral_gain(const SphereMap& total, HarmonicEstimateCache* cache = nullptr, bool per_order = false) const {
    SphereMap sum(resolution_, 1);
    accumulate_channels(sum, total);
    if (cache) return pilot_gain(sum, cache->estimate(sum, 0, per_order));
    return pilot_gain(sum, per_order ? harmonic_estimate_per_order(sum).estimate : harmonic_estimate(sum).estimate);
  }

  /// apply(in) multiplied texel by texel by `gain` (one channel, this resolution), each channel then
  /// rescaled to keep its flux exactly. Applied to every map of a level with the gain of the level's sum,
  /// the maps sum to that sum's twiced estimate (up to the rescaling) — a linear kernel per map with one
  /// nonnegative correction, where twicing each sparse map alone would clamp the negative rings of its
  /// isolated rays and flatten the very lobe it is meant to keep.
  SphereMap apply_with_gain(const SphereMap& in, const SphereMap& gain) const {
    check_gain(gain);  // before the smoothing it would waste
    return with_gain(in, apply(in), gain);
  }

  /// apply_with_gain(in, gain) from `smoothed` = apply(in), to the same bits: every mode of one kernel starts
  /// from K·f, so a caller trying several modes (the held-out fit) smooths each map once.
  SphereMap with_gain(const SphereMap& in, SphereMap smoothed, const SphereMap& gain) const {
    check_gain(gain);
    if (smoothed.resolution() != in.resolution() || smoothed.channels() != in.channels() || in.resolution() != resolution_)
      throw std::invalid_argument("SphereMapKernel: the smoothed map must be the input's, at the kernel's resolution");
    SphereMap out = std::move(smoothed);
    const int C = in.channels();
    const std::size_t T = out.texel_count();
    for (int c = 0; c < C; ++c) {
      double flux = 0, kept = 0;
      for (std::size_t t = 0; t < T; ++t) {
        const std::size_t i = t * std::size_t(C) + std::size_t(c);
        flux += double(in.data()[i]);
        out.data()[i] *= gain.data()[t];
        kept += double(out.data()[i]);
      }
      if (kept > 0 && flux > 0) {
        const float scale = float(flux / kept);
        for (std::size_t t = 0; t < T; ++t) out.data()[t * std::size_t(C) + std::size_t(c)] *= scale;
      }
    }
    return out;
  }

  /// One map sharpened alone: apply_with_gain(in, sharpening_gain(in)).
  SphereMap apply_sharpened(const SphereMap& in) const { return apply_with_gain(in, sharpening_gain(in)); }

  /// The gain that turns this kernel into a local linear estimate for maps that sum to `total` (any
  /// channels; their sum is used). At each texel t where the sum is non-zero (the support: directions the
  /// rays reached), f is fitted by a + b·(u, v) in the tangent plane at ω_t (u, v the source directions'
  /// components along two tangent axes), by least squares weighted by the kernel's row t over the support's
  /// texels only; the estimate is a (Fan & Gijbels 1996 §3.2; on the sphere the tangent-plane projection is
  /// the local chart). Where the support is symmetric about t, a equals K·f up to the normalisation; where
  /// the support ends (a Lambertian emitter's horizon, a shadow's border), the plain kernel loses the mass
  /// that falls outside and leaks it across, a bias of order σ·|∇f| there, while the linear term absorbs the
  /// slope, leaving O(σ²) as inside (the boundary bias of local constant estimates, §3.2.5). Outside the
  /// support the estimate is 0: empty directions stay exactly dark at this resolution. Clamped at 0 and
  /// rescaled to the sum's flux; the gain is its ratio to K·total (0 where K·total is 0). A texel whose
  /// weighted support is degenerate (too few texels in reach to fit a slope) keeps the local mean.
  SphereMap local_linear_gain(const SphereMap& total) const {
    SphereMap sum(resolution_, 1);
    accumulate_channels(sum, total);
    const SphereMap once = apply(sum);
    SphereMap fitted(resolution_, 1);
    double flux = 0, kept = 0;
    const std::size_t T = sum.texel_count();
    for (std::size_t t = 0; t < T; ++t) {
      flux += double(sum.data()[t]);
      if (!(sum.data()[t] > 0)) continue;
      const glm::dvec3& n = centres_[t];
      const glm::dvec3 e1 = glm::normalize(glm::cross(std::abs(n.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0), n));
      const glm::dvec3 e2 = glm::cross(n, e1);
      // Normal equations of the weighted fit, in tangent coordinates relative to ω_t (so u, v ~ σ).
      double s0 = 0, su = 0, sv = 0, suu = 0, suv = 0, svv = 0, f0 = 0, fu = 0, fv = 0;
      // Row t's sources are the targets of source t (a symmetric relation), in increasing order; w_ts as
      // the constructor computed it.
      for (std::uint32_t r = run_offsets_[t]; r < run_offsets_[t + 1]; ++r)
        for (std::size_t src = runs_[r].first; src < std::size_t(runs_[r].first) + runs_[r].second; ++src) {
          const double f = double(sum.data()[src]);
          if (!(f > 0)) continue;
          const double w = double(float(std::exp(-kappa_ * (1.0 - glm::dot(centres_[src], centres_[t]))) / normaliser_[src]));
          const double u = glm::dot(centres_[src], e1), v = glm::dot(centres_[src], e2);
          s0 += w, su += w * u, sv += w * v, suu += w * u * u, suv += w * u * v, svv += w * v * v;
          f0 += w * f, fu += w * u * f, fv += w * v * f;
        }
      // a from the 3 × 3 system by Cramer's rule; the local mean where the fit cannot see a slope.
      const double det = s0 * (suu * svv - suv * suv) - su * (su * svv - suv * sv) + sv * (su * suv - suu * sv);
      double a = s0 > 0 ? f0 / s0 : 0.0;
      if (std::abs(det) > 1e-6 * s0 * suu * svv && suu * svv > 0) {
        const double det_a = f0 * (suu * svv - suv * suv) - su * (fu * svv - suv * fv) + sv * (fu * suv - suu * fv);
        a = det_a / det;
      }
      fitted.data()[t] = float(std::max(0.0, a));
      kept += double(fitted.data()[t]);
    }
    const double rescale = kept > 0 ? flux / kept : 0.0;
    SphereMap gain(resolution_, 1);
    for (std::size_t t = 0; t < T; ++t) {
      const double g = double(once.data()[t]);
      gain.data()[t] = g > 0 ? float(double(fitted.data()[t]) * rescale / g) : 0.0f;
    }
    return gain;
  }

  /// The gain of `mode` for maps that sum to `total` (sharpening_gain, local_linear_gain, extrapolated_gain
  /// two_scale_gain or spectral_gain (per order for spectral_per_order), with `cache` if given; all ones for
  /// plain).
  SphereMap gain(const SphereMap& total, KernelMode mode, HarmonicEstimateCache* cache = nullptr) const {
    if (mode == KernelMode::sharpened) return sharpening_gain(total);
    if (mode == KernelMode::local_linear) return local_linear_gain(total);
    if (mode == KernelMode::extrapolated) return extrapolated_gain(total);
    if (mode == KernelMode::two_scale) return two_scale_gain(total);
    if (mode == KernelMode::spectral) return spectral_gain(total, cache);
    if (mode == KernelMode::spectral_per_order) return spectral_gain(total, cache, true);
    SphereMap ones(resolution_, 1);
    std::fill(ones.values().begin(), ones.values().end(), 1.0f);
    return ones;
  }

  /// One map smoothed alone in `mode`.
  SphereMap apply(const SphereMap& in, KernelMode mode) const {
    return mode == KernelMode::plain ? apply(in) : apply_with_gain(in, gain(in, mode));
  }


 private:
  void check_gain(const SphereMap& gain) const {
    if (gain.resolution() != resolution_ || gain.channels() != 1)
      throw std::invalid_argument("SphereMapKernel: the gain must be one channel at the kernel's resolution");
  }

  int resolution_ = 0;
  double kappa_ = 0;
  std::vector<glm::dvec3> centres_;  ///< texel centres (unit directions)
  std::vector<std::uint32_t> offsets_;      ///< per source: where its weights start in weights_ (CSR)
  std::vector<std::uint32_t> run_offsets_;  ///< per source: where its runs start in runs_ (CSR)
  std::vector<std::pair<std::uint32_t, std::uint32_t>> runs_;  ///< (first target, count): targets, increasing
  std::vector<float> weights_;              ///< w_ts in that order (each source's sum to 1)
  std::vector<double> normaliser_;                ///< per source: Σ_t exp(κ(ω_t·ω_s − 1)) over its targets

  /// Whether texel s of a C-channel map holds anything to smooth.
  static bool lit(const float* map, std::size_t s, int C) {
    for (int c = 0; c < C; ++c)
      if (map[s * std::size_t(C) + std::size_t(c)] != 0.0f) return true;
    return false;
  }
};

LUMX_NAMESPACE_END
