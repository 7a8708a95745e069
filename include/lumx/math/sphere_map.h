// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/sphere_map.h — an equal-area image of the whole sphere of directions, and bilinear lookups on it.
//
// Layout (dissertation 000 §4.6; algorithms.md §9): a 2R × R image made of two R × R squares. The left
// square is the upper hemisphere (z ≥ 0), the right square the lower one (z < 0). Each square maps to its
// hemisphere by Shirley & Chiu's concentric square→disk map (1997) followed by Lambert's azimuthal
// equal-area projection of the disk onto the hemisphere (z = 1 − ρ², |xy| = ρ·√(2 − ρ²)). Both steps
// preserve area, so every texel covers the same solid angle, 4π / (2R²): turning a texel value in W/sr
// or cd into flux is one multiplication, and a piecewise-constant density over texels is uniform in
// solid angle up to one constant (pdf_ω = pdf_uv / 4π).
//
// Seams. The square's border is the equator, and the same square coordinate on the other hemisphere is
// the same equator point, so the texel just outside one square's edge is the mirror-image texel just
// inside the other square. Bilinear lookups use that rule (one flip per edge crossed, so the texel past a
// corner is the square's own corner texel), which makes the interpolant continuous across the equator;
// the poles are the squares' centres, interior points where nothing special is needed.
//
// Directions are in the luminaire's photometric frame (photometric_frame.h: +Z up, nadir −Z).
#pragma once

#include <lumx/math/constants.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

namespace sphere_map {

/// Largest square resolution R a map may have (texel counts stay far below 2^31 and allocations sane).
inline constexpr int kMaxResolution = 4096;

/// Point of the unit square [0,1]² → point of the unit disk (Shirley & Chiu 1997, eq. for the
/// concentric map). The origin is handled explicitly (the formula divides by zero there).
inline glm::vec2 square_to_disk(float sx, float sy) {
  const float a = 2.0f * sx - 1.0f, b = 2.0f * sy - 1.0f;
  if (a == 0.0f && b == 0.0f) return {0.0f, 0.0f};
  float r, phi;
  if (std::abs(a) > std::abs(b)) {
    r = a;
    phi = float(kPi / 4) * (b / a);
  } else {
    r = b;
    phi = float(kPi / 2) - float(kPi / 4) * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

/// Inverse of square_to_disk for a disk point given by radius ρ ≥ 0 and angle φ = atan2(y, x).
inline glm::vec2 disk_to_square(float rho, float phi) {
  constexpr float kQuarter = float(kPi / 4);
  if (phi < -kQuarter) phi += float(2 * kPi);  // φ ∈ [−π/4, 7π/4): four wedges, one per square side
  float a, b;
  if (phi < kQuarter) {  // right wedge: r = a, φ = π/4 · b/a
    a = rho;
    b = phi * float(4 / kPi) * a;
  } else if (phi < 3 * kQuarter) {  // top wedge: r = b, φ = π/2 − π/4 · a/b
    b = rho;
    a = (float(kPi / 2) - phi) * float(4 / kPi) * b;
  } else if (phi < 5 * kQuarter) {  // left wedge: r = a < 0, true angle φ = π + π/4 · b/a
    a = -rho;
    b = (phi - float(kPi)) * float(4 / kPi) * a;
  } else {  // bottom wedge: r = b < 0, true angle φ = 3π/2 − π/4 · a/b
    b = -rho;
    a = (float(3 * kPi / 2) - phi) * float(4 / kPi) * b;
  }
  return {std::clamp(0.5f * (a + 1.0f), 0.0f, 1.0f), std::clamp(0.5f * (b + 1.0f), 0.0f, 1.0f)};
}

/// atan(t) for t ∈ [−1, 1]: an odd minimax polynomial t·P(t²) of degree 15, within 1.3e-7 rad in float
/// (about one float ulp of π/4). glibc's atan2f costs ~25 ns here; the whole direction → square map with
/// this ~8 ns (bench/bench_apl.cpp: atan2f_alone, direction_to_square).
inline float atan_unit(float t) {
  const float u = t * t;
  float p = -0.004054541713648427f;
  p = p * u + 0.021862865288140798f;
  p = p * u - 0.055912192615222414f;
  p = p * u + 0.09642187457744139f;
  p = p * u - 0.1390862567541859f;
  p = p * u + 0.19946564874405892f;
  p = p * u - 0.3332986071611589f;
  p = p * u + 0.9999993355611796f;
  return t * p;
}

/// Unit direction → hemisphere (0: z ≥ 0, the left square; 1: z < 0, the right square) and coordinates
/// inside that hemisphere's square, [0,1]². Kept separate from direction_to_uv because u = 0.5 alone
/// cannot tell the two squares' shared edge apart.
///
/// This is disk_to_square(ρ, atan2(y, x)) with the angle never formed: in each of the concentric map's
/// four wedges the square coordinate along the wedge is ±ρ and the other is (4/π)·atan of the ratio
/// of the in-plane components (y/x in the left/right wedges, x/y in the top/bottom ones) times it.
inline glm::vec2 direction_to_square(const glm::vec3& w, int& half) {
  half = w.z < 0.0f ? 1 : 0;
  // Lambert: ρ² = 1 − |z| = (x² + y²) / (1 + |z|) for unit w; the second form keeps ρ's precision near
  // the poles, where 1 − |z| in float is quantised to multiples of 2⁻²⁴.
  const float rho = std::sqrt((w.x * w.x + w.y * w.y) / (1.0f + std::abs(w.z)));
  // Written with selects rather than branches: the wedge of a random direction is unpredictable.
  const bool x_major = std::abs(w.x) >= std::abs(w.y);
  const float along = x_major ? w.x : w.y, across = x_major ? w.y : w.x;
  const float ratio = along != 0.0f ? across / along : 0.0f;  // along = 0 only at a pole (ρ = 0)
  const float major = std::copysign(rho, along);
  const float minor = float(4 / kPi) * atan_unit(ratio) * major;
  const float a = x_major ? major : minor, b = x_major ? minor : major;
  return {std::clamp(0.5f * (a + 1.0f), 0.0f, 1.0f), std::clamp(0.5f * (b + 1.0f), 0.0f, 1.0f)};
}

/// Unit direction → map coordinates (u, v) ∈ [0,1]², u across the 2R-wide image, v down its R rows.
/// A direction with z = 0 exactly belongs to the upper square; both squares agree there anyway.
inline glm::vec2 direction_to_uv(const glm::vec3& w) {
  int half;
  const glm::vec2 s = direction_to_square(w, half);
  const float u = 0.5f * (s.x + float(half));
  // u = 0.5 is the upper square's right edge. A lower-square point that rounds onto it lies on the lower
  // square's left edge, which is the equator point the upper square reaches at u = 0.
  if (half == 1 && u == 0.5f) return {0.0f, s.y};
  return {u, s.y};
}

/// Map coordinates (u, v) ∈ [0,1]² → unit direction (the inverse of direction_to_uv).
inline glm::vec3 uv_to_direction(const glm::vec2& uv) {
  const bool lower = uv.x > 0.5f;
  const float sx = std::clamp(lower ? 2.0f * uv.x - 1.0f : 2.0f * uv.x, 0.0f, 1.0f);
  const glm::vec2 d = square_to_disk(sx, std::clamp(uv.y, 0.0f, 1.0f));
  const float rho2 = std::min(1.0f, d.x * d.x + d.y * d.y);
  const float scale = std::sqrt(std::max(0.0f, 2.0f - rho2));  // sin θ = ρ√(2 − ρ²)
  const float z = 1.0f - rho2;
  return {d.x * scale, d.y * scale, lower ? -z : z};
}

/// Texel (x, y) of a map of square resolution R that contains unit direction w. One function for the
/// map's lookups and the sampler's pdf, so both always agree on the texel.
inline void texel_of(const glm::vec3& w, int resolution, int& x, int& y) {
  int half;
  const glm::vec2 s = direction_to_square(w, half);
  x = half * resolution + std::min(resolution - 1, int(s.x * float(resolution)));
  y = std::min(resolution - 1, int(s.y * float(resolution)));
}

/// Index (y · 2R + x) of texel (lx, ly) of square `half` (0: left, upper hemisphere; 1: right) in a map of
/// square resolution R, where lx or ly may be −1 or R: outside a square's edge lies the mirror texel of the
/// other square (the equator seam rule of the header comment). Each edge crossed flips to the other
/// square; past a corner both edges are crossed, which flips back (the texel diagonally past a corner is
/// the square's own corner texel).
inline std::size_t seam_texel_index(int R, int half, int lx, int ly) {
  int flips = 0;
  if (lx < 0) lx = 0, ++flips;
  else if (lx >= R) lx = R - 1, ++flips;
  if (ly < 0) ly = 0, ++flips;
  else if (ly >= R) ly = R - 1, ++flips;
  half ^= flips & 1;
  return std::size_t(ly) * std::size_t(2 * R) + std::size_t(half) * std::size_t(R) + std::size_t(lx);
}

/// Solid angle of one texel of a map of square resolution R: 4π / (2R²) sr.
inline double texel_solid_angle(int resolution) {
  return 4.0 * kPi / (2.0 * double(resolution) * double(resolution));
}

}  // namespace sphere_map

/// A sphere map with `channels` float values per texel (1: luminous, 3: RGB), in whatever per-solid-angle
/// unit its owner declares (cd or W/sr for APL maps). Texel (x, y), channel c lives at
/// data()[(y · width() + x) · channels() + c]; x ∈ [0, 2R), y ∈ [0, R).
class SphereMap {
 public:
  SphereMap() = default;
  /// An all-zero map of square resolution R (image 2R × R). R ∈ [1, kMaxResolution], channels 1 or 3.
  SphereMap(int resolution, int channels) : resolution_(resolution), channels_(channels) {
    if (resolution < 1 || resolution > sphere_map::kMaxResolution)
      throw std::invalid_argument("SphereMap: resolution " + std::to_string(resolution) + " outside [1, " +
                                  std::to_string(sphere_map::kMaxResolution) + "]");
    if (channels != 1 && channels != 3)
      throw std::invalid_argument("SphereMap: channels must be 1 or 3, not " + std::to_string(channels));
    values_.assign(std::size_t(2) * resolution * resolution * channels, 0.0f);
  }

  int resolution() const { return resolution_; }
  int width() const { return 2 * resolution_; }
  int height() const { return resolution_; }
  int channels() const { return channels_; }
  bool empty() const { return values_.empty(); }
  std::size_t texel_count() const { return std::size_t(width()) * height(); }
  /// Bytes of texel data held in memory.
  std::size_t bytes() const { return values_.size() * sizeof(float); }
  double texel_solid_angle() const { return sphere_map::texel_solid_angle(resolution_); }

  float* data() { return values_.data(); }
  const float* data() const { return values_.data(); }
  std::vector<float>& values() { return values_; }
  const std::vector<float>& values() const { return values_; }
  float& at(int x, int y, int c) { return values_[(std::size_t(y) * width() + x) * channels_ + c]; }
  float at(int x, int y, int c) const { return values_[(std::size_t(y) * width() + x) * channels_ + c]; }

  /// Value at a texel as RGB (a one-channel map repeats its value).
  glm::vec3 texel(int x, int y) const {
    const float* p = values_.data() + (std::size_t(y) * width() + x) * channels_;
    return channels_ == 1 ? glm::vec3(p[0]) : glm::vec3(p[0], p[1], p[2]);
  }

  /// Texel that contains direction w (unit).
  void texel_of(const glm::vec3& w, int& x, int& y) const { sphere_map::texel_of(w, resolution_, x, y); }

  /// Nearest-texel value in direction w (unit): the piecewise-constant function sampling draws from.
  glm::vec3 lookup_nearest(const glm::vec3& w) const {
    int x, y;
    texel_of(w, x, y);
    return texel(x, y);
  }

  /// Bilinear value in direction w (unit), continuous across the equator seam, the squares' corners and
  /// the poles (see the header comment). A one-channel map returns its value in all three components.
  glm::vec3 lookup(const glm::vec3& w) const { return blend(footprint(w)); }

  /// The four texels and weights of a bilinear lookup, resolved before any texel is read. Splitting
  /// lookup() into footprint() and blend() lets a caller evaluating many maps compute every footprint
  /// first and prefetch its texels, so that cache misses to different maps overlap (apl/evaluation.h).
  struct Footprint {
    const float* texel[4];  ///< (x0,y0), (x0+1,y0), (x0,y0+1), (x0+1,y0+1), seam rule applied
    float tx, ty;           ///< weights of the +1 texels
  };

  Footprint footprint(const glm::vec3& w) const {
    int half;
    const glm::vec2 s = sphere_map::direction_to_square(w, half);
    // Continuous texel coordinates inside the hemisphere's own square; centres at i + 0.5.
    const float px = s.x * float(resolution_) - 0.5f;
    const float py = s.y * float(resolution_) - 0.5f;
    // ⌊p⌋ for p ≥ −0.5 by truncation of p + 1 (std::floor is a library call without SSE4.1).
    const int x0 = int(px + 1.0f) - 1, y0 = int(py + 1.0f) - 1;
    Footprint f;
    f.tx = px - float(x0);
    f.ty = py - float(y0);
    if (x0 >= 0 && y0 >= 0 && x0 + 1 < resolution_ && y0 + 1 < resolution_) {  // interior: no seam
      const std::size_t row = std::size_t(width()) * channels_;
      const float* p = values_.data() + (std::size_t(y0) * width() + std::size_t(half) * resolution_ + x0) * channels_;
      f.texel[0] = p;
      f.texel[1] = p + channels_;
      f.texel[2] = p + row;
      f.texel[3] = p + row + channels_;
    } else {
      f.texel[0] = fetch(half, x0, y0);
      f.texel[1] = fetch(half, x0 + 1, y0);
      f.texel[2] = fetch(half, x0, y0 + 1);
      f.texel[3] = fetch(half, x0 + 1, y0 + 1);
    }
    return f;
  }

  /// The bilinear value of a footprint. a + t·(b − a) returns a exactly when b == a, so a constant map
  /// looks up exactly constant.
  glm::vec3 blend(const Footprint& f) const {
    if (channels_ == 1) {
      const float row0 = *f.texel[0] + f.tx * (*f.texel[1] - *f.texel[0]);
      const float row1 = *f.texel[2] + f.tx * (*f.texel[3] - *f.texel[2]);
      return glm::vec3(row0 + f.ty * (row1 - row0));
    }
    const glm::vec3 v00 = load3(f.texel[0]), v10 = load3(f.texel[1]);
    const glm::vec3 v01 = load3(f.texel[2]), v11 = load3(f.texel[3]);
    const glm::vec3 row0 = v00 + f.tx * (v10 - v00), row1 = v01 + f.tx * (v11 - v01);
    return row0 + f.ty * (row1 - row0);
  }

  /// Adds `flux` (per channel, e.g. W or lm) arriving in direction w to the texel containing w, as
  /// intensity: flux / texel solid angle. Summing particles this way is the histogram estimator of
  /// dissertation 000 §4.3.
  void splat(const glm::vec3& w, const glm::vec3& flux) {
    int x, y;
    texel_of(w, x, y);
    const float inv_sr = float(1.0 / texel_solid_angle());
    float* p = values_.data() + (std::size_t(y) * width() + x) * channels_;
    if (channels_ == 1) {
      p[0] += flux.x * inv_sr;
    } else {
      for (int c = 0; c < 3; ++c) p[c] += flux[c] * inv_sr;
    }
  }

  /// ∫ value dω per channel: Σ texel value × texel solid angle (flux in lm or W for cd or W/sr maps),
  /// summed in double. A one-channel map returns its integral in all three components.
  glm::dvec3 integral() const {
    double sum[3] = {0, 0, 0};
    for (std::size_t i = 0; i < values_.size(); ++i) sum[i % channels_] += double(values_[i]);
    const double sr = texel_solid_angle();
    return channels_ == 1 ? glm::dvec3(sum[0] * sr) : glm::dvec3(sum[0] * sr, sum[1] * sr, sum[2] * sr);
  }

  /// Largest value over all texels and channels (0 for an empty map).
  float max_value() const {
    float m = 0.0f;
    for (float v : values_) m = std::max(m, v);
    return m;
  }

  /// True when every value is finite and ≥ 0; otherwise the first offending texel and channel.
  bool all_finite_nonnegative(int* bad_x = nullptr, int* bad_y = nullptr, int* bad_c = nullptr) const {
    for (std::size_t i = 0; i < values_.size(); ++i) {
      if (std::isfinite(values_[i]) && values_[i] >= 0.0f) continue;
      const std::size_t t = i / channels_;
      if (bad_x) *bad_x = int(t % width());
      if (bad_y) *bad_y = int(t / width());
      if (bad_c) *bad_c = int(i % channels_);
      return false;
    }
    return true;
  }

  /// Each texel replaced by the maximum over its 3×3 neighbourhood (seam rule applied), per channel.
  /// Every texel a bilinear lookup inside texel T reads lies in T's neighbourhood, so a sampler built on
  /// this map gives a non-zero pdf wherever lookup() is non-zero (apl/sampling.h).
  SphereMap dilated() const {
    SphereMap out(resolution_, channels_);
    const int R = resolution_;
    for (int half = 0; half < 2; ++half)
      for (int ly = 0; ly < R; ++ly)
        for (int lx = 0; lx < R; ++lx) {
          float* o = &out.at(half * R + lx, ly, 0);
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const float* t = fetch(half, lx + dx, ly + dy);
              for (int c = 0; c < channels_; ++c) o[c] = std::max(o[c], t[c]);
            }
        }
    return out;
  }

  /// The map at half the resolution: each texel is the mean of a 2×2 block. Blocks never straddle the
  /// two squares and all texels have equal solid angle, so integral() is unchanged (up to rounding).
  /// Requires an even resolution.
  SphereMap downsampled() const {
    if (resolution_ < 2 || resolution_ % 2 != 0)
      throw std::invalid_argument("SphereMap::downsampled: resolution " + std::to_string(resolution_) +
                                  " is not even");
    SphereMap out(resolution_ / 2, channels_);
    for (int y = 0; y < out.height(); ++y)
      for (int x = 0; x < out.width(); ++x)
        for (int c = 0; c < channels_; ++c)
          out.at(x, y, c) = 0.25f * (at(2 * x, 2 * y, c) + at(2 * x + 1, 2 * y, c) + at(2 * x, 2 * y + 1, c) +
                                     at(2 * x + 1, 2 * y + 1, c));
    return out;
  }

 private:
  /// Texel (lx, ly) of square `half`, where lx or ly may be −1 or R: outside a square's edge (or corner)
  /// lies the mirror texel of the other square (the equator seam rule).
  const float* fetch(int half, int lx, int ly) const {
    return values_.data() + sphere_map::seam_texel_index(resolution_, half, lx, ly) * std::size_t(channels_);
  }
  static glm::vec3 load3(const float* p) { return {p[0], p[1], p[2]}; }

  int resolution_ = 0;
  int channels_ = 0;
  std::vector<float> values_;
};

LUMX_NAMESPACE_END
