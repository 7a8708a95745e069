// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// IES LM-63 reading and writing on real files and on synthetic files for what no real file covers.
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/metrics.h>
#include <lumx/photometry/resample.h>
#include <lumx/photometry/validate.h>

#include <gtest/gtest.h>

#include "test_support.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <unistd.h>

using namespace lumx;
namespace fs = std::filesystem;

namespace {

std::vector<fs::path> all_ies_files() { return lumx_test::shared_photometry_files({".ies"}); }

bool is_intentionally_invalid(const fs::path& p) { return p.filename() == "test_file_format_error.ies"; }

/// Candela values equal to `digits` significant digits (what the writer promises).
void expect_same_table(const Photometry& a, const Photometry& b, double rel, const std::string& what) {
  ASSERT_EQ(a.type, b.type) << what;
  ASSERT_EQ(a.symmetry, b.symmetry) << what;
  ASSERT_EQ(a.vertical_deg, b.vertical_deg) << what;
  ASSERT_EQ(a.horizontal_deg.size(), b.horizontal_deg.size()) << what;
  for (std::size_t i = 0; i < a.horizontal_deg.size(); ++i)
    EXPECT_NEAR(a.horizontal_deg[i], b.horizontal_deg[i], 1e-9) << what;
  ASSERT_EQ(a.candela.size(), b.candela.size()) << what;
  for (std::size_t i = 0; i < a.candela.size(); ++i)
    ASSERT_NEAR(a.candela[i], b.candela[i], rel * std::abs(a.candela[i]) + 1e-12) << what << " value " << i;
}

const char* kMinimal2002 =
    "IESNA:LM-63-2002\n[TEST] T1\n[TESTLAB] L\n[ISSUEDATE] 2026\n[MANUFAC] M\nTILT=NONE\n"
    "1 1000 1 5 3 1 2 0.1 0.2 0\n1 1 10\n0 22.5 45 67.5 90\n0 45 90\n"
    "100 90 70 40 0\n100 85 60 30 0\n100 80 50 20 0\n";

}  // namespace

TEST(IesRead, EveryRealFileReads) {
  if (lumx_test::shared_dir().empty()) LUMX_SKIP_WITHOUT_SHARED("data/photometry");
  const auto files = all_ies_files();
  ASSERT_GE(files.size(), 5u);
  std::size_t read = 0;
  for (const auto& f : files) {
    if (is_intentionally_invalid(f)) {
      try {
        read_photometry(f.string());
        ADD_FAILURE() << f << " should be refused";
      } catch (const Error& e) {
        // The junk line "file format error" right after TILT=NONE (line 3).
        EXPECT_EQ(e.diagnostic().line, 3);
        EXPECT_EQ(e.diagnostic().field, "number of lamps");
      }
      continue;
    }
    SCOPED_TRACE(f.string());
    const Photometry p = read_photometry(f.string());
    const double flux = IntensityTable(p).flux_lm();
    EXPECT_TRUE(std::isfinite(flux) && flux > 0) << flux;
    for (const auto& d : validate(p)) EXPECT_NE(d.severity, Severity::error) << d.str();
    ++read;
  }
  EXPECT_GE(read, files.size() - 1);
}

TEST(IesRead, FluxMatchesStatedLumensOnRealFiles) {
  // These manufacturers state lamp lumens equal to the luminaire flux (LOR 100 %): the zonal integral
  // of their tables must reproduce it to the tables' own precision (0.1 %).
  const auto root = lumx_test::shared_dir();
  if (root.empty()) LUMX_SKIP_WITHOUT_SHARED("data/photometry");
  const fs::path dir = root / "data/photometry/holg+eulumdat-rs";
  for (const char* name : {"S01.01.02.354_MAXWELL-8-T4 LUXEON 5050 Square with glass-MEASURED_CIE.IES",
                           "S01.01.02.354_MAXWELL-8-T4 LUXEON 5050 Square with glass-MEASURED_IESNA.ies",
                           "OutdoorRoadway IES OS 8988-2022 03 AM01 60W 4000K.ies"}) {
    const Photometry p = read_photometry((dir / name).string());
    const PhotometricSummary s = summarize(p);
    EXPECT_NEAR(s.flux_lm, s.rated_lamp_flux_lm, 1e-3 * s.rated_lamp_flux_lm) << name;
  }
}

TEST(IesRead, OrientationOfTwinFilesIsAQuarterTurn) {
  // The same luminaire exported with the "CIE" and the "IESNA" C0 orientation: rotating the IESNA
  // file's C-planes by +90 degrees reproduces the CIE file exactly (the --rotate-c option).
  const auto root = lumx_test::shared_dir();
  if (root.empty()) LUMX_SKIP_WITHOUT_SHARED("data/photometry");
  const fs::path dir = root / "data/photometry/holg+eulumdat-rs";
  const Photometry cie = read_photometry((dir / "S01.01.02.354_MAXWELL-8-T4 LUXEON 5050 Square with glass-MEASURED_CIE.IES").string());
  const Photometry iesna = read_photometry((dir / "S01.01.02.354_MAXWELL-8-T4 LUXEON 5050 Square with glass-MEASURED_IESNA.ies").string());
  const IntensityTable a(cie), b(rotate_c_planes(iesna, 90)), unrotated(iesna);
  double max_diff = 0, max_diff_unrotated = 0;
  for (double c = 0; c < 360; c += 5)
    for (double g = 0; g <= 90; g += 1) {
      max_diff = std::max(max_diff, std::abs(a.at_angles(c, g) - b.at_angles(c, g)));
      max_diff_unrotated = std::max(max_diff_unrotated, std::abs(a.at_angles(c, g) - unrotated.at_angles(c, g)));
    }
  EXPECT_EQ(max_diff, 0.0);
  EXPECT_GT(max_diff_unrotated, 0.5 * a.max_cd());
}

TEST(IesWrite, RoundTripReproducesTheModel) {
  if (lumx_test::shared_dir().empty()) LUMX_SKIP_WITHOUT_SHARED("data/photometry");
  for (const auto& f : all_ies_files()) {
    if (is_intentionally_invalid(f)) continue;
    const Photometry p = read_photometry(f.string());
    for (IesVersion v : {IesVersion::lm63_2019, IesVersion::lm63_2002}) {
      IesWriteOptions o;
      o.version = v;
      const std::string text = format_ies(p, o);
      const Photometry q = read_ies(text, "roundtrip.ies");
      // 7 significant digits: relative rounding error at most 5e-7.
      expect_same_table(p, q, 5e-7, f.string());
      EXPECT_NEAR(IntensityTable(q).flux_lm(), IntensityTable(p).flux_lm(), 1e-6 * IntensityTable(p).flux_lm());
      EXPECT_EQ(q.absolute, p.absolute);
      EXPECT_NEAR(q.rated_lamp_flux_lm(), p.rated_lamp_flux_lm(), 1e-6 * p.rated_lamp_flux_lm());
      EXPECT_NEAR(q.opening.width_m, p.opening.width_m, 1e-6);
      EXPECT_NEAR(q.opening.length_m, p.opening.length_m, 1e-6);
      EXPECT_NEAR(q.opening.height_m, p.opening.height_m, 1e-6);
      EXPECT_EQ(q.source.version, v == IesVersion::lm63_2019 ? file_format::kIes2019 : file_format::kIes2002);
    }
  }
}

TEST(IesWrite, VersionLineHasNoSpaceAndWriterOutputIsValid) {
  const Photometry p = read_ies(kMinimal2002, "min.ies");
  IesWriteOptions o;
  o.version = IesVersion::lm63_2002;
  const std::string t2002 = format_ies(p, o);
  EXPECT_EQ(t2002.rfind("IESNA:LM-63-2002\r\n", 0), 0u);
  const std::string t2019 = format_ies(p);
  EXPECT_EQ(t2019.rfind("IES:LM-63-2019\r\n", 0), 0u);
  for (const std::string& t : {t2002, t2019}) {
    DiagnosticList w;
    ReadOptions ro;
    ro.warnings = w.sink();
    const Photometry q = read_ies(t, "written.ies", ro);
    EXPECT_TRUE(w.items.empty()) << w.items.front().str();
    for (const auto& d : validate(q)) EXPECT_NE(d.severity, Severity::error) << d.str();
  }
}

TEST(IesRead, Lm63_2019FileGenerationTypeIsNeverAMultiplier) {
  std::string text = kMinimal2002;
  text.replace(0, std::string("IESNA:LM-63-2002").size(), "IES:LM-63-2019");
  text.replace(text.find("1 1 10\n"), 7, "1 1.10000 10\n");  // accredited lab
  const Photometry p = read_ies(text, "gen.ies");
  EXPECT_EQ(p.source.version, file_format::kIes2019);
  EXPECT_DOUBLE_EQ(p.ies_second_factor, 1.1);
  EXPECT_DOUBLE_EQ(p.at(0, 0), 100.0);  // not 110
  // Written back as 2019, the generation type survives.
  const Photometry q = read_ies(format_ies(p), "gen2.ies");
  EXPECT_NEAR(q.ies_second_factor, 1.1, 1e-12);
}

TEST(IesRead, TiltIncludeIsReadAppliedAndWritten) {
  std::string text = kMinimal2002;
  text.replace(text.find("TILT=NONE"), 9, "TILT=INCLUDE\n1\n3\n0 45 90\n1.0 0.9 0.5");
  const Photometry p = read_ies(text, "tilt.ies");
  ASSERT_TRUE(p.tilt.has_value());
  EXPECT_EQ(p.tilt->lamp_geometry, 1);
  EXPECT_EQ(p.tilt->angles_deg, (std::vector<double>{0, 45, 90}));
  EXPECT_DOUBLE_EQ(p.tilt->multiplier_at(67.5), 0.7);  // halfway between 0.9 and 0.5
  const Photometry tilted = apply_tilt(p, 67.5);
  EXPECT_DOUBLE_EQ(tilted.at(1, 1), 0.7 * p.at(1, 1));
  const Photometry q = read_ies(format_ies(p), "tilt2.ies");
  ASSERT_TRUE(q.tilt.has_value());
  EXPECT_EQ(q.tilt->multipliers, p.tilt->multipliers);
}

TEST(IesRead, ExternalTiltFileOnlyFromTheSameFolder) {
  const fs::path dir = fs::temp_directory_path() / ("lumx_tilt_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "sub");
  std::string text = kMinimal2002;
  text.replace(text.find("TILT=NONE"), 9, "TILT=lamp.tlt");
  std::ofstream(dir / "lum.ies") << text;
  std::ofstream(dir / "lamp.tlt") << "2\n2\n0 90\n1 0.8\n";
  const Photometry p = read_photometry((dir / "lum.ies").string());
  ASSERT_TRUE(p.tilt.has_value());
  EXPECT_EQ(p.tilt->source, "lamp.tlt");
  EXPECT_EQ(p.tilt->lamp_geometry, 2);
  EXPECT_DOUBLE_EQ(p.tilt->multiplier_at(45), 0.9);
  // Reading from memory has no folder to resolve it in.
  EXPECT_THROW(read_ies(text, "mem.ies"), Error);
  // Escaping the folder is refused even if the file exists there.
  std::ofstream(dir / "sub" / "esc.ies") << std::string(kMinimal2002).replace(std::string(kMinimal2002).find("TILT=NONE"), 9, "TILT=../lamp.tlt");
  try {
    read_photometry((dir / "sub" / "esc.ies").string());
    ADD_FAILURE() << "traversal accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.diagnostic().field, "TILT");
    EXPECT_EQ(e.diagnostic().line, 6);
  }
  fs::remove_all(dir);
}

TEST(IesRead, DelimitersLineEndingsAndEncodings) {
  const Photometry ref = read_ies(kMinimal2002, "ref.ies");
  // Commas and tabs as delimiters, CR-only line ends, a BOM, Latin-1 in a keyword, no final newline.
  std::string t = kMinimal2002;
  for (std::size_t pos = t.find("TILT"); (pos = t.find(' ', pos)) != std::string::npos;) t[pos] = ',';
  const Photometry commas = read_ies(t, "commas.ies");
  expect_same_table(ref, commas, 0, "commas");
  std::string tabs = kMinimal2002;
  for (std::size_t pos = tabs.find("TILT"); (pos = tabs.find(' ', pos)) != std::string::npos;) tabs[pos] = '\t';
  expect_same_table(ref, read_ies(tabs, "tabs.ies"), 0, "tabs");
  std::string cr = "\xEF\xBB\xBF" + std::string(kMinimal2002);
  for (char& c : cr)
    if (c == '\n') c = '\r';
  cr.pop_back();
  cr.replace(cr.find("[MANUFAC] M"), 11, "[MANUFAC] M\xB0");  // a Latin-1 degree sign
  const Photometry q = read_ies(cr, "cr.ies");
  expect_same_table(ref, q, 0, "cr+bom");
  ASSERT_NE(q.find_keyword("MANUFAC"), nullptr);
  EXPECT_EQ(q.find_keyword("MANUFAC")->value, "M\xC2\xB0");  // decoded to UTF-8
  // Keywords keep order and [MORE] continuations.
  std::string more = kMinimal2002;
  more.replace(more.find("[MANUFAC] M\n"), 12, "[MANUFAC] M\n[MORE] second line\n[_USER] x\n");
  const Photometry m = read_ies(more, "more.ies");
  EXPECT_EQ(m.find_keyword("MANUFAC")->value, "M\nsecond line");
  EXPECT_EQ(m.keywords.back().name, "_USER");
}

TEST(IesRead, Lm63_1986WithoutVersionLine) {
  std::string t = kMinimal2002;
  t.replace(0, t.find("TILT"), "REPORT NUMBER: 17   DATE: 01-02-1986\nSOME LUMINAIRE, TILT-FREE\n");
  const Photometry p = read_ies(t, "old.ies");
  EXPECT_EQ(p.source.version, file_format::kIes1986);
  ASSERT_EQ(p.keywords.size(), 2u);
  EXPECT_EQ(p.keywords[1].value, "SOME LUMINAIRE, TILT-FREE");
  EXPECT_EQ(p.num_horizontal(), 3u);
}

TEST(IesRead, TypeAAndTypeBRoundTripThroughTypeC) {
  // A Type B floodlight sampled on H, V = -90..90 by 10 degrees; Type A likewise.
  for (PhotometricType type : {PhotometricType::B, PhotometricType::A}) {
    std::string t = "IESNA:LM-63-2002\n[TEST] T\n[TESTLAB] L\n[ISSUEDATE] D\n[MANUFAC] M\nTILT=NONE\n1 -1 1 19 19 " +
                    std::to_string(static_cast<int>(type)) + " 2 0 0 0\n1 1 100\n";
    for (int i = 0; i < 19; ++i) t += std::to_string(-90 + 10 * i) + " ";
    t += "\n";
    for (int i = 0; i < 19; ++i) t += std::to_string(-90 + 10 * i) + " ";
    t += "\n";
    for (int h = -90; h <= 90; h += 10) {
      for (int v = -90; v <= 90; v += 10)
        t += std::to_string(1000.0 * std::pow(std::cos(h * kDegToRad) * std::cos(v * kDegToRad), 4) +
                            5.0 * (h + 90) / 180.0) + " ";
      t += "\n";
    }
    const Photometry p = read_ies(t, "ab.ies");
    EXPECT_EQ(p.type, type);
    EXPECT_EQ(p.symmetry, Symmetry::none);
    const IntensityTable tp(p);
    // Photometric zero of A/B is nadir.
    EXPECT_NEAR(tp.intensity({0, 0, -1}), p.at(9, 9), 1e-9);
    const Photometry c = to_type_c(p, 0.5, 0.5);
    EXPECT_EQ(c.type, PhotometricType::C);
    // The type-C grid samples the A/B interpolant; re-interpolating it adds O(h^2) error with
    // h = 0.5 degree against the source's 10 degree cells: bound it by 1 % of the peak here, and flux
    // by 0.5 %.
    const IntensityTable tc(c);
    EXPECT_NEAR(tc.flux_lm(), tp.flux_lm(), 5e-3 * tp.flux_lm());
    const Photometry back = resample(c, type, p.horizontal_deg, p.vertical_deg);
    for (std::size_t i = 0; i < p.candela.size(); ++i)
      EXPECT_NEAR(back.candela[i], p.candela[i], 0.01 * tp.max_cd()) << "value " << i;
  }
}

TEST(IesRead, RealTypeBFloodlightConvertsToTypeC) {
  const auto root = lumx_test::shared_dir();
  if (root.empty()) LUMX_SKIP_WITHOUT_SHARED("data/photometry");
  for (const char* name : {"flood_2.1.IES", "flood_2.2.ies"}) {
    const Photometry p = read_photometry((root / "data/photometry/echowuzangye+CU-calculations-based-on-IES-file" / name).string());
    ASSERT_EQ(p.type, PhotometricType::B);
    const IntensityTable tb(p);
    const Photometry c = to_type_c(p, 0.5, 0.5);
    EXPECT_NEAR(IntensityTable(c).flux_lm(), tb.flux_lm(), 5e-3 * tb.flux_lm()) << name;
    // Converting to EULUMDAT goes through Type C; LDT -> IES comes back with the same flux.
    const Photometry l = read_ldt(format_ldt(c), "flood.ldt");
    EXPECT_NEAR(IntensityTable(l).flux_lm(), IntensityTable(c).flux_lm(), 1e-5 * tb.flux_lm()) << name;
  }
}

TEST(IesRead, LuminousOpeningShapes) {
  struct Case {
    double w, l, h;
    LuminousShape s;
  };
  const Case cases[] = {{0, 0, 0, LuminousShape::point},
                        {0.2, 0.5, 0, LuminousShape::rectangle},
                        {0.2, 0.5, 0.1, LuminousShape::rectangle_with_luminous_sides},
                        {-0.3, -0.3, 0, LuminousShape::circle},
                        {-0.3, -0.4, 0, LuminousShape::ellipse},
                        {-0.3, -0.3, 0.2, LuminousShape::vertical_cylinder},
                        {-0.1, -0.1, -0.1, LuminousShape::sphere},
                        {-0.1, 0.6, -0.1, LuminousShape::horizontal_cylinder_along_length},
                        {0.6, -0.1, -0.1, LuminousShape::horizontal_cylinder_along_width},
                        {-0.2, 0, -0.2, LuminousShape::vertical_circle}};
  for (const Case& c : cases) {
    std::string t = kMinimal2002;
    char dims[64];
    std::snprintf(dims, sizeof dims, "%g %g %g", c.w, c.l, c.h);
    t.replace(t.find("0.1 0.2 0"), 9, dims);
    EXPECT_EQ(read_ies(t, "shape.ies").opening.shape(), c.s) << dims;
  }
  // Feet are converted to metres.
  std::string ft = kMinimal2002;
  ft.replace(ft.find("1 2 0.1 0.2 0"), 13, "1 1 1 2 0");
  const Photometry p = read_ies(ft, "ft.ies");
  EXPECT_DOUBLE_EQ(p.opening.width_m, 0.3048);
  EXPECT_DOUBLE_EQ(p.opening.length_m, 0.6096);
}

TEST(IesWrite, C90C270SymmetryKeptOrExpanded) {
  // LM-63-1995 range 90..270 kept by default (exact model round trip); expanded to 0..360 on request,
  // for readers that mishandle it. Both describe the same distribution.
  const fs::path file = lumx_test::shared_photometry("dlippok+photometric-viewer/symmetry_to_c90c270.ldt");
  if (file.empty()) LUMX_SKIP_WITHOUT_SHARED("data/photometry");
  const Photometry p = read_photometry(file.string());
  ASSERT_EQ(p.symmetry, Symmetry::plane_c90_c270);
  const Photometry kept = read_ies(format_ies(p), "kept.ies");
  EXPECT_EQ(kept.symmetry, Symmetry::plane_c90_c270);
  EXPECT_EQ(kept.horizontal_deg.front(), 90.0);
  IesWriteOptions o;
  o.expand_c90_c270 = true;
  const Photometry full = read_ies(format_ies(p, o), "full.ies");
  EXPECT_EQ(full.symmetry, Symmetry::none);
  EXPECT_EQ(full.horizontal_deg.front(), 0.0);
  EXPECT_EQ(full.horizontal_deg.back(), 360.0);
  const IntensityTable a(p), b(full);
  for (double c = 0; c < 360; c += 10)
    for (double g = 0; g <= 180; g += 5) EXPECT_NEAR(b.at_angles(c, g), a.at_angles(c, g), 1e-6 * a.max_cd());
}

TEST(IesWrite, RefusesTablesItCannotStateCorrectly) {
  Photometry p = read_ies(kMinimal2002, "min.ies");
  p.horizontal_deg[1] = std::nan("");
  EXPECT_THROW(format_ies(p), Error);
  p = read_ies(kMinimal2002, "min.ies");
  p.symmetry = Symmetry::plane_c0_c180;  // but planes 0..90 are stored: would be read back as quadrant
  EXPECT_THROW(format_ies(p), Error);
  p = read_ies(kMinimal2002, "min.ies");
  EXPECT_THROW(rotate_c_planes(p, std::nan("")), std::invalid_argument);
}
