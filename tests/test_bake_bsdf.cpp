// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The glTF scattering model (lumx/bake/bsdf.h): χ² goodness of fit of sample() against pdf(), agreement of
// sample(), pdf() and eval(), adjointness of the two transport modes, white-furnace energy balance and
// robustness to bad parameters.
#include <lumx/bake/bsdf.h>
#include <lumx/math/constants.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

using namespace lumx;
using namespace lumx::bake;

namespace {

#if defined(__SANITIZE_ADDRESS__)
// The sanitizer build (several times slower) runs a tenth of the samples on a coarser histogram. (CI's sanitizer
// run leaves the χ² tests out, scripts/test.sh: BsdfConsistency runs their sampling code there.)
constexpr int kChi2Samples = 100000;
constexpr int kChi2CosBins = 10, kChi2PhiBins = 20;
constexpr int kFurnaceSamples = 100000;
#else
constexpr int kChi2Samples = 1000000;
constexpr int kChi2CosBins = 20, kChi2PhiBins = 40;
constexpr int kFurnaceSamples = 1000000;
#endif
constexpr double kChi2Significance = 0.01;
/// Relative agreement of a quadrature cell with its halves: expected counts err by ~10⁻⁵, far below √N.
constexpr double kQuadratureTolerance = 1e-5;

/// SplitMix64: a small deterministic generator of uniform doubles in [0, 1).
struct Uniform {
  std::uint64_t state;
  explicit Uniform(std::uint64_t seed) : state(seed) {}
  double operator()() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return double(z >> 11) * 0x1.0p-53;
  }
};

glm::dvec3 direction(double cos_theta, double phi) {
  const double s = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  return {s * std::cos(phi), s * std::sin(phi), cos_theta};
}

/// An outgoing direction at the given cos θo (negative: arriving from inside a volume), slightly off the
/// x axis so that no symmetry of the histogram hides an error.
glm::dvec3 outgoing(double cos_theta) {
  return direction(cos_theta, 0.3);
}

Material dielectric(double roughness, Rgb base = Rgb{0.8, 0.5, 0.2}) {
  Material m;
  m.metallic = 0.0;
  m.roughness = roughness;
  m.base_color = base;
  return m;
}

Material conductor(double roughness, Rgb base = Rgb{0.95, 0.64, 0.54}) {
  Material m;
  m.metallic = 1.0;
  m.roughness = roughness;
  m.base_color = base;
  return m;
}

Material transmissive(double roughness, bool volume, Rgb base = Rgb{0.9, 0.8, 0.7}) {
  Material m = dielectric(roughness, base);
  m.transmission = 1.0;
  m.volume = volume;
  return m;
}

struct Configuration {
  std::string name;
  Material material;
  double cos_o;
};

std::string label(const std::string& kind, double roughness, double cos_o) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%s_r%03d_cos%+04d", kind.c_str(), int(std::lround(roughness * 100)),
                int(std::lround(cos_o * 100)));
  std::string s = buf;
  std::replace(s.begin(), s.end(), '+', 'p');
  std::replace(s.begin(), s.end(), '-', 'm');
  return s;
}

/// The configurations the χ² and furnace tests run: every lobe family at normal, oblique and grazing
/// incidence, rough and smooth, from outside and (volumes) from inside.
std::vector<Configuration> configurations() {
  std::vector<Configuration> list;
  const double cosines[] = {1.0, 0.5, 0.1};
  for (double r : {0.05, 0.3, 0.7, 1.0})
    for (double c : cosines) list.push_back({label("conductor", r, c), conductor(r), c});
  for (double r : {0.05, 0.3, 1.0})
    for (double c : cosines) list.push_back({label("dielectric", r, c), dielectric(r), c});
  for (double r : {0.05, 0.3, 0.7})
    for (double c : cosines) list.push_back({label("thin", r, c), transmissive(r, false), c});
  for (double r : {0.05, 0.3, 0.7, 1.0})
    for (double c : cosines) {
      list.push_back({label("volume_in", r, c), transmissive(r, true), c});     // η = 1.5
      list.push_back({label("volume_out", r, -c), transmissive(r, true), -c});  // η = 1/1.5
    }
  for (double c : cosines) {
    list.push_back({label("smooth_conductor", 0.0, c), conductor(0.0), c});
    list.push_back({label("smooth_dielectric", 0.0, c), dielectric(0.0), c});
    list.push_back({label("smooth_thin", 0.0, c), transmissive(0.0, false), c});
    list.push_back({label("smooth_volume_in", 0.0, c), transmissive(0.0, true), c});
    list.push_back({label("smooth_volume_out", 0.0, -c), transmissive(0.0, true), -c});
    Material dt = dielectric(0.5);
    dt.diffuse_transmission = 0.6;
    dt.diffuse_transmission_color = Rgb{0.5, 0.9, 0.7};
    list.push_back({label("diffuse_transmission", 0.5, c), dt, c});
    Material mixed = dielectric(0.5, Rgb{0.7, 0.6, 0.9});
    mixed.metallic = 0.5;
    mixed.transmission = 0.4;
    mixed.diffuse_transmission = 0.3;
    mixed.specular_color = Rgb{1.2, 0.8, 1.0};
    list.push_back({label("mixed_metallic", 0.5, c), mixed, c});
    Material mixed_volume = mixed;
    mixed_volume.volume = true;
    mixed_volume.roughness = 0.3;
    list.push_back({label("mixed_volume", 0.3, c), mixed_volume, c});
    Material matched = transmissive(0.4, true);
    matched.ior = 1.0;
    list.push_back({label("index_matched", 0.4, c), matched, c});
  }
  return list;
}

// ---------------------------------------------------------------------------------------------------------
// χ² machinery.

/// Upper regularised incomplete gamma Q(a, x) (series for x < a + 1, Lentz continued fraction otherwise).
double gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double log_prefix = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 100000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-15) break;
    }
    return std::max(0.0, 1.0 - sum * std::exp(log_prefix));
  }
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-15) break;
  }
  return std::exp(log_prefix) * h;
}

/// Tensor-product Simpson rule on [x0,x1]×[y0,y1]. Its nodes include the cell's corners, so a narrow lobe
/// whose peak lies on a cut line (see bin_probability) is always seen.
double simpson2d(const std::function<double(double, double)>& f, double x0, double x1, double y0, double y1) {
  static const double weight[3] = {1.0, 4.0, 1.0};
  const double xs[3] = {x0, 0.5 * (x0 + x1), x1}, ys[3] = {y0, 0.5 * (y0 + y1), y1};
  double sum = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) sum += weight[i] * weight[j] * f(xs[i], ys[j]);
  return sum * (x1 - x0) * (y1 - y0) / 36.0;
}

/// Adaptive, anisotropic refinement: the cell is compared with its halves along x and along y, and split
/// along the direction that disagrees more until both agree to 1e-12 + kQuadratureTolerance relative (a
/// lobe at the pole of the (cos θ, φ) chart is then refined in cos θ only).
double adaptive_integral(const std::function<double(double, double)>& f, double x0, double x1, double y0, double y1,
                         double whole, int depth) {
  const double xm = 0.5 * (x0 + x1), ym = 0.5 * (y0 + y1);
  const double left = simpson2d(f, x0, xm, y0, y1), right = simpson2d(f, xm, x1, y0, y1);
  const double bottom = simpson2d(f, x0, x1, y0, ym), top = simpson2d(f, x0, x1, ym, y1);
  const double split_x = left + right, split_y = bottom + top;
  const double error_x = std::abs(split_x - whole), error_y = std::abs(split_y - whole);
  if (depth <= 0 || std::max(error_x, error_y) <= 1e-12 + kQuadratureTolerance * std::abs(split_x))
    return 0.5 * (split_x + split_y);
  if (error_x >= error_y)
    return adaptive_integral(f, x0, xm, y0, y1, left, depth - 1) +
           adaptive_integral(f, xm, x1, y0, y1, right, depth - 1);
  return adaptive_integral(f, x0, x1, y0, ym, bottom, depth - 1) + adaptive_integral(f, x0, x1, ym, y1, top, depth - 1);
}

/// Where a configuration's narrow lobes peak, in (cos θ, φ): cut lines through them put quadrature nodes on
/// the peaks.
struct PeakHints {
  std::vector<double> cos_theta, phi;
  void add(const glm::dvec3& w) {
    cos_theta.push_back(std::clamp(w.z, -1.0, 1.0));
    double p = std::atan2(w.y, w.x);
    if (p < 0.0) p += 2.0 * kPi;
    phi.push_back(p);
  }
};

/// The specular peaks of wo: the mirror direction, −wo (thin transmission) and the refracted direction.
PeakHints peaks(const Material& m, const glm::dvec3& wo) {
  PeakHints h;
  h.add({-wo.x, -wo.y, wo.z});
  h.add(-wo);
  const double eta = wo.z > 0.0 ? m.ior : 1.0 / m.ior;
  const double c = std::abs(wo.z), sin2_t = (1.0 - c * c) / (eta * eta);
  if (sin2_t < 1.0) {
    const double s = std::sqrt(sin2_t), t = std::sqrt(1.0 - sin2_t);
    const double sin_o = std::sqrt(std::max(0.0, 1.0 - c * c));
    const glm::dvec3 planar = sin_o > 0.0 ? glm::dvec3(-wo.x, -wo.y, 0.0) / sin_o : glm::dvec3(1.0, 0.0, 0.0);
    h.add(planar * s + glm::dvec3(0.0, 0.0, wo.z > 0.0 ? -t : t));
  }
  return h;
}

/// Cut points of [a, b]: kCut equal parts plus every hint inside.
std::vector<double> cuts(double a, double b, const std::vector<double>& hints) {
  constexpr int kCut = 4;
  std::vector<double> c;
  for (int i = 0; i <= kCut; ++i) c.push_back(a + (b - a) * i / kCut);
  for (double h : hints)
    if (h > a && h < b) c.push_back(h);
  std::sort(c.begin(), c.end());
  c.erase(std::unique(c.begin(), c.end()), c.end());
  return c;
}

/// Integral of pdf(wo, ·) over one (cos θ, φ) bin; dω = d(cos θ) dφ.
double bin_probability(const Bsdf& bsdf, const glm::dvec3& wo, const PeakHints& hints, double c0, double c1, double p0,
                       double p1) {
  const auto f = [&](double c, double p) { return bsdf.pdf(wo, direction(c, p)); };
  const std::vector<double> xs = cuts(c0, c1, hints.cos_theta), ys = cuts(p0, p1, hints.phi);
  double sum = 0.0;
  for (std::size_t i = 0; i + 1 < xs.size(); ++i)
    for (std::size_t j = 0; j + 1 < ys.size(); ++j)
      sum += adaptive_integral(f, xs[i], xs[i + 1], ys[j], ys[j + 1], simpson2d(f, xs[i], xs[i + 1], ys[j], ys[j + 1]),
                               48);
  return sum;
}

struct Chi2Result {
  double p_value = 1.0;
  double integral = 0.0;                              ///< ∫ pdf over the sphere
  double other_observed = 0.0, other_expected = 0.0;  ///< the delta / no-sample bin
  int degrees_of_freedom = 0;
};

/// Histogram of sample() over (cos θ, φ) on the sphere, plus one bin for delta samples and failed draws,
/// against N × ∫ pdf per bin and N × (1 − ∫ pdf) for the extra bin; bins expecting < 5 are pooled.
Chi2Result chi2_test(const Material& material, const glm::dvec3& wo, int samples, std::uint64_t seed) {
  const Bsdf bsdf(material);
  const PeakHints hints = peaks(material, wo);
  const int n_cos = kChi2CosBins, n_phi = kChi2PhiBins, n_bins = n_cos * n_phi;
  std::vector<double> observed(n_bins + 1, 0.0), expected(n_bins + 1, 0.0);
  Uniform rng(seed);
  for (int k = 0; k < samples; ++k) {
    const double u_lobe = rng();
    const glm::dvec2 u{rng(), rng()};
    const auto s = bsdf.sample(wo, u_lobe, u, TransportMode::importance);
    if (!s || s->delta) {
      observed[n_bins] += 1.0;
      continue;
    }
    const int ic = std::clamp(int((s->wi.z + 1.0) * 0.5 * n_cos), 0, n_cos - 1);
    double phi = std::atan2(s->wi.y, s->wi.x);
    if (phi < 0.0) phi += 2.0 * kPi;
    const int ip = std::clamp(int(phi / (2.0 * kPi) * n_phi), 0, n_phi - 1);
    observed[ic * n_phi + ip] += 1.0;
  }
  Chi2Result r;
  for (int ic = 0; ic < n_cos; ++ic)
    for (int ip = 0; ip < n_phi; ++ip) {
      const double c0 = -1.0 + 2.0 * ic / n_cos, c1 = -1.0 + 2.0 * (ic + 1) / n_cos;
      const double p0 = 2.0 * kPi * ip / n_phi, p1 = 2.0 * kPi * (ip + 1) / n_phi;
      const double prob = bin_probability(bsdf, wo, hints, c0, c1, p0, p1);
      r.integral += prob;
      expected[ic * n_phi + ip] = prob * samples;
    }
  expected[n_bins] = std::max(0.0, 1.0 - r.integral) * samples;
  r.other_observed = observed[n_bins];
  r.other_expected = expected[n_bins];

  double chi2 = 0.0, pooled_obs = 0.0, pooled_exp = 0.0;
  int bins_used = 0;
  for (int b = 0; b <= n_bins; ++b) {
    if (expected[b] < 5.0) {
      pooled_obs += observed[b];
      pooled_exp += expected[b];
      continue;
    }
    const double d = observed[b] - expected[b];
    chi2 += d * d / expected[b];
    ++bins_used;
  }
  if (pooled_exp > 0.0 || pooled_obs > 0.0) {
    const double d = pooled_obs - pooled_exp;
    chi2 += d * d / std::max(pooled_exp, 5.0);  // a pooled bin that expects almost nothing still must not fill
    ++bins_used;
  }
  r.degrees_of_freedom = std::max(1, bins_used - 1);
  r.p_value = gamma_q(0.5 * r.degrees_of_freedom, 0.5 * chi2);
  return r;
}

class BsdfChi2 : public ::testing::TestWithParam<int> {};

TEST_P(BsdfChi2, SampleMatchesPdf) {
  static const std::vector<Configuration> list = configurations();
  const Configuration& cfg = list[std::size_t(GetParam())];
  const glm::dvec3 wo = outgoing(cfg.cos_o);
  const Chi2Result r = chi2_test(cfg.material, wo, kChi2Samples, 1000 + std::uint64_t(GetParam()));
  // Šidák: each of the m tests at 1 − (1 − 0.01)^(1/m) keeps the family's false-rejection rate at 0.01.
  const double threshold = 1.0 - std::pow(1.0 - kChi2Significance, 1.0 / double(list.size()));
  std::printf("[chi2] %-34s p = %.4f  dof = %4d  ∫pdf = %.6f  other: observed %.0f expected %.1f\n", cfg.name.c_str(),
              r.p_value, r.degrees_of_freedom, r.integral, r.other_observed, r.other_expected);
  EXPECT_LE(r.integral, 1.0 + 1e-4) << cfg.name;
  EXPECT_GT(r.p_value, threshold) << cfg.name << ": sample() does not follow pdf()";
}

INSTANTIATE_TEST_SUITE_P(Bsdf, BsdfChi2, ::testing::Range(0, int(configurations().size())),
                         [](const ::testing::TestParamInfo<int>& param_info) {
                           return configurations()[std::size_t(param_info.param)].name;
                         });

// ---------------------------------------------------------------------------------------------------------
// sample() / pdf() / eval() agreement and the transport modes.

double relative_difference(double a, double b) {
  return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1e-300});
}

TEST(BsdfConsistency, SampleAgreesWithPdfAndEval) {
  int checked = 0;
  for (const Configuration& cfg : configurations()) {
    const Bsdf bsdf(cfg.material);
    const glm::dvec3 wo = outgoing(cfg.cos_o);
    Uniform rng(7);
    for (int k = 0; k < 2000; ++k) {
      for (TransportMode mode : {TransportMode::importance, TransportMode::radiance}) {
        const double u_lobe = rng();
        const glm::dvec2 u{rng(), rng()};
        const auto s = bsdf.sample(wo, u_lobe, u, mode);
        if (!s || s->delta) continue;
        const double pdf = bsdf.pdf(wo, s->wi);
        ASSERT_LT(relative_difference(s->pdf, pdf), 1e-6) << cfg.name;
        const Rgb f = bsdf.eval(wo, s->wi, mode);
        for (int c = 0; c < 3; ++c)
          ASSERT_LT(std::abs(s->weight[c] - f[c] * std::abs(s->wi.z) / pdf), 1e-6 * std::max(1.0, s->weight[c]))
              << cfg.name;
        ASSERT_EQ(s->transmitted, (s->wi.z > 0.0) != (wo.z > 0.0)) << cfg.name;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 100000);
}

TEST(BsdfConsistency, SampleIsDeterministic) {
  for (const Configuration& cfg : configurations()) {
    const Bsdf bsdf(cfg.material);
    const glm::dvec3 wo = outgoing(cfg.cos_o);
    Uniform rng(11);
    for (int k = 0; k < 200; ++k) {
      const double u_lobe = rng();
      const glm::dvec2 u{rng(), rng()};
      const auto a = bsdf.sample(wo, u_lobe, u, TransportMode::importance);
      const auto b = bsdf.sample(wo, u_lobe, u, TransportMode::importance);
      ASSERT_EQ(bool(a), bool(b));
      if (a) {
        EXPECT_EQ(a->wi, b->wi);
        EXPECT_EQ(a->weight, b->weight);
        EXPECT_EQ(a->delta, b->delta);
      }
    }
  }
}

/// Importance transport is the adjoint: eval(wo, wi, importance) == eval(wi, wo, radiance). A non-volume
/// surface is presented with the arrival side as +z, so for a transmitted pair the adjoint query is made
/// with both directions mirrored through the surface.
TEST(BsdfTransport, ImportanceIsTheAdjointOfRadiance) {
  int checked = 0;
  for (const Configuration& cfg : configurations()) {
    const Bsdf bsdf(cfg.material);
    const glm::dvec3 wo = outgoing(cfg.cos_o);
    Uniform rng(13);
    for (int k = 0; k < 500; ++k) {
      const glm::dvec3 wi = direction(2.0 * rng() - 1.0, 2.0 * kPi * rng());
      const Rgb importance = bsdf.eval(wo, wi, TransportMode::importance);
      Rgb adjoint;
      if (!cfg.material.volume && wi.z < 0.0)
        adjoint = bsdf.eval(glm::dvec3(wi.x, wi.y, -wi.z), glm::dvec3(wo.x, wo.y, -wo.z), TransportMode::radiance);
      else
        adjoint = bsdf.eval(wi, wo, TransportMode::radiance);
      for (int c = 0; c < 3; ++c)
        ASSERT_LE(std::abs(importance[c] - adjoint[c]), 1e-9 * std::max(1.0, std::abs(importance[c]))) << cfg.name;
      ++checked;
    }
  }
  EXPECT_GT(checked, 10000);
}

/// For a white, fully transmissive rough volume the interface is reciprocal, so the radiance BTDF is the
/// particle BTDF divided by η² (η = ηᵢ/ηₒ, the index on wi's side over wo's; Veach 1997 eq. 5.13), and the
/// reflection is the same in both modes.
TEST(BsdfTransport, RadianceRefractionCarriesEtaSquared) {
  const Material glass = transmissive(0.4, true, Rgb{1.0});
  const Bsdf bsdf(glass);
  Uniform rng(17);
  int refracted = 0;
  for (double cos_o : {0.9, 0.4, -0.9, -0.4}) {
    const glm::dvec3 wo = outgoing(cos_o);
    for (int k = 0; k < 2000; ++k) {
      const glm::dvec3 wi = direction(2.0 * rng() - 1.0, 2.0 * kPi * rng());
      const Rgb importance = bsdf.eval(wo, wi, TransportMode::importance);
      const Rgb radiance = bsdf.eval(wo, wi, TransportMode::radiance);
      const bool transmitted = (wi.z > 0.0) != (wo.z > 0.0);
      const double eta = transmitted ? (wo.z > 0.0 ? 1.5 : 1.0 / 1.5) : 1.0;
      for (int c = 0; c < 3; ++c)
        ASSERT_LE(std::abs(radiance[c] - importance[c] / (eta * eta)), 1e-9 * std::max(1.0, importance[c]));
      if (transmitted && importance.x > 0.0) ++refracted;
    }
  }
  EXPECT_GT(refracted, 500);
  // The smooth interface: the radiance weight of the refracted delta sample is the particle weight / η².
  const Bsdf smooth(transmissive(0.0, true, Rgb{1.0}));
  const glm::dvec3 wo = outgoing(0.7);
  const auto p = smooth.sample(wo, 0.999, {0.5, 0.5}, TransportMode::importance);
  const auto r = smooth.sample(wo, 0.999, {0.5, 0.5}, TransportMode::radiance);
  ASSERT_TRUE(p && r && p->delta && r->delta && p->transmitted);
  EXPECT_NEAR(r->weight.x, p->weight.x / (1.5 * 1.5), 1e-12);
}

// ---------------------------------------------------------------------------------------------------------
// White furnace.

struct Albedo {
  Rgb mean{0.0};
  Rgb sigma{0.0};  ///< standard error of the mean
};

Albedo furnace(const Bsdf& bsdf, const glm::dvec3& wo, TransportMode mode, int samples, std::uint64_t seed) {
  Uniform rng(seed);
  Rgb sum{0.0}, sum2{0.0};
  for (int k = 0; k < samples; ++k) {
    const double u_lobe = rng();
    const glm::dvec2 u{rng(), rng()};
    const auto s = bsdf.sample(wo, u_lobe, u, mode);
    if (!s) continue;
    sum += s->weight;
    sum2 += s->weight * s->weight;
  }
  Albedo a;
  a.mean = sum / double(samples);
  const Rgb var = glm::max(sum2 / double(samples) - a.mean * a.mean, Rgb{0.0});
  a.sigma = glm::sqrt(var / double(samples));
  return a;
}

/// Every configuration, as listed and with white colours, in particle transport. (Radiance transport has
/// the same kernel away from volumes, and through a refracting interface radiance is scaled by η², which
/// is not energy.)
TEST(BsdfFurnace, NoConfigurationCreatesEnergy) {
  double worst_rough = 0.0;
  std::string worst_name;
  for (const Configuration& listed : configurations())
    for (bool white : {false, true}) {
      Configuration cfg = listed;
      if (white) {
        cfg.material.base_color = cfg.material.diffuse_transmission_color = cfg.material.specular_color = Rgb{1.0};
        cfg.name += "_white";
      }
      const Bsdf bsdf(cfg.material);
      const glm::dvec3 wo = outgoing(cfg.cos_o);
      const Albedo a = furnace(bsdf, wo, TransportMode::importance, kFurnaceSamples / 10, 23);
      for (int c = 0; c < 3; ++c) {
        EXPECT_LE(a.mean[c], 1.0 + 4.0 * a.sigma[c] + 1e-12) << cfg.name << " channel " << c;
        if (!bsdf.has_delta_lobe() && a.mean[c] > worst_rough) {
          worst_rough = a.mean[c];
          worst_name = cfg.name;
        }
      }
      if (white) std::printf("[furnace] %-40s albedo %.4f ± %.4f\n", cfg.name.c_str(), a.mean.y, a.sigma.y);
    }
  std::printf("[furnace] highest albedo of a configuration without delta lobes: %.5f (%s)\n", worst_rough,
              worst_name.c_str());
}

/// Delta lobes: over many draws each lobe is chosen with the probability its samples report, and the
/// split of a smooth interface into reflection and transmission is Fresnel's.
TEST(BsdfFurnace, SmoothInterfaceSplitsByFresnel) {
  const Bsdf glass(transmissive(0.0, true, Rgb{1.0}));
  for (double cos_o : {0.9, 0.3, -0.9, -0.7}) {
    const glm::dvec3 wo = outgoing(cos_o);
    Uniform rng(41);
    const int n = kFurnaceSamples / 10;
    int reflected = 0;
    double reported = 0.0;
    for (int k = 0; k < n; ++k) {
      const auto s = glass.sample(wo, rng(), {rng(), rng()}, TransportMode::importance);
      ASSERT_TRUE(s && s->delta);
      if (!s->transmitted) {
        ++reflected;
        reported = s->pdf;
      }
    }
    const double eta = cos_o > 0.0 ? 1.5 : 1.0 / 1.5;
    const double c = std::abs(cos_o), sin2_t = (1.0 - c * c) / (eta * eta);
    const double ct = std::sqrt(std::max(0.0, 1.0 - sin2_t));
    const double rs = (c - eta * ct) / (c + eta * ct), rp = (eta * c - ct) / (eta * c + ct);
    const double fresnel = sin2_t >= 1.0 ? 1.0 : 0.5 * (rs * rs + rp * rp);
    const double sigma = std::sqrt(fresnel * (1.0 - fresnel) / n);
    EXPECT_NEAR(double(reflected) / n, fresnel, 4.0 * sigma + 1e-12) << cos_o;
    if (reflected > 0) {
      EXPECT_NEAR(reported, fresnel, 1e-12) << cos_o;
    }
  }
}

void expect_albedo(const std::string& what, const Material& m, double cos_o, const Rgb& expected) {
  const Bsdf bsdf(m);
  // These configurations scatter every particle with weight one; a quarter of the samples suffices.
  const Albedo a = furnace(bsdf, outgoing(cos_o), TransportMode::importance, kFurnaceSamples / 4, 29);
  std::printf("[furnace] %-34s cos %+.2f  albedo (%.5f %.5f %.5f) ± (%.1e %.1e %.1e)\n", what.c_str(), cos_o, a.mean.x,
              a.mean.y, a.mean.z, a.sigma.x, a.sigma.y, a.sigma.z);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(a.mean[c], expected[c], 4.0 * a.sigma[c] + 1e-9) << what << " cos " << cos_o << " channel " << c;
}

TEST(BsdfFurnace, EnergyConservingCasesReflectOrTransmitEverything) {
  for (double c : {1.0, 0.5, 0.1}) {
    expect_albedo("smooth volume, entering", transmissive(0.0, true, Rgb{1.0}), c, Rgb{1.0});
    expect_albedo("smooth volume, leaving", transmissive(0.0, true, Rgb{1.0}), -c, Rgb{1.0});
    expect_albedo("smooth thin transmission", transmissive(0.0, false, Rgb{1.0}), c, Rgb{1.0});
    expect_albedo("smooth conductor, white", conductor(0.0, Rgb{1.0}), c, Rgb{1.0});
    Material lambert = dielectric(0.6, Rgb{1.0});
    lambert.specular = 0.0;
    expect_albedo("Lambertian, specular 0", lambert, c, Rgb{1.0});
    lambert.base_color = Rgb{0.8, 0.5, 0.2};
    expect_albedo("Lambertian, specular 0, coloured", lambert, c, lambert.base_color);
    Material translucent = dielectric(0.6, Rgb{1.0});
    translucent.specular = 0.0;
    translucent.diffuse_transmission = 1.0;
    expect_albedo("diffuse transmitter, specular 0", translucent, c, Rgb{1.0});
  }
}

/// A white rough plastic where the layer's visible-microfacet Fresnel exceeds the macro-normal Fresnel
/// most: the diffuse coupling's margin keeps the albedo below one.
TEST(BsdfFurnace, RoughWhitePlasticStaysBelowOne) {
  for (double roughness : {0.1, 0.2, 0.3})
    for (double cos_o : {0.7, 0.5}) {
      const Bsdf bsdf(dielectric(roughness, Rgb{1.0}));
      const Albedo a = furnace(bsdf, outgoing(cos_o), TransportMode::importance, kFurnaceSamples, 43);
      std::printf("[furnace] white plastic roughness %.1f cos %.1f   albedo %.5f ± %.5f\n", roughness, cos_o, a.mean.y,
                  a.sigma.y);
      EXPECT_LE(a.mean.y, 1.0 + 4.0 * a.sigma.y);
      EXPECT_GT(a.mean.y, 0.98);
    }
}

TEST(BsdfFurnace, LambertianWithoutSpecularIsExactlyTheBaseColour) {
  Material m = dielectric(0.5, Rgb{0.8, 0.5, 0.2});
  m.specular = 0.0;
  const Bsdf bsdf(m);
  Uniform rng(31);
  for (int k = 0; k < 1000; ++k) {
    const glm::dvec3 wo = direction(rng(), 2.0 * kPi * rng());
    const glm::dvec3 wi = direction(rng(), 2.0 * kPi * rng());
    if (wo.z <= 0.0 || wi.z <= 0.0) continue;
    const Rgb f = bsdf.eval(wo, wi, TransportMode::radiance);
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(f[c], m.base_color[c] / kPi, 1e-15);
    const auto s = bsdf.sample(wo, rng(), {rng(), rng()}, TransportMode::importance);
    ASSERT_TRUE(s);
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(s->weight[c], m.base_color[c], 1e-12);
  }
}

// ---------------------------------------------------------------------------------------------------------
// Robustness.

bool finite(const Rgb& c) {
  return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z);
}

void expect_finite_everywhere(const Material& m, const std::string& what) {
  const Bsdf bsdf(m);
  Uniform rng(37);
  const double z_values[] = {1.0, 0.5, 1e-6, 1e-12, 1e-300, 0.0, -1e-12, -0.5, -1.0};
  for (double zo : z_values)
    for (double zi : z_values) {
      const glm::dvec3 wo = direction(zo, 0.7), wi = direction(zi, 2.9);
      for (TransportMode mode : {TransportMode::importance, TransportMode::radiance}) {
        const Rgb f = bsdf.eval(wo, wi, mode);
        ASSERT_TRUE(finite(f)) << what;
        ASSERT_TRUE(f.x >= 0.0 && f.y >= 0.0 && f.z >= 0.0) << what;
      }
      const double pdf = bsdf.pdf(wo, wi);
      ASSERT_TRUE(std::isfinite(pdf) && pdf >= 0.0) << what << " zo " << zo << " zi " << zi;
    }
  for (double zo : z_values) {
    const glm::dvec3 wo = direction(zo, 0.7);
    for (int k = 0; k < 2000; ++k) {
      const double u_lobe = k == 0 ? 0.0 : k == 1 ? 1.0 - 1e-17 : rng();
      const glm::dvec2 u = k == 0 ? glm::dvec2(0.0) : k == 1 ? glm::dvec2(1.0 - 1e-17) : glm::dvec2(rng(), rng());
      for (TransportMode mode : {TransportMode::importance, TransportMode::radiance}) {
        const auto s = bsdf.sample(wo, u_lobe, u, mode);
        if (!s) continue;
        ASSERT_TRUE(finite(s->weight)) << what << " zo " << zo;
        ASSERT_TRUE(std::isfinite(s->pdf) && s->pdf > 0.0) << what;
        ASSERT_TRUE(std::isfinite(s->wi.x) && std::isfinite(s->wi.y) && std::isfinite(s->wi.z)) << what;
        ASSERT_NEAR(glm::length(s->wi), 1.0, 1e-9) << what;
      }
    }
  }
}

TEST(BsdfRobustness, BadParametersAndGrazingAnglesGiveNoNaN) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  std::vector<std::pair<std::string, Material>> cases;
  for (bool volume : {false, true})
    for (double ior : {nan, 0.0, -1.0, inf, 1.0, 1.0 + 1e-9, 1.0005, 1.01, 0.5, 1e9})
      for (double roughness : {nan, -1.0, 0.0, 1e-5, 0.0316, 0.05, 1.0, 7.0}) {
        Material m = transmissive(roughness, volume);
        m.ior = ior;
        m.diffuse_transmission = 0.3;
        cases.push_back(
            {"ior " + std::to_string(ior) + " roughness " + std::to_string(roughness) + (volume ? " volume" : " thin"),
             m});
      }
  Material wild = dielectric(nan, Rgb{nan, -1.0, 5.0});
  wild.metallic = nan;
  wild.specular = nan;
  wild.specular_color = Rgb{inf, nan, -2.0};
  wild.transmission = nan;
  wild.diffuse_transmission = inf;
  wild.diffuse_transmission_color = Rgb{nan, 2.0, -1.0};
  cases.push_back({"all NaN/inf factors", wild});
  wild.volume = true;
  cases.push_back({"all NaN/inf factors, volume", wild});
  Material black = transmissive(0.5, true, Rgb{0.0});
  black.specular = 0.0;
  cases.push_back({"black, no specular", black});
  for (const auto& [what, m] : cases) expect_finite_everywhere(m, what);
}

TEST(BsdfRobustness, NonVolumeBackFaceScattersNothing) {
  const Bsdf bsdf(dielectric(0.5));
  const glm::dvec3 wo = outgoing(-0.5);
  EXPECT_FALSE(bsdf.sample(wo, 0.5, {0.5, 0.5}, TransportMode::importance));
  EXPECT_EQ(bsdf.eval(wo, outgoing(0.5), TransportMode::importance), Rgb{0.0});
  EXPECT_EQ(bsdf.pdf(wo, outgoing(0.5)), 0.0);
}

}  // namespace
