// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Adaptive-kernel (sample-point, Abramson) density estimation of intensity on the sphere of directions,
// with biweight kernels in chord distance and the pilot tabulated on an equal-area sphere map. docs/render.md, "Adaptive kernels on the sphere".
#include <lumx/render/spherical_kernel_density.h>

#include <lumx/core/diagnostic.h>
#include <lumx/math/constants.h>
#include <lumx/math/sphere_map.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <utility>

LUMX_NAMESPACE_BEGIN
namespace render {

namespace {

// ∫ (1 − c²/h²)² dω over the unit sphere = 2π ∫₀^{h²/2} (1 − 2t/h²)² dt = π h²/3 for h ≤ 2 (t = 1 − cos θ,
// c² = 2t), so K_h = 3/(π h²) (1 − c²/h²)² has unit mass: the planar biweight's constant, exactly.
constexpr double kBiweightNorm = 3.0 / kPi;
const double kBiweightPerGaussian = std::pow(2304.0 / 5.0, 1.0 / 6.0);  // as in adaptive_kernel_density.cpp
constexpr double kMaxChord = 2.0;
constexpr int kLeafSize = 16;

std::string number(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

[[noreturn]] void fail(const std::string& field, const std::string& message) { throw_at_field("", field, message); }

// A kd-tree over points on the unit sphere whose nodes bound their kernels' supports (centre ± h per axis,
// which holds the chord ball).
class KernelTree {
 public:
  struct Item {
    glm::dvec3 p;
    double h;
    double flux;
    std::size_t index;
  };

  explicit KernelTree(std::vector<Item> items) : items_(std::move(items)) {
    if (items_.empty()) return;
    nodes_.reserve(2 * items_.size() / kLeafSize + 2);
    build(0, int(items_.size()));
    weight_.resize(items_.size());
    inv_h2_.resize(items_.size());
    for (std::size_t k = 0; k < items_.size(); ++k) {
      inv_h2_[k] = 1.0 / (items_[k].h * items_[k].h);
      weight_[k] = items_[k].flux * kBiweightNorm * inv_h2_[k];
    }
  }

  /// Σ Φ_i K_{h_i}(ω, ω_i), in storage order.
  double sum(const glm::dvec3& w) const {
    if (nodes_.empty()) return 0.0;
    double s = 0.0;
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& n = nodes_[std::size_t(stack[--top])];
      bool outside = false;
      for (int a = 0; a < 3; ++a) outside = outside || w[a] < n.lo[a] || w[a] > n.hi[a];
      if (outside) continue;
      if (n.left < 0) {
        for (int k = n.begin; k < n.end; ++k) {
          const glm::dvec3 d = w - items_[std::size_t(k)].p;
          const double t = 1.0 - glm::dot(d, d) * inv_h2_[std::size_t(k)];
          if (t > 0.0) s += weight_[std::size_t(k)] * t * t;
        }
      } else {
        stack[top++] = n.right;
        stack[top++] = n.left;
      }
    }
    return s;
  }

 private:
  struct Node {
    glm::dvec3 lo, hi;
    int begin, end, left, right;
  };

  int build(int begin, int end) {
    const int id = int(nodes_.size());
    nodes_.push_back(Node{glm::dvec3(std::numeric_limits<double>::infinity()), glm::dvec3(-std::numeric_limits<double>::infinity()),
                          begin, end, -1, -1});
    glm::dvec3 plo(std::numeric_limits<double>::infinity()), phi(-std::numeric_limits<double>::infinity());
    glm::dvec3 slo = plo, shi = phi;
    for (int k = begin; k < end; ++k) {
      const Item& it = items_[std::size_t(k)];
      plo = glm::min(plo, it.p), phi = glm::max(phi, it.p);
      slo = glm::min(slo, it.p - it.h), shi = glm::max(shi, it.p + it.h);
    }
    nodes_[std::size_t(id)].lo = slo;
    nodes_[std::size_t(id)].hi = shi;
    if (end - begin <= kLeafSize) return id;
    const glm::dvec3 ext = phi - plo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
    const int mid = begin + (end - begin) / 2;
    std::nth_element(items_.begin() + begin, items_.begin() + mid, items_.begin() + end, [axis](const Item& a, const Item& b) {
      return a.p[axis] < b.p[axis] || (a.p[axis] == b.p[axis] && a.index < b.index);
    });
    const int left = build(begin, mid);
    const int right = build(mid, end);
    nodes_[std::size_t(id)].left = left;
    nodes_[std::size_t(id)].right = right;
    return id;
  }

  std::vector<Item> items_;
  std::vector<Node> nodes_;
  std::vector<double> weight_, inv_h2_;
};

}  // namespace

struct AdaptiveKernelDensitySphere::Impl {
  std::unique_ptr<KernelTree> tree;
  double pilot = 0.0, min_h = 0.0, max_h = 0.0;
};

AdaptiveKernelDensitySphere::AdaptiveKernelDensitySphere(std::vector<DirectionDeposit> deposits,
                                                         const SphericalKernelOptions& options)
    : impl_(new Impl) {
  std::unique_ptr<Impl> guard(impl_);
  if (!std::isfinite(options.pilot_bandwidth) || options.pilot_bandwidth < 0.0)
    fail("pilot_bandwidth", "must be 0 (chosen from the directions) or a positive chord, got " + number(options.pilot_bandwidth));
  if (!std::isfinite(options.sensitivity) || options.sensitivity < 0.0 || options.sensitivity > 1.0)
    fail("sensitivity", "must lie in [0, 1], got " + number(options.sensitivity));
  if (!std::isfinite(options.max_factor) || options.max_factor < 1.0)
    fail("max_factor", "must be at least 1, got " + number(options.max_factor));
  if (!std::isfinite(options.bandwidth_scale) || options.bandwidth_scale <= 0.0)
    fail("bandwidth_scale", "must be positive, got " + number(options.bandwidth_scale));

  std::vector<KernelTree::Item> items;
  items.reserve(deposits.size());
  for (std::size_t i = 0; i < deposits.size(); ++i) {
    const DirectionDeposit& d = deposits[i];
    const double len = glm::length(d.direction);
    if (!std::isfinite(len) || !(len > 0.0))
      fail("deposits[" + std::to_string(i) + "].direction", "must be a finite, non-zero vector");
    if (!std::isfinite(d.flux_lm) || d.flux_lm < 0.0)
      fail("deposits[" + std::to_string(i) + "].flux_lm", "must be a finite flux ≥ 0 lm, got " + number(d.flux_lm));
    if (d.flux_lm > 0.0) items.push_back({d.direction / len, 0.0, d.flux_lm, i});
  }
  deposits.clear();
  const std::size_t n = items.size();
  if (n == 0) {
    impl_->pilot = impl_->min_h = impl_->max_h = std::min(options.pilot_bandwidth, kMaxChord);
    guard.release();
    return;
  }

  // Bandwidth rule (docs/render.md): σ² = 1 − R̄ is E[1 − cos θ] about the mean direction, the per-axis
  // tangent-plane variance of a concentrated distribution.
  double total = 0.0, total_sq = 0.0;
  glm::dvec3 resultant(0.0);
  for (const auto& it : items) total += it.flux, total_sq += it.flux * it.flux, resultant += it.flux * it.p;
  const auto rule = [&](double n_eff) {
    const double sigma = std::sqrt(std::max(0.0, 1.0 - glm::length(resultant) / total));
    return std::clamp(options.bandwidth_scale * kBiweightPerGaussian * sigma * std::pow(n_eff, -1.0 / 6.0), 1e-3, kMaxChord);
  };
  const double n_eff = total * total / total_sq;
  const double pilot = options.pilot_bandwidth > 0.0 ? std::min(options.pilot_bandwidth, kMaxChord) : rule(n_eff);
  impl_->pilot = pilot;

  std::vector<double> h(n, pilot);
  if (options.sensitivity > 0.0 && n > 1) {
    // The fixed-h₀ pilot tabulated at the texel centres of an equal-area sphere map with texels δ ≈ h₀/8
    // across (texel solid angle 2π/R²), read back bilinearly at each direction: O(N (h₀/δ)²) instead of a
    // kernel sum per direction, which a narrow beam of many directions would make O(N²). Bilinear
    // interpolation is off by ≤ (δ²/8)|∇²Ĩ| ≤ (δ/h₀)² Ĩ = Ĩ/64 (|∇²K| ≤ 8K/h² near a biweight's centre),
    // which moves λ by ≤ 0.8 %.
    const int resolution = std::clamp(int(std::ceil(8.0 * std::sqrt(2.0 * kPi) / pilot)), 4, std::min(1024, sphere_map::kMaxResolution));
    std::vector<KernelTree::Item> pilot_items = items;
    for (auto& it : pilot_items) it.h = pilot;
    const KernelTree pilot_tree(std::move(pilot_items));
    SphereMap table(resolution, 1);
    for (int y = 0; y < table.height(); ++y)
      for (int x = 0; x < table.width(); ++x) {
        const glm::vec3 w = sphere_map::uv_to_direction({(x + 0.5f) / float(table.width()), (y + 0.5f) / float(table.height())});
        table.at(x, y, 0) = float(pilot_tree.sum(glm::normalize(glm::dvec3(w))));
      }
    std::vector<double> log_pilot(n);
    double log_g = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      // A direction's own kernel covers its nearest texel centres (δ ≈ h₀/8), so the value is positive;
      // the floor only guards the logarithm.
      const double f = table.lookup(glm::vec3(items[i].p)).x;
      log_pilot[i] = std::log(std::max(f, double(std::numeric_limits<float>::min())));
      log_g += items[i].flux * log_pilot[i];
    }
    log_g /= total;
    for (std::size_t i = 0; i < n; ++i) {
      const double lambda = std::clamp(std::exp(-options.sensitivity * (log_pilot[i] - log_g)), 1.0 / options.max_factor, options.max_factor);
      h[i] = std::min(pilot * lambda, kMaxChord);
    }
  }
  impl_->min_h = *std::min_element(h.begin(), h.end());
  impl_->max_h = *std::max_element(h.begin(), h.end());
  for (std::size_t i = 0; i < n; ++i) items[i].h = h[i];
  impl_->tree = std::make_unique<KernelTree>(std::move(items));
  guard.release();
}

AdaptiveKernelDensitySphere::~AdaptiveKernelDensitySphere() { delete impl_; }
AdaptiveKernelDensitySphere::AdaptiveKernelDensitySphere(AdaptiveKernelDensitySphere&& o) noexcept : impl_(o.impl_) { o.impl_ = nullptr; }
AdaptiveKernelDensitySphere& AdaptiveKernelDensitySphere::operator=(AdaptiveKernelDensitySphere&& o) noexcept {
  if (this != &o) {
    delete impl_;
    impl_ = o.impl_;
    o.impl_ = nullptr;
  }
  return *this;
}

double AdaptiveKernelDensitySphere::intensity_cd(const glm::dvec3& direction) const {
  const double len = glm::length(direction);
  if (!impl_ || !impl_->tree || !std::isfinite(len) || !(len > 0.0)) return 0.0;
  return impl_->tree->sum(direction / len);
}

double AdaptiveKernelDensitySphere::pilot_bandwidth() const { return impl_ ? impl_->pilot : 0.0; }
double AdaptiveKernelDensitySphere::min_bandwidth() const { return impl_ ? impl_->min_h : 0.0; }
double AdaptiveKernelDensitySphere::max_bandwidth() const { return impl_ ? impl_->max_h : 0.0; }

}  // namespace render
LUMX_NAMESPACE_END
