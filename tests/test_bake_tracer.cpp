// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The particle tracer against luminaires with exact answers. Tolerances are k standard errors of the Monte Carlo
// estimate, computed from the particles themselves (k = 4 unless stated: a false alarm about 1 in 16 000 per
// check), plus, where a mesh stands in for a curved surface, the tessellation's bias bounded from the mesh.
#include "luminaire_test_scenes.h"

#include <lumx/bake/tracer.h>
#include <lumx/io/photometry_io.h>
#include <lumx/io/rayset_io.h>
#include <lumx/math/sphere_map.h>
#include <lumx/photometry/intensity_table.h>

#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <thread>

#include <glm/gtc/matrix_transform.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>

namespace {

using namespace lumx_test;
using lumx::bake::ExitParticle;
using lumx::bake::luminance;
using lumx::bake::ParticleChunk;
using lumx::bake::TraceCounters;
using lumx::bake::TraceOptions;
using lumx::bake::Tracer;

#if defined(__SANITIZE_ADDRESS__)
constexpr std::uint64_t kParticles = 40000;  // the sanitizer build is ~10x slower: same checks, wider errors
#else
constexpr std::uint64_t kParticles = 400000;
#endif

struct CollectingSink : lumx::bake::ParticleSink {
  std::vector<ExitParticle> exits;
  std::vector<std::uint64_t> chunk_starts;
  std::uint64_t segments = 0;
  void consume(const ParticleChunk& c) override {
    chunk_starts.push_back(c.first_particle);
    exits.insert(exits.end(), c.exits.begin(), c.exits.end());
    segments += c.segments.size();
  }
};

/// Sum of a per-particle quantity over N particles (zero for those not counted) and its standard error
/// sqrt(N · Var) from the sample variance.
struct Estimate {
  double sum = 0.0, sum_sq = 0.0;
  void add(double x) {
    sum += x;
    sum_sq += x * x;
  }
  double standard_error(std::uint64_t n) const {
    const double mean = sum / double(n);
    return std::sqrt(std::max(0.0, sum_sq / double(n) - mean * mean) * double(n));
  }
};

struct Trace {
  TraceCounters counters;
  CollectingSink sink;
};

Trace run(const Tracer& tracer, std::uint64_t particles, int threads = 0, std::uint32_t chunk = 4096,
          std::uint64_t seed = 7) {
  Trace t;
  TraceOptions o;
  o.particles = particles;
  o.threads = threads;
  o.chunk_particles = chunk;
  o.seed = seed;
  t.counters = tracer.trace(o, t.sink);
  return t;
}

// A bare Lambertian disk: every particle leaves at once; exit flux π L A exactly; directions cosine-distributed
// about the normal (far field I(θ) = L A cos θ), azimuths uniform.
TEST(BakeTracer, LambertianDiskEmitsPiLAWithCosineFarField) {
  SceneBuilder b("disk");
  const double L = 1000.0, radius = 0.05;
  b.begin_part("disk", b.add_material(emissive(L)));
  add_disk(b, radius, 64);
  const Tracer tracer(b.scene());
  const double flux = lumx::kPi * L * disk_polygon_area(radius, 64);
  // Vertices are stored in float (2⁻²⁴ relative): the polygon's area is exact to ~10⁻⁷.
  EXPECT_NEAR(tracer.total_flux_lm(), flux, 3e-7 * flux);

  const Trace t = run(tracer, kParticles);
  EXPECT_EQ(t.counters.emitted, kParticles);
  EXPECT_EQ(t.counters.exited, kParticles);
  EXPECT_NEAR(t.counters.emitted_lm, tracer.total_flux_lm(), 1e-9 * flux);
  double exit_sum = 0.0;
  std::vector<double> polar(10, 0.0), azimuth(8, 0.0);
  for (const ExitParticle& x : t.sink.exits) {
    exit_sum += luminance(glm::dvec3(x.flux_lm));
    EXPECT_EQ(x.bounces, 0u);
    ASSERT_GT(x.direction.z, 0.0f);
    ASSERT_LE(std::hypot(x.position.x, x.position.y), radius * (1 + 1e-6));
    // Under cos θ weighting, z² is uniform on [0, 1]: ten equal-probability bins.
    polar[std::min(9, int(10 * double(x.direction.z) * double(x.direction.z)))] += 1;
    const double phi = std::atan2(double(x.direction.y), double(x.direction.x)) + lumx::kPi;
    azimuth[std::min(7, int(8 * phi / (2 * lumx::kPi)))] += 1;
  }
  EXPECT_NEAR(exit_sum, flux, 1e-6 * flux);  // float per-particle fluxes summed in double
  auto chi2 = [&](const std::vector<double>& counts) {
    const double expected = double(kParticles) / counts.size();
    double c = 0.0;
    for (double n : counts) c += (n - expected) * (n - expected) / expected;
    return c;
  };
  EXPECT_LT(chi2(polar), 27.88);   // χ²(9 dof) at p = 0.001
  EXPECT_LT(chi2(azimuth), 24.32);  // χ²(7 dof) at p = 0.001
}

// A point light at the centre of a closed white Lambertian sphere with a port of solid-angle fraction f:
// exit flux Φ f / (1 − ρ (1 − f)) (each diffuse reflection inside a sphere lands uniformly over its area).
TEST(BakeTracer, IntegratingSphereExitFlux) {
  SceneBuilder b("integrating sphere");
  const double rho = 0.8, cos_port = 0.9, radius = 0.1;  // f = (1 − cos α) / 2 = 0.05
  b.begin_part("wall", b.add_material(lambertian(rho)));
  add_sphere(b, radius, 48, 128, std::acos(cos_port), /*outward=*/false);
  b.point_light({0, 0, 0}, 10.0);
  const Tracer tracer(b.scene());
  const double phi = 4 * lumx::kPi * 10.0;
  const double f = 0.5 * (1 - cos_port);
  const double expected = phi * f / (1 - rho * (1 - f));

  const Trace t = run(tracer, kParticles);
  Estimate exit;
  for (const ExitParticle& x : t.sink.exits) exit.add(luminance(glm::dvec3(x.flux_lm)));
  const double se = exit.standard_error(kParticles);
  std::printf("integrating sphere: exit flux %.5f lm, exact %.5f lm, standard error %.5f lm\n", exit.sum, expected, se);
  // The 128-gon port and the polygonal wall differ from the sphere by < 5·10⁻⁴ relative in area.
  EXPECT_NEAR(exit.sum, expected, 4 * se + 5e-4 * expected) << "SE " << se;
  // Interpolated normals make a few grazing bounces point into the wall: they are rejected (counted), a
  // bias below the tolerance above.
  EXPECT_LT(double(t.counters.leaked), 2e-3 * double(kParticles));
  EXPECT_EQ(t.counters.emitted, t.counters.exited + t.counters.absorbed + t.counters.roulette_killed +
                                    t.counters.depth_capped + t.counters.leaked);
  EXPECT_GT(t.counters.roulette_killed, 0u);
  EXPECT_NEAR(t.counters.exited_lm, exit.sum, 1e-6 * exit.sum);
}

// Russian roulette must not change the mean (hard-cases.md §6 item 42): the same integrating sphere traced
// with roulette from the first bounce on and without it (up to the depth cap 256, where a particle keeps 0.8^256 ≈ 1e-25
// of its flux) gives exit fluxes that agree within 5 standard errors of their difference, with independent
// seeds. Roulette trades bounces for variance: it must end paths earlier.
TEST(BakeTracer, RouletteKeepsTheMeanAndShortensPaths) {
  SceneBuilder b("integrating sphere");
  b.begin_part("wall", b.add_material(lambertian(0.8)));
  add_sphere(b, 0.1, 32, 64, std::acos(0.9), /*outward=*/false);
  b.point_light({0, 0, 0}, 10.0);
  const Tracer tracer(b.scene());
  const std::uint64_t n = 100000;
  auto trace = [&](int roulette_depth, std::uint64_t seed, double& mean, double& se, double& bounces) {
    TraceOptions o;
    o.particles = n;
    o.seed = seed;
    o.roulette_depth = roulette_depth;
    o.max_depth = 256;
    CollectingSink sink;
    const TraceCounters c = tracer.trace(o, sink);
    Estimate e;
    double b_sum = 0;
    for (const ExitParticle& x : sink.exits) {
      e.add(luminance(glm::dvec3(x.flux_lm)));
      b_sum += x.bounces;
    }
    mean = e.sum;
    se = e.standard_error(n);
    bounces = b_sum / double(std::max<std::size_t>(1, sink.exits.size()));
    // Without roulette a path stays inside for 256 bounces with probability 0.95^256 ≈ 2e-6 (a few of 10⁵),
    // carrying 0.8^256 of its flux: the cap loses nothing measurable.
    EXPECT_LE(c.depth_capped, 5u) << roulette_depth;
    return c;
  };
  double with_mean, with_se, with_bounces, without_mean, without_se, without_bounces;
  const TraceCounters with = trace(1, 11, with_mean, with_se, with_bounces);
  const TraceCounters without = trace(1 << 30, 12, without_mean, without_se, without_bounces);
  const double sigma = std::hypot(with_se, without_se);
  std::printf("roulette from bounce 1: %.4f ± %.4f lm (%llu killed, mean exit bounces %.2f); none: %.4f ± %.4f lm "
              "(mean exit bounces %.2f); difference %.2f σ\n",
              with_mean, with_se, static_cast<unsigned long long>(with.roulette_killed), with_bounces, without_mean,
              without_se, without_bounces, (with_mean - without_mean) / sigma);
  EXPECT_LT(std::abs(with_mean - without_mean), 5 * sigma);
  EXPECT_GT(with.roulette_killed, n / 10);
  EXPECT_EQ(without.roulette_killed, 0u);
  EXPECT_LT(with_bounces, without_bounces);
  // Zero throughput never divides by zero: a black wall (albedo 0) absorbs every particle at its first hit,
  // with roulette from bounce 0, and leaves no NaN anywhere.
  SceneBuilder black("black sphere");
  black.begin_part("wall", black.add_material(lambertian(0.0)));
  add_sphere(black, 0.1, 16, 32, std::acos(0.9), false);
  black.point_light({0, 0, 0}, 10.0);
  const Tracer black_tracer(black.scene());
  TraceOptions o;
  o.particles = 10000;
  o.roulette_depth = 0;
  CollectingSink sink;
  const TraceCounters c = black_tracer.trace(o, sink);
  for (const ExitParticle& x : sink.exits) {
    ASSERT_TRUE(std::isfinite(x.flux_lm.x) && std::isfinite(x.flux_lm.y) && std::isfinite(x.flux_lm.z));
    EXPECT_EQ(x.bounces, 0u);  // only the particles that leave through the port at once
  }
  EXPECT_TRUE(std::isfinite(c.exited_lm));
  EXPECT_EQ(c.emitted, c.exited + c.absorbed + c.roulette_killed + c.depth_capped + c.leaked);
}

// A point light at the centre of a smooth glass ball (η = 1.5) with Beer–Lambert absorption σ: every path
// crosses the ball radially, so exit flux = Φ e^{−σR} (1 − R₀) / (1 − R₀ e^{−2σR}) with R₀ = ((η−1)/(η+1))²,
// and the emission stays isotropic.
TEST(BakeTracer, GlassBallWithAbsorption) {
  SceneBuilder b("glass ball");
  const double radius = 0.05, ior = 1.5, colour = 0.6;  // attenuation colour 0.6 after R: σR = −ln 0.6
  b.begin_part("ball", b.add_material(smooth_glass(ior, colour, radius)));
  add_sphere(b, radius, 64, 128, 0.0, /*outward=*/true);
  b.point_light({0, 0, 0}, 10.0);
  const Tracer tracer(b.scene());
  const double phi = 4 * lumx::kPi * 10.0;
  const double r0 = std::pow((ior - 1) / (ior + 1), 2), a = colour;  // a = e^{−σR}
  const double expected = phi * a * (1 - r0) / (1 - r0 * a * a);

  const Trace t = run(tracer, kParticles);
  Estimate exit;
  std::vector<double> bins(10, 0.0);
  for (const ExitParticle& x : t.sink.exits) {
    const double y = luminance(glm::dvec3(x.flux_lm));
    exit.add(y);
    bins[std::min(9, int(5 * (double(x.direction.z) + 1)))] += y;  // equal solid angle per z bin
  }
  const double se = exit.standard_error(kParticles);
  std::printf("glass ball: exit flux %.5f lm, exact %.5f lm, standard error %.5f lm\n", exit.sum, expected, se);
  // Facets tilt the normal by < 0.3° from radial: Fresnel at 0.3° differs from R₀ by < 10⁻⁶.
  EXPECT_NEAR(exit.sum, expected, 4 * se + 1e-4 * expected) << "SE " << se;
  EXPECT_EQ(t.counters.leaked, 0u);
  for (double v : bins) EXPECT_NEAR(v, exit.sum / 10, 4 * std::sqrt(exit.sum_sq / 10) + 1e-3 * expected);
}

// A point light at the focus of a perfect paraboloid mirror: the flux the mirror intercepts (solid-angle
// fraction (1 + cos θ_rim) / 2) leaves parallel to the axis; the rest leaves directly, unreflected.
TEST(BakeTracer, ParaboloidMirrorCollimates) {
  SceneBuilder b("paraboloid");
  const double focal = 0.02, rim = 0.08;  // rim at z = 0.06, cos θ_rim = 0.6 from +z
  b.begin_part("mirror", b.add_material(mirror()));
  add_paraboloid(b, focal, rim, 64, 256);
  b.point_light({0, 0, 0}, 1.0);
  const Tracer tracer(b.scene());
  const Trace t = run(tracer, kParticles);
  const double z_rim = rim * rim / (4 * focal) - focal;
  const double fraction = 0.5 * (1 + z_rim / std::hypot(rim, z_rim));
  std::uint64_t reflected = 0;
  double worst_reflected_angle = 0.0;
  for (const ExitParticle& x : t.sink.exits) {
    if (x.bounces == 0) {
      EXPECT_GT(double(x.direction.z) / glm::length(glm::dvec3(x.direction)), z_rim / std::hypot(rim, z_rim) - 1e-3);
      continue;
    }
    ++reflected;
    worst_reflected_angle = std::max(worst_reflected_angle, std::acos(std::min(1.0, double(x.direction.z))));
  }
  const double n = double(kParticles), se = std::sqrt(n * fraction * (1 - fraction));
  std::printf("paraboloid: %llu of %.0f particles reflected, exact %.1f (binomial SE %.1f); widest reflected %.3f deg\n",
              (unsigned long long)reflected, n, n * fraction, se, worst_reflected_angle * 180 / lumx::kPi);
  // The 256-gon rim differs from the circle by < 10⁻⁴ in solid angle.
  EXPECT_NEAR(double(reflected), n * fraction, 4 * se + 1e-4 * n);
  EXPECT_EQ(t.counters.exited, kParticles);
  // Interpolated normals on a 64 × 256 mesh tilt by at most ~0.4°; the reflection turns twice that.
  EXPECT_LT(worst_reflected_angle * 180 / lumx::kPi, 1.0);
}

// Two point lights inside a black box with square holes: a particle leaves only along a straight line through
// a hole (exact visibility), and the exiting fraction is the holes' solid angle over 4π.
TEST(BakeTracer, BoxWithHolesExactVisibility) {
  SceneBuilder b("box with holes");
  const double s = 0.05;
  const std::vector<Hole> holes = {{2, +1, 0.0, 0.0, 0.01}, {0, -1, 0.02, -0.01, 0.01}, {1, +1, -0.02, 0.02, 0.005}};
  b.begin_part("box", b.add_material(black()));
  add_box_with_holes(b, s, 20, holes);
  const std::vector<glm::dvec3> lights = {{0.01, 0.005, -0.02}, {-0.015, 0.01, 0.0}};
  for (const auto& p : lights) b.point_light(p, 1.0);
  const Tracer tracer(b.scene());

  auto hole_corners = [&](const Hole& h, const glm::dvec3& from) {
    const int ua = (h.axis + 1) % 3, va = (h.axis + 2) % 3, lo = std::min(ua, va), hi = std::max(ua, va);
    std::vector<glm::dvec3> c;
    for (auto [du, dv] : {std::pair{-1, -1}, std::pair{1, -1}, std::pair{1, 1}, std::pair{-1, 1}}) {
      glm::dvec3 p;
      p[h.axis] = h.side * s;
      p[lo] = h.u + du * h.half;
      p[hi] = h.v + dv * h.half;
      c.push_back(p - from);
    }
    return c;
  };
  double expected_fraction = 0.0;
  for (const auto& p : lights)
    for (const Hole& h : holes) {
      const auto c = hole_corners(h, p);
      expected_fraction += 0.5 * (triangle_solid_angle(c[0], c[1], c[2]) + triangle_solid_angle(c[0], c[2], c[3])) /
                           (4 * lumx::kPi);
    }
  const Trace t = run(tracer, kParticles);
  std::uint64_t outside_holes = 0;
  for (const ExitParticle& x : t.sink.exits) {
    EXPECT_EQ(x.bounces, 0u);
    bool through = false;
    for (const Hole& h : holes) {
      const double d = double(x.direction[h.axis]);
      if (d * h.side <= 0) continue;
      const double tt = (h.side * s - double(x.position[h.axis])) / d;
      const glm::dvec3 q = glm::dvec3(x.position) + tt * glm::dvec3(x.direction);
      const int ua = (h.axis + 1) % 3, va = (h.axis + 2) % 3, lo = std::min(ua, va), hi = std::max(ua, va);
      if (std::abs(q[lo] - h.u) <= h.half + 1e-6 && std::abs(q[hi] - h.v) <= h.half + 1e-6) through = true;
    }
    outside_holes += through ? 0 : 1;
  }
  EXPECT_EQ(outside_holes, 0u);
  const double n = double(kParticles), f = expected_fraction;
  std::printf("box with holes: %llu of %.0f particles left, exact %.1f (binomial SE %.1f), %llu not through a hole\n",
              (unsigned long long)t.counters.exited, n, n * f, std::sqrt(n * f * (1 - f)), (unsigned long long)outside_holes);
  EXPECT_NEAR(double(t.counters.exited), n * f, 4 * std::sqrt(n * f * (1 - f)));
  EXPECT_EQ(t.counters.exited + t.counters.absorbed, kParticles);
}

// A bare spot light: flux 2π I ∫ falloff dμ (KHR_lights_punctual's smooth cone), and the intensity binned in
// cos θ matches the falloff averaged over each bin.
TEST(BakeTracer, SpotLightFollowsTheConeFalloff) {
  SceneBuilder b("spot");
  lumx::bake::Emitter e;
  e.kind = lumx::bake::EmitterKind::spot;
  e.intensity_cd = Rgb{100.0};
  e.inner_cone_rad = 20 * lumx::kDegToRad;
  e.outer_cone_rad = 30 * lumx::kDegToRad;
  // Aim the spot along +x: rotate −z onto +x.
  e.to_world = glm::rotate(glm::dmat4(1.0), lumx::kPi / 2, glm::dvec3(0, -1, 0));
  e.to_world[3] = glm::dvec4(0.1, 0.2, 0.3, 1.0);
  b.scene().emitters.push_back(e);
  const Tracer tracer(b.scene());
  const double co = std::cos(e.outer_cone_rad);
  auto falloff_integral = [&](double m0, double m1) {  // ∫ falloff dμ by the midpoint rule, 4000 steps
    double sum = 0.0;
    for (int i = 0; i < 4000; ++i) {
      const double m = m0 + (m1 - m0) * (i + 0.5) / 4000;
      sum += lumx::bake::spot_falloff(m, e.inner_cone_rad, e.outer_cone_rad);
    }
    return sum * (m1 - m0) / 4000;
  };
  EXPECT_NEAR(tracer.total_flux_lm(), 2 * lumx::kPi * 100.0 * falloff_integral(co, 1.0), 1e-6 * tracer.total_flux_lm());

  const Trace t = run(tracer, kParticles);
  const int bins = 12;
  std::vector<Estimate> bin(bins);
  for (const ExitParticle& x : t.sink.exits) {
    EXPECT_NEAR(x.position.x, 0.1f, 1e-6f);
    const double mu = double(x.direction.x);  // the axis is +x
    ASSERT_GE(mu, co - 1e-6);
    bin[std::min(bins - 1, int((mu - co) / (1 - co) * bins))].add(luminance(glm::dvec3(x.flux_lm)));
  }
  for (int k = 0; k < bins; ++k) {
    const double m0 = co + (1 - co) * k / bins, m1 = co + (1 - co) * (k + 1) / bins;
    const double expected = 2 * lumx::kPi * 100.0 * falloff_integral(m0, m1);  // lm into the bin
    EXPECT_NEAR(bin[k].sum, expected, 4 * bin[k].standard_error(kParticles) + 1e-9) << "bin " << k;
  }
}

// An IES profile placed by a node (rotated): the flux leaving each equal-area direction cell is the profile's
// intensity integrated over that cell (deterministic quadrature), in the node's frame.
TEST(BakeTracer, IesEmitterReproducesItsProfile) {
  const auto photometry =
      std::make_shared<lumx::Photometry>(lumx::read_photometry(std::string(LUMX_SOURCE_DIR) + "/samples/downlight.ies"));
  SceneBuilder b("ies");
  lumx::bake::Emitter e;
  e.kind = lumx::bake::EmitterKind::ies;
  e.photometry = photometry;
  e.multiplier = 0.5;
  e.to_world = glm::rotate(glm::dmat4(1.0), 0.7, glm::normalize(glm::dvec3(1, 2, 3)));
  b.scene().emitters.push_back(e);
  const Tracer tracer(b.scene());
  const lumx::IntensityTable table(*photometry);
  EXPECT_NEAR(tracer.total_flux_lm(), 0.5 * table.flux_lm(), 1e-9 * table.flux_lm());

  const Trace t = run(tracer, kParticles);
  const int R = 4;
  const glm::dmat3 inverse = glm::transpose(glm::dmat3(e.to_world));
  std::vector<Estimate> cell(2 * R * R);
  for (const ExitParticle& x : t.sink.exits) {
    int cx, cy;
    lumx::sphere_map::texel_of(glm::vec3(inverse * glm::dvec3(x.direction)), R, cx, cy);
    cell[std::size_t(cy) * 2 * R + cx].add(luminance(glm::dvec3(x.flux_lm)));
  }
  const double omega = lumx::sphere_map::texel_solid_angle(R);
  for (int cy = 0; cy < R; ++cy)
    for (int cx = 0; cx < 2 * R; ++cx) {
      double integral = 0.0;  // midpoint rule on 64 × 64 points, uniform in the equal-area map
      for (int i = 0; i < 64; ++i)
        for (int j = 0; j < 64; ++j) {
          const glm::vec2 uv{float((cx + (i + 0.5) / 64) / (2 * R)), float((cy + (j + 0.5) / 64) / R)};
          integral += table.intensity(glm::dvec3(lumx::sphere_map::uv_to_direction(uv)));
        }
      const double expected = 0.5 * integral / (64 * 64) * omega;
      const Estimate& c = cell[std::size_t(cy) * 2 * R + cx];
      EXPECT_NEAR(c.sum, expected, 4 * c.standard_error(kParticles) + 2e-3 * expected + 1e-6)
          << "cell " << cx << "," << cy;
    }
}

// Particle i's path depends on (seed, i) only: identical exits for 1 and 2 threads and any chunk size, and a
// trace split into two passes equals one trace.
TEST(BakeTracer, BitIdenticalForAnyThreadCountChunkAndPass) {
  SceneBuilder b("integrating sphere");
  b.begin_part("wall", b.add_material(lambertian(0.8)));
  add_sphere(b, 0.1, 24, 48, 0.45, false);
  b.point_light({0.01, 0, 0}, 1.0);
  const Tracer tracer(b.scene());
  const std::uint64_t n = 20000;
  const Trace one = run(tracer, n, 1, 4096);
  const Trace two = run(tracer, n, 2, 1000);
  ASSERT_EQ(one.sink.exits.size(), two.sink.exits.size());
  auto same = [](const ExitParticle& a, const ExitParticle& c) {
    return a.index == c.index && a.position == c.position && a.direction == c.direction && a.flux_lm == c.flux_lm &&
           a.bounces == c.bounces;
  };
  for (std::size_t i = 0; i < one.sink.exits.size(); ++i) ASSERT_TRUE(same(one.sink.exits[i], two.sink.exits[i])) << i;
  // 7 threads (more than the cores) and as many as the machine has (hard-cases.md §6 item 48).
  for (const int threads : {7, int(std::max(1u, std::thread::hardware_concurrency()))}) {
    const Trace many = run(tracer, n, threads, 777);
    ASSERT_EQ(many.sink.exits.size(), one.sink.exits.size()) << threads;
    for (std::size_t i = 0; i < one.sink.exits.size(); ++i) ASSERT_TRUE(same(one.sink.exits[i], many.sink.exits[i])) << threads << ": " << i;
  }
  // Counters are reduced in chunk order, not thread order: bit-identical for the same chunk size.
  EXPECT_EQ(one.counters.exited_lm, run(tracer, n, 2, 4096).counters.exited_lm);
  EXPECT_EQ(one.counters.exited_lm, run(tracer, n, 7, 4096).counters.exited_lm);
  EXPECT_NE(run(tracer, n, 2, 4096, 8).sink.exits.front().direction, one.sink.exits.front().direction);

  CollectingSink passes;
  for (std::uint64_t first : {std::uint64_t(0), n / 2}) {
    TraceOptions o;
    o.seed = 7;
    o.first_particle = first;
    o.particles = n / 2;
    o.normalization_particles = n;
    tracer.trace(o, passes);
  }
  ASSERT_EQ(passes.exits.size(), one.sink.exits.size());
  for (std::size_t i = 0; i < passes.exits.size(); ++i) ASSERT_TRUE(same(passes.exits[i], one.sink.exits[i])) << i;
}

// A rayset placed by a node: its rays, transformed, are the particles; its flux is the file's.
TEST(BakeTracer, RaysetEmitterPlacedByItsNode) {
  const auto dir = lumx_test::unique_temp_path("lumx_tracer_rayset");
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "beam.tm25ray").string();
  lumx::RayChunk chunk;
  for (int i = 0; i < 100; ++i) chunk.push_back({0.001f * i, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, 0.5f);
  lumx::RaysetInfo info;
  lumx::MemoryRaySource rays(chunk, info);
  lumx::write_tm25(path, rays.info(), rays);

  SceneBuilder b("rayset");
  lumx::bake::Emitter e;
  e.kind = lumx::bake::EmitterKind::rayset;
  e.rayset_path = path;
  e.to_world = glm::rotate(glm::dmat4(1.0), lumx::kPi / 2, glm::dvec3(1, 0, 0));  // +z → −y
  e.to_world[3] = glm::dvec4(1, 2, 3, 1);
  b.scene().emitters.push_back(e);
  const Tracer tracer(b.scene());
  EXPECT_NEAR(tracer.total_flux_lm(), 50.0, 1e-6);
  const Trace t = run(tracer, 1000);
  for (const ExitParticle& x : t.sink.exits) {
    EXPECT_NEAR(x.direction.y, -1.0f, 1e-6f);
    EXPECT_NEAR(x.position.y, 2.0f, 1e-6f);
    EXPECT_NEAR(x.position.z, 3.0f, 1e-6f);
    EXPECT_GE(x.position.x, 1.0f - 1e-6f);
  }
  std::filesystem::remove_all(dir);
}

// Watertight closed meshes (hard-cases.md §6 item 47). A closed box (each face two triangles; the shared
// diagonal passes through the face centre) is shot from its centre with rays aimed exactly at its 8
// vertices, 12 edge midpoints, 24 edge thirds and 6 face centres: with a black box none may get out; with a
// white box (albedo 0.9, flat normals) none may get out either, however often it bounces, nor be counted as
// a leak; and both hold with the box 10⁵ m from the origin, where a float has a step of 7.8 mm and a
// self-hit offset scaled to the origin's size would be needed.
TEST(BakeTracer, ClosedBoxesAreWatertightAtEdgesVerticesAndFarFromTheOrigin) {
  const auto dir = lumx_test::unique_temp_path("lumx_tracer_watertight");
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "aim.tm25ray").string();
  const glm::dvec3 h(0.5, 0.4, 0.3);  // half sizes, m
  std::vector<glm::dvec3> targets;
  for (int x : {-1, 1})
    for (int y : {-1, 1})
      for (int z : {-1, 1}) targets.push_back(h * glm::dvec3(x, y, z));  // vertices
  for (int axis = 0; axis < 3; ++axis)
    for (int a : {-1, 1})
      for (int b : {-1, 1})
        for (double t : {-1.0 / 3, 0.0, 1.0 / 3}) {  // points on the 12 edges
          glm::dvec3 q;
          q[axis] = t * h[axis];
          q[(axis + 1) % 3] = a * h[(axis + 1) % 3];
          q[(axis + 2) % 3] = b * h[(axis + 2) % 3];
          targets.push_back(q);
        }
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {-1, 1}) {
      glm::dvec3 q(0.0);
      q[axis] = side * h[axis];
      targets.push_back(q);  // face centres, on the diagonal two triangles share
    }
  lumx::RayChunk chunk;
  for (const glm::dvec3& q : targets) chunk.push_back({0.0f, 0.0f, 0.0f}, glm::vec3(glm::normalize(q)), 1.0f);
  lumx::RaysetInfo info;
  lumx::MemoryRaySource rays(chunk, info);
  lumx::write_tm25(path, rays.info(), rays);

  for (const double offset : {0.0, 1e5})
    for (const double albedo : {0.0, 0.9}) {
      SCOPED_TRACE("offset " + std::to_string(offset) + " m, albedo " + std::to_string(albedo));
      SceneBuilder b("closed box");
      b.begin_part("box", b.add_material(lambertian(albedo)));
      const glm::dmat4 frame = glm::translate(glm::dmat4(1.0), glm::dvec3(offset, -offset, offset));
      b.box(frame, h, /*outward=*/true);
      lumx::bake::Emitter e;
      e.kind = lumx::bake::EmitterKind::rayset;
      e.rayset_path = path;
      e.to_world = frame;
      b.scene().emitters.push_back(e);
      const Tracer tracer(b.scene());
      const Trace t = run(tracer, 20000);
      EXPECT_EQ(t.sink.exits.size(), 0u);
      EXPECT_EQ(t.counters.exited, 0u);
      EXPECT_EQ(t.counters.leaked, 0u);
      EXPECT_EQ(t.counters.emitted, t.counters.absorbed + t.counters.roulette_killed + t.counters.depth_capped);
      if (albedo > 0) {
        EXPECT_GT(t.counters.roulette_killed, 0u);  // they did bounce
      }
    }
  std::filesystem::remove_all(dir);
}

// A clear glass slab 0.1 mm thick (a closed box, 0.2 × 0.2 × 1e-4 m) under a point light (hard-cases.md §6
// item 47, "planes 1e-4 apart"). Light can reach the underside only through both faces: every particle
// that leaves downwards has scattered at least twice, and one that crossed with exactly two refractions
// leaves parallel to the ray it arrived on, displaced by less than the slab's thickness times the tangent
// of the refraction angle (< 1e-4 · 1.2 here), so its backward line passes that close to the light. A ray
// that skipped the second face (an offset beyond 0.1 mm) would leave bent, after one scattering event.
TEST(BakeTracer, ThinGlassSlabIsCrossedFaceByFace) {
  SceneBuilder b("thin slab");
  b.begin_part("slab", b.add_material(smooth_glass(1.5, 1.0, 1.0)));
  const double half_thickness = 5e-5;
  b.box(glm::dmat4(1.0), {0.1, 0.1, half_thickness}, /*outward=*/true);
  const glm::dvec3 light(0.0, 0.0, 0.05);
  b.point_light(light, 1.0);
  const Tracer tracer(b.scene());
  const Trace t = run(tracer, 40000);
  EXPECT_EQ(t.counters.leaked, 0u);
  std::size_t down = 0, straight = 0;
  double worst = 0;
  for (const ExitParticle& x : t.sink.exits) {
    if (x.direction.z >= 0 || x.position.z > 0) continue;  // the upper half space: reflected or never hit
    ++down;
    EXPECT_GE(x.bounces, 2u);
    if (x.bounces != 2 || std::abs(x.position.x) > 0.099 || std::abs(x.position.y) > 0.099) continue;
    ++straight;
    const glm::dvec3 p(x.position), d = glm::normalize(glm::dvec3(x.direction));
    const glm::dvec3 to_light = light - p;
    const double miss = glm::length(to_light - glm::dot(to_light, -d) * -d);  // distance of the light from the line
    worst = std::max(worst, miss);
    EXPECT_LT(miss, 1.2e-4 * 2 * half_thickness / 1e-4 + 1e-5) << x.direction.x << ' ' << x.direction.y << ' ' << x.direction.z;
  }
  std::printf("thin slab: %zu of %zu exits below, %zu straight through, worst distance of the light from their line %.3g m\n",
              down, t.sink.exits.size(), straight, worst);
  EXPECT_GT(straight, 1000u);
  // Energy: the glass absorbs nothing; what is not capped (trapped by total internal reflection) leaves.
  // Smooth glass is sampled by its Fresnel reflectance with weight 1, so nothing is absorbed or lost to
  // roulette, and the sum is exact up to rounding.
  EXPECT_EQ(t.counters.absorbed, 0u);
  EXPECT_EQ(t.counters.roulette_killed, 0u);
  const double phi = 4 * lumx::kPi;
  EXPECT_NEAR(t.counters.exited_lm + double(t.counters.depth_capped) * phi / 40000.0, phi, 1e-6 * phi);
}

TEST(BakeTracer, LuminaireWithoutFluxIsRefusedByName) {
  SceneBuilder b("dark");
  b.begin_part("box", b.add_material(black()));
  add_box_with_holes(b, 0.05, 2, std::vector<Hole>{});
  try {
    const Tracer tracer(b.scene());
    FAIL() << "expected lumx::Error";
  } catch (const lumx::Error& err) {
    EXPECT_NE(std::string(err.what()).find("no emitter"), std::string::npos) << err.what();
  }
}



// A closed white sphere (albedo exactly 1, no port) traps every particle: with roulette switched off, all of
// them reach the depth cap and are counted there, none leaves.
TEST(BakeTracer, ClosedWhiteSphereHitsTheDepthCap) {
  SceneBuilder b("closed white sphere");
  b.begin_part("wall", b.add_material(lambertian(1.0)));
  add_sphere(b, 0.1, 24, 48, 0.0, false);
  b.point_light({0, 0, 0}, 1.0);
  const Tracer tracer(b.scene());
  TraceOptions o;
  o.particles = 2000;
  o.max_depth = 40;
  o.roulette_depth = 1000;
  CollectingSink sink;
  const TraceCounters c = tracer.trace(o, sink);
  EXPECT_EQ(c.exited, 0u);
  EXPECT_EQ(c.roulette_killed, 0u);
  EXPECT_EQ(c.depth_capped + c.leaked, o.particles);
  EXPECT_GT(c.depth_capped, o.particles * 9 / 10);
}

// Internal segments: each starts where the particle was emitted or scattered and ends on the surface it hit
// (here the glass ball's sphere), and there is one per cast ray that hit something.
TEST(BakeTracer, SegmentsEndOnTheSurfaceTheyHit) {
  SceneBuilder b("glass ball");
  const double radius = 0.05;
  b.begin_part("ball", b.add_material(smooth_glass(1.5, 0.6, radius)));
  add_sphere(b, radius, 32, 64, 0.0, true);
  b.point_light({0, 0, 0}, 1.0);
  const Tracer tracer(b.scene());
  TraceOptions o;
  o.particles = 5000;
  o.record_segments = true;
  struct SegmentSink : lumx::bake::ParticleSink {
    std::vector<lumx::bake::PathSegment> segments;
    void consume(const ParticleChunk& c) override { segments.insert(segments.end(), c.segments.begin(), c.segments.end()); }
  } sink;
  const TraceCounters c = tracer.trace(o, sink);
  EXPECT_EQ(sink.segments.size(), c.segments - c.exited);
  ASSERT_FALSE(sink.segments.empty());
  const double sagitta = radius * (1 - std::cos(lumx::kPi / 32));  // a chord's largest distance from the sphere
  for (const auto& s : sink.segments) {
    const glm::dvec3 end = glm::dvec3(s.origin) + double(s.length_m) * glm::dvec3(s.direction);
    ASSERT_NEAR(glm::length(end), radius, sagitta + 1e-5);
    ASSERT_GT(s.length_m, 0.0f);
    ASSERT_LE(luminance(glm::dvec3(s.flux_lm)), tracer.total_flux_lm() / o.particles * (1 + 1e-6));
  }
}

}  // namespace
