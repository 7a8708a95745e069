// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Bad and awkward IES LM-63 input: hard-cases.md §6 items 1-10, written from the contract
// (include/lumx/io/photometry_io.h, formats.md §1) without reference to the reader's source.
//
// Expected behaviour per class: E = lumx::Error located by file (the name passed), line (> 0, and the
// specific line where the class names one) and a non-empty field; W = loads and a warning reaches
// ReadOptions::warnings; X = exact values. The corpus lives in tests/data/bad (make_corpus.py there
// regenerates it); each file is named after its class.
#include "bad_input_support.h"

#include <lumx/photometry/intensity_table.h>
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/photometric_frame.h>
#include <lumx/photometry/photometry.h>
#include <lumx/photometry/resample.h>
#include <lumx/photometry/symmetry.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;
using lumx::Photometry;
using lumx::Symmetry;
using namespace lumx_bad;

namespace {

const std::vector<double> kBaseH = {0, 90, 180, 270, 360};
const std::vector<double> kBaseV = {0, 30, 60, 90};
const std::vector<double> kBaseCd = {500, 400, 200, 0,   //
                                     500, 350, 150, 0,   //
                                     500, 300, 100, 0,   //
                                     500, 350, 150, 0,   //
                                     500, 400, 200, 0};

/// The table every delimiter/encoding variant of ies_valid_2002_typec.ies holds (X).
void expect_base_table(const Photometry& p) {
  EXPECT_EQ(p.type, lumx::PhotometricType::C);
  EXPECT_EQ(p.symmetry, Symmetry::none);
  EXPECT_EQ(p.horizontal_deg, kBaseH);
  EXPECT_EQ(p.vertical_deg, kBaseV);
  EXPECT_EQ(p.candela, kBaseCd);
  EXPECT_FALSE(p.absolute);
  ASSERT_EQ(p.lamp_sets.size(), 1u);
  EXPECT_EQ(p.lamp_sets[0].count, 1);
  EXPECT_DOUBLE_EQ(p.rated_lamp_flux_lm(), 1000.0);
  EXPECT_DOUBLE_EQ(p.input_watts, 25.0);
}

Photometry read_corpus(const std::string& name, const lumx::ReadOptions& o = {}) {
  return lumx::read_ies(corpus(name), name, o);
}

/// Reads a corpus file expecting E located on one of `lines` (any line > 0 if empty).
std::optional<lumx::Diagnostic> expect_ies_error(const std::string& name, const std::vector<int>& lines,
                                                 const lumx::ReadOptions& o = {}) {
  SCOPED_TRACE(name);
  const std::string text = corpus(name);
  auto d = catch_error([&] { (void)lumx::read_ies(text, name, o); });
  expect_located(d, name, lines);
  return d;
}

/// The base file with the numbers after TILT=NONE replaced by `numbers`.
std::string base_with_numbers(const std::string& numbers) {
  return "IESNA:LM-63-2002\n[TEST] X\n[TESTLAB] X\n[ISSUEDATE] X\n[MANUFAC] X\nTILT=NONE\n" + numbers;
}

struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("lumx_bad_input_" + std::to_string(::getpid()) + "_" +
                                        std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::permissions(path, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(path, ec);
  }
};

void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream f(p, std::ios::binary);
  f << bytes;
}

}  // namespace

// ---- sanity: the valid seed loads exactly --------------------------------------------------------------

TEST(BadInputIes, ValidSeedLoadsExactly) {
  lumx::DiagnosticList w;
  const Photometry p = read_corpus("ies_valid_2002_typec.ies", collecting(w));
  expect_base_table(p);
  EXPECT_EQ(p.source.file, "ies_valid_2002_typec.ies");
  EXPECT_EQ(count_warnings(w), 0u) << dump(w);
}

// ---- item 1: counts of -1, 0, 2^31-1, and counts the file cannot hold ---------------------------------

TEST(BadInputIes, AngleCountsNegativeZeroOrHugeAreLocatedErrors) {
  for (const char* name : {"ies_count_vertical_negative.ies", "ies_count_vertical_zero.ies",
                           "ies_count_horizontal_negative.ies", "ies_count_horizontal_zero.ies",
                           "ies_count_huge.ies", "ies_count_horizontal_huge.ies"}) {
    const std::string text = corpus(name);
    const int count_line = line_of(text, "1 1000 1 ");  // the line holding both counts
    const auto t0 = std::chrono::steady_clock::now();
    expect_ies_error(name, {count_line});
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LT(s, 1.0) << name << ": a count must be rejected before anything is sized from it";
  }
}

TEST(BadInputIes, CountsTheFileCannotHoldAreRejectedQuickly) {
  // 3000 x 3000 is inside ReadLimits::max_angles per axis, but 9 million values cannot be in 400 bytes.
  // The error belongs on the count line, or where the data runs out.
  const std::string name = "ies_count_exceeds_data.ies";
  const std::string text = corpus(name);
  const int last = last_content_line(text);
  const auto t0 = std::chrono::steady_clock::now();
  expect_ies_error(name, {line_of(text, "1 1000 1 3000"), last, last + 1});
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
}

TEST(BadInputIes, CountAboveReadLimitIsRejected) {
  lumx::ReadOptions o;
  o.limits.max_angles = 3;  // the base file has 4 vertical and 5 horizontal angles
  const std::string name = "ies_valid_2002_typec.ies";
  expect_ies_error(name, {line_of(corpus(name), "1 1000 1 4 5")}, o);
}

TEST(BadInputIes, FileLargerThanLimitIsRejected) {
  lumx::ReadOptions o;
  o.limits.max_file_bytes = 100;  // the file has ~250 bytes
  const std::string path = (bad_dir() / "ies_valid_2002_typec.ies").string();
  auto d = catch_error([&] { (void)lumx::read_photometry(path, o); });
  if (d) {
    EXPECT_EQ(d->file, path);
  }
}

// ---- item 2: truncation -----------------------------------------------------------------------------

TEST(BadInputIes, TruncatedCandelaBlockNamesTheLine) {
  for (const char* name : {"ies_truncated_candela.ies", "ies_truncated_candela_no_newline.ies"}) {
    const std::string text = corpus(name);
    const int last = last_content_line(text);  // the line where the data stops ("500 350")
    // The missing value is after the last one present: on that line, or the (empty) line after it.
    expect_ies_error(name, {last, last + 1});
  }
}

TEST(BadInputIes, CompleteFileWithoutFinalNewlineLoads) {
  const std::string text = corpus("ies_complete_no_final_newline.ies");
  ASSERT_NE(text.back(), '\n');
  expect_base_table(read_corpus("ies_complete_no_final_newline.ies"));
}

TEST(BadInputIes, FileTwoValuesShortIsAnError) {
  // The base file cut after "...500 400" of its last plane: two candela values are missing.
  std::string text = corpus("ies_valid_2002_typec.ies");
  text.resize(text.size() - std::string(" 200 0\n").size());
  auto d = catch_error([&] { (void)lumx::read_ies(text, "cut.ies"); });
  expect_located(d, "cut.ies", {last_content_line(text), last_content_line(text) + 1});
}

// ---- item 3: decreasing or repeated angles ----------------------------------------------------------

TEST(BadInputIes, DecreasingOrRepeatedAnglesAreErrors) {
  struct Case {
    const char* name;
    const char* angles_line;
  };
  for (const Case& c : {Case{"ies_vertical_decreasing.ies", "0 60 30 90"}, Case{"ies_vertical_repeated.ies", "0 30 30 90"},
                        Case{"ies_horizontal_decreasing.ies", "0 180 90 270 360"},
                        Case{"ies_horizontal_repeated.ies", "0 90 90 270 360"}}) {
    expect_ies_error(c.name, {line_of(corpus(c.name), c.angles_line)});
  }
}

// ---- item 4: nan / inf, negative candela ------------------------------------------------------------

TEST(BadInputIes, NanOrInfAnywhereIsAnError) {
  struct Case {
    const char* name;
    const char* token_line;
  };
  for (const Case& c : {Case{"ies_candela_nan.ies", "500 nan"}, Case{"ies_candela_inf.ies", "500 inf"},
                        Case{"ies_angle_nan.ies", "0 30 nan 90"}, Case{"ies_multiplier_inf.ies", "1 1000 inf"}}) {
    expect_ies_error(c.name, {line_of(corpus(c.name), c.token_line)});
  }
}

TEST(BadInputIes, CandelaOverflowingToInfIsAnError) {
  // Each value is finite as written, but value x multiplier is not: the model holds absolute cd, so
  // inf would enter it. Located at the multiplier or at the overflowing value.
  {
    const std::string name = "ies_multiplier_overflow.ies";  // multiplier 1e308, values up to 500
    const std::string text = corpus(name);
    expect_ies_error(name, {line_of(text, "1e308"), line_of(text, "500 400 200 0")});
  }
  {
    const std::string name = "ies_candela_overflow.ies";  // multiplier 10, one value 1e308
    const std::string text = corpus(name);
    expect_ies_error(name, {line_of(text, "1 1000 10 "), line_of(text, "1e308")});
  }
}

TEST(BadInputIes, SmallNegativeCandelaIsNoiseAndWarns) {
  lumx::DiagnosticList w;
  const Photometry p = read_corpus("ies_candela_negative_noise.ies", collecting(w));
  EXPECT_GE(count_warnings(w), 1u) << "a negative value within 1e-3 x peak must be reported";
  for (const auto& d : w.items) EXPECT_EQ(d.file, "ies_candela_negative_noise.ies") << d.str();
  ASSERT_EQ(p.candela.size(), kBaseCd.size());
  // Plane H=180 reads "500 300 100 -0.25": the noise value is kept or clamped to 0, nothing else changes.
  std::vector<double> want = kBaseCd;
  want[2 * 4 + 3] = p.candela[2 * 4 + 3];
  EXPECT_TRUE(p.candela[2 * 4 + 3] == -0.25 || p.candela[2 * 4 + 3] == 0.0) << p.candela[2 * 4 + 3];
  EXPECT_EQ(p.candela, want);
}

TEST(BadInputIes, LargeNegativeCandelaIsAnError) {
  const std::string name = "ies_candela_negative_large.ies";
  expect_ies_error(name, {line_of(corpus(name), "500 300 100 -50")});
}

TEST(BadInputIes, NegativeCandelaThresholdIsOneThousandthOfPeak) {
  // Peak 500 cd: -0.5 is exactly 1e-3 x peak (W), -0.6 is beyond it (E).
  const std::string head = "1 1000 1 4 5 1 2 0.5 0.6 0\n1 1 25\n0 30 60 90\n0 90 180 270 360\n"
                           "500 400 200 0\n500 350 150 0\n";
  const std::string tail = "\n500 350 150 0\n500 400 200 0\n";
  {
    lumx::DiagnosticList w;
    const Photometry p = lumx::read_ies(base_with_numbers(head + "500 300 100 -0.5" + tail), "edge.ies", collecting(w));
    EXPECT_GE(count_warnings(w), 1u);
    EXPECT_EQ(p.candela.size(), 20u);
  }
  const std::string text = base_with_numbers(head + "500 300 100 -0.6" + tail);
  auto d = catch_error([&] { (void)lumx::read_ies(text, "beyond.ies"); });
  expect_located(d, "beyond.ies", {line_of(text, "-0.6")});
}

TEST(BadInputIes, CandelaMultiplierIsApplied) {
  // ies_sym_quadrant.ies has multiplier 2.
  const Photometry p = read_corpus("ies_sym_quadrant.ies");
  EXPECT_DOUBLE_EQ(p.candela_multiplier, 2.0);
  EXPECT_EQ(p.candela, (std::vector<double>{600, 400, 200, 100, 20, 600, 360, 180, 80, 20, 600, 320, 160, 60, 20}));
}

// ---- item 5: lumens = -1 (absolute photometry) --------------------------------------------------------

TEST(BadInputIes, AbsoluteIsotropicFluxIsFourPiTimesIntensity) {
  const Photometry p = read_corpus("ies_lumens_absolute_isotropic.ies");
  EXPECT_TRUE(p.absolute);
  EXPECT_EQ(p.rated_lamp_flux_lm(), 0.0);
  EXPECT_EQ(p.symmetry, Symmetry::rotational);
  ASSERT_EQ(p.vertical_deg.size(), 10u);
  for (double c : p.candela) EXPECT_EQ(c, 100.0);
  // A constant is reproduced exactly by the bilinear interpolant, and flux_lm() integrates that exactly.
  const double flux = lumx::IntensityTable(p).flux_lm();
  EXPECT_NEAR(flux, 4.0 * lumx::kPi * 100.0, 4.0 * lumx::kPi * 100.0 * 1e-9);
}

TEST(BadInputIes, AbsoluteCosineFluxIsPiTimesPeakWithinDerivedBound) {
  // I(gamma) = I0 cos(gamma), I0 = 1000 cd, on gamma = 0..90 step h = 5 degrees (one plane, lumens -1).
  // Exact flux of the cosine: 2 pi I0 int_0^{pi/2} cos g sin g dg = pi I0.
  // flux_lm() integrates the piecewise-linear interpolant L of the samples. On each cell [a, b]
  //   f - L = (I0 cos xi / 2) (g - a)(b - g)  in  [0, I0 h^2 / 8]   (f'' = -I0 cos <= 0 on [0, 90]),
  // so 0 <= pi I0 - flux <= 2 pi (I0 h^2 / 8) int_0^{pi/2} sin g dg = pi I0 h^2 / 4:
  // relative error in [0, h^2/4] = [0, 1.904e-3]. To leading order it is h^2/12 = 6.346e-4 (the cell
  // integral of (g-a)(b-g)/2 is h^3/12, weighted by cos g sin g whose integral is 1/2); the measured
  // value is 6.351e-4. Independently of that, flux_lm() must equal the closed-form integral of L:
  //   int_a^b L sin = c0 (cos a - cos b) + (c1 - c0)/h (sin b - sin a - h cos b).
  const Photometry p = read_corpus("ies_lumens_absolute_cosine.ies");
  EXPECT_TRUE(p.absolute);
  ASSERT_EQ(p.vertical_deg.size(), 19u);
  ASSERT_EQ(p.candela.size(), 19u);
  const double I0 = 1000.0, h = 5.0 * lumx::kDegToRad;
  for (std::size_t i = 0; i < 19; ++i)
    EXPECT_NEAR(p.candela[i], I0 * std::cos(p.vertical_deg[i] * lumx::kDegToRad), 1e-9) << i;

  double closed = 0;
  for (std::size_t j = 0; j + 1 < 19; ++j) {
    const double a = p.vertical_deg[j] * lumx::kDegToRad, b = p.vertical_deg[j + 1] * lumx::kDegToRad;
    const double c0 = p.candela[j], c1 = p.candela[j + 1];
    closed += c0 * (std::cos(a) - std::cos(b)) + (c1 - c0) / (b - a) * (std::sin(b) - std::sin(a) - (b - a) * std::cos(b));
  }
  closed *= 2.0 * lumx::kPi;

  const double flux = lumx::IntensityTable(p).flux_lm();
  EXPECT_NEAR(flux, closed, closed * 1e-12);
  const double rel = (lumx::kPi * I0 - flux) / (lumx::kPi * I0);
  EXPECT_GE(rel, 0.0) << "the interpolant of a concave function lies below it";
  EXPECT_LE(rel, h * h / 4.0);
  EXPECT_NEAR(rel, h * h / 12.0, 1e-5);
}

// ---- item 6: Type C horizontal ranges and symmetry --------------------------------------------------

namespace {
const std::vector<double> kSymV = {0, 45, 90, 135, 180};
const std::vector<double> kR1 = {300, 200, 100, 50, 10}, kR2 = {300, 180, 90, 40, 10}, kR3 = {300, 160, 80, 30, 10};

lumx::AngleTable hand_grid(const std::vector<double>& h, const std::vector<std::vector<double>>& planes, double scale) {
  lumx::AngleTable t;
  t.horizontal_deg = h;
  t.vertical_deg = kSymV;
  for (const auto& pl : planes)
    for (double v : pl) t.candela.push_back(v * scale);
  return t;
}

void expect_expands_to(const Photometry& p, const lumx::AngleTable& want) {
  const lumx::AngleTable got = lumx::expand(lumx::stored_table(p), p.symmetry);
  EXPECT_EQ(got.horizontal_deg, want.horizontal_deg);
  EXPECT_EQ(got.vertical_deg, want.vertical_deg);
  EXPECT_EQ(got.candela, want.candela);
}
}  // namespace

TEST(BadInputIes, SingleHorizontalAngleIsRotational) {
  const Photometry p = read_corpus("ies_sym_rotational.ies");
  EXPECT_EQ(p.symmetry, Symmetry::rotational);
  EXPECT_EQ(p.horizontal_deg, std::vector<double>{0});
  expect_expands_to(p, hand_grid({0}, {kR1}, 1));
  const lumx::IntensityTable t(p);
  for (double c : {0.0, 45.0, 123.0, 270.0, 359.0})
    for (std::size_t iv = 1; iv < kSymV.size(); ++iv) EXPECT_DOUBLE_EQ(t.at_angles(c, kSymV[iv]), kR1[iv]);
}

TEST(BadInputIes, QuadrantRangeExpandsToHandBuiltGrid) {
  const Photometry p = read_corpus("ies_sym_quadrant.ies");  // H 0 45 90, multiplier 2
  EXPECT_EQ(p.symmetry, Symmetry::quadrant);
  expect_expands_to(p, hand_grid({0, 45, 90, 135, 180, 225, 270, 315}, {kR1, kR2, kR3, kR2, kR1, kR2, kR3, kR2}, 2));
  const lumx::IntensityTable t(p);
  EXPECT_NEAR(t.at_angles(300, 45), t.at_angles(60, 45), 1e-9);
  EXPECT_NEAR(t.at_angles(120, 60), t.at_angles(60, 60), 1e-9);
}

TEST(BadInputIes, C0C180RangeExpandsToHandBuiltGrid) {
  const Photometry p = read_corpus("ies_sym_c0_c180.ies");  // H 0 90 180
  EXPECT_EQ(p.symmetry, Symmetry::plane_c0_c180);
  expect_expands_to(p, hand_grid({0, 90, 180, 270}, {kR1, kR2, kR3, kR2}, 1));
}

TEST(BadInputIes, C90C270RangeOf1995ExpandsToHandBuiltGrid) {
  const Photometry p = read_corpus("ies_sym_c90_c270.ies");  // H 90 180 270; I(C) = I(180 - C)
  EXPECT_EQ(p.symmetry, Symmetry::plane_c90_c270);
  EXPECT_EQ(p.horizontal_deg, (std::vector<double>{90, 180, 270}));
  expect_expands_to(p, hand_grid({0, 90, 180, 270}, {kR2, kR1, kR2, kR3}, 1));
}

TEST(BadInputIes, FullRangeHasNoSymmetry) {
  const Photometry p = read_corpus("ies_valid_2002_typec.ies");
  EXPECT_EQ(p.symmetry, Symmetry::none);
}

TEST(BadInputIes, UndefinedHorizontalRangesAreErrors) {
  expect_ies_error("ies_sym_range_0_270.ies", {line_of(corpus("ies_sym_range_0_270.ies"), "0 90 180 270")});
  expect_ies_error("ies_sym_range_0_45.ies", {line_of(corpus("ies_sym_range_0_45.ies"), "\n0 45\n") + 1});
}

// ---- item 7: TILT -------------------------------------------------------------------------------------

TEST(BadInputIes, TiltIncludeIsReadAndApplied) {
  const Photometry p = read_corpus("ies_tilt_include_valid.ies");
  ASSERT_TRUE(p.tilt.has_value());
  EXPECT_EQ(p.tilt->source, "INCLUDE");
  EXPECT_EQ(p.tilt->lamp_geometry, 1);
  EXPECT_EQ(p.tilt->angles_deg, (std::vector<double>{0, 45, 90}));
  EXPECT_EQ(p.tilt->multipliers, (std::vector<double>{1, 0.8, 0.5}));
  EXPECT_EQ(p.candela, kBaseCd) << "TILT multipliers are kept beside the table, not folded in";
  const Photometry t45 = lumx::apply_tilt(p, 45);
  const Photometry t67 = lumx::apply_tilt(p, 67.5);
  for (std::size_t i = 0; i < kBaseCd.size(); ++i) {
    EXPECT_DOUBLE_EQ(t45.candela[i], kBaseCd[i] * 0.8);
    EXPECT_DOUBLE_EQ(t67.candela[i], kBaseCd[i] * 0.65);
  }
}

TEST(BadInputIes, TiltIncludeWithBadPairCountIsAnError) {
  for (const char* name : {"ies_tilt_include_zero_pairs.ies", "ies_tilt_include_huge_count.ies",
                           "ies_tilt_include_negative_count.ies"}) {
    const std::string text = corpus(name);
    const int count_line = line_of(text, "TILT=INCLUDE") + 2;  // TILT=, geometry, pair count
    const auto t0 = std::chrono::steady_clock::now();
    expect_ies_error(name, {count_line});
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0) << name;
  }
}

TEST(BadInputIes, TiltIncludeWithTooFewValuesIsAnError) {
  // 3 pairs announced, 2 multipliers given: everything after shifts (units type becomes 0.5, ...).
  expect_ies_error("ies_tilt_include_too_few.ies", {});
}

TEST(BadInputIes, ExternalTiltFileIsResolvedInTheFilesFolder) {
  const std::string path = (bad_dir() / "ies_tilt_external_valid.ies").string();
  const Photometry p = lumx::read_photometry(path);
  ASSERT_TRUE(p.tilt.has_value());
  EXPECT_EQ(p.tilt->source, "ies_tilt_external_valid.tlt");
  EXPECT_EQ(p.tilt->angles_deg, (std::vector<double>{0, 45, 90}));
  EXPECT_EQ(p.tilt->multipliers, (std::vector<double>{1, 0.8, 0.5}));
  expect_base_table(p);

  // From memory: only with base_dir.
  lumx::ReadOptions o;
  o.base_dir = bad_dir().string();
  EXPECT_TRUE(read_corpus("ies_tilt_external_valid.ies", o).tilt.has_value());
  const std::string text = corpus("ies_tilt_external_valid.ies");
  expect_ies_error("ies_tilt_external_valid.ies", {line_of(text, "TILT=")});
}

TEST(BadInputIes, MissingExternalTiltFileIsAnError) {
  const std::string path = (bad_dir() / "ies_tilt_file_missing.ies").string();
  auto d = catch_error([&] { (void)lumx::read_photometry(path); });
  expect_located(d, path, {line_of(corpus("ies_tilt_file_missing.ies"), "TILT=")});
}

TEST(BadInputIes, ExternalTiltOutsideTheFolderIsRefusedEvenIfItExists) {
  // tmp/a/b/lamp*.ies name tilt files that exist (tmp/a/x.tlt, tmp/a/b/sub/x.tlt, an absolute path),
  // so the only reason to fail is the name itself: '../' or a path separator.
  TempDir tmp;
  const fs::path a = tmp.path / "a", b = a / "b";
  fs::create_directories(b / "sub");
  const std::string tilt = "1\n3\n0 45 90\n1 0.8 0.5\n";
  write_bytes(a / "x.tlt", tilt);
  write_bytes(b / "sub" / "x.tlt", tilt);
  write_bytes(b / "ok.tlt", tilt);
  const std::string numbers = corpus("ies_valid_2002_typec.ies").substr(corpus("ies_valid_2002_typec.ies").find("TILT=NONE\n") + 10);
  auto make = [&](const std::string& tilt_line) {
    return "IESNA:LM-63-2002\n[TEST] X\n[TESTLAB] X\n[ISSUEDATE] X\n[MANUFAC] X\n" + tilt_line + "\n" + numbers;
  };
  write_bytes(b / "ok.ies", make("TILT=ok.tlt"));
  EXPECT_TRUE(lumx::read_photometry((b / "ok.ies").string()).tilt.has_value()) << "control case";

  const std::vector<std::string> bad_names = {"TILT=../x.tlt", "TILT=sub/x.tlt", "TILT=sub\\x.tlt",
                                              "TILT=" + (a / "x.tlt").string(), "TILT=./ok.tlt"};
  int k = 0;
  for (const auto& line : bad_names) {
    SCOPED_TRACE(line);
    const fs::path f = b / ("lamp" + std::to_string(k++) + ".ies");
    write_bytes(f, make(line));
    auto d = catch_error([&] { (void)lumx::read_photometry(f.string()); });
    expect_located(d, f.string(), {6});
  }
  // The corpus files of this class, read in place.
  for (const char* name : {"ies_tilt_file_traversal.ies", "ies_tilt_file_subdir.ies"}) {
    const std::string path = (bad_dir() / name).string();
    auto d = catch_error([&] { (void)lumx::read_photometry(path); });
    expect_located(d, path, {line_of(corpus(name), "TILT=")});
  }
}

// ---- item 8: Types A and B, negative opening dimensions ---------------------------------------------

namespace {
const std::vector<double> kTypeBV = {-90, -45, 0, 45, 90};
const std::vector<double> kTypeBCd = {10, 300, 1000, 300, 10, 10, 250, 800, 250, 10, 10, 100, 400, 100, 10};

/// File value at (H, V) of the lateral-symmetric A/B seed (H stored 0..90, I(-H) = I(H)).
double ab_value(double H, double V) {
  const double ah = std::abs(H);
  const int ih = static_cast<int>(std::lround(ah / 45.0)), iv = static_cast<int>(std::lround((V + 90) / 45.0));
  return kTypeBCd[static_cast<std::size_t>(ih * 5 + iv)];
}

/// Checks orientation by a round trip through Type C: every sample direction (H, V) of the file whose
/// Type C angles fall on the 1-degree grid of to_type_c() has the file's value there, and resampling
/// that Type C table back to the original type reproduces the value at the same direction.
void expect_orientation(const Photometry& p) {
  const lumx::PhotometricType type = p.type;
  const Photometry c = lumx::to_type_c(p, 1.0, 1.0);
  const lumx::IntensityTable tc(c);
  std::vector<double> hs, vs;
  int checked = 0;
  for (double H : {-90.0, -45.0, 0.0, 45.0, 90.0})
    for (double V : kTypeBV) {
      const auto a = lumx::angles_from_direction(lumx::PhotometricType::C, lumx::direction_from_angles(type, H, V));
      const double C = std::fmod(a.horizontal_deg + 360.0, 360.0), g = a.vertical_deg;
      if (std::abs(C - std::round(C)) > 1e-7 || std::abs(g - std::round(g)) > 1e-7) continue;
      ++checked;
      SCOPED_TRACE("H=" + std::to_string(H) + " V=" + std::to_string(V) + " -> C=" + std::to_string(C) +
                   " gamma=" + std::to_string(g));
      EXPECT_NEAR(tc.at_angles(std::round(C), std::round(g)), ab_value(H, V), 1e-6);
      const Photometry back = lumx::resample(c, type, {H}, {V});
      EXPECT_NEAR(back.candela.at(0), ab_value(H, V), 1e-6);
    }
  EXPECT_GE(checked, 15);
}
}  // namespace

TEST(BadInputIes, TypeBLoadsWithLateralSymmetryAndCorrectOrientation) {
  const Photometry p = read_corpus("ies_valid_typeb.ies");
  EXPECT_EQ(p.type, lumx::PhotometricType::B);
  EXPECT_EQ(p.symmetry, Symmetry::lateral);
  EXPECT_TRUE(p.absolute);
  EXPECT_EQ(p.horizontal_deg, (std::vector<double>{0, 45, 90}));
  EXPECT_EQ(p.vertical_deg, kTypeBV);
  EXPECT_EQ(p.candela, kTypeBCd);
  const lumx::IntensityTable t(p);
  EXPECT_DOUBLE_EQ(t.at_angles(-45, 45), 250.0);
  EXPECT_DOUBLE_EQ(t.at_angles(0, 0), 1000.0);
  expect_orientation(p);
}

TEST(BadInputIes, TypeALoadsWithLateralSymmetryAndCorrectOrientation) {
  const Photometry p = read_corpus("ies_valid_typea.ies");
  EXPECT_EQ(p.type, lumx::PhotometricType::A);
  EXPECT_EQ(p.symmetry, Symmetry::lateral);
  EXPECT_EQ(p.candela, kTypeBCd);
  expect_orientation(p);
}

TEST(BadInputIes, NegativeWidthAndLengthGiveARoundOpening) {
  const Photometry m = read_corpus("ies_opening_circle.ies");  // -0.3 -0.3 0, metres
  EXPECT_EQ(m.units, lumx::IesUnits::metres);
  EXPECT_DOUBLE_EQ(m.opening.width_m, -0.3);
  EXPECT_DOUBLE_EQ(m.opening.length_m, -0.3);
  EXPECT_EQ(m.opening.height_m, 0.0);
  EXPECT_EQ(m.opening.shape(), lumx::LuminousShape::circle);
  expect_base_table(m);

  const Photometry f = read_corpus("ies_opening_circle_feet.ies");  // -1 -1 0, feet
  EXPECT_EQ(f.units, lumx::IesUnits::feet);
  EXPECT_NEAR(f.opening.width_m, -lumx::kMetresPerFoot, 1e-15);
  EXPECT_NEAR(f.opening.length_m, -lumx::kMetresPerFoot, 1e-15);
  EXPECT_EQ(f.opening.shape(), lumx::LuminousShape::circle);
}

// ---- item 9: delimiters, line endings, encodings, old headers --------------------------------------

TEST(BadInputIes, DelimiterAndEncodingVariantsLoadTheSameTable) {
  for (const char* name : {"ies_delim_commas.ies", "ies_delim_tabs.ies", "ies_crlf.ies", "ies_lone_cr.ies", "ies_bom.ies",
                           "ies_latin1_keywords.ies", "ies_1986_no_version.ies", "ies_long_label.ies",
                           "ies_wrapped_values.ies"}) {
    SCOPED_TRACE(name);
    lumx::DiagnosticList w;
    try {
      expect_base_table(read_corpus(name, collecting(w)));
    } catch (const lumx::Error& e) {
      ADD_FAILURE() << "must load: " << e.what();
    }
    for (const auto& d : w.items) EXPECT_NE(d.severity, lumx::Severity::error) << d.str();
  }
}

TEST(BadInputIes, HeaderQuirksOfRealFilesLoad) {
  {  // "TILT=" inside keyword text is not the TILT line (formats.md 1.6).
    const Photometry p = read_corpus("ies_keyword_mentions_tilt.ies");
    expect_base_table(p);
    EXPECT_FALSE(p.tilt.has_value());
    const lumx::Keyword* k = p.find_keyword("OTHER");
    ASSERT_NE(k, nullptr);
    EXPECT_EQ(k->value, "see TILT=INCLUDE note");
  }
  {  // "IESNA: LM-63-2002" (blank inside the version line): loads, W.
    lumx::DiagnosticList w;
    expect_base_table(read_corpus("ies_version_with_space.ies", collecting(w)));
    EXPECT_GE(count_warnings(w), 1u);
  }
  {  // LM-63-2019 file-generation type 1.10000 and ballast factor 0.9: reported, never applied.
    const Photometry p = read_corpus("ies_2019_filegen_type.ies");
    EXPECT_EQ(p.candela, kBaseCd);
    EXPECT_DOUBLE_EQ(p.ies_second_factor, 1.1);
    EXPECT_DOUBLE_EQ(p.ballast_factor, 0.9);
  }
}

TEST(BadInputIes, Latin1KeywordTextIsKept) {
  const Photometry p = read_corpus("ies_latin1_keywords.ies");
  const lumx::Keyword* k = p.find_keyword("LUMINAIRE");
  ASSERT_NE(k, nullptr);
  EXPECT_EQ(k->value.rfind("BEAM 120", 0), 0u) << k->value;
  EXPECT_NE(p.find_keyword("MANUFAC"), nullptr);
}

TEST(BadInputIes, CrlfAndLoneCrCountLinesLikeLf) {
  // The same error must be reported on the same line whatever the line ending.
  const std::string lf = corpus("ies_candela_nan.ies");
  const int want = line_of(lf, "500 nan");
  for (const char* nl : {"\r\n", "\r"}) {
    std::string t;
    for (char ch : lf) {
      if (ch == '\n') t += nl;
      else t += ch;
    }
    auto d = catch_error([&] { (void)lumx::read_ies(t, "nl.ies"); });
    expect_located(d, "nl.ies", {want});
  }
}

// ---- item 10: the writer --------------------------------------------------------------------------

TEST(BadInputIes, WriterOutputStartsWithVersionAndRoundTripsExactly) {
  for (const char* name : {"ies_valid_2002_typec.ies", "ies_sym_quadrant.ies", "ies_sym_c90_c270.ies",
                           "ies_valid_typeb.ies", "ies_tilt_include_valid.ies"}) {
    SCOPED_TRACE(name);
    const Photometry p = read_corpus(name);
    for (auto version : {lumx::IesVersion::lm63_2002, lumx::IesVersion::lm63_2019}) {
      lumx::IesWriteOptions wo;
      wo.version = version;
      const std::string text = lumx::format_ies(p, wo);
      const std::string first = text.substr(0, text.find_first_of("\r\n"));
      EXPECT_EQ(first, version == lumx::IesVersion::lm63_2002 ? "IESNA:LM-63-2002" : "IES:LM-63-2019");
      lumx::DiagnosticList w;
      const Photometry q = lumx::read_ies(text, "roundtrip.ies", collecting(w));
      EXPECT_EQ(count_warnings(w), 0u) << "writer output must pass the strict reader cleanly:\n" << dump(w);
      EXPECT_EQ(q.type, p.type);
      EXPECT_EQ(q.symmetry, p.symmetry);
      EXPECT_EQ(q.horizontal_deg, p.horizontal_deg);
      EXPECT_EQ(q.vertical_deg, p.vertical_deg);
      EXPECT_EQ(q.candela, p.candela);
      EXPECT_EQ(q.absolute, p.absolute);
      EXPECT_EQ(q.tilt.has_value(), p.tilt.has_value());
      if (q.tilt && p.tilt) {
        EXPECT_EQ(q.tilt->angles_deg, p.tilt->angles_deg);
        EXPECT_EQ(q.tilt->multipliers, p.tilt->multipliers);
      }
    }
  }
}

// ---- writing files: failures are errors and never damage the previous file ------------------------

TEST(BadInputWrite, WritingIntoAMissingFolderIsAnError) {
  TempDir tmp;
  const Photometry p = read_corpus("ies_valid_2002_typec.ies");
  for (const fs::path& target : {tmp.path / "no_such_folder" / "out.ies", tmp.path / "no" / "such" / "out.ldt"}) {
    auto d = catch_error([&] { lumx::write_photometry(p, target.string()); });
    if (d) {
      EXPECT_FALSE(d->message.empty());
    }
    EXPECT_FALSE(fs::exists(target));
  }
  // The "folder" is a regular file.
  write_bytes(tmp.path / "file", "x");
  auto d = catch_error([&] { lumx::write_photometry(p, (tmp.path / "file" / "out.ies").string()); });
  (void)d;
}

TEST(BadInputWrite, WritingIntoAReadOnlyFolderIsAnError) {
  if (::geteuid() == 0) GTEST_SKIP() << "root ignores folder permissions";
  TempDir tmp;
  const fs::path ro = tmp.path / "ro";
  fs::create_directories(ro);
  fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
  const Photometry p = read_corpus("ies_valid_2002_typec.ies");
  auto d = catch_error([&] { lumx::write_photometry(p, (ro / "out.ies").string()); });
  (void)d;
  fs::permissions(ro, fs::perms::owner_all);
  EXPECT_FALSE(fs::exists(ro / "out.ies"));
}

TEST(BadInputWrite, FailedOverwriteLeavesTheOldFileByteIdentical) {
  TempDir tmp;
  const Photometry good = read_corpus("ies_valid_2002_typec.ies");
  Photometry bad = good;
  bad.candela.pop_back();  // 19 values for a 5 x 4 grid: cannot be expressed

  for (const char* file : {"keep.ies", "keep.ldt"}) {
    SCOPED_TRACE(file);
    const fs::path target = tmp.path / file;
    lumx::write_photometry(good, target.string());
    const std::string before = lumx_test::read_text(target);
    ASSERT_FALSE(before.empty());
    std::vector<fs::path> listing_before;
    for (const auto& e : fs::directory_iterator(tmp.path)) listing_before.push_back(e.path());
    std::sort(listing_before.begin(), listing_before.end());

    auto d = catch_error([&] { lumx::write_photometry(bad, target.string()); });
    (void)d;
    EXPECT_EQ(lumx_test::read_text(target), before) << "the previous file must be untouched";
    std::vector<fs::path> listing_after;
    for (const auto& e : fs::directory_iterator(tmp.path)) listing_after.push_back(e.path());
    std::sort(listing_after.begin(), listing_after.end());
    EXPECT_EQ(listing_after, listing_before) << "no temporary file may be left behind";
  }
  // format_* report the same inconsistency directly.
  (void)catch_error([&] { (void)lumx::format_ies(bad); });
  (void)catch_error([&] { (void)lumx::format_ldt(bad); });
}

// ---- never crash: truncation at every byte and ~200 corruptions per seed ---------------------------

TEST(BadInputSweep, IesTypeCNeverCrashes) {
  const std::string good = corpus("ies_valid_2002_typec.ies");
  ASSERT_NO_THROW((void)lumx::read_ies(good, "seed.ies"));
  never_crash_sweep([](const std::string& s) { return lumx::read_ies(s, "fuzz.ies"); }, good, "ies_valid_2002_typec",
                    0x1E5C0FFEEull);
}

TEST(BadInputSweep, IesTypeBNeverCrashes) {
  const std::string good = corpus("ies_valid_typeb.ies");
  ASSERT_NO_THROW((void)lumx::read_ies(good, "seed.ies"));
  never_crash_sweep([](const std::string& s) { return lumx::read_ies(s, "fuzz.ies"); }, good, "ies_valid_typeb",
                    0xB0B0B0B0ull);
}

TEST(BadInputSweep, IesEveryNumberReplacedByHostileTokens) {
  for (const char* name : {"ies_valid_2002_typec.ies", "ies_valid_typeb.ies", "ies_tilt_include_valid.ies"}) {
    SCOPED_TRACE(name);
    token_sweep([](const std::string& s) { return lumx::read_ies(s, "fuzz.ies"); }, corpus(name), name);
  }
}

TEST(BadInputSweep, IesTiltIncludeNeverCrashes) {
  const std::string good = corpus("ies_tilt_include_valid.ies");
  ASSERT_NO_THROW((void)lumx::read_ies(good, "seed.ies"));
  never_crash_sweep([](const std::string& s) { return lumx::read_ies(s, "fuzz.ies"); }, good, "ies_tilt_include_valid",
                    0x7117ull, 100);
}
