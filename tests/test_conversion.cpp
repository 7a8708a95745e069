// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// IES <-> EULUMDAT conversion: flux within 0.1 % (in practice ~1e-7: both formats carry the same
// table) and candela at the stored angles to the written precision, in both directions, on every
// real file.
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/metrics.h>
#include <lumx/photometry/resample.h>

#include <gtest/gtest.h>

#include "test_support.h"

#include <filesystem>

using namespace lumx;
namespace fs = std::filesystem;

namespace {

std::vector<fs::path> files_with(const std::vector<std::string>& exts) { return lumx_test::shared_photometry_files(exts); }

/// Both tables agree at every direction of `a`'s expanded grid, to `rel` of `a`'s peak.
void expect_same_distribution(const Photometry& a, const Photometry& b, double rel, const std::string& what) {
  const IntensityTable ta(a), tb(b);
  EXPECT_LE(lumx_test::max_candela_difference(a, b), rel * ta.max_cd()) << what;
  EXPECT_NEAR(tb.flux_lm(), ta.flux_lm(), 1e-3 * ta.flux_lm()) << what;   // the 0.1 % requirement
  EXPECT_NEAR(tb.flux_lm(), ta.flux_lm(), 1e-5 * ta.flux_lm()) << what;   // what is actually achieved
}

}  // namespace

TEST(Conversion, IesToLdtToIes) {
  std::size_t n = 0;
  if (lumx_test::shared_dir().empty()) LUMX_SKIP_WITHOUT_SHARED("data/photometry");
  for (const auto& f : files_with({".ies"})) {
    if (f.filename() == "test_file_format_error.ies") continue;
    SCOPED_TRACE(f.string());
    Photometry p = read_photometry(f.string());
    if (p.type != PhotometricType::C) p = to_type_c(p, 1, 1);  // EULUMDAT is Type C only
    const Photometry l = read_ldt(format_ldt(p), "converted.ldt");
    expect_same_distribution(p, l, 1e-6, f.string() + " -> LDT");
    EXPECT_EQ(l.absolute, p.absolute);
    if (!p.absolute) {
      EXPECT_NEAR(l.rated_lamp_flux_lm(), p.rated_lamp_flux_lm(), 1e-6 * p.rated_lamp_flux_lm());
    }
    const Photometry back = read_ies(format_ies(l), "back.ies");
    expect_same_distribution(p, back, 2e-6, f.string() + " -> LDT -> IES");
    EXPECT_EQ(back.symmetry, p.symmetry);
    ++n;
  }
  EXPECT_GE(n, 5u);
}

TEST(Conversion, LdtToIesToLdt) {
  std::size_t n = 0;
  if (lumx_test::shared_dir().empty()) LUMX_SKIP_WITHOUT_SHARED("data/photometry");
  for (const auto& f : files_with({".ldt"})) {
    SCOPED_TRACE(f.string());
    const Photometry p = read_photometry(f.string());
    const Photometry i = read_ies(format_ies(p), "converted.ies");
    expect_same_distribution(p, i, 1e-6, f.string() + " -> IES");
    EXPECT_EQ(i.symmetry, p.symmetry);
    const Photometry back = read_ldt(format_ldt(i), "back.ldt");
    expect_same_distribution(p, back, 2e-6, f.string() + " -> IES -> LDT");
    EXPECT_EQ(back.absolute, p.absolute);
    ++n;
  }
  EXPECT_GE(n, 5u);
}

TEST(Conversion, TwinFilesFromOneLuminaireAgree) {
  // luxpy ships the same test lamps as IES and LDT (Isym 2, 3, 4). Their tables agree to the LDT's
  // printed precision (values rounded to 0.01 cd/klm, at most 0.005 cd here), so their fluxes agree to
  // 1e-5 relative (hard-cases #16 asks 1e-6 for identical data; these files differ by that rounding).
  const auto root = lumx_test::shared_dir();
  if (root.empty()) LUMX_SKIP_WITHOUT_SHARED("data/photometry");
  const fs::path dir = root / "data/photometry/ksmet1977+luxpy";
  const std::pair<const char*, Symmetry> twins[] = {
      {"Testlamp_Isym2_theta180+_erco_33499000_1xqt32_230w", Symmetry::plane_c0_c180},
      {"Testlamp_Isym3_symmetryOverC90C270axis", Symmetry::plane_c90_c270},
      {"Testlamp_Isym4_43cef5d76a391dd85c41d4d09d68600d", Symmetry::quadrant},
      {"luxpy_test_lid_file", Symmetry::quadrant}};
  for (const auto& [stem, sym] : twins) {
    fs::path ies = dir / (std::string(stem) + ".ies");
    if (!fs::exists(ies)) ies = dir / (std::string(stem) + ".IES");
    const Photometry a = read_photometry(ies.string());
    const Photometry b = read_photometry((dir / (std::string(stem) + ".ldt")).string());
    EXPECT_EQ(a.symmetry, sym) << stem;
    EXPECT_EQ(b.symmetry, sym) << stem;
    const IntensityTable ta(a), tb(b);
    EXPECT_NEAR(ta.flux_lm(), tb.flux_lm(), 1e-5 * ta.flux_lm()) << stem;
    for (double c = 0; c < 360; c += 15)
      for (double g = 0; g <= 180; g += 5) EXPECT_NEAR(ta.at_angles(c, g), tb.at_angles(c, g), 0.0051) << stem;
  }
}

TEST(Conversion, RotationOptionIsExplicitAndLossless) {
  const fs::path file = lumx_test::shared_photometry("dlippok+photometric-viewer/no_symmetry.ldt");
  if (file.empty()) LUMX_SKIP_WITHOUT_SHARED("data/photometry");
  const Photometry p = read_photometry(file.string());
  const Photometry r = rotate_c_planes(p, 90);
  const Photometry i = read_ies(format_ies(r), "rot.ies");
  const IntensityTable tp(p), ti(i);
  for (double c = 0; c < 360; c += 15)
    for (double g = 0; g <= 180; g += 2.5)
      EXPECT_NEAR(ti.at_angles(std::fmod(c + 90, 360), g), tp.at_angles(c, g), 1e-6 * tp.max_cd());
  EXPECT_NEAR(ti.flux_lm(), tp.flux_lm(), 1e-6 * tp.flux_lm());
}
