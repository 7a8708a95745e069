// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Radiance volume: grid layout, mass conservation of the voxel traversal (random segments, axis-parallel
// rays, rays on faces, edges and corners, negative coordinates), the isotropic-field estimate, the
// windowed and clamped query, and merging partial volumes.
#include <lumx/math/aabb.h>
#include <lumx/volume/radiance_volume.h>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

using namespace lumx;

namespace {

const double kY00 = 0.5 / std::sqrt(kPi);

glm::dvec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<double> g;
  for (;;) {
    const glm::dvec3 v(g(rng), g(rng), g(rng));
    const double n = glm::length(v);
    if (n > 1e-6) return v / n;
  }
}

// Length of {o + t d : t in [0, len]} inside the closed box, d a unit vector: Liang–Barsky, clipping
// against the six half-spaces one after the other (written independently of Aabb::clip).
double clipped_length(const Aabb& box, const glm::dvec3& o, const glm::dvec3& d, double len) {
  double t0 = 0, t1 = len;
  const double p[6] = {-d.x, d.x, -d.y, d.y, -d.z, d.z};
  const double q[6] = {o.x - box.lo.x, box.hi.x - o.x, o.y - box.lo.y, box.hi.y - o.y, o.z - box.lo.z, box.hi.z - o.z};
  for (int i = 0; i < 6; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0) return 0;
      continue;
    }
    const double r = q[i] / p[i];
    if (p[i] < 0)
      t0 = std::max(t0, r);
    else
      t1 = std::min(t1, r);
  }
  return t1 > t0 ? t1 - t0 : 0.0;
}

// Σ over voxels of coefficient q of channel c.
double coefficient_sum(const RadianceVolume& v, int c, int q) {
  double sum = 0;
  const glm::ivec3 n = v.counts();
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) sum += v.voxel_coefficients(i, j, k, c)[q];
  return sum;
}

// Voxels whose DC coefficient (channel 0) is non-zero.
std::vector<glm::ivec3> touched_voxels(const RadianceVolume& v) {
  std::vector<glm::ivec3> out;
  const glm::ivec3 n = v.counts();
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i)
        if (v.voxel_coefficients(i, j, k, 0)[0] != 0.0f) out.emplace_back(i, j, k);
  return out;
}

// Length deposited in voxel (i, j, k), read back from its DC coefficient for flux 1 in channel 0.
double voxel_length(const RadianceVolume& v, int i, int j, int k) {
  return v.voxel_coefficients(i, j, k, 0)[0] * v.voxel_volume() / kY00;
}

std::string what(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no exception)";
}

const glm::vec3 kUnitFlux(1.0f, 1.0f, 1.0f);

}  // namespace

TEST(Aabb, HelpersAndSlabClip) {
  Aabb b;
  EXPECT_FALSE(b.valid());  // default is empty
  b.expand({1, 2, 3});
  EXPECT_TRUE(b.valid());  // a single point is a valid (degenerate) box
  b.expand({-1, 0, 5});
  EXPECT_EQ(b.lo, glm::dvec3(-1, 0, 3));
  EXPECT_EQ(b.hi, glm::dvec3(1, 2, 5));
  EXPECT_EQ(b.extent(), glm::dvec3(2, 2, 2));
  EXPECT_TRUE(b.contains({1, 0, 4}));  // closed faces
  EXPECT_FALSE(b.contains({1.0000001, 0, 4}));

  const Aabb unit{{0, 0, 0}, {1, 1, 1}};
  RayInterval r = unit.clip({-1, 0.5, 0.5}, {1, 0, 0}, 0, 10);
  EXPECT_EQ(r.t0, 1.0);
  EXPECT_EQ(r.t1, 2.0);
  r = unit.clip({0.5, 0.5, 0.5}, {0, 0, -2}, 0, 10);  // unnormalised direction, start inside
  EXPECT_EQ(r.t0, 0.0);
  EXPECT_EQ(r.t1, 0.25);
  EXPECT_TRUE(unit.clip({-1, 2, 0.5}, {1, 0, 0}, 0, 10).empty());        // parallel, outside the y slab
  EXPECT_FALSE(unit.clip({-1, 1, 0.5}, {1, 0, 0}, 0, 10).empty());       // parallel, on the face y = 1
  EXPECT_TRUE(unit.clip({-1, 0.5, 0.5}, {1, 0, 0}, 0, 0.5).empty());     // stops short
  const RayInterval graze = unit.clip({-1, 1, 0.5}, {1, -1, 0}, 0, 10);  // touches the edge x = y = 0 only
  EXPECT_FALSE(graze.empty());
  EXPECT_EQ(graze.length(), 0.0);
  EXPECT_TRUE(unit.clip({NAN, 0.5, 0.5}, {1, 0, 0}, 0, 10).empty());
  EXPECT_TRUE(unit.clip({0.5, 0.5, 0.5}, {NAN, 0, 0}, 0, 10).empty());
  EXPECT_TRUE(unit.clip({-1, 0.5, 0.5}, {1e-320, 0, 0}, 0, 10).empty());  // subnormal: far, no NaN
}

TEST(RadianceVolume, GridFollowsTheAspectWithCubicVoxels) {
  // 2 x 1 x 1, 32768 voxels: s = cbrt(2/32768) = 0.03937, 2/s = 50.8 -> 51, 1/s = 25.4 -> 26.
  const Aabb box{{0, 0, 0}, {2, 1, 1}};
  const RadianceVolume v(box);
  EXPECT_EQ(v.counts(), glm::ivec3(51, 26, 26));
  EXPECT_NEAR(v.voxel_size(), std::cbrt(2.0 / 32768), 1e-15);
  EXPECT_EQ(v.bands(), 4);
  EXPECT_EQ(v.channels(), 3);
  EXPECT_EQ(v.coefficient_count(), 16);
  EXPECT_EQ(v.coefficients().size(), std::size_t(51 * 26 * 26) * 3 * 16);
  // Cubic voxels: the grid's extent is counts x s on every axis, centred on the box and covering it.
  const glm::dvec3 ext = v.bounds().extent();
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(ext[a], v.counts()[a] * v.voxel_size(), 1e-12);
    EXPECT_LE(v.bounds().lo[a], box.lo[a]);
    EXPECT_GE(v.bounds().hi[a], box.hi[a]);
    EXPECT_NEAR(v.bounds().center()[a], box.center()[a], 1e-12);
  }
  // A cube with a perfect-cube target is tiled exactly.
  const RadianceVolume cube(Aabb{{-1, -1, -1}, {1, 1, 1}});
  EXPECT_EQ(cube.counts(), glm::ivec3(32, 32, 32));
  EXPECT_EQ(cube.voxel_size(), 0.0625);
  EXPECT_EQ(cube.bounds().lo, glm::dvec3(-1, -1, -1));
  EXPECT_EQ(cube.bounds().hi, glm::dvec3(1, 1, 1));
  // 32768 voxels x 3 channels x 16 float coefficients = 6 MiB (000 §4.6).
  EXPECT_GE(cube.bytes(), std::size_t(6) << 20);
  EXPECT_LT(cube.bytes(), (std::size_t(6) << 20) + 4096);
  // Layout ((k ny + j) nx + i) channels ncoef + c ncoef + q.
  EXPECT_EQ(cube.voxel_coefficients(3, 5, 7, 2) - cube.coefficients().data(), ((7 * 32 + 5) * 32 + 3) * 48 + 2 * 16);
  EXPECT_THROW(cube.voxel_coefficients(32, 0, 0, 0), std::out_of_range);
  EXPECT_THROW(cube.voxel_coefficients(0, 0, -1, 0), std::out_of_range);
  EXPECT_THROW(cube.voxel_coefficients(0, 0, 0, 3), std::out_of_range);
}

TEST(RadianceVolume, DegenerateBoxes) {
  // Flat: one voxel across, s solved over the other two axes (sqrt(32768) = 181.02 -> 182).
  const RadianceVolume flat(Aabb{{0, 0, 0.5}, {1, 1, 0.5}});
  EXPECT_EQ(flat.counts(), glm::ivec3(182, 182, 1));
  EXPECT_NEAR(flat.voxel_size(), 1 / std::sqrt(32768.0), 1e-9);
  EXPECT_NEAR(flat.bounds().center().z, 0.5, 1e-15);
  // Nearly flat behaves the same: the thin axis does not multiply the count.
  const RadianceVolume thin(Aabb{{0, 0, 0}, {1, 1, 1e-6}});
  EXPECT_EQ(thin.counts(), glm::ivec3(182, 182, 1));
  // A line: all voxels along it.
  const RadianceVolume line(Aabb{{0, 0, 0}, {0, 2, 0}}, 1000, 2, 1);
  EXPECT_EQ(line.counts(), glm::ivec3(1, 1000, 1));
  EXPECT_NEAR(line.voxel_size(), 0.002, 1e-15);
  // A point: one unit voxel centred on it.
  const RadianceVolume point(Aabb{{3, -4, 5}, {3, -4, 5}}, 100, 1, 1);
  EXPECT_EQ(point.counts(), glm::ivec3(1, 1, 1));
  EXPECT_EQ(point.voxel_size(), 1.0);
  EXPECT_EQ(point.bounds().center(), glm::dvec3(3, -4, 5));
  // Deposits in a flat grid still conserve length: a perpendicular crossing deposits s.
  RadianceVolume f2(Aabb{{0, 0, 0}, {1, 1, 0}}, 100, 2, 1);
  EXPECT_NEAR(f2.add_segment({0.55, 0.55, -1}, {0, 0, 1}, 2, kUnitFlux), f2.voxel_size(), 1e-15);
  EXPECT_NEAR(coefficient_sum(f2, 0, 0) * f2.voxel_volume() / kY00, f2.voxel_size(), 1e-7);
  EXPECT_NEAR(f2.add_segment({-1, 0.55, 0}, {1, 0, 0}, 3, kUnitFlux), f2.bounds().extent().x, 1e-15);
}

TEST(RadianceVolume, RejectsInvalidInputNamingTheField) {
  const Aabb ok{{0, 0, 0}, {1, 1, 1}};
  EXPECT_NE(what([&] { RadianceVolume(Aabb{{0, 0, NAN}, {1, 1, 1}}); }).find("box"), std::string::npos);
  EXPECT_NE(what([&] { RadianceVolume(Aabb{{0, 2, 0}, {1, 1, 1}}); }).find("box"), std::string::npos);
  EXPECT_NE(what([&] { RadianceVolume(Aabb{{0, 0, 0}, {1, INFINITY, 1}}); }).find("box"), std::string::npos);
  EXPECT_NE(what([&] { RadianceVolume(Aabb{{-1e308, 0, 0}, {1e308, 1, 1}}); }).find("box"), std::string::npos);
  EXPECT_NE(what([&] { RadianceVolume(Aabb{}); }).find("box"), std::string::npos);
  EXPECT_NE(what([&] { RadianceVolume(ok, 0); }).find("target_voxel_count"), std::string::npos);
  EXPECT_NE(what([&] { RadianceVolume(ok, (1 << 24) + 1); }).find("target_voxel_count"), std::string::npos);
  EXPECT_NE(what([&] { RadianceVolume(ok, 64, 0); }).find("bands"), std::string::npos);
  EXPECT_NE(what([&] { RadianceVolume(ok, 64, 9); }).find("bands"), std::string::npos);
  EXPECT_NE(what([&] { RadianceVolume(ok, 64, 4, 2); }).find("channels"), std::string::npos);
  EXPECT_NO_THROW(RadianceVolume(ok, 1, 1, 1));
  EXPECT_NO_THROW(RadianceVolume(ok, 64, 8, 3));

  RadianceVolume v(ok, 64);
  EXPECT_NE(what([&] { v.add_segment({0, 0, 0}, {0, 0, 0}, 1, kUnitFlux); }).find("direction"), std::string::npos);
  EXPECT_NE(what([&] { v.add_segment({0, 0, 0}, {NAN, 1, 0}, 1, kUnitFlux); }).find("direction"), std::string::npos);
  EXPECT_NE(what([&] { v.add_segment({0, 0, 0}, {1, 0, 0}, -1, kUnitFlux); }).find("length"), std::string::npos);
  EXPECT_NE(what([&] { v.add_segment({0, 0, 0}, {1, 0, 0}, INFINITY, kUnitFlux); }).find("length"), std::string::npos);
  EXPECT_NE(what([&] { v.add_segment({NAN, 0, 0}, {1, 0, 0}, 1, kUnitFlux); }).find("origin"), std::string::npos);
  EXPECT_NE(what([&] { v.add_segment({0, 0, 0}, {1, 0, 0}, 1, {1, NAN, 1}); }).find("flux"), std::string::npos);
  EXPECT_THROW(v.radiance({0.5, 0.5, 0.5}, {0, 0, 0}), std::invalid_argument);
  EXPECT_THROW(v.radiance({NAN, 0.5, 0.5}, {0, 0, 1}), std::invalid_argument);
}

TEST(RadianceVolume, ZeroLengthSegmentsDepositNothing) {
  RadianceVolume v(Aabb{{0, 0, 0}, {1, 1, 1}}, 64);
  EXPECT_EQ(v.add_segment({0.5, 0.5, 0.5}, {1, 0, 0}, 0.0, kUnitFlux), 0.0);
  EXPECT_EQ(v.add_segment({0.5, 0.5, 0.5}, {0, 0, 0}, 0.0, kUnitFlux), 0.0);  // direction irrelevant
  EXPECT_EQ(v.add_segment({-1, 1, 0.5}, {1, -1, 0}, 10, kUnitFlux), 0.0);     // touches an edge only
  EXPECT_EQ(v.add_segment({2, 2, 2}, {1, 1, 1}, 10, kUnitFlux), 0.0);         // points away
  for (float c : v.coefficients()) ASSERT_EQ(c, 0.0f);
}

TEST(RadianceVolume, MassConservationForRandomSegments) {
  const Aabb box{{-0.3, 0.1, -2.0}, {0.7, 0.6, -1.2}};
  RadianceVolume v(box, 3000, 3, 3);
  const Aabb& g = v.bounds();
  const glm::dvec3 c = g.center(), e = g.extent();
  const double diag = glm::length(e);
  const glm::vec3 flux(1.0f, 2.0f, 0.5f);
  std::mt19937 rng(20240613);
  std::uniform_real_distribution<double> u(-1.0, 1.0), u01(0.0, 1.0);
  int outside = 0, inside_to_out = 0, out_to_inside = 0, through = 0, contained = 0;
  double total = 0;
  for (int n = 0; n < 10000; ++n) {
    const glm::dvec3 o = c + e * glm::dvec3(u(rng), u(rng), u(rng));  // the grid scaled x2 about its centre
    const glm::dvec3 d = random_unit(rng);
    const double len = u01(rng) * 1.5 * diag;
    const double expected = clipped_length(g, o, d, len);
    const double got = v.add_segment(o, d, len, flux);
    ASSERT_NEAR(got, expected, 1e-9 * std::max(expected, 1e-3 * diag)) << "segment " << n;
    total += expected;
    const bool a = g.contains(o), b = g.contains(o + len * d);
    if (expected == 0)
      ++outside;
    else if (a && b)
      ++contained;
    else if (a)
      ++inside_to_out;
    else if (b)
      ++out_to_inside;
    else
      ++through;
  }
  EXPECT_GT(outside, 100);
  EXPECT_GT(contained, 100);
  EXPECT_GT(inside_to_out, 100);
  EXPECT_GT(out_to_inside, 100);
  EXPECT_GT(through, 100);
  // The DC coefficients hold the same length: Σ c00 V / (Φ_c Y00) = Σ ℓ (float accumulation).
  for (int ch = 0; ch < 3; ++ch)
    EXPECT_NEAR(coefficient_sum(v, ch, 0) * v.voxel_volume() / (flux[ch] * kY00), total, 1e-5 * total) << ch;
}

TEST(RadianceVolume, AxisParallelRaysEachAxisBothSigns) {
  RadianceVolume v(Aabb{{-1, -2, 0}, {3, 1, 2}}, 4000, 2, 1);
  const Aabb& g = v.bounds();
  const double s = v.voxel_size();
  const glm::ivec3 n = v.counts();
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {1.0, -1.0}) {
      RadianceVolume w(Aabb{{-1, -2, 0}, {3, 1, 2}}, 4000, 2, 1);
      glm::dvec3 o = g.lo + 0.37 * g.extent();  // not on a face
      o[axis] = sign > 0 ? g.lo[axis] - 1 : g.hi[axis] + 1;
      glm::dvec3 d(0.0);
      d[axis] = sign;
      EXPECT_NEAR(w.add_segment(o, d, g.extent()[axis] + 2, kUnitFlux), g.extent()[axis], 1e-12);
      const std::vector<glm::ivec3> hit = touched_voxels(w);
      ASSERT_EQ(int(hit.size()), n[axis]) << "axis " << axis << " sign " << sign;
      for (const glm::ivec3& h : hit) {
        EXPECT_NEAR(voxel_length(w, h.x, h.y, h.z), s, 1e-6 * s);
        // Band 1 records the direction: Y_1(d) is -c y, c z, -c x.
        const float* q = w.voxel_coefficients(h.x, h.y, h.z, 0);
        const double c1 = std::sqrt(3 / (4 * kPi)) * s / w.voxel_volume();
        const glm::dvec3 expected_band1 = glm::dvec3(-d.y, d.z, -d.x) * c1;
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(q[1 + k], expected_band1[k], 1e-6 * c1);
      }
    }
}

TEST(RadianceVolume, RaysOnFacesEdgesAndCornersAreCountedOnce) {
  const Aabb box{{-1, -1, -1}, {1, 1, 1}};
  const RadianceVolume prototype(box, 512, 2, 1);
  ASSERT_EQ(prototype.counts(), glm::ivec3(8, 8, 8));
  ASSERT_EQ(prototype.voxel_size(), 0.25);
  ASSERT_EQ(prototype.bounds().lo, box.lo);
  const double s = 0.25, diag = s * std::sqrt(3.0);
  struct Case {
    const char* name;
    glm::dvec3 origin, direction;
    double length, expected;
    int voxels;
  };
  const Case cases[] = {
      {"interior face y=0", {-2, 0, 0.1}, {1, 0, 0}, 4, 2, 8},
      {"interior edge y=z=0", {-2, 0, 0}, {1, 0, 0}, 4, 2, 8},
      {"edge, negative direction", {2, 0.5, -0.25}, {-1, 0, 0}, 4, 2, 8},
      {"outer face y=lo", {-2, -1, 0.1}, {1, 0, 0}, 4, 2, 8},
      {"outer face y=hi", {-2, 1, 0.1}, {1, 0, 0}, 4, 2, 8},
      {"outer edge y=z=hi", {1.5, 1, 1}, {-1, 0, 0}, 4, 2, 8},
      {"main diagonal through corners", {-1, -1, -1}, {1, 1, 1}, 2 * std::sqrt(3.0), 2 * std::sqrt(3.0), 8},
      {"diagonal from outside", {-2, -2, -2}, {1, 1, 1}, 10, 2 * std::sqrt(3.0), 8},
      {"from the centre corner, negative", {0, 0, 0}, {-1, -1, -1}, 10, std::sqrt(3.0), 4},
      {"face diagonal in the plane z=0.5", {-1, -1, 0.5}, {1, 1, 0}, 10, 2 * std::sqrt(2.0), 8},
      {"starting on an interior corner, axis", {0.25, -0.5, 0.75}, {0, 1, 0}, 0.5, 0.5, 2},
  };
  for (const Case& k : cases) {
    RadianceVolume v(box, 512, 2, 1);
    const double got = v.add_segment(k.origin, k.direction, k.length, kUnitFlux);
    EXPECT_NEAR(got, k.expected, 1e-12) << k.name;
    const std::vector<glm::ivec3> hit = touched_voxels(v);
    EXPECT_EQ(int(hit.size()), k.voxels) << k.name;
    double sum = 0;
    for (const glm::ivec3& h : hit) sum += voxel_length(v, h.x, h.y, h.z);
    EXPECT_NEAR(sum, k.expected, 1e-6) << k.name;
  }
  // Through the corners, each diagonal voxel gets the whole voxel diagonal.
  RadianceVolume v(box, 512, 2, 1);
  v.add_segment({-1, -1, -1}, {1, 1, 1}, 10, kUnitFlux);
  for (int i = 0; i < 8; ++i) EXPECT_NEAR(voxel_length(v, i, i, i), diag, 1e-6) << i;
}

TEST(RadianceVolume, NegativeCoordinatesUseFloor) {
  const Aabb box{{-1, -1, -1}, {1, 1, 1}};
  RadianceVolume v(box, 512, 2, 1);  // s = 0.25
  // Inside voxel floor((p + 1) / 0.25) = (0, 1, 2).
  EXPECT_NEAR(v.add_segment({-0.9, -0.6, -0.3}, {1, 0.2, 0.1}, 0.05, kUnitFlux), 0.05, 1e-15);
  std::vector<glm::ivec3> hit = touched_voxels(v);
  ASSERT_EQ(hit.size(), 1u);
  EXPECT_EQ(hit[0], glm::ivec3(0, 1, 2));
  // Starting far out at negative coordinates and entering the grid's lowest corner voxel.
  RadianceVolume w(box, 512, 2, 1);
  const glm::dvec3 target(-0.95, -0.9, -0.99);
  const glm::dvec3 origin(-3.7, -2.2, -1.5);
  w.add_segment(origin, target - origin, glm::length(target - origin), kUnitFlux);
  hit = touched_voxels(w);
  ASSERT_FALSE(hit.empty());
  for (const glm::ivec3& h : hit) EXPECT_EQ(h, glm::ivec3(0, 0, 0));
}

TEST(RadianceVolume, IsotropicLineFieldGivesDirectionIndependentRadiance) {
  // Uniform isotropic random lines (direction uniform, foot point uniform on the disc of radius R
  // perpendicular to it) cross any region of volume V with mean length V / (πR²), so every voxel sees
  // radiance L = N Φ / (4π · πR²) in every direction.
  const Aabb box{{0, 0, 0}, {1, 1, 1}};
  RadianceVolume v(box, 64, 4, 1);
  const glm::dvec3 center(0.5);
  const double radius = 1.0;  // > half-diagonal 0.866: every line through the box crosses the disc
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const int lines = 600000;  // statistical spread over directions about ±2 %
  for (int n = 0; n < lines; ++n) {
    const glm::dvec3 d = random_unit(rng);
    const glm::dvec3 a = glm::normalize(glm::cross(d, std::abs(d.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
    const glm::dvec3 b = glm::cross(d, a);
    const double r = radius * std::sqrt(u01(rng)), phi = 2 * kPi * u01(rng);
    const glm::dvec3 foot = center + r * (std::cos(phi) * a + std::sin(phi) * b);
    v.add_segment(foot - 2 * radius * d, d, 4 * radius, glm::vec3(1.0f));
  }
  const double expected = lines / (4 * kPi * kPi * radius * radius);
  double lo = INFINITY, hi = 0;
  for (int n = 0; n < 300; ++n) {
    const glm::vec3 l = v.radiance(center, random_unit(rng));
    EXPECT_EQ(l.x, l.y);  // single channel -> (v, v, v)
    EXPECT_EQ(l.x, l.z);
    lo = std::min(lo, double(l.x));
    hi = std::max(hi, double(l.x));
  }
  EXPECT_NEAR(lo, expected, 0.04 * expected);
  EXPECT_NEAR(hi, expected, 0.04 * expected);
  // Unwindowed the noise in bands 1-3 shows more, but the mean level is the same.
  v.set_window(sh::Window::none);
  EXPECT_NEAR(v.radiance(center, {0, 0, 1}).x, expected, 0.08 * expected);
}

TEST(RadianceVolume, QueryIsClampedAndWindowed) {
  const Aabb box{{0, 0, 0}, {1, 1, 1}};
  RadianceVolume v(box, 27, 4, 3);
  v.add_segment({-1, 0.5, 0.5}, {1, 0, 0}, 3, glm::vec3(1.0f, 2.0f, 3.0f));
  // Unwindowed, a single direction rings negative behind it: the query clamps to exactly 0.
  v.set_window(sh::Window::none);
  EXPECT_EQ(v.window(), sh::Window::none);
  const glm::dvec3 mid(0.5, 0.5, 0.5);
  std::vector<double> c(16);
  for (int q = 0; q < 16; ++q) c[q] = v.voxel_coefficients(1, 1, 1, 0)[q];
  const double unclamped_back = sh::evaluate_sum(c.data(), 4, {-1, 0, 0});
  ASSERT_LT(unclamped_back, 0.0);
  EXPECT_EQ(v.radiance(mid, {-1, 0, 0}), glm::vec3(0.0f));
  const glm::vec3 forward = v.radiance(mid, {1, 0, 0});
  EXPECT_GT(forward.x, 0.0f);
  EXPECT_NEAR(forward.y, 2 * forward.x, 1e-5 * forward.y);  // channels scale with their flux
  EXPECT_NEAR(forward.z, 3 * forward.x, 1e-5 * forward.z);
  EXPECT_NEAR(forward.x, sh::evaluate_sum(c.data(), 4, {1, 0, 0}), 1e-5 * forward.x);
  // Windowed (the default de la Vallée Poussin), nothing is negative anywhere, even before the clamp:
  // the evaluated value with that window is the kernel, which is >= 0.
  v.set_window(sh::Window::vallee_poussin);
  sh::apply_window(c.data(), 4, sh::Window::vallee_poussin);
  std::mt19937 rng(4);
  for (int n = 0; n < 500; ++n) {
    const glm::dvec3 d = random_unit(rng);
    EXPECT_GE(sh::evaluate_sum(c.data(), 4, d), -1e-6 * forward.x);  // zero at the antipode, up to float storage
    const glm::vec3 l = v.radiance(glm::dvec3(1.5, -0.3, 0.7) * std::abs(d.x) + mid * (1 - std::abs(d.x)), d);
    EXPECT_GE(std::min({l.x, l.y, l.z}), 0.0f);
  }
  // The window keeps the DC term: the direction-average is unchanged.
  double mean_none = 0, mean_vp = 0;
  const sh::GaussLegendreRule gl = sh::gauss_legendre(8);
  for (sh::Window w : {sh::Window::none, sh::Window::vallee_poussin}) {
    v.set_window(w);
    double sum = 0;
    for (std::size_t i = 0; i < gl.nodes.size(); ++i)
      for (int j = 0; j < 16; ++j) {
        const double z = gl.nodes[i], r = std::sqrt(1 - z * z), phi = 2 * kPi * (j + 0.5) / 16;
        // Without the clamp the quadrature would be exact; the clamp only adds where the value was < 0.
        sum += gl.weights[i] * 2 * kPi / 16 * v.radiance(mid, {r * std::cos(phi), r * std::sin(phi), z}).x;
      }
    (w == sh::Window::none ? mean_none : mean_vp) = sum;
  }
  EXPECT_NEAR(mean_vp, c[0] / (2 * std::sqrt(kPi)) * 4 * kPi, 1e-5 * mean_vp);
  EXPECT_GE(mean_none, mean_vp);
}

TEST(RadianceVolume, TrilinearBetweenVoxelCentresClampedAtTheBorder) {
  RadianceVolume v(Aabb{{0, 0, 0}, {2, 1, 1}}, 2, 1, 1);  // two unit voxels along x, DC only
  ASSERT_EQ(v.counts(), glm::ivec3(2, 1, 1));
  v.add_segment({0.5, -1, 0.5}, {0, 1, 0}, 3, kUnitFlux);  // crosses voxel 0 only (x = 0.5)
  const double l0 = v.radiance({0.5, 0.5, 0.5}, {0, 1, 0}).x;
  EXPECT_NEAR(l0, kY00 * kY00 * 1.0, 1e-7);  // c00 = Φ ℓ Y00 / V with ℓ = V = 1
  const glm::dvec3 d(0.3, 0.4, std::sqrt(0.75));
  EXPECT_NEAR(v.radiance({1.0, 0.5, 0.5}, d).x, 0.5 * l0, 1e-7);
  EXPECT_NEAR(v.radiance({1.25, 0.5, 0.5}, d).x, 0.25 * l0, 1e-7);
  EXPECT_EQ(v.radiance({1.5, 0.5, 0.5}, d).x, 0.0f);
  EXPECT_NEAR(v.radiance({-5.0, 9.0, -3.0}, d).x, l0, 1e-7);  // outside: the nearest border value
  EXPECT_NEAR(v.radiance({0.2, 0.9, 0.1}, d).x, l0, 1e-7);    // inside voxel 0, before its centre
}

TEST(RadianceVolume, AccumulateMergesPartialVolumesOnTheSameGrid) {
  const Aabb box{{0, 0, 0}, {1, 2, 1}};
  RadianceVolume all(box, 500), a(box, 500), b(box, 500);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-0.5, 2.5);
  for (int n = 0; n < 200; ++n) {
    const glm::dvec3 o(u(rng), u(rng), u(rng));
    const glm::dvec3 d = random_unit(rng);
    all.add_segment(o, d, 2.0, kUnitFlux);
    (n % 2 ? a : b).add_segment(o, d, 2.0, kUnitFlux);
  }
  a.accumulate(b);
  ASSERT_EQ(a.coefficients().size(), all.coefficients().size());
  for (std::size_t i = 0; i < a.coefficients().size(); ++i)
    ASSERT_NEAR(a.coefficients()[i], all.coefficients()[i], 1e-4 * (1 + std::abs(all.coefficients()[i])));

  EXPECT_THROW(a.accumulate(RadianceVolume(Aabb{{0, 0, 0}, {1, 2, 1.5}}, 500)), std::invalid_argument);
  EXPECT_THROW(a.accumulate(RadianceVolume(box, 600)), std::invalid_argument);
  EXPECT_THROW(a.accumulate(RadianceVolume(box, 500, 3)), std::invalid_argument);
  EXPECT_THROW(a.accumulate(RadianceVolume(box, 500, 4, 1)), std::invalid_argument);
  EXPECT_NO_THROW(a.accumulate(RadianceVolume(box, 500)));

  std::vector<float> wrong(3);
  EXPECT_THROW(a.set_coefficients(wrong), std::invalid_argument);
  a.set_coefficients(all.coefficients());
  EXPECT_EQ(a.coefficients(), all.coefficients());
}
