// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The lumx command-line tool as a user runs it: help, version, usage errors, and each subcommand on
// real files.
#include <gtest/gtest.h>
#include "cli_test_support.h"
#include <nlohmann/json.hpp>

#include "test_support.h"

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace fs = std::filesystem;

namespace {

using lumx_test::CliRun;
CliRun run(const std::string& args, bool stderr_too = true) { return lumx_test::run_cli(args, stderr_too); }

std::string q(const fs::path& p) { return lumx_test::quoted(p); }

/// A fresh folder per test (ctest runs tests in parallel processes).
fs::path scratch(const std::string& test) {
  const fs::path d = fs::temp_directory_path() / ("lumx_cli_" + test + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

const fs::path kSample = fs::path(LUMX_TEST_DATA_DIR) / "../../samples/downlight.ies";

}  // namespace

TEST(Cli, HelpAndVersion) {
  const CliRun h = run("--help");
  EXPECT_EQ(h.status, 0);
  for (const char* cmd : {"info", "check", "convert", "plot"}) EXPECT_NE(h.out.find(cmd), std::string::npos) << cmd;
  const CliRun c = run("convert --help");
  EXPECT_EQ(c.status, 0);
  EXPECT_NE(c.out.find("--rotate-c"), std::string::npos);
  const CliRun v = run("--version");
  EXPECT_EQ(v.status, 0);
  EXPECT_NE(v.out.find("0.1.0"), std::string::npos);
  EXPECT_NE(v.out.find("LM-63-2019"), std::string::npos);
  EXPECT_NE(v.out.find("EULUMDAT"), std::string::npos);
}

TEST(Cli, UsageErrorsGoToStderrWithNonZeroStatus) {
  const CliRun none = run("", false);
  EXPECT_NE(none.status, 0);
  EXPECT_TRUE(none.out.empty()) << "usage must go to stderr";
  const CliRun bad = run("info", false);
  EXPECT_NE(bad.status, 0);
  const CliRun unknown = run("frobnicate x", false);
  EXPECT_NE(unknown.status, 0);
}

/// An IES file with a junk line where the lamp line belongs (line 3), as some real files have.
fs::path junk_ies(const fs::path& dir) {
  const fs::path p = dir / "junk_line.ies";
  std::ofstream(p) << "IESNA:LM-63-2002\nTILT=NONE\nfile format error\n1 1000 1 3 1 1 2 0 0 0\n1 1 10\n0 45 90\n0\n100 50 0\n";
  return p;
}

TEST(Cli, MissingAndBadFiles) {
  const CliRun m = run("info /nonexistent/lumx.ies");
  EXPECT_EQ(m.status, 1);
  EXPECT_NE(m.out.find("/nonexistent/lumx.ies"), std::string::npos);
  const CliRun b = run("check " + q(junk_ies(scratch("bad"))));
  EXPECT_EQ(b.status, 1);
  EXPECT_NE(b.out.find("junk_line.ies:3: error: number of lamps:"), std::string::npos) << b.out;
}

TEST(Cli, InfoTextAndJson) {
  const CliRun t = run("info " + q(kSample));
  EXPECT_EQ(t.status, 0) << t.out;
  EXPECT_NE(t.out.find("quadrant"), std::string::npos);
  const CliRun j = run("info --json " + q(kSample), false);
  ASSERT_EQ(j.status, 0);
  const auto doc = nlohmann::json::parse(j.out);
  // The sample's analytic flux is 2125 lm (see samples/README.md); the 2.5 degree table integrates
  // within 0.2 % of it.
  EXPECT_NEAR(doc["flux_lm"].get<double>(), 2125.0, 0.002 * 2125.0);
  EXPECT_EQ(doc["symmetry"], "quadrant (C0-C180 and C90-C270)");
  EXPECT_GT(doc["c0_c180"]["beam_deg"].get<double>(), doc["c90_c270"]["beam_deg"].get<double>());
}

TEST(Cli, CheckClassifiesEveryRealFile) {
  const auto files = lumx_test::shared_photometry_files({".ies", ".ldt"});
  if (files.empty()) LUMX_SKIP_WITHOUT_SHARED("data/photometry");
  std::string args = "check --json";
  for (const auto& f : files) args += " " + q(f);
  const CliRun r = run(args, false);
  EXPECT_EQ(r.status, 1);  // one intentionally invalid file
  const auto doc = nlohmann::json::parse(r.out);
  ASSERT_EQ(doc.size(), files.size());
  std::size_t bad = 0;
  for (const auto& e : doc) {
    if (!e["ok"].get<bool>()) {
      ++bad;
      EXPECT_NE(e["file"].get<std::string>().find("test_file_format_error.ies"), std::string::npos) << e.dump();
    }
  }
  EXPECT_EQ(bad, 1u);
}

TEST(Cli, ConvertRoundTripAndPlot) {
  const fs::path d = scratch("convert");
  fs::remove(d / "s.ldt");
  ASSERT_EQ(run("convert " + q(kSample) + " " + q(d / "s.ldt")).status, 0);
  ASSERT_EQ(run("convert " + q(d / "s.ldt") + " " + q(d / "s.ies") + " --ies-version 2002").status, 0);
  EXPECT_EQ(lumx_test::read_text(d / "s.ies").rfind("IESNA:LM-63-2002", 0), 0u);
  const auto a = nlohmann::json::parse(run("info --json " + q(kSample), false).out);
  const auto b = nlohmann::json::parse(run("info --json " + q(d / "s.ies"), false).out);
  EXPECT_NEAR(a["flux_lm"].get<double>(), b["flux_lm"].get<double>(), 1e-6 * a["flux_lm"].get<double>());
  const CliRun c = run("check " + q(d / "s.ldt") + " " + q(d / "s.ies"));
  EXPECT_EQ(c.status, 0) << c.out;

  ASSERT_EQ(run("plot " + q(kSample) + " -o " + q(d / "p.png")).status, 0);
  const std::string png = lumx_test::read_text(d / "p.png");
  ASSERT_GT(png.size(), 1000u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  ASSERT_EQ(run("plot " + q(kSample) + " -o " + q(d / "p.svg")).status, 0);
  EXPECT_NE(lumx_test::read_text(d / "p.svg").find("<svg"), std::string::npos);
  EXPECT_NE(run("plot " + q(kSample) + " -o " + q(d / "p.bmp")).status, 0);
}

TEST(Cli, FailedConvertLeavesThePreviousFile) {
  const fs::path d = scratch("keep");
  const fs::path out = d / "keep.ies";
  ASSERT_EQ(run("convert " + q(kSample) + " " + q(out)).status, 0);
  const std::string before = lumx_test::read_text(out);
  const fs::path bad = junk_ies(scratch("keep_bad"));
  EXPECT_EQ(run("convert " + q(bad) + " " + q(out)).status, 1);
  EXPECT_EQ(lumx_test::read_text(out), before);
  for (const auto& e : fs::directory_iterator(d))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << "temporary file left: " << e.path();
}

TEST(Cli, ConvertOutputFormatFollowsTheExtension) {
  const fs::path d = scratch("extension");
  // TM-33: .xml and .json; --tm33-version 18 writes the TM-33-18 root.
  ASSERT_EQ(run("convert " + q(kSample) + " " + q(d / "s.xml")).status, 0);
  const std::string xml = lumx_test::read_text(d / "s.xml");
  EXPECT_EQ(xml.rfind("<?xml", 0), 0u);
  EXPECT_NE(xml.find("<IESTM33-22>"), std::string::npos);
  ASSERT_EQ(run("convert " + q(kSample) + " " + q(d / "s.json")).status, 0);
  EXPECT_TRUE(nlohmann::json::parse(lumx_test::read_text(d / "s.json")).contains("IESTM33-22"));
  ASSERT_EQ(run("convert " + q(kSample) + " " + q(d / "s18.xml") + " --tm33-version 18").status, 0);
  EXPECT_NE(lumx_test::read_text(d / "s18.xml").find("<IESTM33>"), std::string::npos);
  // TM-33 in, EULUMDAT out: the flux survives; info and check read TM-33.
  ASSERT_EQ(run("convert " + q(d / "s.json") + " " + q(d / "back.ldt")).status, 0);
  const auto a = nlohmann::json::parse(run("info --json " + q(kSample), false).out);
  const auto b = nlohmann::json::parse(run("info --json " + q(d / "back.ldt"), false).out);
  const auto c = nlohmann::json::parse(run("info --json " + q(d / "s.xml"), false).out);
  EXPECT_NEAR(b["flux_lm"].get<double>(), a["flux_lm"].get<double>(), 1e-6 * a["flux_lm"].get<double>());
  EXPECT_EQ(c["format"], "TM-33");
  EXPECT_EQ(c["flux_lm"].get<double>(), a["flux_lm"].get<double>());
  EXPECT_EQ(run("check " + q(d / "s.xml")).status, 0);
  // An unknown extension is an error, and nothing is written.
  const CliRun u = run("convert " + q(kSample) + " " + q(d / "y.txt"));
  EXPECT_EQ(u.status, 1);
  EXPECT_NE(u.out.find("unknown extension '.txt'"), std::string::npos) << u.out;
  EXPECT_FALSE(fs::exists(d / "y.txt"));
  // A bundle: .lumx, or any name with --bundle.
  ASSERT_EQ(run("convert " + q(kSample) + " " + q(d / "b.lumx")).status, 0);
  EXPECT_TRUE(fs::exists(d / "b.lumx" / "manifest.json"));
  ASSERT_EQ(run("convert " + q(kSample) + " " + q(d / "folder") + " --bundle").status, 0);
  EXPECT_TRUE(fs::exists(d / "folder" / "manifest.json"));
  // A bundle's far field to TM-33.
  ASSERT_EQ(run("convert " + q(d / "b.lumx") + " " + q(d / "far.xml")).status, 0);
  EXPECT_NE(lumx_test::read_text(d / "far.xml").find("<IntData"), std::string::npos);
}

TEST(Cli, GldfInfoCheckAndExtract) {
  const fs::path shared = lumx_test::shared_dir();
  if (shared.empty()) LUMX_SKIP_WITHOUT_SHARED("data/gldf");
  const fs::path gldf = shared / "data/gldf/containers/Trilux_Belviso_S_CDP.gldf";
  const fs::path xsd = shared / "data/gldf/xsd/gldf.xsd";
  const CliRun info = run("info " + q(gldf), false);
  ASSERT_EQ(info.status, 0) << info.out;
  EXPECT_NE(info.out.find("ldc/TX054020.ldt"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("variant:"), std::string::npos) << info.out;
  const auto j = nlohmann::json::parse(run("info --json " + q(gldf), false).out);
  EXPECT_EQ(j["format"], "GLDF");
  EXPECT_EQ(j["photometries"].size(), 2u);
  const CliRun check = run("check --xsd " + q(xsd) + " " + q(gldf), false);
  EXPECT_EQ(check.status, 0) << check.out;
  EXPECT_EQ(check.out, gldf.string() + ": OK\n");
  const fs::path d = scratch("gldf");
  const CliRun x = run("convert " + q(gldf) + " " + q(d / "out"));
  ASSERT_EQ(x.status, 0) << x.out;
  EXPECT_TRUE(fs::exists(d / "out" / "TX054020.ldt"));
  EXPECT_EQ(run("check " + q(d / "out" / "TX054019.ldt")).status, 0);
  const CliRun w = run("convert " + q(d / "out" / "TX054019.ldt") + " " + q(d / "x.gldf"));
  EXPECT_EQ(w.status, 1);
  EXPECT_NE(w.out.find("does not write them"), std::string::npos) << w.out;
}

TEST(Cli, JsonStaysValidWithNonUtf8Bytes) {
  // A Latin-1 byte inside a bad number: the finding quotes it, and the JSON must still parse.
  const fs::path d = scratch("json");
  std::ofstream(d / "bad.ies") << "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n5\xB0 1\n";
  const CliRun r = run("check --json " + q(d / "bad.ies"), false);
  EXPECT_EQ(r.status, 1);
  const auto doc = nlohmann::json::parse(r.out);
  ASSERT_EQ(doc.size(), 1u);
  EXPECT_FALSE(doc[0]["ok"].get<bool>());
  EXPECT_EQ(doc[0]["findings"][0]["line"], 7);
}

TEST(Cli, NonFiniteAnglesAreUsageErrors) {
  const fs::path d = scratch("nan");
  EXPECT_NE(run("convert " + q(kSample) + " " + q(d / "o.ies") + " --rotate-c nan", false).status, 0);
  EXPECT_NE(run("convert " + q(kSample) + " " + q(d / "o.ies") + " --apply-tilt inf", false).status, 0);
  EXPECT_FALSE(fs::exists(d / "o.ies"));
}

// ---- bundles ----

TEST(CliBundle, PhotometryToBundleAndBackKeepsTheFlux) {
  const fs::path d = scratch("bundle_roundtrip");
  const fs::path bundle = d / "downlight.lumx";
  const CliRun c = run("convert " + q(kSample) + " " + q(bundle) + " --map-resolution 128");
  ASSERT_EQ(c.status, 0) << c.out;
  EXPECT_TRUE(fs::exists(bundle / "manifest.json"));
  const CliRun info = run("info --json " + q(bundle), false);
  ASSERT_EQ(info.status, 0) << info.out;
  const auto j = nlohmann::json::parse(info.out);
  ASSERT_EQ(j["levels"].size(), 1u);
  EXPECT_EQ(j["levels"][0]["apls"], 1);
  EXPECT_EQ(j["levels"][0]["map_resolution"], 128);
  const double bundle_flux = j["levels"][0]["flux_lm"];
  EXPECT_EQ(run("check " + q(bundle)).out, bundle.string() + ": OK\n");
  // Back to IES: the far field of the one APL carries the file's flux (within 0.5 %).
  const fs::path ies = d / "back.ies";
  ASSERT_EQ(run("convert " + q(bundle) + " " + q(ies)).status, 0);
  const auto a = nlohmann::json::parse(run("info --json " + q(kSample), false).out);
  const auto b = nlohmann::json::parse(run("info --json " + q(ies), false).out);
  const double fa = a["flux_lm"], fb = b["flux_lm"];
  EXPECT_NEAR(fb, fa, 0.005 * fa);
  EXPECT_NEAR(bundle_flux, fa, 1e-4 * fa);
  EXPECT_NEAR(double(b["max_cd"]), double(a["max_cd"]), 0.03 * double(a["max_cd"]));
}

TEST(CliBundle, CheckReportsALocatedFindingAndFails) {
  const fs::path d = scratch("bundle_check");
  const fs::path bundle = d / "b.lumx";
  ASSERT_EQ(run("convert " + q(kSample) + " " + q(bundle)).status, 0);
  const auto m = nlohmann::json::parse(lumx_test::read_text(bundle / "manifest.json"));
  const fs::path payload = bundle / std::string(m["levels"][0]["maps"][1]["file"]);
  std::string bytes = lumx_test::read_text(payload);
  bytes[bytes.size() - 7] ^= 1;
  std::ofstream(payload, std::ios::binary | std::ios::trunc) << bytes;
  const CliRun c = run("check " + q(bundle));
  EXPECT_EQ(c.status, 1);
  EXPECT_NE(c.out.find(payload.string()), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("/levels/0/maps/1/sha256"), std::string::npos) << c.out;
  const CliRun info = run("info " + q(d / "nothing.lumx"));
  EXPECT_EQ(info.status, 1);
}

TEST(CliBundle, PlotsMapsAndPositions) {
  const fs::path d = scratch("bundle_plot");
  const fs::path bundle = d / "b.lumx";
  ASSERT_EQ(run("convert " + q(kSample) + " " + q(bundle)).status, 0);
  for (const char* name : {"map.png", "map.svg"}) {
    const CliRun p = run("plot " + q(bundle) + " --apl 0 -o " + q(d / name));
    EXPECT_EQ(p.status, 0) << p.out;
    EXPECT_GT(fs::file_size(d / name), 1000u) << name;
  }
  const CliRun p = run("plot " + q(bundle) + " --level 0 -o " + q(d / "apls.svg"));
  EXPECT_EQ(p.status, 0) << p.out;
  EXPECT_NE(lumx_test::read_text(d / "apls.svg").find("<svg"), std::string::npos);
  EXPECT_EQ(run("plot " + q(bundle) + " --apl 5 -o " + q(d / "x.png")).status, 1);
  EXPECT_EQ(run("plot " + q(bundle) + " --level 3 -o " + q(d / "x.png")).status, 1);
  EXPECT_FALSE(fs::exists(d / "x.png"));
}
