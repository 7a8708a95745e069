// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/line_fit.h — the point nearest to a set of rays' lines (least squares), and sliding a ray along
// its line. A ray's start point is only where it was recorded: in free space any point of its line
// describes the same ray, so a rayset recorded on a surface around a smaller emitter has lines that meet
// near the emitter, wherever the start points are.
#pragma once

#include <lumx/version.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>

LUMX_NAMESPACE_BEGIN

/// Accumulates flux-weighted lines (start p, unit direction ω, flux Φ). The point x nearest to them
/// minimises Σ Φ |(I − ωωᵀ)(x − p)|², the squared distance from x to each line measured across it; its
/// normal equations are A x = b with A = Σ Φ (I − ωωᵀ) and b = Σ Φ (I − ωωᵀ) p. Sums are taken about the
/// first line's start point (`origin`), so a luminaire far from the coordinate origin loses no precision.
struct LineFit {
  bool has_origin = false;
  glm::dvec3 origin{0.0};
  glm::dmat3 A{0.0};
  glm::dvec3 b{0.0};
  double weight = 0;         ///< Σ Φ
  double across2 = 0;        ///< Σ Φ |(I − ωωᵀ)(p − o)|²: with A and b, each line's squared distance to any x
  glm::dvec3 first{0.0};     ///< Σ Φ (p − o)
  double second = 0;         ///< Σ Φ |p − o|²: with `first`, the start points' squared distance to any x

  /// Adds one ray; rays without positive finite flux, with a non-finite position or a direction that is
  /// not a unit vector (±1e-3) are left out (the caller reports them).
  void add(const glm::vec3& position, const glm::vec3& direction, float flux) {
    if (!(flux > 0) || !std::isfinite(flux) || !std::isfinite(position.x + position.y + position.z) ||
        !std::isfinite(direction.x + direction.y + direction.z) ||
        !(std::abs(glm::dot(direction, direction) - 1.0f) <= 1e-3f))
      return;
    if (!has_origin) {
      origin = glm::dvec3(position);
      has_origin = true;
    }
    const glm::dvec3 w = glm::normalize(glm::dvec3(direction)), p = glm::dvec3(position) - origin;
    const glm::dmat3 P = glm::dmat3(1.0) - glm::outerProduct(w, w);
    const double f = double(flux);
    A += f * P;
    b += f * (P * p);
    weight += f;
    across2 += f * glm::dot(p, P * p);
    first += f * p;
    second += f * glm::dot(p, p);
  }
  /// Adds another fit's lines (same result as adding them one by one, up to rounding).
  void add(const LineFit& o) {
    if (!(o.weight > 0)) return;
    if (!has_origin) {
      *this = o;
      return;
    }
    // Move o's sums from its origin to ours: p − o_this = (p − o_that) + d.
    const glm::dvec3 d = o.origin - origin;
    A += o.A;
    b += o.b + o.A * d;
    across2 += o.across2 + 2.0 * glm::dot(d, o.b) + glm::dot(d, o.A * d);
    first += o.first + o.weight * d;
    second += o.second + 2.0 * glm::dot(d, o.first) + o.weight * glm::dot(d, d);
    weight += o.weight;
  }

  /// Flux-weighted mean squared distance from x to the lines, measured across them.
  double mean_line_distance2(const glm::dvec3& x) const {
    if (!(weight > 0)) return 0;
    const glm::dvec3 y = x - origin;
    return std::max(0.0, (glm::dot(y, A * y) - 2.0 * glm::dot(y, b) + across2) / weight);
  }
  /// Flux-weighted mean squared distance from x to the start points.
  double mean_start_distance2(const glm::dvec3& x) const {
    if (!(weight > 0)) return 0;
    const glm::dvec3 y = x - origin;
    return std::max(0.0, (weight * glm::dot(y, y) - 2.0 * glm::dot(y, first) + second) / weight);
  }

  /// The nearest point, with the directions the lines do not fix taken from `anchor`: in the eigenbasis
  /// of the mean projector A/W (eigenvalues in [0, 1]; a cone of half-angle α has one ≈ α²/2 along its
  /// axis), components with eigenvalue ≥ `min_eigenvalue` are the least-squares solution, the others the
  /// anchor's (a truncated solve: no pull toward the anchor where the lines decide).
  glm::dvec3 solve(const glm::dvec3& anchor, double min_eigenvalue) const {
    if (!(weight > 0)) return anchor;
    glm::dvec3 lambda;
    glm::dmat3 V;
    symmetric_eigen(A / weight, lambda, V);
    const glm::dvec3 y0 = anchor - origin, rhs = b / weight;
    glm::dvec3 y(0.0);
    for (int i = 0; i < 3; ++i) {
      const glm::dvec3 v = V[i];
      const double c = lambda[i] >= min_eigenvalue && lambda[i] > 0 ? glm::dot(v, rhs) / lambda[i] : glm::dot(v, y0);
      y += c * v;
    }
    return y + origin;
  }

  /// Eigen-decomposition of a symmetric 3 × 3 matrix by cyclic Jacobi rotations (Golub & Van Loan
  /// §8.5): M = V diag(λ) Vᵀ, eigenvectors in V's columns.
  static void symmetric_eigen(glm::dmat3 M, glm::dvec3& lambda, glm::dmat3& V) {
    V = glm::dmat3(1.0);
    for (int sweep = 0; sweep < 50; ++sweep) {
      const double off = M[0][1] * M[0][1] + M[0][2] * M[0][2] + M[1][2] * M[1][2];
      if (off <= 1e-30 * (M[0][0] * M[0][0] + M[1][1] * M[1][1] + M[2][2] * M[2][2]) || off == 0) break;
      for (int p = 0; p < 2; ++p)
        for (int q = p + 1; q < 3; ++q) {
          if (M[p][q] == 0) continue;
          // The rotation zeroing M[p][q]: tan(2θ) = 2 M_pq / (M_qq − M_pp), t = tan θ (the smaller root).
          const double tau = (M[q][q] - M[p][p]) / (2 * M[p][q]);
          const double t = (tau >= 0 ? 1.0 : -1.0) / (std::abs(tau) + std::sqrt(1 + tau * tau));
          const double c = 1 / std::sqrt(1 + t * t), s = t * c;
          glm::dmat3 J(1.0);
          J[p][p] = c;
          J[q][q] = c;
          J[q][p] = s;   // column q, row p
          J[p][q] = -s;  // column p, row q
          M = glm::transpose(J) * M * J;
          V = V * J;
        }
    }
    lambda = glm::dvec3(M[0][0], M[1][1], M[2][2]);
  }
};

/// The point of the line through `p` along unit `w` nearest to `c`.
inline glm::vec3 slide_to_nearest(const glm::vec3& p, const glm::vec3& w, const glm::dvec3& c) {
  const glm::dvec3 pd(p), wd(w);
  return glm::vec3(pd + glm::dot(c - pd, wd) * wd);
}

LUMX_NAMESPACE_END
