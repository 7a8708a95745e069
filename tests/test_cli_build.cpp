// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// `lumx build` and `lumx eval --rays` as a user runs them on a rayset of an analytic emitter: held-out
// error tables stored and printed, map resolutions chosen on held-out rays, the same numbers as the
// library's (whatever the thread count), the bundle's own rays regraded by rebuilding from half.
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/map_fit.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/photometry_io.h>
#include <lumx/io/rayset_io.h>
#include <lumx/photometry/intensity_table.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "analytic_emitters.h"
#include "cli_test_support.h"
#include "test_support.h"

#include <cmath>
#include <filesystem>
#include <string>

#include <unistd.h>

namespace fs = std::filesystem;
using namespace lumx;

namespace {

bool has(const std::string& text, const std::string& what) { return text.find(what) != std::string::npos; }

struct BuiltDisk {
  fs::path dir, rays, bundle;
  lumx_test::CliRun build;
  BuiltDisk() : dir(fs::temp_directory_path() / ("lumx_cli_build_" + std::to_string(::getpid()))) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    rays = dir / "disk.tm25ray";
    bundle = dir / "disk.lumx";
    const lumx_test::PlanarEmitter disk("disk", lumx_test::PlanarEmitter::Shape::disk, 0.1, 0, 1, 1000);
    // The sanitizer build runs the same commands on fewer rays, so that the rule and the fit give R 32 maps,
    // and on two levels: grading the 64-APL level there took most of a two-minute test.
    auto src = disk.source(lumx_test::kSanitized ? 50000 : 200000, 21);
    RaysetInfo info = src->info();
    info.header_flux = 1000;
    write_tm25(rays.string(), info, *src);
    build = lumx_test::run_cli("build " + lumx_test::quoted(rays) + " " + lumx_test::quoted(bundle) +
                               (lumx_test::kSanitized ? " --levels 1 8" : " --levels 1 8 64"));
  }
  ~BuiltDisk() { fs::remove_all(dir); }
};

}  // namespace

TEST(CliBuild, StoresAndPrintsHeldOutTablesTheLibraryReproduces) {
  const BuiltDisk b;
  ASSERT_EQ(b.build.status, 0) << b.build.out;
  EXPECT_TRUE(has(b.build.out, "rays not used to build the levels, their noise removed")) << b.build.out;
  EXPECT_TRUE(has(b.build.out, "maps:     resolutions chosen on held-out rays:")) << b.build.out;
  EXPECT_TRUE(has(b.build.out, "(odd rays the levels never saw)")) << b.build.out;
  EXPECT_TRUE(has(b.build.out, "noise floor")) << b.build.out;
  EXPECT_EQ(lumx_test::run_cli("check " + lumx_test::quoted(b.bundle)).status, 0);

  const BundleReader reader(b.bundle.string());
  const auto& prov = reader.manifest().provenance;
  EXPECT_EQ(prov.at("error_tables").rfind("held out", 0), 0u) << prov.at("error_tables");
  EXPECT_EQ(prov.at("source_rays"), "200000");
  ASSERT_EQ(reader.manifest().levels.size(), 3u);
  // The fitted maps in words: one entry per level with its resolution, and the far field's.
  const std::string& smoothing = prov.at("map_smoothing");
  for (std::size_t k = 0; k < 3; ++k)
    EXPECT_TRUE(has(smoothing, "level " + std::to_string(k) + ": R " +
                                   std::to_string(reader.manifest().levels[k].map_resolution) + ","))
        << smoothing;
  EXPECT_TRUE(has(smoothing, "far field: R ")) << smoothing;
  std::printf("map_smoothing: %s\n", smoothing.c_str());

  // The library on the same file, one thread (the CLI used every core): the same tables and resolutions.
  const auto rays = open_rayset(b.rays.string());
  AplBuildOptions bo;
  bo.level_counts = {1, 8, 64};
  bo.threads = 1;
  AplErrorReport report;
  bool fitted = false;
  const AplBuildOptions half = half_rays_build_options(bo, rays->info().ray_count);
  const AplSet set = build_with_held_out_errors(
      *rays, [&](RaySource& r) { return build_apl_set(r, half); }, [&](RaySource& r) { return build_apl_set(r, bo); },
      AplErrorOptions{}, &report, &fitted);
  ASSERT_TRUE(fitted);
  for (std::size_t k = 0; k < 3; ++k) {
    const ErrorTable& stored = reader.manifest().levels[k].error;
    ASSERT_EQ(stored.relative_distance, (std::vector<double>{0.5, 0.75, 1, 2, 5, 10})) << k;
    for (std::size_t s = 0; s < 6; ++s) {
      EXPECT_EQ(stored.relative_rmse[s], set.levels[k].error.relative_rmse[s]) << k << " " << s;
      EXPECT_GT(stored.relative_rmse[s], 0) << k << " " << s;
    }
    EXPECT_EQ(reader.manifest().levels[k].map_resolution, set.levels[k].map_resolution) << k;
    EXPECT_EQ(set.levels[k].map_resolution, report.levels[k].map_resolution) << k;
  }

  // The attached far field carries the rays' flux (0.5 %: the Type C grid's quadrature of the map).
  bool found = false;
  for (std::size_t i = 0; i < reader.manifest().attachments.size(); ++i)
    if (reader.manifest().attachments[i].first.name == "far_field.ies") {
      found = true;
      const std::string bytes = reader.read_attachment(i);
      const Photometry p = read_ies(std::string_view(bytes), "far_field.ies");
      EXPECT_NEAR(IntensityTable(p).flux_lm(), 1000, 5);
    }
  EXPECT_TRUE(found);
}

TEST(CliBuild, EvalOnTheBundlesOwnRaysRebuildsFromHalf) {
  const BuiltDisk b;
  ASSERT_EQ(b.build.status, 0) << b.build.out;
  const lumx_test::CliRun own = lumx_test::run_cli("eval " + lumx_test::quoted(b.bundle) + " --rays " + lumx_test::quoted(b.rays));
  ASSERT_EQ(own.status, 0) << own.out;
  EXPECT_TRUE(has(own.out, "these rays built the bundle")) << own.out;
  EXPECT_TRUE(has(own.out, "(its levels rebuilt from the even rays)")) << own.out;
  const lumx_test::CliRun forced =
      lumx_test::run_cli("eval " + lumx_test::quoted(b.bundle) + " --rays " + lumx_test::quoted(b.rays) + " --independent");
  ASSERT_EQ(forced.status, 0) << forced.out;
  EXPECT_TRUE(has(forced.out, "(the rays it was built from: errors shared with them cancel)")) << forced.out;
  EXPECT_FALSE(has(forced.out, "rebuilt from the even rays")) << forced.out;
}

TEST(CliBuild, MaxResolutionCapsEveryLevelsMaps) {
  const fs::path dir = lumx_test::fresh_temp_dir("lumx_cli_build_cap");
  const lumx_test::PlanarEmitter disk("disk", lumx_test::PlanarEmitter::Shape::disk, 0.1, 0, 1, 1000);
  auto src = disk.source(100000, 5);
  write_tm25((dir / "disk.tm25ray").string(), src->info(), *src);
  // 100 000 rays give the one-APL level R 64 by the rule; the cap makes it and every other level at most 16.
  const lumx_test::CliRun r = lumx_test::run_cli("build " + lumx_test::quoted(dir / "disk.tm25ray") + " " +
                                                 lumx_test::quoted(dir / "b") + " --levels 1 8 --max-resolution 16");
  ASSERT_EQ(r.status, 0) << r.out;
  const BundleReader bundle((dir / "b").string());
  ASSERT_EQ(bundle.manifest().levels.size(), 2u);
  for (const auto& level : bundle.manifest().levels) EXPECT_LE(level.map_resolution, 16);
  EXPECT_TRUE(has(r.out, "1 APLs (R 16), 8 APLs (R 16) as built")) << r.out;
  EXPECT_NE(lumx_test::run_cli("build " + lumx_test::quoted(dir / "disk.tm25ray") + " " + lumx_test::quoted(dir / "c") +
                               " --max-resolution 0")
                .status,
            0);
  fs::remove_all(dir);
}

TEST(CliBuild, PointSourcesBehindAperturesShipAsMaskedApls) {
  // The analytic suite's box with holes as a TM-25 file: lumx build finds the two point sources, says
  // so, and ships one masked APL per source in a format-3 bundle that lumx check accepts.
  const fs::path dir = lumx_test::fresh_temp_dir("lumx_cli_build_box");
  const lumx_test::PinholeBox box = lumx_test::suite_pinhole_box();
  auto src = box.source(lumx_test::kSanitized ? 200000 : 400000, 3);
  write_tm25((dir / "box.tm25ray").string(), src->info(), *src);
  const lumx_test::CliRun r =
      lumx_test::run_cli("build " + lumx_test::quoted(dir / "box.tm25ray") + " " + lumx_test::quoted(dir / "b"));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(has(r.out, "point sources: 2;")) << r.out;
  const BundleReader bundle((dir / "b").string());
  EXPECT_EQ(bundle.manifest().format_version, 3);
  ASSERT_EQ(bundle.manifest().levels.size(), 2u);
  EXPECT_EQ(bundle.manifest().masks.size(), 2u);
  const AplSet set = bundle.load();
  for (const Apl& a : set.levels[1].apls) EXPECT_TRUE(a.mask);
  const lumx_test::CliRun check = lumx_test::run_cli("check " + lumx_test::quoted(dir / "b"));
  EXPECT_EQ(check.status, 0) << check.out;
  const lumx_test::CliRun info = lumx_test::run_cli("info " + lumx_test::quoted(dir / "b"));
  EXPECT_TRUE(has(info.out, "beam masks:  2 (point sources behind apertures, 8 caps); masked APLs per level: 0 2")) << info.out;
  // Graded against the rays, the borders no mask places widen the bounds, in a row of their own.
  const lumx_test::CliRun eval =
      lumx_test::run_cli("eval " + lumx_test::quoted(dir / "b") + " --rays " + lumx_test::quoted(dir / "box.tm25ray"));
  ASSERT_EQ(eval.status, 0) << eval.out;
  EXPECT_TRUE(has(eval.out, "\nborder ")) << eval.out;
  EXPECT_TRUE(has(eval.out, "note: border: what a patch centre outside every beam mask may still receive")) << eval.out;
  // --no-point-sources keeps the clustered levels asked for, without masks.
  const lumx_test::CliRun plain = lumx_test::run_cli("build " + lumx_test::quoted(dir / "box.tm25ray") + " " +
                                                     lumx_test::quoted(dir / "p") + " --levels 1 8 --no-eval --no-point-sources");
  ASSERT_EQ(plain.status, 0) << plain.out;
  EXPECT_FALSE(has(plain.out, "point sources:")) << plain.out;
  const BundleReader clustered((dir / "p").string());
  EXPECT_EQ(clustered.manifest().format_version, 2);
  EXPECT_EQ(clustered.manifest().levels.size(), 2u);
  EXPECT_TRUE(clustered.manifest().masks.empty());
  fs::remove_all(dir);
}

// `lumx build --representations apl,far-field`: the far field is built through the seam, stored as a model,
// listed by `lumx info`, checked by `lumx check`, and graded beside the APL levels by `lumx build` (held out)
// and `lumx eval` (rays of another run). A point at the centre cannot stand for a 0.2 m disk close by: the
// far field's error must be resolved at d = 0.5 and fall with distance.
TEST(CliBuild, FurtherRepresentationsAreBuiltStoredAndGradedThroughTheSeam) {
  const fs::path dir = lumx_test::fresh_temp_dir("lumx_cli_build_models");
  const lumx_test::PlanarEmitter disk("disk", lumx_test::PlanarEmitter::Shape::disk, 0.1, 0, 1, 1000);
  for (const auto& [name, seed] : {std::pair<const char*, int>{"a.tm25ray", 5}, {"b.tm25ray", 6}}) {
    auto src = disk.source(lumx_test::kSanitized ? 40000 : 100000, seed);
    write_tm25((dir / name).string(), src->info(), *src);
  }
  const lumx_test::CliRun r = lumx_test::run_cli("build " + lumx_test::quoted(dir / "a.tm25ray") + " " +
                                                 lumx_test::quoted(dir / "b") + " --levels 1 8 --representations apl,far-field");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(has(r.out, "representations graded through the seam")) << r.out;
  const BundleReader bundle((dir / "b").string());
  ASSERT_EQ(bundle.manifest().models.size(), 1u);
  EXPECT_EQ(bundle.manifest().models[0].type, "far-field");
  EXPECT_EQ(bundle.manifest().format_version, 4);
  const lumx_test::CliRun info = lumx_test::run_cli("info " + lumx_test::quoted(dir / "b"));
  EXPECT_TRUE(has(info.out, "far-field")) << info.out;
  const lumx_test::CliRun check = lumx_test::run_cli("check " + lumx_test::quoted(dir / "b"));
  EXPECT_EQ(check.status, 0) << check.out;
  const lumx_test::CliRun eval = lumx_test::run_cli("eval " + lumx_test::quoted(dir / "b") + " --rays " +
                                                    lumx_test::quoted(dir / "b.tm25ray") + " --json", false);
  ASSERT_EQ(eval.status, 0) << eval.out;
  const nlohmann::json j = nlohmann::json::parse(eval.out);
  ASSERT_EQ(j.at("models").size(), 1u);
  const nlohmann::json& spheres = j["models"][0]["spheres"];
  ASSERT_EQ(spheres.size(), 6u);
  EXPECT_TRUE(spheres[0]["resolved"].get<bool>());
  EXPECT_GT(spheres[0]["noise_removed"].get<double>(), spheres[5]["noise_removed"].get<double>());
  const lumx_test::CliRun bad = lumx_test::run_cli("build " + lumx_test::quoted(dir / "a.tm25ray") + " " +
                                                   lumx_test::quoted(dir / "c") + " --representations apl,no-such");
  EXPECT_NE(bad.status, 0);
  EXPECT_TRUE(has(bad.out, "no-such")) << bad.out;
  EXPECT_FALSE(fs::exists(dir / "c"));
  fs::remove_all(dir);
}
