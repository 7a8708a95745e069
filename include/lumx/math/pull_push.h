// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/pull_push.h — progressive preview filtering of a particle histogram on an equal-area sphere map
// (seed 002 §5; algorithms.md §6): a noisy early histogram becomes a smooth image that keeps the borders
// of bright and dark regions.
//
// Pull: a pyramid of sums — each texel of level l+1 holds the flux and the particle count of the 2×2 texels
// below it (levels halve R until R = 1; the two hemisphere squares stay apart, so every texel keeps equal
// solid angle). Push, coarse to fine: a texel with at least `stable_count` particles is *stable* and keeps
// its value (§5.1); an unstable one is replaced by an upsampled value of the level above, / 4 since levels
// hold sums (§5.2) — unless it lies on a shadow border: it has stable neighbours, but no more than 6 of 8
// (Algorithm 2). Borders are kept only on levels ≥ `always_upsample_below`; finer levels upsample every
// unstable texel, so borders do not look pixelated (§5.3). Upsampling is bilateral (§5.5): the 4 nearest
// coarse texels H_i, weighted by closeness c_i = exp(−d_i² / 2σ_d²) (d_i in coarse texels) and similarity
// s_i = exp(−(f̃ − f(H_i))² / 2σ_r²) to the bilinear estimate f̃, with σ_r = `sigma_range` · f̃ — which
// cuts the leaks of light into shadow that plain bilinear interpolation makes (§5.4). Neighbours across the
// equator follow the sphere map's seam rule (math/sphere_map.h).
//
// The filtered map is rescaled to the histogram's total flux: a preview shows the light's distribution,
// and pushing values into unstable texels must not create or lose flux.
#pragma once

#include <lumx/math/sphere_map.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

LUMX_NAMESPACE_BEGIN

struct PullPushOptions {
  double stable_count = 32;       ///< particles a texel needs to be stable (002 §5.1)
  int always_upsample_below = 2;  ///< levels 0 .. this − 1 upsample every unstable texel (002 §5.3)
  double sigma_spatial = 1.0;     ///< σ_d of the closeness weights, in coarse-level texels
  double sigma_range = 0.5;       ///< σ_r as a fraction of the bilinear estimate f̃
};

/// What the push did to each level-0 texel.
enum class PullPushTexel : std::uint8_t { stable, upsampled, border };

struct PullPushResult {
  std::vector<double> flux;            ///< per level-0 texel (y · 2R + x), the histogram's unit
  std::vector<PullPushTexel> kind;     ///< per level-0 texel
  int levels = 0;                      ///< pyramid levels, level 0 included
};

/// Filters a histogram of square resolution R (a power of two, image 2R × R): `flux` and `count` per texel
/// (y · 2R + x). Throws std::invalid_argument for a bad R, sizes that differ from 2R², or a negative or
/// non-finite value.
inline PullPushResult pull_push(const std::vector<double>& flux, const std::vector<double>& count, int R,
                                const PullPushOptions& o = {}) {
  if (R < 1 || R > sphere_map::kMaxResolution || (R & (R - 1)) != 0)
    throw std::invalid_argument("pull_push: R must be a power of two in [1, " +
                                std::to_string(sphere_map::kMaxResolution) + "]");
  const std::size_t n = std::size_t(2) * std::size_t(R) * std::size_t(R);
  if (flux.size() != n || count.size() != n)
    throw std::invalid_argument("pull_push: flux and count must have 2R^2 values");
  for (std::size_t i = 0; i < n; ++i)
    if (!(flux[i] >= 0) || !std::isfinite(flux[i]) || !(count[i] >= 0) || !std::isfinite(count[i]))
      throw std::invalid_argument("pull_push: flux and count must be finite and >= 0 (texel " + std::to_string(i) +
                                  ")");

  // Pull: level l has square resolution R >> l.
  std::vector<std::vector<double>> f{flux}, c{count};
  for (int r = R; r > 1; r /= 2) {
    const int h = r / 2;
    std::vector<double> fu(std::size_t(2) * h * h), cu(fu.size());
    const std::vector<double>& fd = f.back();
    const std::vector<double>& cd = c.back();
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < 2 * h; ++x) {
        const std::size_t up = std::size_t(y) * std::size_t(2 * h) + std::size_t(x);
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) {
            const std::size_t down = std::size_t(2 * y + dy) * std::size_t(2 * r) + std::size_t(2 * x + dx);
            fu[up] += fd[down];
            cu[up] += cd[down];
          }
      }
    f.push_back(std::move(fu));
    c.push_back(std::move(cu));
  }
  const int levels = int(f.size());

  // Push: `above` holds the filtered sums of level l+1.
  std::vector<double> above = f.back();
  std::vector<PullPushTexel> kind;
  for (int l = levels - 2; l >= 0; --l) {
    const int r = R >> l, h = r / 2;
    const std::vector<double>& fl = f[std::size_t(l)];
    const std::vector<double>& cl = c[std::size_t(l)];
    std::vector<double> out(fl.size());
    kind.assign(fl.size(), PullPushTexel::stable);
    for (int y = 0; y < r; ++y)
      for (int x = 0; x < 2 * r; ++x) {
        const std::size_t i = std::size_t(y) * std::size_t(2 * r) + std::size_t(x);
        if (cl[i] >= o.stable_count) {
          out[i] = fl[i];
          continue;
        }
        const int half = x / r, lx = x % r;
        if (l >= o.always_upsample_below) {  // Algorithm 2: an unstable texel with 1..6 stable neighbours
          int stable = 0;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
              if ((dx || dy) && cl[sphere_map::seam_texel_index(r, half, lx + dx, y + dy)] >= o.stable_count) ++stable;
          if (stable > 0 && stable <= 6) {
            out[i] = fl[i];
            kind[i] = PullPushTexel::border;
            continue;
          }
        }
        // Bilateral interpolation from the 4 nearest texels of the level above (their centres in its
        // texel units: this texel's centre is at (lx + 0.5) / 2 − 0.5).
        const double ux = (lx + 0.5) / 2 - 0.5, uy = (y + 0.5) / 2 - 0.5;
        const int x0 = int(std::floor(ux)), y0 = int(std::floor(uy));
        const double tx = ux - x0, ty = uy - y0;
        double v[4], d2[4];
        for (int k = 0; k < 4; ++k) {
          const int kx = k & 1, ky = k >> 1;
          v[k] = above[sphere_map::seam_texel_index(h, half, x0 + kx, y0 + ky)];
          d2[k] = (tx - kx) * (tx - kx) + (ty - ky) * (ty - ky);
        }
        const double bilinear = (1 - ty) * ((1 - tx) * v[0] + tx * v[1]) + ty * ((1 - tx) * v[2] + tx * v[3]);
        double value = bilinear;
        const double sr = o.sigma_range * bilinear;
        if (sr > 0) {
          double sum = 0, weight = 0;
          for (int k = 0; k < 4; ++k) {
            const double w = std::exp(-d2[k] / (2 * o.sigma_spatial * o.sigma_spatial)) *
                             std::exp(-(bilinear - v[k]) * (bilinear - v[k]) / (2 * sr * sr));
            sum += w * v[k];
            weight += w;
          }
          if (weight > 0) value = sum / weight;
        }
        out[i] = value / 4;
        kind[i] = PullPushTexel::upsampled;
      }
    above = std::move(out);
  }
  if (levels == 1) kind.assign(above.size(), PullPushTexel::stable);

  // Keep the histogram's flux.
  double total_in = 0, total_out = 0;
  for (std::size_t i = 0; i < n; ++i) total_in += flux[i], total_out += above[i];
  if (total_out > 0)
    for (double& v : above) v *= total_in / total_out;
  return {std::move(above), std::move(kind), levels};
}

LUMX_NAMESPACE_END
