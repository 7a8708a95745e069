// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// pull_push (math/pull_push.h): [Krosl2017] §5's pull of sums and bilateral push, then the result rescaled to
// the histogram's flux.
#include <lumx/math/pull_push.h>

#include <lumx/math/sphere_map.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

PullPushResult pull_push(const std::vector<double>& flux, const std::vector<double>& count, int R,
                         const PullPushOptions& o) {
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
