// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Emitters whose irradiance is known without rays: each writes a seeded rayset of itself and evaluates its
// exact irradiance at a point, by closed form or deterministic quadrature — never from rays. They are the
// ground truth the error estimates of lumx/apl/error.h are checked against.
//
//   PlanarEmitter  a disk or rectangle in the plane z = 0 emitting into z > 0; every surface point emits
//                  intensity per area ∝ cos^m θ (m = 1: Lambertian; large m: a narrow spot). Intensity per
//                  area (Φ/A)·(m+1)/(2π)·cos^m θ integrates to Φ/A over the hemisphere. Irradiance at x with
//                  normal n:  E = ∫_S (Φ/A)·(m+1)/(2π) · cos^m θ_s · max(0, n·(p − x)/r) / r² dA,
//                  cos θ_s = (x − p)_z / r, by Gauss–Legendre quadrature over the shape.
//  PinholeBox      isotropic point sources inside an opaque axis-aligned cube with square holes in its
//                  faces. Rays start where they leave a hole. A point outside the cube receives
//                  Σ (Φ_s/4π)·max(0, n·(s − x)/r)/r² from every source s whose segment to x leaves the cube
//                  through a hole; a point inside receives nothing (the rays start at the holes).
#pragma once

#include <lumx/rays/rayset.h>
#include <lumx/math/constants.h>

#include <glm/glm.hpp>

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace lumx_test {

/// SplitMix64 on a counter: the k-th uniform of a stream, independent of how many were drawn before.
inline double uniform01(std::uint64_t seed, std::uint64_t k) {
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + (k + 1) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return double(z >> 11) * 0x1.0p-53;
}

/// Gauss–Legendre nodes and weights on [0, 1] (Newton on P_n, from the Chebyshev guess).
inline std::vector<std::pair<double, double>> gauss_legendre01(int n) {
  std::vector<std::pair<double, double>> out(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    double x = std::cos(lumx::kPi * (i + 0.75) / (n + 0.5)), dp = 1;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-15) break;
    }
    out[std::size_t(i)] = {0.5 * (1 - x), 1.0 / ((1 - x * x) * dp * dp)};  // weight 2/((1−x²)P'²) × ½
  }
  return out;
}

class AnalyticEmitter {
 public:
  virtual ~AnalyticEmitter() = default;
  virtual std::string name() const = 0;
  /// `n` rays drawn with `seed` (rays a hole blocks are drawn and dropped: fewer come out).
  virtual lumx::RayChunk rays(std::uint64_t n, std::uint64_t seed) const = 0;
  /// Exact irradiance (lx for lm) at x with normal `normal`.
  virtual double irradiance(const glm::dvec3& x, const glm::dvec3& normal) const = 0;
  std::unique_ptr<lumx::RaySource> source(std::uint64_t n, std::uint64_t seed) const {
    lumx::RaysetInfo info;
    info.file = name();
    info.format = "analytic";
    return std::make_unique<lumx::MemoryRaySource>(rays(n, seed), info);
  }
};

class PlanarEmitter : public AnalyticEmitter {
 public:
  enum class Shape { disk, rectangle };
  /// A disk of radius a (half_y ignored) or a rectangle 2a × 2·half_y, flux Φ (lm), exponent m.
  PlanarEmitter(std::string name, Shape shape, double a, double half_y, double m, double flux)
      : name_(std::move(name)), shape_(shape), a_(a), b_(half_y), m_(m), flux_(flux) {
    const int nr = 48, nphi = 96;
    const auto gl = gauss_legendre01(nr);
    if (shape_ == Shape::disk) {
      // Area element in (u = r²/a², φ): dA = ½a² du dφ; Gauss in u, trapezoid (exact for periodic) in φ.
      for (const auto& [u, w] : gl)
        for (int j = 0; j < nphi; ++j) {
          const double r = a_ * std::sqrt(u), phi = 2 * lumx::kPi * (j + 0.5) / nphi;
          nodes_.push_back({r * std::cos(phi), r * std::sin(phi), w * 0.5 * a_ * a_ * 2 * lumx::kPi / nphi});
        }
    } else {
      const auto glx = gauss_legendre01(64);
      for (const auto& [u, wu] : glx)
        for (const auto& [v, wv] : glx)
          nodes_.push_back({a_ * (2 * u - 1), b_ * (2 * v - 1), wu * wv * 4 * a_ * b_});
    }
  }
  std::string name() const override { return name_; }
  double area() const { return shape_ == Shape::disk ? lumx::kPi * a_ * a_ : 4 * a_ * b_; }

  lumx::RayChunk rays(std::uint64_t n, std::uint64_t seed) const override {
    lumx::RayChunk c;
    c.reserve(std::size_t(n));
    const float f = float(flux_ / double(n));
    for (std::uint64_t i = 0; i < n; ++i) {
      const double u1 = uniform01(seed, 4 * i), u2 = uniform01(seed, 4 * i + 1);
      const double u3 = uniform01(seed, 4 * i + 2), u4 = uniform01(seed, 4 * i + 3);
      glm::dvec3 p;
      if (shape_ == Shape::disk) {
        const double r = a_ * std::sqrt(u1), phi = 2 * lumx::kPi * u2;
        p = {r * std::cos(phi), r * std::sin(phi), 0};
      } else {
        p = {a_ * (2 * u1 - 1), b_ * (2 * u2 - 1), 0};
      }
      // pdf ∝ cos^m θ on the hemisphere: cos θ = u^(1/(m+1)).
      const double ct = std::pow(u3, 1.0 / (m_ + 1)), st = std::sqrt(std::max(0.0, 1 - ct * ct));
      const double phi = 2 * lumx::kPi * u4;
      c.push_back(glm::vec3(p), glm::vec3(float(st * std::cos(phi)), float(st * std::sin(phi)), float(ct)), f);
    }
    return c;
  }

  double irradiance(const glm::dvec3& x, const glm::dvec3& normal) const override {
    const double k = flux_ / area() * (m_ + 1) / (2 * lumx::kPi);
    double e = 0;
    for (const Node& q : nodes_) {
      const glm::dvec3 d = x - glm::dvec3(q.x, q.y, 0);  // from the surface point to x
      const double r2 = glm::dot(d, d), r = std::sqrt(r2);
      if (!(d.z > 0)) continue;
      const double cs = d.z / r, cr = -glm::dot(normal, d) / r;
      if (cr <= 0) continue;
      e += q.w * std::pow(cs, m_) * cr / r2;
    }
    return k * e;
  }

 private:
  struct Node {
    double x, y, w;
  };
  std::string name_;
  Shape shape_;
  double a_, b_, m_, flux_;
  std::vector<Node> nodes_;
};

/// Another emitter turned by `degrees` about the y axis (rays and exact irradiance alike): the same light
/// aimed elsewhere, to tell what depends on where a lobe falls on the maps from what does not.
class RotatedEmitter : public AnalyticEmitter {
 public:
  RotatedEmitter(std::unique_ptr<AnalyticEmitter> inner, double degrees)
      : inner_(std::move(inner)), degrees_(degrees), c_(std::cos(degrees * lumx::kPi / 180)),
        s_(std::sin(degrees * lumx::kPi / 180)) {}
  std::string name() const override {
    return inner_->name() + ", turned " + std::to_string(int(std::lround(degrees_))) + "° about y";
  }
  lumx::RayChunk rays(std::uint64_t n, std::uint64_t seed) const override {
    const lumx::RayChunk in = inner_->rays(n, seed);
    lumx::RayChunk out;
    out.reserve(in.size());
    for (std::size_t i = 0; i < in.size(); ++i)
      out.push_back(glm::vec3(turn(glm::dvec3(in.position(i)))), glm::vec3(turn(glm::dvec3(in.direction(i)))), in.flux[i]);
    return out;
  }
  double irradiance(const glm::dvec3& x, const glm::dvec3& normal) const override {
    return inner_->irradiance(unturn(x), unturn(normal));
  }

 private:
  glm::dvec3 turn(const glm::dvec3& v) const { return {c_ * v.x + s_ * v.z, v.y, -s_ * v.x + c_ * v.z}; }
  glm::dvec3 unturn(const glm::dvec3& v) const { return {c_ * v.x - s_ * v.z, v.y, s_ * v.x + c_ * v.z}; }
  std::unique_ptr<AnalyticEmitter> inner_;
  double degrees_, c_, s_;
};

class PinholeBox : public AnalyticEmitter {
 public:
  struct Hole {
    int axis;     ///< 0, 1, 2: the face's normal axis
    int side;     ///< −1 or +1
    double u0, u1, v0, v1;  ///< the hole's extent in the face's two other coordinates (axis order)
  };
  struct Source {
    glm::dvec3 p;
    double flux;  ///< lm into the whole sphere (what the holes block is lost)
  };
  PinholeBox(std::string name, double half, std::vector<Hole> holes, std::vector<Source> sources)
      : name_(std::move(name)), h_(half), holes_(std::move(holes)), sources_(std::move(sources)) {}
  std::string name() const override { return name_; }
  const std::vector<Hole>& holes() const { return holes_; }

  lumx::RayChunk rays(std::uint64_t n, std::uint64_t seed) const override {
    lumx::RayChunk c;
    double total = 0;
    for (const Source& s : sources_) total += s.flux;
    const float f = float(total / double(n));
    for (std::uint64_t i = 0; i < n; ++i) {
      // Source by flux, then an isotropic direction.
      double pick = uniform01(seed, 3 * i) * total;
      std::size_t si = 0;
      while (si + 1 < sources_.size() && pick >= sources_[si].flux) pick -= sources_[si++].flux;
      const double z = 1 - 2 * uniform01(seed, 3 * i + 1), phi = 2 * lumx::kPi * uniform01(seed, 3 * i + 2);
      const double s = std::sqrt(std::max(0.0, 1 - z * z));
      const glm::dvec3 w(s * std::cos(phi), s * std::sin(phi), z);
      glm::dvec3 exit;
      if (leaves_through_hole(sources_[si].p, w, 1e300, exit)) c.push_back(glm::vec3(exit), glm::vec3(w), f);
    }
    return c;
  }

  double irradiance(const glm::dvec3& x, const glm::dvec3& normal) const override {
    if (std::abs(x.x) < h_ && std::abs(x.y) < h_ && std::abs(x.z) < h_) return 0;
    double e = 0;
    for (const Source& s : sources_) {
      const glm::dvec3 d = x - s.p;
      const double r = glm::length(d);
      const glm::dvec3 w = d / r;
      glm::dvec3 exit;
      if (!leaves_through_hole(s.p, w, r, exit)) continue;
      const double cr = -glm::dot(normal, w);
      if (cr > 0) e += s.flux / (4 * lumx::kPi) * cr / (r * r);
    }
    return e;
  }

 private:
  /// From p inside the cube along unit w: where it leaves the cube, and whether that is in a hole. False
  /// when the exit lies beyond `max_t` (the segment ends inside the cube).
  bool leaves_through_hole(const glm::dvec3& p, const glm::dvec3& w, double max_t, glm::dvec3& exit) const {
    double t = INFINITY;
    int axis = 0, side = 1;
    for (int a = 0; a < 3; ++a) {
      if (w[a] == 0) continue;
      const int sd = w[a] > 0 ? 1 : -1;
      const double ta = (sd * h_ - p[a]) / w[a];
      if (ta < t) t = ta, axis = a, side = sd;
    }
    if (!(t <= max_t)) return false;
    exit = p + t * w;
    exit[axis] = side * h_;
    const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
    const int u_axis = std::min(ua, va), v_axis = std::max(ua, va);
    for (const Hole& hole : holes_)
      if (hole.axis == axis && hole.side == side && exit[u_axis] >= hole.u0 && exit[u_axis] <= hole.u1 &&
          exit[v_axis] >= hole.v0 && exit[v_axis] <= hole.v1)
        return true;
    return false;
  }

  std::string name_;
  double h_;
  std::vector<Hole> holes_;
  std::vector<Source> sources_;
};

/// The analytic suite's box with holes: two isotropic 500 lm point sources in a 10 cm box with four
/// rectangular holes (1 M rays emitted, about 112 000 leave).
inline PinholeBox suite_pinhole_box() {
  using H = PinholeBox::Hole;
  return {"two point sources in a 10 cm box with four holes", 0.05,
          {H{2, 1, -0.03, 0.01, -0.02, 0.03}, H{2, -1, 0.0, 0.03, -0.03, 0.0}, H{0, 1, -0.04, -0.01, -0.01, 0.03},
           H{1, -1, -0.02, 0.02, -0.045, -0.02}},
          {{{-0.02, 0.01, 0.0}, 500}, {{0.015, -0.01, 0.01}, 500}}};
}

}  // namespace lumx_test
