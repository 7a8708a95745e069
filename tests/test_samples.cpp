// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The sample programs as a user runs them: samples/led_strip_rays.cpp writes the rayset the README's main
// job builds from, so what it writes is checked against the luminaire it describes.
#include <lumx/bake/gltf_reader.h>
#include <lumx/bake/luminaire_check.h>
#include <lumx/io/rayset_io.h>

#include "cli_test_support.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <string>

#include <unistd.h>

namespace fs = std::filesystem;
using namespace lumx;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("lumx_samples_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

/// Writes the strip's rays with the sample program; fails the test if it does not exit 0.
fs::path write_strip(const fs::path& dir, const std::string& args) {
  const fs::path out = dir / "strip.tm25ray";
  const lumx_test::CliRun r = lumx_test::run_program(LUMX_SAMPLE_LED_STRIP_RAYS, lumx_test::quoted(out) + " " + args);
  EXPECT_EQ(r.status, 0) << r.out;
  return out;
}

}  // namespace

TEST(SampleLedStripRays, RaysFollowTheDescribedLuminaire) {
  if (std::string(LUMX_SAMPLE_LED_STRIP_RAYS).empty()) GTEST_SKIP() << "samples not built (LUMX_BUILD_SAMPLES=OFF)";
  const fs::path dir = scratch("strip");
  constexpr int kRays = 160000, kDies = 8;
  const auto rays = open_rayset(write_strip(dir, "--rays " + std::to_string(kRays) + " --seed 7").string());
  EXPECT_EQ(rays->info().format, "TM-25");
  EXPECT_EQ(rays->info().ray_count, std::uint64_t(kRays));
  EXPECT_NEAR(rays->info().header_flux, 800.0, 1e-9);

  // Per die (found from x: centres 15 mm apart, dies 2 mm wide): start points on the die, its ray count
  // (each ray picks a die with chance 1/8: binomial, sd sqrt(N·(1/8)(7/8)) ≈ 132 rays), and the share of
  // its flux within 30° of nadir, whose exact value is 1 − cos^(m+1) 30° (m = 1 bare, m = 8 under a lens),
  // a binomial proportion of n ≈ 20 000 rays. 4 standard errors bound a false failure at ~6e-5 each.
  std::array<double, kDies> count{}, within{}, flux{};
  RayChunk c;
  rays->rewind();
  while (rays->next(c, 50000)) {
    for (std::size_t i = 0; i < c.size(); ++i) {
      const double die_x = c.x[i] / 0.015 + 3.5;
      const int die = int(std::lround(die_x));
      ASSERT_TRUE(die >= 0 && die < kDies) << c.x[i];
      ASSERT_LE(std::abs(c.x[i] - (die - 3.5) * 0.015), 0.001 + 1e-6);
      ASSERT_LE(std::abs(c.y[i]), 0.001 + 1e-6);
      ASSERT_EQ(c.z[i], 0.0f);
      ASSERT_LT(c.dz[i], 0.0f) << "every die faces down";
      count[die] += 1;
      flux[die] += c.flux[i];
      if (-c.dz[i] > std::cos(30.0 * 3.14159265358979323846 / 180.0)) within[die] += 1;
    }
  }
  for (int d = 0; d < kDies; ++d) {
    SCOPED_TRACE("die " + std::to_string(d));
    EXPECT_NEAR(count[d], kRays / kDies, 4 * std::sqrt(kRays * (1.0 / kDies) * (1 - 1.0 / kDies)));
    EXPECT_NEAR(flux[d], count[d] * 800.0 / kRays, 1e-6 * flux[d]);
    const int m = d % 2 == 0 ? 1 : 8;
    const double exact = 1 - std::pow(std::cos(30.0 * 3.14159265358979323846 / 180.0), m + 1);
    const double n = count[d], se = std::sqrt(exact * (1 - exact) / n);
    EXPECT_NEAR(within[d] / n, exact, 4 * se);
  }
  fs::remove_all(dir);
}

TEST(SampleLedStripRays, SameSeedSameRaysOtherSeedOtherRays) {
  if (std::string(LUMX_SAMPLE_LED_STRIP_RAYS).empty()) GTEST_SKIP() << "samples not built (LUMX_BUILD_SAMPLES=OFF)";
  const fs::path a = scratch("seed_a"), b = scratch("seed_b"), c = scratch("seed_c");
  const RayChunk ra = read_all_rays(*open_rayset(write_strip(a, "--rays 5000 --seed 3").string()), 5000);
  const RayChunk rb = read_all_rays(*open_rayset(write_strip(b, "--rays 5000 --seed 3").string()), 5000);
  const RayChunk rc = read_all_rays(*open_rayset(write_strip(c, "--rays 5000 --seed 4").string()), 5000);
  ASSERT_EQ(ra.size(), 5000u);
  EXPECT_EQ(ra.dx, rb.dx);
  EXPECT_EQ(ra.x, rb.x);
  EXPECT_NE(ra.dx, rc.dx);
  for (const auto& d : {a, b, c}) fs::remove_all(d);
}

TEST(SampleLedStripRays, BadArgumentsAreRefused) {
  if (std::string(LUMX_SAMPLE_LED_STRIP_RAYS).empty()) GTEST_SKIP() << "samples not built (LUMX_BUILD_SAMPLES=OFF)";
  EXPECT_EQ(lumx_test::run_program(LUMX_SAMPLE_LED_STRIP_RAYS, "").status, 2);
  const lumx_test::CliRun huge = lumx_test::run_program(LUMX_SAMPLE_LED_STRIP_RAYS, "x.tm25ray --rays 99999999999");
  EXPECT_EQ(huge.status, 2);
  EXPECT_NE(huge.out.find("--rays"), std::string::npos) << huge.out;
}

// The procedural luminaires: each is a glTF file lumx reads and finds nothing wrong with, with the flux its
// description states (π L A over the meshed emitters: within 1 % of the round figure the sample aims at).
TEST(SampleLuminaires, FourCheckedLuminairesWithTheirStatedFlux) {
  if (std::string(LUMX_SAMPLE_LUMINAIRES).empty()) GTEST_SKIP() << "samples not built (LUMX_BUILD_SAMPLES=OFF)";
  const auto dir = lumx_test::unique_temp_path("lumx_sample_luminaires");
  std::filesystem::remove_all(dir);
  const lumx_test::CliRun r = lumx_test::run_program(LUMX_SAMPLE_LUMINAIRES, lumx_test::quoted(dir));
  ASSERT_EQ(r.status, 0) << r.out;
  const std::pair<const char*, double> expected[] = {
      {"troffer.glb", 9000.0}, {"pendant.glb", 1500.0}, {"shape_sorter.glb", 400.0}, {"chandelier.glb", 1250.0}};
  for (const auto& [name, flux] : expected) {
    const auto scene = lumx::bake::read_gltf_luminaire((dir / name).string());
    double total = 0.0;
    for (const auto& e : scene.emitters) total += lumx::bake::emitter_flux_lm(scene, e);
    EXPECT_NEAR(total, flux, 0.025 * flux) << name;
    EXPECT_TRUE(lumx::bake::check_luminaire(scene).empty()) << name;
    const lumx_test::CliRun check = lumx_test::run_cli("check " + lumx_test::quoted(dir / name));
    EXPECT_EQ(check.status, 0) << check.out;
  }
  std::filesystem::remove_all(dir);
}
