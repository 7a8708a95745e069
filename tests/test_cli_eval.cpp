// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// `lumx eval` as a user runs it: irradiance at points (--level, --lod, located errors for bad lines), the
// error report against a TM-25 rayset (table, JSON equal to the library's numbers, plots, error tables
// stored in the bundle), and usage errors.
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/evaluation.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/rayset_io.h>

#include <gtest/gtest.h>
#include "cli_test_support.h"
#include <nlohmann/json.hpp>

#include "test_support.h"

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <unistd.h>

namespace fs = std::filesystem;
using namespace lumx;

namespace {

using lumx_test::CliRun;
CliRun run(const std::string& args, bool stderr_too = true) { return lumx_test::run_cli(args, stderr_too); }

std::string q(const fs::path& p) { return lumx_test::quoted(p); }

fs::path scratch(const std::string& test) {
  const fs::path d = fs::temp_directory_path() / ("lumx_cli_eval_" + test + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write_text(const fs::path& p, const std::string& s) {
  std::ofstream f(p, std::ios::binary);
  f << s;
}

/// A small ring luminaire (radius 5 cm, downward cos lobes tilted outward) written as TM-25, and the
/// bundle built from what the TM-25 reader gives back.
struct Fixture {
  fs::path dir, rays, bundle;
  explicit Fixture(const std::string& name) : dir(scratch(name)), rays(dir / "ring.tm25ray"), bundle(dir / "ring.lumx") {
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    RayChunk c;
    for (int i = 0; i < 40000; ++i) {
      const float a = float(2 * kPi) * u(rng);
      const glm::vec3 axis = glm::normalize(glm::vec3(0.5f * std::cos(a), 0.5f * std::sin(a), -1.0f));
      const glm::vec3 t1 = glm::normalize(glm::cross(axis, glm::vec3(0, 0, 1))), t2 = glm::cross(axis, t1);
      const float ct = std::sqrt(u(rng)), st = std::sqrt(1 - ct * ct), az = float(2 * kPi) * u(rng);
      c.push_back({0.05f * std::cos(a), 0.05f * std::sin(a), 0.0f},
                  glm::normalize(st * std::cos(az) * t1 + st * std::sin(az) * t2 + ct * axis), 0.025f);
    }
    RaysetInfo info;
    info.file = "ring";
    info.quantity = PhotometricQuantity::photometric;
    info.header_flux = 1000.0;
    MemoryRaySource src(std::move(c), info);
    write_tm25(rays.string(), info, src);
    const auto back = open_rayset(rays.string());
    AplBuildOptions o;
    o.level_counts = {1, 8, 64};
    o.map_resolution = 16;
    write_bundle(bundle.string(), build_apl_set(*back, o));
  }
  ~Fixture() { fs::remove_all(dir); }
};

std::vector<double> numbers(const std::string& text) {
  std::vector<double> v;
  std::istringstream in(text);
  double x;
  while (in >> x) v.push_back(x);
  return v;
}

}  // namespace

TEST(CliEval, PointsAtLevelsAndByLod) {
  const Fixture fx("points");
  const fs::path pts = fx.dir / "points.txt";
  // Comments, blank lines, commas, an unnormalised normal; points on the floor 1 m below, facing up, and
  // one close to the ring facing down (0 from a downward luminaire).
  write_text(pts,
             "# x y z nx ny nz\n"
             "0 0 -1 0 0 1\n"
             "\n"
             "0.3, 0.1, -1, 0, 0, 2   # commas and a long normal\n"
             "0.06 0 -0.02 0 0 1\n"
             "2 -1 -3 0 0 1\n"
             "0 0 -0.5 0 0 -1\n");
  const BundleReader reader(fx.bundle.string());
  const AplSet set = reader.load();
  const std::vector<glm::vec3> xs = {{0, 0, -1}, {0.3f, 0.1f, -1}, {0.06f, 0, -0.02f}, {2, -1, -3}, {0, 0, -0.5f}};
  const std::vector<glm::vec3> ns = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, -1}};

  // Default: the finest level, to stdout, one value per point.
  const CliRun fine = run("eval " + q(fx.bundle) + " --points " + q(pts), false);
  ASSERT_EQ(fine.status, 0) << fine.out;
  const std::vector<double> v = numbers(fine.out);
  ASSERT_EQ(v.size(), 5u) << fine.out;
  for (std::size_t i = 0; i < 5; ++i) {
    const double e = irradiance(set, 2, xs[i], ns[i]).irradiance.x;
    EXPECT_NEAR(v[i], e, 1e-8 * std::abs(e) + 1e-300) << i;
  }
  EXPECT_GT(v[0], 0);
  EXPECT_EQ(v[4], 0.0);

  // --level 0 into a file; the far-off point agrees with the finest level within a few %.
  const fs::path out = fx.dir / "e0.txt";
  const CliRun l0 = run("eval " + q(fx.bundle) + " --points " + q(pts) + " --level 0 -o " + q(out));
  ASSERT_EQ(l0.status, 0) << l0.out;
  EXPECT_NE(l0.out.find("irradiance in lx"), std::string::npos) << l0.out;
  const std::vector<double> v0 = numbers(lumx_test::read_text(out));
  ASSERT_EQ(v0.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    const double e = irradiance(set, 0, xs[i], ns[i]).irradiance.x;
    EXPECT_NEAR(v0[i], e, 1e-8 * std::abs(e) + 1e-300) << i;
  }
  EXPECT_NEAR(v0[3], v[3], 0.05 * v[3]);

  // --lod: every value is one of the levels' values at that point, and reruns give the same bytes.
  const CliRun lod1 = run("eval " + q(fx.bundle) + " --points " + q(pts) + " --lod", false);
  const CliRun lod2 = run("eval " + q(fx.bundle) + " --points " + q(pts) + " --lod", false);
  ASSERT_EQ(lod1.status, 0) << lod1.out;
  EXPECT_EQ(lod1.out, lod2.out);
  const std::vector<double> vl = numbers(lod1.out);
  ASSERT_EQ(vl.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    bool found = false;
    for (std::size_t k = 0; k < set.levels.size(); ++k) {
      const double e = irradiance(set, k, xs[i], ns[i]).irradiance.x;
      found = found || std::abs(vl[i] - e) <= 1e-8 * std::abs(e);
    }
    EXPECT_TRUE(found) << i << " " << vl[i];
  }
}

TEST(CliEval, BadPointLinesAreLocated) {
  const Fixture fx("bad");
  struct Case {
    const char* text;
    const char* expect;
  };
  const Case cases[] = {
      {"0 0 -1 0 0 1\n# ok\n1 2 3 0 0\n", ":3: error: point: expected 6 numbers"},
      {"1 2 x 0 0 1\n", ":1: error: position: 'x' is not a number"},
      {"\n1 2 3 0 0 0\n", ":2: error: normal: the normal has zero length"},
      {"1 2 3 0 0 inf\n", ":1: error: normal: 'inf' is not a finite number"},
      {"1 2 3 0 0 1 7\n", ":1: error: point: expected 6 numbers"},
  };
  for (const Case& c : cases) {
    const fs::path pts = fx.dir / "bad.txt";
    write_text(pts, c.text);
    const CliRun r = run("eval " + q(fx.bundle) + " --points " + q(pts));
    EXPECT_EQ(r.status, 1) << c.text;
    EXPECT_NE(r.out.find(pts.string() + c.expect), std::string::npos) << r.out;
  }
  const CliRun missing = run("eval " + q(fx.bundle) + " --points " + q(fx.dir / "none.txt"));
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.out.find("none.txt"), std::string::npos);
  const CliRun level = run("eval " + q(fx.bundle) + " --points " + q(fx.dir / "bad.txt") + " --level 9");
  EXPECT_EQ(level.status, 1);
  EXPECT_NE(level.out.find("levels 0..2"), std::string::npos) << level.out;
}

TEST(CliEval, RaysReportTableJsonPlotsAndStoredTables) {
  const Fixture fx("rays");
  // The table: a row per level and the far field, the noise floor, the cost columns.
  const fs::path plots = fx.dir / "plots";
  const CliRun t = run("eval " + q(fx.bundle) + " --rays " + q(fx.rays) + " --plots " + q(plots) +
                       " --plot-format svg --distances 0.5,1,5");
  ASSERT_EQ(t.status, 0) << t.out;
  for (const char* s : {"relative RMSE (eq. 5.1)", "noise floor", "far field", "ns/point", "bytes", "Hellinger",
                        "20000 rays", "the even ones make the pilot", "512 patches"})
    EXPECT_NE(t.out.find(s), std::string::npos) << s << "\n" << t.out;
  for (const char* f : {"error_vs_distance.svg", "error_vs_time.svg", "error_vs_bytes.svg"}) {
    ASSERT_TRUE(fs::exists(plots / f)) << f;
    const std::string svg = lumx_test::read_text(plots / f);
    EXPECT_NE(svg.find("<svg"), std::string::npos) << f;
  }

  // JSON: the same numbers as the library computes from the same file (timings aside).
  const CliRun j = run("eval " + q(fx.bundle) + " --rays " + q(fx.rays) + " --json --patches 8", false);
  ASSERT_EQ(j.status, 0) << j.out;
  const nlohmann::json doc = nlohmann::json::parse(j.out);
  const AplSet set = BundleReader(fx.bundle.string()).load();
  const auto src = open_rayset(fx.rays.string());
  AplErrorOptions o;
  o.patch_resolution = 8;
  o.min_timing_seconds = 0;
  // As the CLI grades rays from another run: the pilot (one level of 64 APLs, built as the bundle records)
  // from the even rays, the levels graded on the odd ones.
  AplBuildOptions pilot_options;  // the fixture's bundle records no build options: the defaults
  ASSERT_EQ(set.provenance.count("build_options"), 0u);
  pilot_options.level_counts = {64};
  const auto build_pilot = [&](RaySource& r) { return build_apl_set(r, pilot_options); };
  const AplErrorReport r = evaluate_independent(set, *src, build_pilot, o);
  ASSERT_EQ(doc["levels"].size(), 3u);
  EXPECT_EQ(doc["patches"], 128);
  EXPECT_EQ(doc["ray_count"], 20000);
  for (std::size_t s = 0; s < 6; ++s) {
    EXPECT_EQ(doc["spheres"][s]["reference"], r.reference.sphere[s].centred ? "patch centres" : "patch means");
    EXPECT_EQ(doc["spheres"][s]["centring_shift"].get<double>(), r.reference.sphere[s].centring_shift);
  }
  for (std::size_t k = 0; k < 3; ++k)
    for (std::size_t s = 0; s < 6; ++s) {
      EXPECT_EQ(doc["levels"][k]["relative_rmse"][s].get<double>(), r.levels[k].errors[s].relative_rmse);
      EXPECT_EQ(doc["levels"][k]["hellinger"][s].get<double>(), r.levels[k].errors[s].hellinger);
    }
  for (std::size_t s = 0; s < 6; ++s)
    EXPECT_EQ(doc["spheres"][s]["noise_floor"].get<double>(), r.reference.sphere[s].noise_floor);
  EXPECT_EQ(doc["far_field"]["relative_rmse"].size(), 6u);

  // --store-errors: the bundle then carries the tables (default distances and patches), and stays valid
  // with the same stored resolutions.
  std::vector<std::size_t> stored_maps;
  {
    const BundleReader before(fx.bundle.string());
    for (const auto& l : before.manifest().levels) stored_maps.push_back(l.maps.size());
  }
  const CliRun st = run("eval " + q(fx.bundle) + " --rays " + q(fx.rays) + " --store-errors --independent");
  ASSERT_EQ(st.status, 0) << st.out;
  EXPECT_TRUE(check_bundle(fx.bundle.string()).empty());
  const BundleReader stored(fx.bundle.string());
  o.patch_resolution = 16;
  const AplErrorReport r16 = evaluate_independent(set, *src, build_pilot, o);
  for (std::size_t k = 0; k < 3; ++k) {
    const ErrorTable& e = stored.manifest().levels[k].error;
    ASSERT_EQ(e.relative_distance, (std::vector<double>{0.5, 0.75, 1, 2, 5, 10}));
    for (std::size_t s = 0; s < 6; ++s) {
      const IrradianceErrors& x = r16.levels[k].errors[s];
      EXPECT_EQ(e.relative_rmse[s], x.resolved ? x.relative_rmse_noise_removed : x.noise_removed_upper);
    }
  }
  EXPECT_NE(stored.manifest().provenance.at("error_tables").find("20000 rays"), std::string::npos);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(stored.manifest().levels[k].maps.size(), stored_maps[k]) << k;
  // The maps themselves are rewritten losslessly.
  const AplSet after = stored.load();
  for (std::size_t k = 0; k < 3; ++k)
    for (std::size_t i = 0; i < set.levels[k].size(); ++i)
      ASSERT_EQ(after.levels[k].apls[i].map.values(), set.levels[k].apls[i].map.values()) << k << " " << i;
}

TEST(CliEval, UsageErrors) {
  const Fixture fx("usage");
  const CliRun neither = run("eval " + q(fx.bundle));
  EXPECT_EQ(neither.status, 1);
  EXPECT_NE(neither.out.find("exactly one of --points or --rays"), std::string::npos) << neither.out;
  const CliRun both = run("eval " + q(fx.bundle) + " --points a --rays b");
  EXPECT_EQ(both.status, 1);
  const CliRun level_and_lod = run("eval " + q(fx.bundle) + " --points a --level 0 --lod");
  EXPECT_EQ(level_and_lod.status, 1);
  EXPECT_NE(level_and_lod.out.find("not both"), std::string::npos);
  const CliRun rays_level = run("eval " + q(fx.bundle) + " --rays " + q(fx.rays) + " --level 1");
  EXPECT_EQ(rays_level.status, 1);
  const CliRun bad_patches = run("eval " + q(fx.bundle) + " --rays " + q(fx.rays) + " --patches 0", false);
  EXPECT_NE(bad_patches.status, 0);
  const CliRun not_rays = run("eval " + q(fx.bundle) + " --rays " + q(fx.dir / "missing.tm25ray"));
  EXPECT_EQ(not_rays.status, 1);
  EXPECT_NE(not_rays.out.find("missing.tm25ray"), std::string::npos) << not_rays.out;
  const CliRun help = run("eval --help");
  EXPECT_EQ(help.status, 0);
  for (const char* s : {"--points", "--lod", "--rays", "--plots", "--patches", "--store-errors"})
    EXPECT_NE(help.out.find(s), std::string::npos) << s;
}
