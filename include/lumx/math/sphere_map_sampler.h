// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/sphere_map_sampler.h — importance sampling of directions from a SphereMap (algorithms.md §3).
//
// The sampled density is proportional to the map's nearest-texel function (SphereMap::lookup_nearest):
// a texel's importance is its value for a one-channel map and the mean of its three channels for an RGB
// map. Texels are drawn by PiecewiseConstant2D over the 2R × R image, a point is drawn uniformly inside
// the texel's square, and the point is lifted to the sphere by the map's own transform. Because the
// map is equal-area (math/sphere_map.h), a density uniform over a texel's square is uniform over its solid
// angle, and the density per steradian is the density over the unit image divided by its area on the
// sphere: pdf_ω = pdf_uv / 4π = P(texel) / (4π / 2R²).
//
// MIS needs sample().pdf and pdf(direction) to agree exactly, so sample() returns the pdf of the texel
// that the direction it returns falls in, found by the same rule pdf() and lookup_nearest() use. That
// is also the density of the texel it was drawn from: in exact arithmetic the two texels differ only
// for points on texel edges, a set of measure zero. In float they differ when rounding in the map's
// transforms moves a point lying within ~1e-7 of an edge across it (a first version of math/sphere_map.h,
// with ρ = √(1 − |z|), also moved points within ~1e-4 of a pole at large R). Such points are pulled towards their texel's centre and lifted again, so a sample lies in
// the texel it was drawn from (and never in a zero texel); its pdf is still computed from the returned
// direction, so the equality holds even if the pull were to fail.
#pragma once

#include <lumx/math/piecewise_constant_2d.h>
#include <lumx/math/sphere_map.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// A sampled direction and its density.
struct DirectionSample {
  glm::vec3 direction{0.0f};  ///< unit direction in the map's frame; (0,0,0) when invalid
  float pdf = 0.0f;           ///< per steradian; 0 marks an invalid sample (all-zero map)
};

/// Draws directions with density proportional to a sphere map's nearest-texel values.
class SphereMapSampler {
 public:
  /// The sampler of an all-zero function: is_zero(), every sample invalid, every pdf 0.
  SphereMapSampler() = default;

  /// Builds the tables from `map` (which need not outlive the sampler). Throws std::invalid_argument for
  /// an empty map or a texel that is negative or not finite. An all-zero map gives a zero sampler.
  explicit SphereMapSampler(const SphereMap& map) : resolution_(map.resolution()) {
    if (map.empty()) throw std::invalid_argument("SphereMapSampler: empty sphere map");
    int bad_x = 0, bad_y = 0, bad_c = 0;
    if (!map.all_finite_nonnegative(&bad_x, &bad_y, &bad_c))
      throw std::invalid_argument("SphereMapSampler: texel (" + std::to_string(bad_x) + ", " + std::to_string(bad_y) +
                                  ") channel " + std::to_string(bad_c) + " is negative or not finite");
    inverse_texel_solid_angle_ = 1.0 / map.texel_solid_angle();
    if (map.channels() == 1) {
      distribution_ = PiecewiseConstant2D(map.data(), map.width(), map.height());
    } else {
      std::vector<float> importance(map.texel_count());
      for (std::size_t i = 0; i < importance.size(); ++i) importance[i] = texel_importance(map.data() + 3 * i);
      distribution_ = PiecewiseConstant2D(importance.data(), map.width(), map.height());
    }
  }

  /// Importance of an RGB texel: the mean of its channels, summed in double (cannot overflow).
  static float texel_importance(const float* rgb) {
    return float((double(rgb[0]) + double(rgb[1]) + double(rgb[2])) / 3.0);
  }

  int resolution() const { return resolution_; }
  bool is_zero() const { return distribution_.is_zero(); }

  /// A direction for u1, u2 ∈ [0, 1) (clamped). pdf == pdf(direction) bit for bit; pdf 0 only for a
  /// zero sampler.
  DirectionSample sample(float u1, float u2) const {
    const PiecewiseConstant2D::Sample s = distribution_.sample(u1, u2);
    if (!(s.pdf > 0.0f)) return {};
    const int R = resolution_;
    const int half = s.cell_x >= R ? 1 : 0;  // 0: upper square (z ≥ 0), 1: lower square
    const int square_x = s.cell_x - half * R;
    // Offsets of the point inside its texel, in [0, 1) (exact: float · integer fits a double).
    double offset_x = double(s.point.x) * double(2 * R) - double(s.cell_x);
    double offset_y = double(s.point.y) * double(R) - double(s.cell_y);

    glm::vec3 w = lift(half, (square_x + offset_x) / R, (s.cell_y + offset_y) / R);
    int x, y;
    texel_of(w, x, y);
    // Rounding put the point into a neighbour: halve its distance to the texel centre and retry. After
    // kPullSteps halvings the point is within 1/2^kPullSteps of a texel width from the centre.
    for (int step = 0; step < kPullSteps && (x != s.cell_x || y != s.cell_y); ++step) {
      offset_x = 0.5 + 0.5 * (offset_x - 0.5);
      offset_y = 0.5 + 0.5 * (offset_y - 0.5);
      w = lift(half, (square_x + offset_x) / R, (s.cell_y + offset_y) / R);
      texel_of(w, x, y);
    }
    // Exactly what pdf(w) computes: the density of the texel w falls in.
    return {w, texel_pdf(x, y)};
  }

  /// Density per steradian of sample() in direction w (unit length): that of the texel containing w, found
  /// as SphereMap::texel_of finds it. 0 for a zero sampler or a non-finite w.
  float pdf(const glm::vec3& w) const {
    if (is_zero() || !(std::isfinite(w.x) && std::isfinite(w.y) && std::isfinite(w.z))) return 0.0f;
    int x, y;
    texel_of(w, x, y);
    return texel_pdf(x, y);
  }

  /// Bytes of table data held in memory.
  std::size_t bytes() const { return distribution_.bytes(); }

 private:
  static constexpr int kPullSteps = 12;

  /// The texel of w, by the function SphereMap::texel_of uses too.
  void texel_of(const glm::vec3& w, int& x, int& y) const { sphere_map::texel_of(w, resolution_, x, y); }

  /// Direction of point (sx, sy) of square `half`. uv_to_direction cannot be handed u = 0.5 for the
  /// lower square's left edge (u = 0.5 is the upper square's right edge), so the lower square's point is
  /// taken as the upper square's point at the same square coordinates, mirrored in z: both squares use
  /// the same disk point, z = ±(1 − ρ²) (math/sphere_map.h).
  static glm::vec3 lift(int half, double sx, double sy) {
    const glm::vec2 uv(0.5f * std::clamp(float(sx), 0.0f, 1.0f), std::clamp(float(sy), 0.0f, 1.0f));
    glm::vec3 w = sphere_map::uv_to_direction(uv);
    if (half == 1) w.z = -w.z;
    return w;
  }

  float texel_pdf(int x, int y) const { return float(distribution_.probability(x, y) * inverse_texel_solid_angle_); }

  int resolution_ = 0;
  double inverse_texel_solid_angle_ = 0.0;
  PiecewiseConstant2D distribution_;
};

LUMX_NAMESPACE_END
