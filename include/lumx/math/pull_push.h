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

#include <lumx/version.h>

#include <cstdint>
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
PullPushResult pull_push(const std::vector<double>& flux, const std::vector<double>& count, int R,
                         const PullPushOptions& o = {});

LUMX_NAMESPACE_END
