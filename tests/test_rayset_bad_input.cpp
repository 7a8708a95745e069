// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Hostile and broken ray files (hard-cases.md §6, items 17-20): truncation at every kind of offset, wrong
// magic and versions, flags that contradict each other, counts larger than the file or overflowing, huge
// text and table sizes, NaN/zero directions and bad fluxes, broken text files, and a mutation sweep. Every
// failure must be a lumx::Error naming the file, the byte offset (or line) and the field — never a crash,
// a hang or an allocation sized by a header count.
#include "rayset_test_support.h"

#include <lumx/io/rayset_io.h>

#include <gtest/gtest.h>

#include <functional>
#include <random>

using namespace lumx;
using namespace lumx_rays;

namespace {

/// Opens and streams every ray; returns the error's diagnostic, or nullopt if the file was read.
std::optional<Diagnostic> read_error(const fs::path& p, std::vector<Diagnostic>* warnings = nullptr,
                                     RaysetReadOptions o = {}) {
  try {
    if (warnings) o.warnings = [warnings](const Diagnostic& d) { warnings->push_back(d); };
    auto src = open_rayset(p.string(), o);
    RayChunk c;
    while (src->next(c, 4096)) {
    }
  } catch (const Error& e) {
    return e.diagnostic();
  }
  return std::nullopt;
}

/// The located-error contract: the file, a byte offset or line, a field, a message.
void expect_located(const Diagnostic& d, const fs::path& p) {
  EXPECT_EQ(d.file, p.string());
  EXPECT_TRUE(d.byte_offset >= 0 || d.line > 0) << d.str();
  EXPECT_FALSE(d.field.empty()) << d.str();
  EXPECT_FALSE(d.message.empty()) << d.str();
  EXPECT_EQ(d.severity, Severity::error);
}

/// A TM-25 with a spectral table, two additional columns and additional text: every preamble block.
Tm25Spec full_spec() {
  Tm25Spec s;
  s.spectral = 3;
  s.lambda_min = 400, s.lambda_max = 700;
  s.tables = {{{400, 0.5f}, {500, 1}, {550, 0.9f}, {600, 0.4f}, {700, 0.1f}}};  // 4 + 40 bytes, padded to 64
  s.column_names = {"temperature", "id"};
  s.additional_text = "measured 2016";  // 13 characters: 52 bytes, padded to 64
  for (int i = 0; i < 4; ++i) s.rows.push_back({float(i), 1, 2, 0, 0, 1, 0.25f, 300.0f + i, float(i)});
  return s;
}

std::string lighttools_binary(std::uint32_t major, std::uint32_t type, std::uint32_t far, std::uint32_t colour,
                              std::uint32_t units, const std::vector<std::vector<float>>& rows, bool end = true) {
  std::string b(44, '\0');
  std::memcpy(&b[0], "LTRF", 4);
  put32(b, 4, major);
  put32(b, 12, type);
  put32(b, 16, far);
  put32(b, 20, colour);
  put32(b, 24, units);
  putf(b, 40, 1.0f);
  for (const auto& r : rows)
    for (float v : r) appendf(b, v);
  if (end) b += "LTRFEND";
  return b;
}

std::string zemax_binary(std::uint32_t rays, std::uint32_t units, std::int32_t format, std::int32_t flux_type,
                         const std::vector<std::vector<float>>& rows) {
  std::string b(208, '\0');
  puti(b, 0, 1010);
  put32(b, 4, rays);
  std::memcpy(&b[8], "test", 4);
  putf(b, 108, 1), putf(b, 112, 1), putf(b, 116, 0.55f);
  put32(b, 136, units);
  puti(b, 192, format);
  puti(b, 196, flux_type);
  for (const auto& r : rows)
    for (float v : r) appendf(b, v);
  return b;
}

}  // namespace

TEST(RaysetBadInput, Tm25TruncatedAnywhereIsALocatedError) {
  const fs::path d = scratch("trunc");
  const std::string full = build_tm25(full_spec());
  // Layout of full_spec(): preamble 36288, table block 64, names 1024, text 64, rays 4 x 9 floats.
  const std::size_t table_at = 36288, names_at = table_at + 64, text_at = names_at + 1024, rays_at = text_at + 64;
  ASSERT_EQ(full.size(), rays_at + 4 * 36);
  const fs::path whole = d / "whole.tm25ray";
  write_bytes(whole, full);
  std::vector<Diagnostic> w;
  ASSERT_FALSE(read_error(whole, &w)) << read_error(whole)->str();
  EXPECT_TRUE(w.empty());

  std::vector<std::size_t> cuts;
  for (std::size_t L = 0; L < 300; ++L) cuts.push_back(L);
  for (std::size_t L = 300; L < table_at; L += 997) cuts.push_back(L);
  for (std::size_t L = table_at; L < full.size(); L += 3) cuts.push_back(L);
  const fs::path p = d / "cut.tm25ray";
  for (std::size_t L : cuts) {
    SCOPED_TRACE("truncated to " + std::to_string(L) + " bytes");
    write_bytes(p, full.substr(0, L));
    const auto e = read_error(p);
    ASSERT_TRUE(e);
    expect_located(*e, p);
    EXPECT_LE(e->byte_offset, static_cast<std::int64_t>(L));
    // Where the cut is tells which field must be named.
    std::pair<std::int64_t, std::string> want;
    if (L < 4)
      want = {0, "file type (4.7.1.1)"};
    else if (L < 8)
      want = {4, "version (4.7.1.2)"};
    else if (L < 12)
      want = {8, "creation method (4.7.1.3)"};
    else if (L < 16)
      want = {12, "total luminous flux (4.7.1.4)"};
    else if (L < 20)
      want = {16, "total radiant flux (4.7.1.5)"};
    else if (L < 28)
      want = {20, "number of rays (4.7.1.6)"};
    else if (L < 56)
      want = {28, "creation date (4.7.1.7)"};
    else if (L < 88)
      want = {static_cast<std::int64_t>(L / 4 * 4), ""};  // the i32/f32 field cut
    else if (L < 256)
      want = {88, "reserved (4.7.1.16)"};
    else if (L < 288)
      want = {static_cast<std::int64_t>(L / 4 * 4), ""};  // a flag
    else if (L < table_at)
      want = {static_cast<std::int64_t>(288 + (L - 288) / 4000 * 4000), ""};  // a text field
    else if (L < table_at + 44)
      want = {static_cast<std::int64_t>(table_at), "spectral table 1 (4.7.4)"};
    else if (L < names_at)
      want = {static_cast<std::int64_t>(table_at + 44), "spectral table padding (4.7.4)"};
    else if (L < text_at)
      want = {80, "number of additional items (4.7.1.14)"};
    else if (L < rays_at)
      want = {84, "additional text size (4.7.1.15)"};
    else
      want = {20, "number of rays (4.7.1.6)"};
    EXPECT_EQ(e->byte_offset, want.first) << e->str();
    if (!want.second.empty()) {
      EXPECT_EQ(e->field, want.second) << e->str();
    }
    if (L >= 288 && L < table_at) {
      EXPECT_NE(e->field.find("(4.7.3."), std::string::npos) << e->str();
    }
  }
  fs::remove_all(d);
}

TEST(RaysetBadInput, Tm25HeaderFieldsAndConsistencyRules) {
  const fs::path d = scratch("tm25hdr");
  const fs::path p = d / "bad.tm25ray";
  struct Case {
    const char* what;
    std::function<void(Tm25Spec&)> mutate;
    std::int64_t offset;
    const char* field;
    const char* in_message = "";
  };
  const auto plain = [] {
    Tm25Spec s;
    s.rows = three_rows();
    return s;
  };
  const std::vector<Case> cases = {
      {"wrong magic", [](Tm25Spec& s) { std::memcpy(s.magic, "TM26", 4); }, 0, "file type (4.7.1.1)"},
      {"TM-25-20 version", [](Tm25Spec& s) { s.version = 2020; }, 4, "version (4.7.1.2)", "2020 is not supported"},
      {"version 0", [](Tm25Spec& s) { s.version = 0; }, 4, "version (4.7.1.2)"},
      {"negative luminous flux", [](Tm25Spec& s) { s.phi_v = -1; }, 12, "total luminous flux (4.7.1.4)"},
      {"infinite radiant flux", [](Tm25Spec& s) { s.phi_e = INFINITY; }, 16, "total radiant flux (4.7.1.5)"},
      {"2^40 rays", [](Tm25Spec& s) { s.rays_field = std::uint64_t(1) << 40; }, 20, "number of rays (4.7.1.6)"},
      {"2^63 rays", [](Tm25Spec& s) { s.rays_field = std::uint64_t(1) << 63; }, 20, "number of rays (4.7.1.6)"},
      {"one ray too many", [](Tm25Spec& s) { s.rays_field = 4; }, 20, "number of rays (4.7.1.6)", "the file has 84"},
      {"rays just under the limit but not in the file",
       [](Tm25Spec& s) { s.rays_field = (std::uint64_t(1) << 34) - 1; }, 20, "number of rays (4.7.1.6)"},
      {"spectral identifier 5", [](Tm25Spec& s) { s.spectral = 5; }, 60, "spectral data identifier (4.7.1.9)"},
      {"spectral identifier -1", [](Tm25Spec& s) { s.spectral = -1; }, 60, "spectral data identifier (4.7.1.9)"},
      {"single wavelength 0", [](Tm25Spec& s) { s.spectral = 1; }, 64, "single wavelength (4.7.1.10)"},
      {"negative table count", [](Tm25Spec& s) { s.tables_field = -1; }, 76, "number of spectral tables (4.7.1.13)"},
      {"identifier 3 without a table", [](Tm25Spec& s) { s.spectral = 3; }, 76, "number of spectral tables (4.7.1.13)"},
      {"2^31-1 tables", [](Tm25Spec& s) { s.tables_field = 0x7FFFFFFF; }, 76, "number of spectral tables (4.7.1.13)"},
      {"negative additional items", [](Tm25Spec& s) { s.additional_field = -5; }, 80,
       "number of additional items (4.7.1.14)"},
      {"2^31-1 additional items", [](Tm25Spec& s) { s.additional_field = 0x7FFFFFFF; }, 80,
       "number of additional items (4.7.1.14)"},
      {"1000 additional items not in the file", [](Tm25Spec& s) { s.additional_field = 1000; }, 80,
       "number of additional items (4.7.1.14)", "the file ends"},
      {"text size not a multiple of 32", [](Tm25Spec& s) { s.text_size_field = 33; }, 84,
       "additional text size (4.7.1.15)"},
      {"negative text size", [](Tm25Spec& s) { s.text_size_field = -32; }, 84, "additional text size (4.7.1.15)"},
      {"huge text size", [](Tm25Spec& s) { s.text_size_field = 0x7FFFFFE0; }, 84, "additional text size (4.7.1.15)"},
      {"16 MiB of text not in the file", [](Tm25Spec& s) { s.text_size_field = 16 << 20; }, 84,
       "additional text size (4.7.1.15)", "past the end"},
      {"position flag 0", [](Tm25Spec& s) { s.flags[0] = 0; }, 256, "position flag (4.7.2.1)"},
      {"direction flag 2", [](Tm25Spec& s) { s.flags[1] = 2; }, 260, "direction flag (4.7.2.2)"},
      {"radiant flag 2", [](Tm25Spec& s) { s.flags[2] = 2; }, 264, "radiant flux flag (4.7.2.3)"},
      {"no flux flag", [](Tm25Spec& s) { s.flags[2] = 0; }, 272, "luminous flux flag (4.7.2.5)"},
      {"identifier 2 without wavelength flag", [](Tm25Spec& s) { s.spectral = 2; }, 268, "wavelength flag (4.7.2.4)"},
      {"identifier 2 with luminous flux", [](Tm25Spec& s) { s.spectral = 2, s.flags[3] = 1, s.flags[4] = 1; }, 272,
       "luminous flux flag (4.7.2.5)"},
      {"identifier 4 with luminous flux only",
       [](Tm25Spec& s) {
         s.spectral = 4, s.flags[2] = 0, s.flags[4] = 1, s.flags[7] = 1, s.tables = {{{500, 1}}};
       },
       272, "luminous flux flag (4.7.2.5)"},
      {"spectrum index flag without identifier 4", [](Tm25Spec& s) { s.flags[7] = 1; }, 284,
       "spectrum index flag (4.7.2.8)"},
      {"identifier 4 without spectrum index flag",
       [](Tm25Spec& s) {
         s.spectral = 4, s.tables = {{{500, 1}}};
       },
       284, "spectrum index flag (4.7.2.8)"},
      {"tristimulus without luminous flux", [](Tm25Spec& s) { s.flags[6] = 1; }, 280, "tristimulus flag (4.7.2.7)"},
      {"tristimulus with a spectral identifier",
       [](Tm25Spec& s) { s.flags[4] = 1, s.flags[6] = 1, s.spectral = 1, s.lambda = 555; }, 280,
       "tristimulus flag (4.7.2.7)"},
      {"Stokes without radiant flux", [](Tm25Spec& s) { s.flags[2] = 0, s.flags[4] = 1, s.flags[5] = 1; }, 276,
       "Stokes flag (4.7.2.6)"},
      {"empty spectral table", [](Tm25Spec& s) { s.spectral = 3, s.tables = {{}}; }, 36288, "spectral table 1 (4.7.4)"},
      {"table count past the file",
       [](Tm25Spec& s) {
         s.spectral = 3, s.tables = {{{500, 1}}};
         s.rows.clear();
       },
       36288, "spectral table 1 (4.7.4)"},
      {"negative wavelength in a table",
       [](Tm25Spec& s) {
         s.spectral = 3, s.tables = {{{500, 1}, {-1, 1}}};
       },
       36300, "spectral table 1 (4.7.4)"},
      {"NaN weight in a table",
       [](Tm25Spec& s) {
         s.spectral = 3, s.tables = {{{500, NAN}}};
       },
       36296, "spectral table 1 (4.7.4)"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    Tm25Spec s = plain();
    c.mutate(s);
    std::string bytes = build_tm25(s);
    if (std::string(c.what) == "table count past the file") {
      bytes.resize(36288 + 4);  // the count says 1 pair, the file ends right after it
    }
    write_bytes(p, bytes);
    const auto e = read_error(p);
    ASSERT_TRUE(e) << "read without error";
    expect_located(*e, p);
    EXPECT_EQ(e->byte_offset, c.offset) << e->str();
    EXPECT_EQ(e->field, c.field) << e->str();
    EXPECT_NE(e->message.find(c.in_message), std::string::npos) << e->str();
  }
  fs::remove_all(d);
}

TEST(RaysetBadInput, Tm25WarningsAreNotErrors) {
  const fs::path d = scratch("tm25warn");
  const fs::path p = d / "w.tm25ray";
  // Trailing bytes, creation method -1 (ams files), an empty column name, a non-unit direction,
  // a header flux that disagrees with the rays: all readable, each a warning.
  Tm25Spec s;
  s.method = -1;
  s.phi_e = 5;
  s.column_names = {""};
  s.rows = {{1, 2, 3, 0, 0, 2, 0.5f, 7}, {0, 0, 0, 1, 0, 0, 0.25f, 8}};
  std::string bytes = build_tm25(s) + "junk";
  write_bytes(p, bytes);
  std::vector<Diagnostic> w;
  ASSERT_FALSE(read_error(p, &w));
  std::vector<std::string> fields;
  for (const auto& x : w) {
    EXPECT_EQ(x.severity, Severity::warning);
    fields.push_back(x.field);
  }
  EXPECT_EQ(fields, (std::vector<std::string>{"creation method (4.7.1.3)", "additional column 1 name (4.7.5)",
                                              "ray data", "direction", "total radiant flux (4.7.1.5)"}));
  EXPECT_EQ(w[2].byte_offset, static_cast<std::int64_t>(bytes.size() - 4));
  // NaN header flux is legal and gives no flux warning.
  s.phi_e = NAN;
  s.method = 0;
  s.column_names = {"x2"};
  write_bytes(p, build_tm25(s));
  w.clear();
  ASSERT_FALSE(read_error(p, &w));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].field, "direction");
  fs::remove_all(d);
}

TEST(RaysetBadInput, Tm25BadRaysAreLocatedAtTheirBytes) {
  const fs::path d = scratch("tm25rays");
  const fs::path p = d / "r.tm25ray";
  const std::int64_t r2 = 36288 + 2 * 28;  // third ray's record
  struct Case {
    const char* what;
    std::function<void(Tm25Spec&)> mutate;
    std::int64_t offset;
    const char* field;
  };
  const std::vector<Case> cases = {
      {"NaN direction", [](Tm25Spec& s) { s.rows[2][4] = NAN; }, r2 + 12, "ray direction kx ky kz (4.7.2.2)"},
      {"zero direction", [](Tm25Spec& s) { s.rows[2][3] = s.rows[2][4] = s.rows[2][5] = 0; }, r2 + 12,
       "ray direction kx ky kz (4.7.2.2)"},
      {"infinite direction", [](Tm25Spec& s) { s.rows[2][5] = -INFINITY; }, r2 + 12,
       "ray direction kx ky kz (4.7.2.2)"},
      {"NaN position", [](Tm25Spec& s) { s.rows[2][1] = NAN; }, r2, "ray position x y z (4.7.2.1)"},
      {"NaN flux", [](Tm25Spec& s) { s.rows[2][6] = NAN; }, r2 + 24, "radiant flux (4.7.2.3)"},
      {"negative flux", [](Tm25Spec& s) { s.rows[2][6] = -1e-3f; }, r2 + 24, "radiant flux (4.7.2.3)"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    Tm25Spec s;
    s.rows = three_rows();
    c.mutate(s);
    write_bytes(p, build_tm25(s));
    const auto e = read_error(p);
    ASSERT_TRUE(e);
    expect_located(*e, p);
    EXPECT_EQ(e->byte_offset, c.offset) << e->str();
    EXPECT_EQ(e->field, c.field) << e->str();
    EXPECT_NE(e->message.find("ray 3:"), std::string::npos) << e->str();
  }
  // Per-ray wavelength (identifier 2), Stokes values and spectrum indices are checked too.
  Tm25Spec wl;
  wl.spectral = 2, wl.flags[3] = 1, wl.lambda_min = 400, wl.lambda_max = 700;
  wl.rows = {{0, 0, 0, 0, 0, 1, 1, 500}, {0, 0, 0, 0, 0, 1, 1, 0}};
  write_bytes(p, build_tm25(wl));
  auto e = read_error(p);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->byte_offset, 36288 + 32 + 28);
  EXPECT_EQ(e->field, "wavelength (4.7.2.4)");
  Tm25Spec stokes;
  stokes.flags[5] = 1;
  stokes.rows = {{0, 0, 0, 0, 0, 1, 1, 0.5f, -0.5f, 1.5f, 0, 0, 1}};
  write_bytes(p, build_tm25(stokes));
  e = read_error(p);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->byte_offset, 36288 + 4 * 9);
  EXPECT_EQ(e->field, "Stokes parameters (4.7.2.6)");
  Tm25Spec index;
  index.spectral = 4, index.flags[7] = 1, index.tables = {{{450, 1}}, {{550, 1}}};
  index.rows = {{0, 0, 0, 0, 0, 1, 1, 2}, {0, 0, 0, 0, 0, 1, 1, 3}};
  const std::string ib = build_tm25(index);
  write_bytes(p, ib);
  e = read_error(p);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->byte_offset, static_cast<std::int64_t>(ib.size() - 4));
  EXPECT_EQ(e->field, "spectrum index (4.7.2.8)");
  // Additional columns are skipped: the flux is the right column whatever follows it.
  Tm25Spec extra = full_spec();
  write_bytes(p, build_tm25(extra));
  auto src = open_rayset(p.string());
  const RayChunk c = read_all_rays(*src, 10);
  ASSERT_EQ(c.size(), 4u);
  EXPECT_EQ(c.flux[3], 0.25f);
  EXPECT_FLOAT_EQ(c.x[3], 0.003f);
  EXPECT_EQ(src->info().text.at("additional column 1"), "temperature");
  EXPECT_EQ(src->info().text.at("additional text"), "measured 2016");
  fs::remove_all(d);
}

TEST(RaysetBadInput, LightToolsAndZemaxBinaries) {
  const fs::path d = scratch("vendorbin");
  const fs::path p = d / "v.ray";
  const std::vector<std::vector<float>> rows = {{1, 2, 3, 0, 0, 1, 0.5f}, {0, 0, 0, 1, 0, 0, 0.5f}};
  struct Case {
    const char* what;
    std::string bytes;
    std::int64_t offset;
    const char* field;
  };
  std::string bad_dir = lighttools_binary(2, 0, 0, 0, 1, rows);
  putf(bad_dir, 44 + 28 + 16, NAN);
  std::string zshort = zemax_binary(2, 4, 0, 0, rows);
  zshort.resize(150);
  const std::vector<Case> cases = {
      {"LT no end marker", lighttools_binary(2, 0, 0, 0, 1, rows, false), 44 + 56 - 7, "end marker"},
      {"LT truncated header", lighttools_binary(2, 0, 0, 0, 1, rows).substr(0, 30), 28, "origin x"},
      {"LT polarisation", lighttools_binary(3, 0, 0, 0, 1, rows), 4, "major version"},
      {"LT data type 2", lighttools_binary(2, 2, 0, 0, 1, rows), 12, "data type"},
      {"LT far field", lighttools_binary(2, 0, 1, 0, 1, rows), 16, "far-field flag"},
      {"LT tristimulus", lighttools_binary(2, 0, 0, 1, 1, rows), 20, "colour information"},
      {"LT unit code 9", lighttools_binary(2, 0, 0, 0, 9, rows), 24, "length units"},
      {"LT partial ray", lighttools_binary(2, 0, 0, 2, 1, rows), 44 + 32, "ray data"},  // 7 floats, 8 expected
      {"LT NaN direction", bad_dir, 44 + 28 + 12, "ray direction"},
      {"Zemax count past the file", zemax_binary(3, 4, 0, 0, rows), 4, "number of rays"},
      {"Zemax count 2^32-1", zemax_binary(0xFFFFFFFFu, 4, 0, 0, rows), 4, "number of rays"},
      {"Zemax format 1", zemax_binary(2, 4, 1, 0, rows), 192, "ray format type"},
      {"Zemax flux type 2", zemax_binary(2, 4, 0, 2, rows), 196, "flux type"},
      {"Zemax spectral in lm", zemax_binary(2, 4, 2, 1, rows), 196, "flux type"},
      {"Zemax unit code 5", zemax_binary(2, 5, 0, 0, rows), 136, "dimension units"},
      {"Zemax short header", zshort, 140, "location, rotation and scale"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    write_bytes(p, c.bytes);
    const auto e = read_error(p);
    ASSERT_TRUE(e) << "read without error";
    expect_located(*e, p);
    EXPECT_EQ(e->byte_offset, c.offset) << e->str();
    EXPECT_EQ(e->field, c.field) << e->str();
  }
  // Units: LightTools code 3 is metres, Zemax code 1 inches.
  write_bytes(p, lighttools_binary(2, 1, 0, 0, 3, rows));
  auto src = open_rayset(p.string());
  EXPECT_EQ(src->info().quantity, PhotometricQuantity::photometric);
  EXPECT_EQ(read_all_rays(*src, 10).x[0], 1.0f);
  write_bytes(p, zemax_binary(2, 1, 0, 1, rows));
  src = open_rayset(p.string());
  EXPECT_EQ(src->info().source_length_unit, "in");
  EXPECT_FLOAT_EQ(read_all_rays(*src, 10).y[0], 0.0508f);
  // LightTools system units: read as the default unit, with a warning.
  write_bytes(p, lighttools_binary(2, 0, 0, 0, 0, rows));
  std::vector<Diagnostic> w;
  ASSERT_FALSE(read_error(p, &w));
  ASSERT_GE(w.size(), 1u);
  EXPECT_EQ(w[0].field, "length units");
  fs::remove_all(d);
}

TEST(RaysetBadInput, TextFormatsAreLocatedByLine) {
  const fs::path d = scratch("text");
  const fs::path p = d / "t.txt";
  struct Case {
    const char* what;
    std::string text;
    int line;
    const char* field;
  };
  const std::string lt =
      "# LightTools\nlt_rdf_version: 2.0\nlt_datatype: radiant_power\nlt_length_units: millimeters\nlt_startofdata\n";
  const std::vector<Case> cases = {
      {"plain: no header", "# lumx rays\n0 0 0 0 0 1 1\n", 1, "header"},
      {"plain: unknown unit", "# lumx-rays length=furlong flux=lm\n", 1, "length"},
      {"plain: no flux unit", "# lumx-rays length=mm\n0 0 0 0 0 1\n", 1, "flux"},
      {"plain: bad flux unit", "# lumx-rays length=mm flux=cd\n", 1, "flux"},
      {"plain: not key=value", "# lumx-rays length=mm flux=lm total\n", 1, "header"},
      {"plain: nan", "# lumx-rays length=mm flux=lm\n0 0 0 0 0 1 1\n\n0 0 0 nan 0 1 1\n", 4, "ray"},
      {"plain: inf", "# lumx-rays length=mm flux=lm\n0 0 0 0 0 1 1\n0 0 0 0 0 1 inf\n", 3, "ray"},
      {"plain: word", "# lumx-rays length=mm flux=lm\n0 0 0 0 0 1 1\n0 0 x 0 0 1 1\n", 3, "ray"},
      {"plain: column count changes", "# lumx-rays length=mm flux=lm\n0 0 0 0 0 1 1\n0 0 0 0 0 1\n", 3, "ray"},
      {"plain: too many numbers", "# lumx-rays length=mm flux=lm\n0 0 0 0 0 1 1 1 1 1\n", 2, "ray"},
      {"plain: zero direction", "# lumx-rays length=mm flux=lm\n0 0 0 0 0 1 1\n1 2 3 0 0 0 1\n", 3, "direction"},
      {"plain: negative flux", "# lumx-rays length=mm flux=lm\n1 2 3 0 0 1 -2\n", 2, "flux"},
      {"plain: zero wavelength", "# lumx-rays length=mm flux=W\n1 2 3 0 0 1 2 0\n", 2, "wavelength"},
      {"plain: overflowing number", "# lumx-rays length=mm flux=lm\n1e39 2 3 0 0 1 2\n", 2, "ray"},
      {"LT: bad number", lt + "1 2 3 0 0 1 abc\nlt_endofdata\n", 6, "ray"},
      {"LT: missing end", lt + "1 2 3 0 0 1 1\n", 6, "end of data"},
      {"LT: header line without colon", "# LightTools\nlt_rdf_version: 2.0\nnonsense\nlt_startofdata\n", 3, "header"},
      {"LT: unknown datatype", "lt_rdf_version: 2.0\nlt_datatype: candles\nlt_startofdata\nlt_endofdata\n", 2,
       "lt_datatype"},
      {"LT: unknown unit",
       "lt_rdf_version: 2.0\nlt_datatype: radiant_power\nlt_length_units: cubits\nlt_startofdata\nlt_endofdata\n", 3,
       "lt_length_units"},
      {"Zemax: count mismatch", "3 4 0 0 0 0 0\n1 2 3 0 0 1 1\n1 2 3 0 0 1 1\n", 1, "number of rays"},
      {"Zemax: unit code 7", "1 7 0 0 0 0 0\n1 2 3 0 0 1 1\n", 1, "dimension units"},
      // Found by the fuzzer: a code beyond int64 was cast before it was checked (undefined behaviour).
      {"Zemax: unit code 5e21", "1 5000000000000000000008 0 0 0 0 0\n1 2 3 0 0 1 1\n", 1, "dimension units"},
      {"Zemax: unit code -1e300", "1 -1e300 0 0 0 0 0\n1 2 3 0 0 1 1\n", 1, "dimension units"},
      {"Zemax: fractional count", "1.5 4 0 0 0 0 0\n1 2 3 0 0 1 1\n", 1, "number of rays"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    write_bytes(p, c.text);
    RaysetReadOptions o;
    if (std::string(c.what).rfind("plain", 0) == 0) o.format = RaysetFormat::plain_text;
    if (std::string(c.what).rfind("LT", 0) == 0) o.format = RaysetFormat::lighttools_text;
    if (std::string(c.what).rfind("Zemax", 0) == 0) o.format = RaysetFormat::zemax_text;
    const auto e = read_error(p, nullptr, o);
    ASSERT_TRUE(e) << "read without error";
    EXPECT_EQ(e->file, p.string());
    EXPECT_EQ(e->line, c.line) << e->str();
    EXPECT_EQ(e->field, c.field) << e->str();
  }
  // A line longer than the limit is refused at its line, without reading it whole.
  write_bytes(p, "# lumx-rays length=mm flux=lm\n0 0 0 0 0 1 1\n" + std::string(200000, '1') + "\n");
  const auto e = read_error(p);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->line, 3);
  EXPECT_EQ(e->field, "line");
  fs::remove_all(d);
}

TEST(RaysetBadInput, MutationSweepNeverCrashes) {
  const fs::path d = scratch("mutate");
  std::vector<std::pair<std::string, std::string>> seeds = {
      {"a.tm25ray", build_tm25(full_spec())},
      {"b.ray", lighttools_binary(2, 0, 0, 2, 1, {{1, 2, 3, 0, 0, 1, 0.5f, 550}, {0, 0, 0, 1, 0, 0, 0.5f, 450}})},
      {"c.dat", zemax_binary(2, 4, 2, 0, {{1, 2, 3, 0, 0, 1, 0.5f, 0.55f}, {0, 0, 0, 1, 0, 0, 0.5f, 0.45f}})},
      {"d.rays", "# lumx-rays length=mm flux=lm total=2\n1 2 3 0 0 1 1\n# c\n4 5 6 0 1 0 1\n"},
      {"e.txt",
       "# LightTools\nlt_rdf_version: 2.0\nlt_datatype: radiant_power\nlt_color_info: wavelength\n"
       "lt_length_units: millimeters\nlt_startofdata\n1 2 3 0 0 1 1 550\nlt_endofdata\n"},
      {"f.txt", "2 4 0 0 0 0 0\n1 2 3 0 0 1 1\n1 2 3 0 1 0 1\n"},
  };
  std::mt19937 rng(12345);
  const std::int32_t specials[] = {0, -1, 1, 2, 3, 4, 7, 8, 32, 33, 1010, 2013, 0x7FFFFFFF, INT32_MIN, 0x7FC00000};
  int errors = 0, reads = 0;
  for (const auto& [name, seed] : seeds) {
    const fs::path p = d / name;
    for (int k = 0; k < 400; ++k) {
      std::string b = seed;
      const int edits = 1 + static_cast<int>(rng() % 3);
      for (int e = 0; e < edits && !b.empty(); ++e) {
        // Bias towards the header, where counts and flags live.
        const std::size_t limit = rng() % 2 ? std::min<std::size_t>(b.size(), 320) : b.size();
        const std::size_t at = rng() % limit;
        switch (rng() % 4) {
          case 0:
            b[at] = static_cast<char>(rng());
            break;
          case 1:
            if (at / 4 * 4 + 4 <= b.size()) puti(b, at / 4 * 4, specials[rng() % 15]);  // an aligned field
            break;
          case 2:
            b.resize(at);
            break;
          default:
            b.insert(at, std::string(1 + rng() % 8, static_cast<char>(rng())));
            break;
        }
      }
      write_bytes(p, b);
      try {
        auto src = open_rayset(p.string());
        const RaysetSummary s = summarize_rays(*src, 1000);
        EXPECT_EQ(s.rays, src->info().ray_count);
        ++reads;
      } catch (const Error& e) {
        EXPECT_EQ(e.diagnostic().file, p.string());
        EXPECT_FALSE(e.diagnostic().field.empty()) << e.what();
        ++errors;
      } catch (const std::exception& e) {
        ADD_FAILURE() << name << " mutation " << k << ": non-lumx exception " << e.what();
      }
    }
  }
  std::printf("  mutation sweep: %d read, %d refused with a located error\n", reads, errors);
  EXPECT_GT(errors, 500);
  fs::remove_all(d);
}
