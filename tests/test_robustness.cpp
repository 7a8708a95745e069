// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Regression tests for hostile values reaching the model, writers and file system helpers.
#include <lumx/io/atomic_file.h>
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/resample.h>

#include <gtest/gtest.h>

#include "memory_test_support.h"
#include "test_support.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <sys/stat.h>
#include <unistd.h>

using namespace lumx;
namespace fs = std::filesystem;

namespace {
const char* kTable =
    "IESNA:LM-63-2002\n[TEST] T\n[TESTLAB] L\n[ISSUEDATE] D\n[MANUFAC] M\nTILT=NONE\n"
    "1 -1 1 3 5 1 2 0 0 0\n1 1 10\n0 45 90\n0 90 180 270 360\n"
    "100 80 10\n100 60 10\n100 50 10\n100 60 10\n120 90 20\n";  // C360 differs from C0 (noise)

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("lumx_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}
}  // namespace

TEST(Robustness, TiltMultiplierAtNanNeverReadsPastTheTable) {
  TiltTable t;
  t.angles_deg = {0, 45, 90};
  t.multipliers = {1, 0.8, 0.5};
  EXPECT_EQ(t.multiplier_at(std::nan("")), 1.0);
  EXPECT_EQ(t.multiplier_at(1e300), 0.5);
  EXPECT_EQ(t.multiplier_at(-1e300), 1.0);
}

TEST(Robustness, RotationKeepsFluxWhenC0AndC360Differ) {
  const Photometry p = read_ies(kTable, "seam.ies");
  const double flux = IntensityTable(p).flux_lm();
  for (double deg : {90.0, 180.0, 270.0, -90.0}) {
    const Photometry r = rotate_c_planes(p, deg);
    EXPECT_NEAR(IntensityTable(r).flux_lm(), flux, 1e-12 * flux) << deg;
  }
}

TEST(Robustness, ExternalTiltThroughASymlinkOutOfTheFolderIsRefused) {
  const fs::path d = fresh_dir("tilt_link");
  fs::create_directories(d / "lum");
  std::ofstream(d / "outside.tlt") << "1\n2\n0 90\n1 0.5\n";
  fs::create_symlink(d / "outside.tlt", d / "lum" / "lamp.tlt");
  std::string text = kTable;
  text.replace(text.find("TILT=NONE"), 9, "TILT=lamp.tlt");
  std::ofstream(d / "lum" / "l.ies") << text;
  try {
    read_photometry((d / "lum" / "l.ies").string());
    ADD_FAILURE() << "symlink out of the folder accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.diagnostic().field, "TILT");
    EXPECT_NE(e.diagnostic().message.find("outside"), std::string::npos);
  }
  fs::remove_all(d);
}

TEST(Robustness, LdtWithOneGammaAngleIsALocatedError) {
  std::string ldt = lumx_test::read_text(lumx_test::data_dir() / "ldt/isym2_point.ldt");
  // Line 6 is Ng.
  std::size_t pos = 0;
  for (int i = 0; i < 5; ++i) pos = ldt.find('\n', pos) + 1;
  ldt.replace(pos, ldt.find('\n', pos) - pos, "1");
  try {
    read_ldt(ldt, "ng1.ldt");
    ADD_FAILURE() << "Ng = 1 accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.diagnostic().line, 6);
    EXPECT_EQ(e.diagnostic().field, "Ng");
  }
}

TEST(Robustness, WritersUsePlainDecimals) {
  Photometry p = read_ies(kTable, "tiny.ies");
  for (double& c : p.candela) c *= 1e-9;  // values far below 1 cd
  p.candela[0] = 2e7;                      // and one far above
  for (const std::string& text : {format_ies(p), format_ldt(p)})
    for (std::size_t i = text.find("TILT") == std::string::npos ? 0 : text.find("TILT"); i < text.size(); ++i)
      ASSERT_FALSE((text[i] == 'e' || text[i] == 'E') && i > 0 && std::isdigit(static_cast<unsigned char>(text[i - 1])))
          << "exponent notation near: " << text.substr(i > 20 ? i - 20 : 0, 40);
}

TEST(Robustness, AtomicWriteKeepsPermissionsAndLeavesNoTemporary) {
  const fs::path d = fresh_dir("atomic");
  const fs::path f = d / "x.ies";
  write_file_atomically(f.string(), "one");
  ASSERT_EQ(::chmod(f.c_str(), 0600), 0);
  write_file_atomically(f.string(), "two");
  struct stat st {};
  ASSERT_EQ(::stat(f.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_EQ(lumx_test::read_text(f), "two");
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(d)) n += e.is_regular_file();
  EXPECT_EQ(n, 1u);
  EXPECT_THROW(write_file_atomically((d / "missing" / "y.ies").string(), "z"), Error);
  fs::remove_all(d);
}

TEST(Robustness, HugeFilesAreReadInMemoryBoundedByTheirSize) {
  // 14 MiB of one number per line: the readers keep only the values the header implies, and never a
  // per-line or per-token index of the whole file (which cost ~25x the file size before).
  const std::size_t n = 7u << 20;
  std::string ies = std::string(kTable);
  std::string ldt = lumx_test::read_text(lumx_test::data_dir() / "ldt/isym2_point.ldt");
  ies.reserve(ies.size() + 2 * n);
  ldt.reserve(ldt.size() + 2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    ies += "1\n";
    ldt += "1\n";
  }
  // The peak is reset first: a peak left by an earlier test in the same process would hide the growth.
  if (!lumx_test::reset_peak_rss()) GTEST_SKIP() << "the kernel refused to reset the peak RSS; growth not measured";
  const long before = lumx_test::proc_status_kb("VmRSS:");
  ReadOptions quiet;
  quiet.warnings = [](const Diagnostic&) {};
  EXPECT_NO_THROW(read_ies(ies, "big.ies", quiet));  // trailing values are a warning
  EXPECT_NO_THROW(read_ldt(ldt, "big.ldt", quiet));
  const long grown_kb = lumx_test::proc_status_kb("VmHWM:") - before;
  EXPECT_LT(grown_kb * 1024.0, 2.0 * static_cast<double>(ies.size())) << grown_kb << " kB";
}
