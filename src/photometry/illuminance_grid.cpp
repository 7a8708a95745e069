// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/math/constants.h>
#include <lumx/photometry/illuminance_grid.h>

#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN

double illuminance_lx(const IntensityTable& t, double x_m, double y_m, double h, double tilt_deg) {
  const double r2 = x_m * x_m + y_m * y_m + h * h, r = std::sqrt(r2);
  const glm::dvec3 w(x_m / r, y_m / r, -h / r);  // towards the point, plane frame
  const double ct = std::cos(tilt_deg * kDegToRad), st = std::sin(tilt_deg * kDegToRad);
  // Into the luminaire's frame: the inverse of the rotation about X that takes nadir to (0, sin, -cos).
  const glm::dvec3 d(w.x, w.y * ct + w.z * st, -w.y * st + w.z * ct);
  return t.intensity(d) * (h / r) / r2;
}

IlluminanceGrid illuminance_grid(const IntensityTable& t, const IlluminanceGridOptions& o) {
  const double h = o.mounting_height_m;
  if (!(h > 0) || !std::isfinite(h)) throw std::invalid_argument("isolux: the mounting height must be > 0");
  if (!(o.tilt_deg >= 0 && o.tilt_deg <= 85)) throw std::invalid_argument("isolux: the tilt must lie in [0, 85] degrees");
  if (o.samples < 3 || o.samples > 4001) throw std::invalid_argument("isolux: samples must lie in [3, 4001]");
  IlluminanceGrid g;
  const bool automatic = !(o.x_max_m > o.x_min_m) || !(o.y_max_m > o.y_min_m);
  if (automatic) {
    // Coarse survey over +-10 mounting heights, then the box around what is lit.
    const int n = 201;
    const double lim = 10 * h;
    std::vector<double> e(static_cast<std::size_t>(n) * n);
    double emax = 0;
    for (int iy = 0; iy < n; ++iy)
      for (int ix = 0; ix < n; ++ix) {
        const double v = illuminance_lx(t, -lim + 2 * lim * ix / (n - 1), -lim + 2 * lim * iy / (n - 1), h, o.tilt_deg);
        e[static_cast<std::size_t>(iy) * n + static_cast<std::size_t>(ix)] = v;
        emax = std::max(emax, v);
      }
    double x0 = -h, x1 = h, y0 = -h, y1 = h;
    for (int iy = 0; iy < n; ++iy)
      for (int ix = 0; ix < n; ++ix)
        if (emax > 0 && e[static_cast<std::size_t>(iy) * n + static_cast<std::size_t>(ix)] >= 0.005 * emax) {
          const double x = -lim + 2 * lim * ix / (n - 1), y = -lim + 2 * lim * iy / (n - 1);
          x0 = std::min(x0, x);
          x1 = std::max(x1, x);
          y0 = std::min(y0, y);
          y1 = std::max(y1, y);
        }
    const double px = 0.1 * (x1 - x0), py = 0.1 * (y1 - y0);
    g.x_min_m = std::max(-lim, x0 - px);
    g.x_max_m = std::min(lim, x1 + px);
    g.y_min_m = std::max(-lim, y0 - py);
    g.y_max_m = std::min(lim, y1 + py);
  } else {
    g.x_min_m = o.x_min_m;
    g.x_max_m = o.x_max_m;
    g.y_min_m = o.y_min_m;
    g.y_max_m = o.y_max_m;
  }
  const double wx = g.x_max_m - g.x_min_m, wy = g.y_max_m - g.y_min_m;
  const double step = std::max(wx, wy) / (o.samples - 1);
  g.nx = std::max(3, static_cast<int>(std::round(wx / step)) + 1);
  g.ny = std::max(3, static_cast<int>(std::round(wy / step)) + 1);
  g.lux.resize(static_cast<std::size_t>(g.nx) * static_cast<std::size_t>(g.ny));
  for (int iy = 0; iy < g.ny; ++iy)
    for (int ix = 0; ix < g.nx; ++ix) {
      const double v = illuminance_lx(t, g.x(ix), g.y(iy), h, o.tilt_deg);
      g.lux[static_cast<std::size_t>(iy) * static_cast<std::size_t>(g.nx) + static_cast<std::size_t>(ix)] = v;
      g.max_lux = std::max(g.max_lux, v);
    }
  return g;
}

LUMX_NAMESPACE_END
