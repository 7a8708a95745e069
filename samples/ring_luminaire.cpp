// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// samples/ring_luminaire.cpp — embedding lumx: build an APL set and a radiance volume by hand, ship them as
// a bundle, then load only what a scene needs and light it.
//
//   ring_luminaire OUT_BUNDLE
//
// The luminaire: 64 LEDs on a ring of radius 0.25 m, each a downward lobe I(ω) ∝ cos³ of the angle to
// an axis tilted 20° outwards, 15.6 lm each (1000 lm in all). Its APL set has three levels that are
// cuts of one tree: 64 APLs (one per LED), 8 (each the sum of 8 neighbouring LEDs, placed at their
// flux-weighted centroid) and 1 (the whole ring: the classic far field). The radiance volume holds the
// LEDs' light inside the luminaire's box (segments from each LED to the box's boundary).
//
// What it prints: the bundle's size, the bytes a distant scene reads (level 8 at reduced resolution),
// and irradiance below the luminaire from each level and from the LOD rule (eq. 6.2), against the exact
// sum over the 64 LEDs' analytic lobes.
#include <lumx/apl/evaluation.h>
#include <lumx/apl/lod.h>
#include <lumx/apl/far_field.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/photometry_io.h>
#include <lumx/volume/radiance_volume.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

using namespace lumx;

namespace {

constexpr int kLeds = 64;
constexpr double kRing = 0.25;         // m
constexpr double kLedFlux = 1000.0 / kLeds;  // lm
constexpr int kResolution = 128;

struct Led {
  glm::vec3 position, axis;
  double peak_cd;  // I(ω) = peak · max(0, ω·axis)³, flux = peak · 2π/4
};

Led led(int i) {
  const double phi = 2 * kPi * (i + 0.5) / kLeds, tilt = 20 * kDegToRad;
  Led l;
  l.position = glm::vec3(float(kRing * std::cos(phi)), float(kRing * std::sin(phi)), 0.0f);
  l.axis = glm::normalize(glm::vec3(float(std::sin(tilt) * std::cos(phi)), float(std::sin(tilt) * std::sin(phi)),
                                    float(-std::cos(tilt))));
  l.peak_cd = kLedFlux / (2 * kPi / 4);  // ∫ cos³ over the hemisphere = 2π/4
  return l;
}

double led_intensity(const Led& l, const glm::vec3& w) {
  const double c = std::max(0.0, double(glm::dot(w, l.axis)));
  return l.peak_cd * c * c * c;
}

AplSet build_set() {
  AplSet set;
  set.quantity = PhotometricQuantity::photometric;
  set.channels = ChannelLayout::luminance;
  set.bounds.center = glm::dvec3(0.0);
  set.bounds.radius = kRing + 0.02;
  set.provenance["source"] = "samples/ring_luminaire.cpp (analytic)";
  set.provenance["manufacturer"] = "lumx sample";
  AplLevel leds, groups, whole;
  leds.map_resolution = groups.map_resolution = whole.map_resolution = kResolution;
  for (int i = 0; i < kLeds; ++i) {
    const Led l = led(i);
    Apl a;
    a.position = l.position;
    a.parent = i / 8;
    a.map = SphereMap(kResolution, 1);
    // Texel value: the mean of 3×3 stratified lookups, so the map's flux is the lobe's within O(1/R²).
    for (int y = 0; y < a.map.height(); ++y)
      for (int x = 0; x < a.map.width(); ++x) {
        double sum = 0;
        for (int s = 0; s < 9; ++s)
          sum += led_intensity(l, sphere_map::uv_to_direction({(x + (s % 3 + 0.5f) / 3) / a.map.width(),
                                                                (y + (s / 3 + 0.5f) / 3) / a.map.height()}));
        a.map.at(x, y, 0) = float(sum / 9);
      }
    leds.apls.push_back(std::move(a));
  }
  auto merge = [](const std::vector<Apl>& children, int count, int group_parent) {
    AplLevel level;
    level.map_resolution = kResolution;
    for (int p = 0; p < count; ++p) {
      Apl a;
      a.map = SphereMap(kResolution, 1);
      a.parent = group_parent;
      glm::dvec3 weighted(0.0);
      double flux = 0;
      for (const Apl& c : children)
        if (c.parent == p) {
          for (std::size_t t = 0; t < a.map.values().size(); ++t) a.map.values()[t] += c.map.values()[t];
          const double f = c.map.integral().x;
          weighted += f * glm::dvec3(c.position);
          flux += f;
        }
      a.position = glm::vec3(weighted / flux);
      level.apls.push_back(std::move(a));
    }
    return level;
  };
  groups = merge(leds.apls, 8, 0);
  whole = merge(groups.apls, 1, -1);
  set.levels = {std::move(whole), std::move(groups), std::move(leds)};
  update_fluxes(set);
  return set;
}

RadianceVolume build_volume() {
  RadianceVolume volume(Aabb{glm::dvec3(-0.27, -0.27, -0.05), glm::dvec3(0.27, 0.27, 0.01)}, 32768, 4, 1);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int per_led = 2000;
  for (int i = 0; i < kLeds; ++i) {
    const Led l = led(i);
    for (int k = 0; k < per_led; ++k) {
      // Directions ∝ cos³ about the LED's axis (inverse CDF of cos⁴ in cos θ), each carrying equal flux.
      const float cos_t = std::pow(u(rng), 0.25f), sin_t = std::sqrt(std::max(0.0f, 1 - cos_t * cos_t));
      const float phi = float(2 * kPi) * u(rng);
      const glm::vec3 t = glm::normalize(glm::cross(l.axis, glm::vec3(0, 0, 1)));
      const glm::vec3 b = glm::cross(l.axis, t);
      const glm::vec3 w = cos_t * l.axis + sin_t * (std::cos(phi) * t + std::sin(phi) * b);
      volume.add_segment(glm::dvec3(l.position), glm::dvec3(w), 1.0, glm::vec3(float(kLedFlux / per_led)));
    }
  }
  return volume;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_BUNDLE\n", argv[0]);
    return 2;
  }
  const std::string out = argv[1];
  try {
    const AplSet set = build_set();
    const RadianceVolume volume = build_volume();
    write_bundle(out, set, &volume);

    // A scene far away: open the manifest, load level 8 at a reduced resolution.
    BundleReader distant(out);
    const AplLevel level8 = distant.load_level(1, 32);
    std::printf("bundle %s: %llu bytes; a distant scene read %llu bytes (manifest + 8 APLs at %d x %d)\n",
                out.c_str(), (unsigned long long)distant.manifest().total_bytes(),
                (unsigned long long)distant.bytes_read(), 2 * level8.map_resolution, level8.map_resolution);

    // Irradiance on the floor below, from each level and from the LOD rule, against the analytic LEDs.
    const AplSet loaded = BundleReader(out).load();
    std::printf("\n%8s %6s %12s %12s %12s %12s %14s\n", "depth m", "d", "exact lx", "1 APL", "8 APLs", "64 APLs",
                "LOD (APLs)");
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (double depth : {0.1, 0.27, 0.5, 1.0, 2.5, 10.0}) {
      const glm::vec3 x(0.25f, 0.0f, float(-depth)), n(0, 0, 1);
      double exact = 0;
      for (int i = 0; i < kLeds; ++i) {
        const Led l = led(i);
        const glm::dvec3 d = glm::dvec3(x) - glm::dvec3(l.position);
        const double r2 = glm::dot(d, d);
        const glm::dvec3 w = d / std::sqrt(r2);
        exact += led_intensity(l, glm::vec3(w)) * std::max(0.0, -w.z) / r2;
      }
      double e[3];
      for (std::size_t k = 0; k < 3; ++k) e[k] = irradiance(loaded, k, x, n).irradiance.x;
      // The LOD rule picks a level per shading point at random; average 1000 picks.
      double lod = 0, count = 0;
      for (int s = 0; s < 1000; ++s) {
        const std::size_t k = choose_level_by_distance(loaded, glm::dvec3(x), u(rng));
        lod += e[k];
        count += double(loaded.levels[k].size());
      }
      std::printf("%8.2f %6.2f %12.4f %12.4f %12.4f %12.4f %8.4f (%3.0f)\n", depth,
                  loaded.relative_distance(glm::dvec3(x)), exact, e[0], e[1], e[2], lod / 1000, count / 1000);
    }
    // The far field of level 1, as legacy tools read it.
    const Photometry far = far_field_photometry(loaded, 0);
    write_photometry(far, out + ".ies");
    std::printf("\nfar field: %s.ies (flux %.2f lm; the LEDs emit %.2f lm)\n", out.c_str(),
                IntensityTable(far).flux_lm(), kLeds * kLedFlux);
    // Directions are those the light travels: (0, 0, -1) is the light heading down, which a viewer
    // below the ring looking up sees.
    std::printf("radiance volume: %d x %d x %d voxels of %.4f m; glow seen from below the ring: %.1f cd/m^2\n",
                volume.counts().x, volume.counts().y, volume.counts().z, volume.voxel_size(),
                volume.radiance({kRing, 0.0, -0.01}, {0, 0, -1}).x);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
