// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include "contour.h"

#include <cmath>

LUMX_NAMESPACE_BEGIN

std::vector<Segment> contour_segments(const std::vector<double>& v, int nx, int ny, double level) {
  std::vector<Segment> out;
  auto at = [&](int ix, int iy) { return v[static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(ix)]; };
  for (int iy = 0; iy + 1 < ny; ++iy)
    for (int ix = 0; ix + 1 < nx; ++ix) {
      // Corners counter-clockwise: 0 (ix, iy), 1 (ix+1, iy), 2 (ix+1, iy+1), 3 (ix, iy+1).
      const double c[4] = {at(ix, iy), at(ix + 1, iy), at(ix + 1, iy + 1), at(ix, iy + 1)};
      if (!std::isfinite(c[0]) || !std::isfinite(c[1]) || !std::isfinite(c[2]) || !std::isfinite(c[3])) continue;
      const double px[4] = {0, 1, 1, 0}, py[4] = {0, 0, 1, 1};
      int mask = 0;
      for (int k = 0; k < 4; ++k)
        if (c[k] >= level) mask |= 1 << k;
      if (mask == 0 || mask == 15) continue;
      // Crossing on edge k (corner k to k+1).
      auto cross = [&](int k, double& x, double& y) {
        const int j = (k + 1) % 4;
        const double t = (level - c[k]) / (c[j] - c[k]);
        x = ix + px[k] + t * (px[j] - px[k]);
        y = iy + py[k] + t * (py[j] - py[k]);
      };
      std::vector<int> edges;
      for (int k = 0; k < 4; ++k)
        if (((mask >> k) & 1) != ((mask >> ((k + 1) % 4)) & 1)) edges.push_back(k);
      if (edges.size() == 2) {
        Segment s{};
        cross(edges[0], s.x0, s.y0);
        cross(edges[1], s.x1, s.y1);
        out.push_back(s);
      } else if (edges.size() == 4) {  // saddle: pair the edges so the high corners join if the centre is high
        const bool centre_high = (c[0] + c[1] + c[2] + c[3]) / 4 >= level;
        const bool corner0_high = (mask & 1) != 0;
        const int pairs[2][4] = {{0, 1, 2, 3}, {0, 3, 1, 2}};
        const int* p = pairs[centre_high == corner0_high ? 0 : 1];
        for (int q = 0; q < 2; ++q) {
          Segment s{};
          cross(p[2 * q], s.x0, s.y0);
          cross(p[2 * q + 1], s.x1, s.y1);
          out.push_back(s);
        }
      }
    }
  return out;
}

std::vector<double> nice_levels(double max, double min_fraction, int max_levels) {
  std::vector<double> out;
  if (!(max > 0) || !std::isfinite(max)) return out;
  const double lo = min_fraction * max;
  double decade = std::pow(10.0, std::floor(std::log10(max)));
  const double steps[3] = {5, 2, 1};
  while (static_cast<int>(out.size()) < max_levels && decade * 5 > lo) {
    for (double s : steps) {
      const double v = s * decade;
      if (v <= 0.95 * max && v > lo && static_cast<int>(out.size()) < max_levels) out.push_back(v);
    }
    decade /= 10;
  }
  return out;
}

LUMX_NAMESPACE_END
