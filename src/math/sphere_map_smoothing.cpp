// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// smooth_sparse_map (math/sphere_map_smoothing.h): pull sums flux and ray counts up each hemisphere's
// pyramid; push hands each node's flux to its four children, by the data under a dense node and by the
// prior's or the bilinear shape under a sparse one, so every node keeps its flux.
#include <lumx/math/sphere_map_smoothing.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

LUMX_NAMESPACE_BEGIN

std::vector<double> smooth_sparse_map(const std::vector<double>& flux, const std::vector<std::uint32_t>& rays,
                                      int R, double min_rays, const std::vector<double>* prior) {
  if (R < 1 || (R & (R - 1)) != 0) throw std::invalid_argument("smooth_sparse_map: R must be a power of two");
  const std::size_t W = std::size_t(2 * R), texels = W * std::size_t(R);
  if (flux.size() != texels || rays.size() != texels || (prior && prior->size() != texels))
    throw std::invalid_argument("smooth_sparse_map: flux, rays and prior must hold 2R·R texels");
  if (!(min_rays > 0)) return flux;
  int levels = 0;
  while ((R >> levels) > 1) ++levels;  // pyramid level L has resolution R >> L; level `levels` is 1 × 1
  // Pull: per hemisphere square h and level L, flux F and count C, row-major (R >> L)².
  std::vector<std::vector<double>> F[2], G[2];
  std::vector<std::vector<double>> C[2], P[2];  // P: the prior's pyramid (empty without a prior)
  for (int h = 0; h < 2; ++h) {
    F[h].resize(std::size_t(levels) + 1);
    C[h].resize(std::size_t(levels) + 1);
    G[h].resize(std::size_t(levels) + 1);
    F[h][0].resize(std::size_t(R) * std::size_t(R));
    C[h][0].resize(std::size_t(R) * std::size_t(R));
    if (prior) {
      P[h].resize(std::size_t(levels) + 1);
      P[h][0].resize(std::size_t(R) * std::size_t(R));
    }
    for (int y = 0; y < R; ++y)
      for (int x = 0; x < R; ++x) {
        const std::size_t t = std::size_t(y) * W + std::size_t(h * R + x);
        F[h][0][std::size_t(y) * std::size_t(R) + std::size_t(x)] = flux[t];
        C[h][0][std::size_t(y) * std::size_t(R) + std::size_t(x)] = double(rays[t]);
        if (prior) {
          const double v = (*prior)[t];
          P[h][0][std::size_t(y) * std::size_t(R) + std::size_t(x)] = std::isfinite(v) && v > 0 ? v : 0.0;
        }
      }
    for (int L = 1; L <= levels; ++L) {
      const std::size_t n = std::size_t(R >> L), m = 2 * n;
      F[h][std::size_t(L)].assign(n * n, 0.0);
      C[h][std::size_t(L)].assign(n * n, 0.0);
      if (prior) P[h][std::size_t(L)].assign(n * n, 0.0);
      for (std::size_t y = 0; y < m; ++y)
        for (std::size_t x = 0; x < m; ++x) {
          F[h][std::size_t(L)][(y / 2) * n + x / 2] += F[h][std::size_t(L) - 1][y * m + x];
          C[h][std::size_t(L)][(y / 2) * n + x / 2] += C[h][std::size_t(L) - 1][y * m + x];
          if (prior) P[h][std::size_t(L)][(y / 2) * n + x / 2] += P[h][std::size_t(L) - 1][y * m + x];
        }
    }
  }
  // Push. Top: the two hemispheres share the map's flux; an unreliable one is weighted by its area (half).
  const double total = F[0][std::size_t(levels)][0] + F[1][std::size_t(levels)][0];
  {
    double w[2];
    // Which hemisphere the rays went to is never in doubt once there is one: a downlight's few rays must
    // not light the ceiling. Only a map without rays (flux without counts) splits by the prior or area.
    const bool dense = C[0][std::size_t(levels)][0] + C[1][std::size_t(levels)][0] > 0;
    for (int h = 0; h < 2; ++h)
      w[h] = dense ? F[h][std::size_t(levels)][0] : prior ? P[h][std::size_t(levels)][0] : 0.5 * total;
    const double sum = w[0] + w[1];
    for (int h = 0; h < 2; ++h) G[h][std::size_t(levels)].assign(1, sum > 0 ? total * w[h] / sum : 0.5 * total);
    // (Without rays to decide and a dark prior, half each: the map's flux is kept either way.)
  }
  for (int h = 0; h < 2; ++h)
    for (int L = levels; L >= 1; --L) {
      const std::size_t n = std::size_t(R >> L), m = 2 * n;
      const std::vector<double>& parent = G[h][std::size_t(L)];
      const std::vector<double>& data = F[h][std::size_t(L) - 1];
      const std::vector<double>& count = C[h][std::size_t(L)];
      std::vector<double>& child = G[h][std::size_t(L) - 1];
      child.assign(m * m, 0.0);
      // The parent level's flux bilinearly interpolated at a child's centre (parent texel units, centres
      // at i + 0.5; clamped at the square's border), a quarter of it per child.
      auto upsampled = [&](std::size_t cx, std::size_t cy) {
        const double u = (double(cx) + 0.5) / 2.0 - 0.5, v = (double(cy) + 0.5) / 2.0 - 0.5;
        const double fu = std::floor(u), fv = std::floor(v);
        const double ax = u - fu, ay = v - fv;
        auto at = [&](double i, double j) {
          const std::size_t x = std::size_t(std::clamp(i, 0.0, double(n - 1)));
          const std::size_t y = std::size_t(std::clamp(j, 0.0, double(n - 1)));
          return parent[y * n + x];
        };
        return 0.25 * ((1 - ax) * (1 - ay) * at(fu, fv) + ax * (1 - ay) * at(fu + 1, fv) +
                       (1 - ax) * ay * at(fu, fv + 1) + ax * ay * at(fu + 1, fv + 1));
      };
      for (std::size_t py = 0; py < n; ++py)
        for (std::size_t px = 0; px < n; ++px) {
          double w[4], sum = 0;
          const bool dense = count[py * n + px] >= 4 * min_rays;
          for (int k = 0; k < 4; ++k) {
            const std::size_t cx = 2 * px + std::size_t(k & 1), cy = 2 * py + std::size_t(k >> 1);
            w[k] = dense ? data[cy * m + cx] : prior ? P[h][std::size_t(L) - 1][cy * m + cx] : upsampled(cx, cy);
            sum += w[k];
          }
          if (!dense && prior && !(sum > 0)) {  // the prior is dark here: the smooth shape instead
            sum = 0;
            for (int k = 0; k < 4; ++k) {
              w[k] = upsampled(2 * px + std::size_t(k & 1), 2 * py + std::size_t(k >> 1));
              sum += w[k];
            }
          }
          const double g = parent[py * n + px];
          for (int k = 0; k < 4; ++k) {
            const std::size_t cx = 2 * px + std::size_t(k & 1), cy = 2 * py + std::size_t(k >> 1);
            child[cy * m + cx] = sum > 0 ? g * w[k] / sum : 0.25 * g;
          }
        }
    }
  std::vector<double> out(texels);
  for (int h = 0; h < 2; ++h)
    for (int y = 0; y < R; ++y)
      for (int x = 0; x < R; ++x)
        out[std::size_t(y) * W + std::size_t(h * R + x)] = G[h][0][std::size_t(y) * std::size_t(R) + std::size_t(x)];
  return out;
}

LUMX_NAMESPACE_END
