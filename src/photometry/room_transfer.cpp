// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/math/constants.h>
#include <lumx/photometry/room_transfer.h>

#include <array>
#include <cmath>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN

double form_factor_parallel_rectangles(double a, double b, double c) {
  if (!(a > 0) || !(b > 0) || !(c > 0)) return 0.0;
  const double x = a / c, y = b / c;
  const double x1 = std::sqrt(1 + x * x), y1 = std::sqrt(1 + y * y);
  const double t = std::log(x1 * y1 / std::sqrt(1 + x * x + y * y)) + x * y1 * std::atan(x / y1) +
                   y * x1 * std::atan(y / x1) - x * std::atan(x) - y * std::atan(y);
  return 2.0 / (kPi * x * y) * t;
}

WallTransferFactors wall_transfer_factors(double x_m, double y_m, double h_m, const Reflectances& r) {
  if (!(x_m > 0) || !(y_m > 0) || !(h_m > 0) || !std::isfinite(x_m * y_m * h_m))
    throw std::invalid_argument("room sizes must be finite and > 0");
  for (double v : {r.ceiling, r.walls, r.floor})
    if (!(v >= 0 && v < 1)) throw std::invalid_argument("reflectances must lie in [0, 1)");
  const double a_floor = x_m * y_m, a_walls = 2 * h_m * (x_m + y_m);
  const double f_fc = form_factor_parallel_rectangles(x_m, y_m, h_m);  // floor -> ceiling (and back)
  const double f_fw = 1 - f_fc;                                       // floor -> walls (= ceiling -> walls)
  const double f_wf = f_fw * a_floor / a_walls;                       // reciprocity: walls -> floor (= ceiling)
  const double f_ww = 1 - 2 * f_wf;                                   // walls -> walls
  // Surfaces 0 floor, 1 walls, 2 ceiling. f[j][i]: form factor from j to i.
  const double f[3][3] = {{0, f_fw, f_fc}, {f_wf, f_ww, f_wf}, {f_fc, f_fw, 0}};
  const double rho[3] = {r.floor, r.walls, r.ceiling};
  // Received flux: phi_i = phi0_i + sum_j rho_j f[j][i] phi_j, i.e. (I - M) phi = phi0.
  double m[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m[i][j] = (i == j ? 1.0 : 0.0) - rho[j] * f[j][i];
  // Walls row of (I - M)^-1 via the cofactors of the 3 x 3 matrix.
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  // inv[1][j] = cofactor(j, 1) / det.
  const double inv10 = -(m[1][0] * m[2][2] - m[1][2] * m[2][0]) / det;
  const double inv11 = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
  const double inv12 = -(m[0][0] * m[1][2] - m[0][2] * m[1][0]) / det;
  return WallTransferFactors{inv10, inv11 - 1.0, inv12};
}

LUMX_NAMESPACE_END
