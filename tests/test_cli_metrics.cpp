// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// `lumx info` carries the metrics (zonal lumens, CIE flux code, BUG, spacing criterion, luminance, UGR),
// and `lumx plot --kind` draws every diagram as finite, labelled SVG and PNG.
#include "cli_test_support.h"
#include "test_support.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace fs = std::filesystem;

namespace {

using lumx_test::CliRun;
CliRun run(const std::string& args) { return lumx_test::run_cli(args); }
std::string q(const fs::path& p) { return lumx_test::quoted(p); }

const fs::path kSample = fs::path(LUMX_TEST_DATA_DIR) / "../../samples/downlight.ies";

fs::path scratch(const std::string& test) {
  const fs::path d = fs::temp_directory_path() / ("lumx_cli_metrics_" + test + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

bool has_non_finite_text(const std::string& s) {
  for (const char* bad : {"nan", "NaN", "inf", "Inf"})
    if (s.find(bad) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST(CliMetrics, InfoJsonCarriesTheMetrics) {
  const CliRun r = lumx_test::run_cli("info " + q(kSample) + " --json", false);
  ASSERT_EQ(r.status, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const auto& m = j.at("metrics");
  EXPECT_EQ(m.at("zonal_lumens").at("summary").size(), 9u);
  EXPECT_NEAR(m.at("zonal_lumens").at("luminaire_lm").get<double>(), j.at("flux_lm").get<double>(), 1e-3 * j.at("flux_lm").get<double>());
  EXPECT_EQ(m.at("cie_flux_code").at("code").get<std::string>().size() >= 9, true);
  EXPECT_EQ(m.at("bug_rating").at("rating").get<std::string>().substr(0, 1), "B");
  EXPECT_GT(m.at("spacing_criterion").at("c0_c180").get<double>(), 0.3);
  EXPECT_GT(m.at("luminance_cd_m2").at("max").get<double>(), 0);
  const auto& u = m.at("ugr");
  ASSERT_EQ(u.at("crosswise").size(), 19u);
  ASSERT_EQ(u.at("endwise").size(), 19u);
  for (const auto& row : u.at("crosswise")) {
    ASSERT_EQ(row.size(), 5u);
    for (const auto& v : row) {
      ASSERT_TRUE(v.is_number()) << row;
      EXPECT_TRUE(std::isfinite(v.get<double>()));
    }
  }
  EXPECT_DOUBLE_EQ(u.at("spacing_to_height").get<double>(), 0.25);
}

TEST(CliMetrics, InfoTextSummarisesThem) {
  const CliRun r = run("info " + q(kSample));
  ASSERT_EQ(r.status, 0) << r.out;
  for (const char* line : {"zonal lumens:", "CIE flux code:", "BUG rating:", "spacing (SC):", "luminance:", "UGR 4Hx8H:"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;
}

TEST(CliMetrics, PointSourceHasNoUgrButInfoStillWorks) {
  const fs::path d = scratch("point");
  const fs::path f = d / "point.ies";
  std::ofstream(f) << "IESNA:LM-63-2002\n[TEST] point\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 10\n0 45 90\n0\n"
                      "100 80 0\n";
  const CliRun j = lumx_test::run_cli("info " + q(f) + " --json", false);
  ASSERT_EQ(j.status, 0) << j.out;
  const nlohmann::json m = nlohmann::json::parse(j.out).at("metrics");
  EXPECT_TRUE(m.at("ugr").is_null());
  EXPECT_NE(m.at("ugr_error").get<std::string>().find("luminous area"), std::string::npos);
  EXPECT_TRUE(m.at("cie_flux_code").is_object());
  const CliRun p = run("plot " + q(f) + " --kind ugr -o " + q(d / "u.svg"));
  EXPECT_EQ(p.status, 1);
  EXPECT_NE(p.out.find("point.ies"), std::string::npos) << p.out;
  EXPECT_NE(p.out.find("luminous area"), std::string::npos) << p.out;
  EXPECT_FALSE(fs::exists(d / "u.svg"));
}

TEST(CliMetrics, EveryKindDrawsFiniteLabelledSvgAndPng) {
  const fs::path d = scratch("kinds");
  struct Kind {
    const char* name;
    const char* args;
    std::vector<const char*> labels;
  };
  const Kind kinds[] = {
      {"polar", "", {}},
      {"isolux", "--height 2.5 --tilt 20", {" lx", "x (C0) / m", "E max"}},
      {"isocandela", "", {" cd", "C0", "peak"}},
      {"cone", "--distances 1 2 3", {"h / m", "E mean / lx"}},
      {"ugr", "", {"Viewed crosswise", "Viewed endwise", "Ceiling"}},
  };
  for (const Kind& k : kinds)
    for (const char* ext : {".svg", ".png"}) {
      const fs::path out = d / (std::string(k.name) + ext);
      const CliRun r = run("plot " + q(kSample) + " --kind " + k.name + " " + k.args + " -o " + q(out));
      ASSERT_EQ(r.status, 0) << k.name << ext << "\n" << r.out;
      ASSERT_TRUE(fs::exists(out)) << out;
      EXPECT_GT(fs::file_size(out), 2000u) << out;
      for (const char* l : k.labels) EXPECT_NE(r.out.find(l), std::string::npos) << k.name << ": " << l << "\n" << r.out;
      EXPECT_FALSE(has_non_finite_text(r.out)) << r.out;
      if (std::string(ext) == ".svg") {
        const std::string svg = lumx_test::read_text(out);
        EXPECT_NE(svg.find("<svg"), std::string::npos);
        EXPECT_FALSE(has_non_finite_text(svg)) << out;
      }
    }
  // The UGR image prints 190 values, each with one decimal.
  const CliRun u = run("plot " + q(kSample) + " --kind ugr -o " + q(d / "u2.svg"));
  std::size_t decimals = 0;
  for (std::size_t pos = u.out.find(" | "); pos != std::string::npos; pos = u.out.find(" | ", pos + 1))
    if (pos + 4 < u.out.size() && std::isdigit(static_cast<unsigned char>(u.out[pos + 3]))) ++decimals;
  EXPECT_EQ(decimals, 190u) << u.out;
}

TEST(CliMetrics, BadKindsAndOptionsAreRefused) {
  const fs::path d = scratch("bad");
  EXPECT_NE(run("plot " + q(kSample) + " --kind pie -o " + q(d / "x.svg")).status, 0);
  EXPECT_NE(run("plot " + q(kSample) + " --kind isolux --tilt 95 -o " + q(d / "x.svg")).status, 0);
  const CliRun ext = run("plot " + q(kSample) + " --kind cone -o " + q(d / "x.bmp"));
  EXPECT_EQ(ext.status, 1);
  EXPECT_NE(ext.out.find("x.bmp"), std::string::npos) << ext.out;
  EXPECT_FALSE(fs::exists(d / "x.bmp"));
}
