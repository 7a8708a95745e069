// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// `lumx info` and `lumx check` on raysets, as a user runs them: real files, a plain-text file, a broken
// file (located finding, exit 1), and photometry files still taking their own path.
#include <gtest/gtest.h>
#include "cli_test_support.h"
#include <nlohmann/json.hpp>

#include "rayset_test_support.h"

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

using lumx_test::CliRun;
CliRun run(const std::string& args, bool stderr_too = true) { return lumx_test::run_cli(args, stderr_too); }

std::string q(const fs::path& p) { return lumx_test::quoted(p); }

bool has(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST(CliRays, InfoSummarisesARealTm25File) {
  const fs::path f = lumx_rays::real_file("rayfile_LERTDUW_S2WP_blue_100k_20161013_IES_TM25.TM25RAY");
  if (f.empty()) LUMX_SKIP_WITHOUT_SHARED("data/raysets");
  const CliRun r = run("info " + q(f));
  EXPECT_EQ(r.status, 0) << r.out;
  for (const char* part : {"format:        TM-25 2013", "rays:          100000", "the header states 1.68 W",
                           "bounding box:", "bounding sphere:", "spectral table 1: 76 points, 390..510 nm",
                           "text:          name: LERTDUW_S2WP", "text:          manufacturer: OSRAM"})
    EXPECT_TRUE(has(r.out, part)) << part << "\n" << r.out;

  const CliRun j = run("info --json " + q(f), false);
  ASSERT_EQ(j.status, 0) << j.out;
  const auto doc = nlohmann::json::parse(j.out);
  EXPECT_EQ(doc["format"], "TM-25");
  EXPECT_EQ(doc["rays"], 100000);
  EXPECT_EQ(doc["quantity"], "radiometric");
  EXPECT_EQ(doc["flux_unit"], "W");
  EXPECT_NEAR(doc["header_flux"].get<double>(), 1.68, 1e-6);
  EXPECT_NEAR(doc["flux_sum"].get<double>(), 1.68, 1e-6);
  EXPECT_NEAR(doc["bounding_box_m"]["max"][0].get<double>(), 0.0029325, 1e-9);
  EXPECT_GT(doc["bounding_sphere_m"]["radius"].get<double>(), 0.004);
  EXPECT_EQ(doc["spectrum"]["tables"][0]["points"], 76);
  EXPECT_EQ(doc["text"]["equipment"], "Rigo 801");
  EXPECT_TRUE(doc["warnings"].empty());
}

TEST(CliRays, InfoJsonReportsNanHeaderAsNullAndTheFluxWarning) {
  const fs::path f = lumx_rays::real_file("Cyl10k.1.tm25ray");
  if (f.empty()) LUMX_SKIP_WITHOUT_SHARED("data/raysets");
  const CliRun j = run("info --json " + q(f), false);
  ASSERT_EQ(j.status, 0) << j.out;
  const auto doc = nlohmann::json::parse(j.out);
  EXPECT_EQ(doc["header_flux"], 1.0);
  EXPECT_NEAR(doc["flux_sum"].get<double>(), 10000, 1e-3);
  ASSERT_EQ(doc["warnings"].size(), 1u);
  EXPECT_EQ(doc["warnings"][0]["byte_offset"], 12);
  EXPECT_EQ(doc["warnings"][0]["field"], "total luminous flux (4.7.1.4)");
  const CliRun z = run("info --json " + q(lumx_rays::real_file("ZemaxText.txt")), false);
  ASSERT_EQ(z.status, 0) << z.out;
  EXPECT_TRUE(nlohmann::json::parse(z.out)["header_flux"].is_null());
}

TEST(CliRays, CheckReportsOkWarningsAndLocatedErrors) {
  const fs::path good = lumx_rays::real_file("rayfile_LERTDUW_S2WP_green_100k_20161013_IES_TM25.TM25RAY");
  if (good.empty()) LUMX_SKIP_WITHOUT_SHARED("data/raysets");
  const CliRun ok = run("check " + q(good));
  EXPECT_EQ(ok.status, 0);
  EXPECT_EQ(ok.out, good.string() + ": OK\n");

  const fs::path cyl = lumx_rays::real_file("Cyl10k.1.tm25ray");
  const CliRun w = run("check " + q(cyl));
  EXPECT_EQ(w.status, 0) << w.out;
  EXPECT_TRUE(has(w.out, cyl.string() + ":@12: warning: total luminous flux (4.7.1.4): ")) << w.out;
  EXPECT_TRUE(has(w.out, "OK (with 1 warning(s))")) << w.out;
  EXPECT_EQ(run("check --strict " + q(cyl)).status, 1);

  // A copy cut inside its rays: the ray count no longer fits the file.
  const fs::path d = lumx_rays::scratch("cli");
  const fs::path cut = d / "cut.tm25ray";
  const std::string bytes = lumx_rays::read_bytes(good);
  lumx_rays::write_bytes(cut, bytes.substr(0, bytes.size() - 10));
  const CliRun bad = run("check " + q(cut) + " " + q(good));
  EXPECT_EQ(bad.status, 1);
  EXPECT_TRUE(has(bad.out, cut.string() + ":@20: error: number of rays (4.7.1.6): 100000 rays of 7 columns"))
      << bad.out;
  EXPECT_TRUE(has(bad.out, good.string() + ": OK")) << bad.out;
  const CliRun info_bad = run("info " + q(cut));
  EXPECT_EQ(info_bad.status, 1);
  EXPECT_TRUE(has(info_bad.out, ":@20: error: number of rays")) << info_bad.out;

  const CliRun js = run("check --json " + q(cut), false);
  EXPECT_EQ(js.status, 1);
  const auto doc = nlohmann::json::parse(js.out);
  EXPECT_EQ(doc[0]["ok"], false);
  EXPECT_EQ(doc[0]["findings"][0]["byte_offset"], 20);
  fs::remove_all(d);
}

TEST(CliRays, PlainTextAndVendorFilesAndPhotometryStillWork) {
  const fs::path d = lumx_rays::scratch("cli_plain");
  const fs::path p = d / "two.rays";
  lumx_rays::write_bytes(p, "# lumx-rays length=m flux=lm total=3\n0 0 0 0 0 1 1\n1 0 0 0 0 -1 2\n");
  const CliRun r = run("info " + q(p));
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(has(r.out, "format:        plain text 1")) << r.out;
  EXPECT_TRUE(has(r.out, "rays sum to 3 lm; the header states 3 lm")) << r.out;
  EXPECT_TRUE(has(r.out, "bounding box:  x 0..1, y 0..0, z 0..0 m")) << r.out;
  EXPECT_EQ(run("check " + q(p)).out, p.string() + ": OK\n");
  // A broken plain-text file: located by line.
  lumx_rays::write_bytes(d / "bad.rays", "# lumx-rays length=m flux=lm\n0 0 0 0 0 0 1\n");
  const CliRun b = run("check " + q(d / "bad.rays"));
  EXPECT_EQ(b.status, 1);
  EXPECT_TRUE(has(b.out, "bad.rays:2: error: direction: ray 1: direction is the zero vector")) << b.out;
  const fs::path lt = lumx_rays::real_file("ThreeRays_Wavelength.1.txt");
  if (!lt.empty()) {
    const CliRun t = run("info " + q(lt), false);
    EXPECT_EQ(t.status, 0);
    EXPECT_TRUE(has(t.out, "wavelength per ray, 450..620 nm")) << t.out;
  }
  // Photometry keeps its own path.
  const fs::path ies = fs::path(LUMX_SOURCE_DIR) / "samples/downlight.ies";
  const CliRun i = run("info " + q(ies));
  EXPECT_EQ(i.status, 0);
  EXPECT_TRUE(has(i.out, "IES LM-63")) << i.out;
  EXPECT_EQ(run("check " + q(ies)).status, 0);
  fs::remove_all(d);
}
