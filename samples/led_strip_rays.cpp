// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// samples/led_strip_rays.cpp — writing a rayset with lumx: a procedural LED strip as an IES TM-25 file,
// the input of the README's main job (`lumx build`), made on the spot so a fresh clone needs no data.
//
//   led_strip_rays OUT.tm25ray [--rays N] [--seed S]
//
// The luminaire: 8 LED dies, 2 mm × 2 mm, 15 mm apart along x (a 107 mm strip), all facing down (−z, the
// photometric nadir). Even dies are bare, with a Lambertian lobe I(θ) = Φ/π · cos θ; odd dies sit under a
// collimating lens, with I(θ) = Φ (m+1)/(2π) · cos^m θ, m = 8. Each die emits 100 lm (800 lm in all).
// Each ray leaves a die drawn at random, starts uniformly on it, its direction follows the die's lobe (cos θ = u^(1/(m+1)); m = 1 for the
// bare dies is the cosine-weighted hemisphere), and every ray carries the same flux, so each die emits
// 100 lm up to the binomial noise of its ray count.
//
// The rays are generated as a stream (a RaySource), never all in memory: ray i draws its random numbers
// from a counter-based hash of (seed, i), so the file is the same for a given seed whatever the chunking,
// and millions of rays cost no memory. What it prints: the rays, the flux, and the analytic intensity at
// nadir (cd) and the share of the flux within 30° of nadir, to compare with `lumx info` of a build.
#include <lumx/io/rayset_io.h>
#include <lumx/math/constants.h>
#include <lumx/rays/rayset.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

using namespace lumx;

namespace {

constexpr int kDies = 8;
constexpr double kPitch = 0.015;    // m between die centres
constexpr double kDieSize = 0.002;  // m, square
constexpr double kDieFlux = 100.0;  // lm
constexpr int kLensExponent = 8;    // cos^m lobe of the dies under a lens

int lobe_exponent(int die) { return die % 2 == 0 ? 1 : kLensExponent; }

/// SplitMix64 (Steele, Lea & Flood 2014): a bijective 64-bit mix, used as a counter-based generator.
std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

/// Uniform in [0, 1) from the top 53 bits.
double uniform(std::uint64_t bits) { return double(bits >> 11) * 0x1.0p-53; }

/// The strip's rays, generated on demand in index order.
class LedStripRays : public RaySource {
 public:
  LedStripRays(std::uint64_t rays, std::uint64_t seed) : rays_(rays), seed_(seed) {
    info_.format = "synthetic";
    info_.ray_count = rays;
    info_.quantity = PhotometricQuantity::photometric;
    info_.header_flux = kDies * kDieFlux;
    info_.simulated = true;
    info_.text["name"] = "8-die LED strip (synthetic)";
    info_.text["ray file creator"] = "lumx samples/led_strip_rays.cpp, seed " + std::to_string(seed);
  }
  const RaysetInfo& info() const override { return info_; }
  void rewind() override { next_ = 0; }
  bool next(RayChunk& out, std::size_t max_rays) override {
    out.clear();
    if (next_ >= rays_) return false;
    const std::uint64_t end = std::min<std::uint64_t>(rays_, next_ + std::max<std::size_t>(1, max_rays));
    out.reserve(std::size_t(end - next_));
    const float flux = float(kDies * kDieFlux / double(rays_));
    for (; next_ < end; ++next_) {
      const std::uint64_t key = mix(seed_ ^ mix(next_));
      // The die is drawn at random too (equal chance each): a die chosen by ray index would make every
      // split of the file by index (even/odd rays, as noise estimates use) a different luminaire.
      const int die = int(mix(key) % kDies);
      const double u[4] = {uniform(mix(key + 1)), uniform(mix(key + 2)), uniform(mix(key + 3)), uniform(mix(key + 4))};
      const double x = (die - (kDies - 1) / 2.0) * kPitch + (u[0] - 0.5) * kDieSize;
      const double y = (u[1] - 0.5) * kDieSize;
      // cos θ distributed as (m+1) cos^m θ sin θ: cos θ = u^(1/(m+1)).
      const double cos_t = std::pow(1.0 - u[2], 1.0 / (lobe_exponent(die) + 1));
      const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
      const double phi = 2 * kPi * u[3];
      out.push_back(glm::vec3(float(x), float(y), 0.0f),
                    glm::vec3(float(sin_t * std::cos(phi)), float(sin_t * std::sin(phi)), float(-cos_t)), flux);
    }
    return true;
  }

 private:
  RaysetInfo info_;
  std::uint64_t rays_, seed_, next_ = 0;
};

std::uint64_t parse_count(const char* text, const char* what) {
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text, &end, 10);
  if (!end || *end || v == 0 || v > 100'000'000ull) {
    std::fprintf(stderr, "led_strip_rays: %s must be a whole number in 1..100000000, got '%s'\n", what, text);
    std::exit(2);
  }
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  std::uint64_t rays = 200'000, seed = 1;
  std::string out;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--rays" && i + 1 < argc) rays = parse_count(argv[++i], "--rays");
    else if (a == "--seed" && i + 1 < argc) seed = parse_count(argv[++i], "--seed");
    else if (out.empty() && a.rfind("--", 0) != 0) out = a;
    else {
      std::fprintf(stderr, "usage: led_strip_rays OUT.tm25ray [--rays N] [--seed S]\n");
      return 2;
    }
  }
  if (out.empty()) {
    std::fprintf(stderr, "usage: led_strip_rays OUT.tm25ray [--rays N] [--seed S]\n");
    return 2;
  }
  try {
    LedStripRays source(rays, seed);
    write_tm25(out, source.info(), source);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "led_strip_rays: %s\n", e.what());
    return 1;
  }
  // Analytic far field: I(0) = Σ Φ (m+1)/(2π); flux within θ: Φ (1 − cos^(m+1) θ).
  double nadir_cd = 0, within_30 = 0;
  for (int d = 0; d < kDies; ++d) {
    const int m = lobe_exponent(d);
    nadir_cd += kDieFlux * (m + 1) / (2 * kPi);
    within_30 += kDieFlux * (1 - std::pow(std::cos(30 * kDegToRad), m + 1));
  }
  std::printf("%s: %llu rays, %.1f lm (8-die LED strip, seed %llu); analytic nadir intensity %.2f cd, "
              "%.1f %% of the flux within 30 deg of nadir\n",
              out.c_str(), static_cast<unsigned long long>(rays), kDies * kDieFlux, static_cast<unsigned long long>(seed),
              nadir_cd, 100 * within_30 / (kDies * kDieFlux));
  return 0;
}
