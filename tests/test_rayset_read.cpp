// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Reading raysets: every real file in ../shared/data/raysets against an independent reading by
// tests/tools/rayset_reference.py (Python, struct module), the three-ray files across formats, TM-25
// header facts, chunking and rewinding, and the text formats (plain text, LightTools, Zemax).
#include "rayset_test_support.h"

#include <lumx/io/rayset_io.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace lumx;
using namespace lumx_rays;

namespace {

const char* quantity_name(PhotometricQuantity q) {
  return q == PhotometricQuantity::photometric ? "photometric" : "radiometric";
}

RayChunk read_all(const fs::path& p, RaysetReadOptions o = {}) {
  auto src = open_rayset(p.string(), o);
  return read_all_rays(*src, 1000000);
}

}  // namespace

TEST(RaysetRealFiles, EveryFileMatchesAnIndependentReading) {
  const auto files = real_ray_files();
  if (files.empty()) LUMX_SKIP_WITHOUT_SHARED("data/raysets");
  EXPECT_GE(files.size(), 13u);
  for (const auto& f : files) {
    SCOPED_TRACE(f.filename().string());
    std::vector<Diagnostic> warnings;
    auto src = open_collect(f, warnings);
    const RaysetSummary s = summarize_rays(*src);
    const RaysetInfo& info = src->info();
    const auto ref = python_reference(f);
    ASSERT_TRUE(ref);
    const nlohmann::json& r = *ref;
    EXPECT_EQ(info.format, r["format"].get<std::string>());
    EXPECT_EQ(s.rays, r["rays"].get<std::uint64_t>());
    EXPECT_EQ(info.ray_count, s.rays);
    EXPECT_STREQ(quantity_name(info.quantity), r["quantity"].get<std::string>().c_str());
    const bool text = info.format.find("text") != std::string::npos;
    const double ref_sum = r["flux_sum"].get<double>();
    // Binary files: the same float32 values summed exactly on both sides. Text: C++ parses floats,
    // Python doubles.
    EXPECT_NEAR(s.flux_sum, ref_sum, std::abs(ref_sum) * (text ? 1e-6 : 1e-12));
    if (r["header_flux"].is_null()) {
      EXPECT_TRUE(std::isnan(info.header_flux));
    } else {
      const double h = r["header_flux"].get<double>();
      EXPECT_NEAR(info.header_flux, h, std::abs(h) * 1e-7);
    }
    const glm::dvec3 extent = s.hi - s.lo;
    const double scale = std::max({extent.x, extent.y, extent.z, 1e-3});
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(s.lo[k], r["lo"][k].get<double>(), 1e-6 * scale) << "axis " << k;
      EXPECT_NEAR(s.hi[k], r["hi"][k].get<double>(), 1e-6 * scale) << "axis " << k;
    }
    EXPECT_NEAR(s.bounds.radius, r["radius"].get<double>(), 1e-6 * scale);
    // Only the documented flux warning may appear on real files.
    for (const auto& w : warnings) {
      EXPECT_EQ(w.severity, Severity::warning) << w.str();
      EXPECT_NE(w.message.find("the rays are kept as they are"), std::string::npos) << w.str();
    }
    std::printf("  %-60s %-18s %7llu rays, header %-12.6g sum %.9g %s\n", f.filename().string().c_str(),
                info.format.c_str(), static_cast<unsigned long long>(s.rays), info.header_flux, s.flux_sum,
                flux_unit(info.quantity));
  }
}

TEST(RaysetRealFiles, ThreeRayFilesAgreeAcrossFormats) {
  const fs::path lt_bin = real_file("ThreeRays_Wavelength.1.ray");
  if (lt_bin.empty()) LUMX_SKIP_WITHOUT_SHARED("data/raysets");
  const RayChunk ref = read_all(lt_bin);
  ASSERT_EQ(ref.size(), 3u);
  ASSERT_EQ(ref.wavelength_nm.size(), 3u);
  EXPECT_FLOAT_EQ(ref.wavelength_nm[0], 550.0f);
  EXPECT_FLOAT_EQ(ref.wavelength_nm[1], 450.0f);
  EXPECT_FLOAT_EQ(ref.wavelength_nm[2], 620.0f);
  // Positions in the file are mm: -0.6668399 mm is -6.668399e-4 m.
  EXPECT_NEAR(ref.x[0], -6.668399e-4, 1e-10);
  for (const char* name : {"ThreeRays_Wavelength.1.txt", "ThreeRays_Wavelength_ZMX.ray",
                           "ThreeRays_Wavelength_ZMW_to_LT.ray", "ThreeRays_PowerOnly.1.ray"}) {
    SCOPED_TRACE(name);
    const RayChunk c = read_all(real_file(name));
    ASSERT_EQ(c.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_NEAR(c.x[i], ref.x[i], 1e-9);
      EXPECT_NEAR(c.y[i], ref.y[i], 1e-9);
      EXPECT_NEAR(c.z[i], ref.z[i], 1e-9);
      EXPECT_NEAR(c.dx[i], ref.dx[i], 1e-6);
      EXPECT_NEAR(c.dy[i], ref.dy[i], 1e-6);
      EXPECT_NEAR(c.dz[i], ref.dz[i], 1e-6);
      EXPECT_NEAR(c.flux[i], ref.flux[i], 1e-6 * ref.flux[i]);
      if (std::string(name) == "ThreeRays_PowerOnly.1.ray") {
        EXPECT_TRUE(c.wavelength_nm.empty());
      } else {
        ASSERT_EQ(c.wavelength_nm.size(), 3u);
        EXPECT_NEAR(c.wavelength_nm[i], ref.wavelength_nm[i], 1e-3);  // Zemax stores µm
      }
    }
  }
}

TEST(RaysetRealFiles, Tm25HeaderTextSpectraAndFluxPolicy) {
  const fs::path blue = real_file("rayfile_LERTDUW_S2WP_blue_100k_20161013_IES_TM25.TM25RAY");
  if (blue.empty()) LUMX_SKIP_WITHOUT_SHARED("data/raysets");
  {
    std::vector<Diagnostic> w;
    auto src = open_collect(blue, w);
    const RaysetInfo& i = src->info();
    EXPECT_EQ(i.format, "TM-25");
    EXPECT_EQ(i.version, "2013");
    EXPECT_EQ(i.quantity, PhotometricQuantity::radiometric);
    EXPECT_FLOAT_EQ(static_cast<float>(i.header_flux), 1.68f);
    EXPECT_NEAR(i.values.at("luminous flux lm"), 54.644249, 1e-5);
    EXPECT_EQ(i.text.at("name"), "LERTDUW_S2WP");
    EXPECT_EQ(i.text.at("manufacturer"), "OSRAM Opto Semiconductors GmbH");
    EXPECT_EQ(i.text.at("equipment"), "Rigo 801");
    EXPECT_EQ(i.text.at("creation date"), "2016-10-13 13:24:12");
    ASSERT_EQ(i.spectra.size(), 1u);
    EXPECT_EQ(i.spectra[0].wavelength_nm.size(), 76u);
    EXPECT_FLOAT_EQ(i.spectra[0].wavelength_nm.front(), 390.0f);
    EXPECT_FLOAT_EQ(i.spectra[0].wavelength_nm.back(), 510.0f);
    EXPECT_EQ(i.values.at("spectral identifier"), 3);
    EXPECT_FALSE(i.simulated);
    summarize_rays(*src);
    EXPECT_TRUE(w.empty()) << w.front().str();  // header 1.68 W, rays 1.68 W: no warning
  }
  {
    // Cyl10k: the header says 1 lm, the rays sum to 10 000 lm. Kept as they are, one warning, located.
    std::vector<Diagnostic> w;
    auto src = open_collect(real_file("Cyl10k.1.tm25ray"), w);
    const RaysetSummary s = summarize_rays(*src);
    EXPECT_NEAR(s.flux_sum, 10000, 1e-3);
    EXPECT_EQ(src->info().header_flux, 1.0);
    ASSERT_EQ(w.size(), 1u);
    EXPECT_EQ(w[0].byte_offset, 12);
    EXPECT_EQ(w[0].field, "total luminous flux (4.7.1.4)");
    EXPECT_NE(w[0].message.find("10000 times"), std::string::npos) << w[0].message;
    summarize_rays(*src);  // passes after the first warn no more
    EXPECT_EQ(w.size(), 1u);
  }
  {
    // farfield: every ray starts at the origin; single wavelength 500 nm; luminous flux NaN (legal).
    std::vector<Diagnostic> w;
    auto src = open_collect(real_file("farfield.TM25ray"), w);
    const RaysetSummary s = summarize_rays(*src);
    EXPECT_EQ(s.lo, glm::dvec3(0.0));
    EXPECT_EQ(s.hi, glm::dvec3(0.0));
    EXPECT_EQ(s.bounds.radius, 0.0);
    ASSERT_TRUE(src->info().wavelength_nm);
    EXPECT_EQ(*src->info().wavelength_nm, 500.0);
    EXPECT_TRUE(std::isnan(src->info().values.at("luminous flux lm")));
  }
  {
    // green: luminous flux per ray only; asking for radiant flux warns and reads the luminous column.
    RaysetReadOptions o;
    o.flux = FluxPreference::radiant;
    std::vector<Diagnostic> w;
    auto src = open_collect(real_file("rayfile_LERTDUW_S2WP_green_100k_20161013_IES_TM25.TM25RAY"), w, o);
    EXPECT_EQ(src->info().quantity, PhotometricQuantity::photometric);
    EXPECT_EQ(src->info().header_flux, 337.0);
    ASSERT_EQ(w.size(), 1u);
    EXPECT_EQ(w[0].field, "radiant flux flag (4.7.2.3)");
  }
}

TEST(RaysetRealFiles, ChunkSizesAndRewindGiveTheSameRays) {
  const fs::path f = real_file("Cyl1M_Faberge.1.tm25ray");
  if (f.empty()) LUMX_SKIP_WITHOUT_SHARED("data/raysets");
  auto src = open_rayset(f.string());
  const RayChunk all = read_all_rays(*src, 200000);
  ASSERT_EQ(all.size(), 126281u);
  for (std::size_t chunk : {std::size_t(1), std::size_t(7), std::size_t(4096), std::size_t(1) << 20}) {
    if (chunk == 1) {  // one ray at a time over a prefix only (slow path, same code)
      src->rewind();
      RayChunk c;
      for (std::size_t i = 0; i < 1000; ++i) {
        ASSERT_TRUE(src->next(c, 1));
        ASSERT_EQ(c.size(), 1u);
        EXPECT_EQ(c.x[0], all.x[i]);
        EXPECT_EQ(c.flux[0], all.flux[i]);
      }
      continue;
    }
    src->rewind();
    RayChunk c, joined;
    while (src->next(c, chunk)) {
      EXPECT_LE(c.size(), chunk);
      for (auto [dst, from] : {std::pair{&joined.x, &c.x},
                               {&joined.y, &c.y},
                               {&joined.z, &c.z},
                               {&joined.dx, &c.dx},
                               {&joined.dy, &c.dy},
                               {&joined.dz, &c.dz},
                               {&joined.flux, &c.flux}})
        dst->insert(dst->end(), from->begin(), from->end());
    }
    EXPECT_TRUE(c.empty());
    EXPECT_FALSE(src->next(c, chunk));  // stays at the end
    EXPECT_TRUE(same_rays(joined, all)) << "chunk " << chunk;
  }
  // max_rays is a cap on memory: read_all_rays refuses more.
  EXPECT_THROW(read_all_rays(*src, 1000), Error);
}

TEST(RaysetRealFiles, ZemaxTextUnitsAndWavelengths) {
  const fs::path mm = real_file("ZemaxText.txt");
  if (mm.empty()) LUMX_SKIP_WITHOUT_SHARED("data/raysets");
  const RayChunk a = read_all(mm);
  const RayChunk b = read_all(real_file("ZemaxWavelengthText.txt"));
  ASSERT_EQ(a.size(), 9u);
  ASSERT_EQ(b.size(), 9u);
  // Header "9 4 ...": 9 rays in mm; "9 2 ...": dimension code 2 is cm (docs/rays.md).
  EXPECT_NEAR(a.x[0], -0.118104e-3, 1e-10);
  EXPECT_NEAR(b.x[0], -0.118104e-2, 1e-9);
  EXPECT_TRUE(a.wavelength_nm.empty());
  ASSERT_EQ(b.wavelength_nm.size(), 9u);
  EXPECT_NEAR(b.wavelength_nm[0], 510.0, 1e-3);  // 0.51 µm
  EXPECT_NEAR(b.wavelength_nm[8], 450.0, 1e-3);
}

TEST(RaysetFormats, DetectionByExtensionAndContent) {
  for (const auto& [name, format] :
       std::vector<std::pair<std::string, RaysetFormat>>{{"Cyl10k.1.tm25ray", RaysetFormat::tm25},
                                                         {"ThreeRays_PowerOnly.1.ray", RaysetFormat::lighttools_binary},
                                                         {"ThreeRays_Wavelength.1.txt", RaysetFormat::lighttools_text},
                                                         {"ThreeRays_Wavelength_ZMX.ray", RaysetFormat::zemax_binary},
                                                         {"ZemaxText.txt", RaysetFormat::zemax_text}}) {
    const fs::path p = real_file(name);
    if (p.empty()) LUMX_SKIP_WITHOUT_SHARED("data/raysets");
    EXPECT_EQ(detect_rayset_format(p.string()), format) << name;
  }
  const fs::path d = scratch("detect");
  write_bytes(d / "a.rays", "# lumx-rays length=mm flux=lm\n0 0 0 0 0 1 1\n");
  EXPECT_EQ(detect_rayset_format((d / "a.rays").string()), RaysetFormat::plain_text);
  write_bytes(d / "x.txt", "hello\nworld\n");
  EXPECT_EQ(detect_rayset_format((d / "x.txt").string()), std::nullopt);
  EXPECT_EQ(detect_rayset_format((d / "missing.ray").string()), std::nullopt);
  EXPECT_EQ(detect_rayset_format((fs::path(LUMX_SOURCE_DIR) / "samples/downlight.ies").string()), std::nullopt);
  // The .tm25ray extension decides; the content is then checked.
  write_bytes(d / "fake.tm25ray", "LTRF and more bytes");
  EXPECT_EQ(detect_rayset_format((d / "fake.tm25ray").string()), RaysetFormat::tm25);
  try {
    open_rayset((d / "fake.tm25ray").string());
    ADD_FAILURE() << "opened";
  } catch (const Error& e) {
    EXPECT_EQ(e.diagnostic().byte_offset, 0);
    EXPECT_EQ(e.diagnostic().field, "file type (4.7.1.1)");
  }
  try {
    open_rayset((d / "x.txt").string());
    ADD_FAILURE() << "opened";
  } catch (const Error& e) {
    EXPECT_EQ(e.diagnostic().field, "format");
  }
  fs::remove_all(d);
}

TEST(RaysetPlainText, HeaderUnitsColumnsCommentsAndLineEnds) {
  const fs::path d = scratch("plain");
  // 7 columns, inches, CRLF, BOM, comments, commas and tabs between numbers.
  write_bytes(d / "a.rays",
              "\xEF\xBB\xBF# lumx-rays length=in flux=W total=3\r\n# a comment\r\n\r\n"
              "1, 0, 0, 0, 0, 2, 1\r\n0\t1\t0\t3 4 0 2\r\n");
  std::vector<Diagnostic> w;
  auto src = open_collect(d / "a.rays", w);
  EXPECT_EQ(src->info().format, "plain text");
  EXPECT_EQ(src->info().quantity, PhotometricQuantity::radiometric);
  EXPECT_EQ(src->info().ray_count, 2u);
  EXPECT_EQ(src->info().source_length_unit, "in");
  const RayChunk c = read_all_rays(*src, 10);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_FLOAT_EQ(c.x[0], 0.0254f);
  EXPECT_FLOAT_EQ(c.y[1], 0.0254f);
  EXPECT_EQ(c.dz[0], 1.0f);  // (0, 0, 2) normalised
  EXPECT_FLOAT_EQ(c.dx[1], 0.6f);
  EXPECT_FLOAT_EQ(c.dy[1], 0.8f);
  ASSERT_EQ(w.size(), 1u);  // the normalisation, once per pass; total 3 = 1 + 2 so no flux warning
  EXPECT_NE(w[0].message.find("2 of 2 directions"), std::string::npos) << w[0].str();

  // 6 columns: equal rays sharing the stated total; 8 columns: wavelength in nm.
  write_bytes(d / "b.rays", "# lumx-rays length=mm flux=lm total=10\n0 0 0 0 0 1\n0 0 1 0 1 0\n");
  const RayChunk b = read_all_rays(*open_rayset((d / "b.rays").string()), 10);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b.flux[0], 5.0f);
  EXPECT_FLOAT_EQ(b.z[1], 0.001f);
  write_bytes(d / "c.rays", "# lumx-rays flux=W length=m\n0 0 0 1 0 0 2 555\n");
  const RayChunk c8 = read_all_rays(*open_rayset((d / "c.rays").string()), 10);
  ASSERT_EQ(c8.wavelength_nm.size(), 1u);
  EXPECT_EQ(c8.wavelength_nm[0], 555.0f);
  fs::remove_all(d);
}

TEST(RaysetLightToolsText, PhotometricHeaderAndRefusals) {
  const fs::path d = scratch("lttext");
  const std::string head =
      "# LightTools test\nlt_rdf_version: 2.0\nlt_datatype: luminous_power\nlt_far_field_data: no\n"
      "lt_color_info: none\nlt_length_units: centimeters\nlt_luminous_flux: 3\n";
  write_bytes(d / "a.txt", head + "lt_startofdata\n1 0 0 0 0 1 1\n0 1 0 0 1 0 2\nlt_endofdata\n");
  std::vector<Diagnostic> w;
  auto src = open_collect(d / "a.txt", w);
  EXPECT_EQ(src->info().format, "LightTools text");
  EXPECT_EQ(src->info().quantity, PhotometricQuantity::photometric);
  EXPECT_EQ(src->info().header_flux, 3.0);
  const RaysetSummary s = summarize_rays(*src);
  EXPECT_EQ(s.rays, 2u);
  EXPECT_FLOAT_EQ(static_cast<float>(s.hi.x), 0.01f);
  EXPECT_TRUE(w.empty());
  // Far-field data, tristimulus colour, an unknown version: refused at their lines.
  const auto line_of_error = [&](const std::string& text) {
    write_bytes(d / "b.txt", text);
    try {
      open_rayset((d / "b.txt").string());
    } catch (const Error& e) {
      return std::make_pair(e.diagnostic().line, e.diagnostic().field);
    }
    return std::make_pair(0, std::string());
  };
  std::string far = head;
  far.replace(far.find("far_field_data: no"), 18, "far_field_data: yes");
  EXPECT_EQ(line_of_error(far + "lt_startofdata\nlt_endofdata\n"), std::make_pair(4, std::string("lt_far_field_data")));
  std::string v3 = head;
  v3.replace(v3.find("2.0"), 3, "3.0");
  EXPECT_EQ(line_of_error(v3 + "lt_startofdata\nlt_endofdata\n"), std::make_pair(2, std::string("lt_rdf_version")));
  EXPECT_EQ(line_of_error(head + "lt_startofdata\n1 0 0 0 0 1 1\n"), std::make_pair(9, std::string("end of data")));
  EXPECT_EQ(line_of_error(head), std::make_pair(7, std::string("lt_startofdata")));
  fs::remove_all(d);
}
