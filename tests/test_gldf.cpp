// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// GLDF containers: every shared container listed, checked against the GLDF XSD and its photometry read;
// hostile archives (path traversal, zip bombs, oversized entries) refused before extraction; findings
// located as container.gldf!/entry:line.
#include <lumx/io/gldf_io.h>
#include <lumx/photometry/intensity_table.h>

#include <gtest/gtest.h>
#include <zip.h>

#include "test_support.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

using namespace lumx;
namespace fs = std::filesystem;

namespace {

fs::path gldf_dir() {
  const auto root = lumx_test::shared_dir();
  return root.empty() ? fs::path() : root / "data" / "gldf";
}

std::vector<fs::path> shared_containers() {
  std::vector<fs::path> out;
  if (gldf_dir().empty() || !fs::exists(gldf_dir() / "containers")) return out;
  for (const auto& e : fs::directory_iterator(gldf_dir() / "containers"))
    if (e.path().extension() == ".gldf") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

/// Writes a ZIP with the given entries (name, bytes), deflated, or stored when `store` (so that the entry's
/// bytes appear as they are in the archive).
void write_zip(const fs::path& path, const std::vector<std::pair<std::string, std::string>>& entries,
               bool store = false) {
  fs::remove(path);
  int err = 0;
  zip_t* z = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &err);
  ASSERT_NE(z, nullptr);
  for (const auto& [name, bytes] : entries) {
    zip_source_t* s = zip_source_buffer(z, bytes.data(), bytes.size(), 0);
    ASSERT_NE(s, nullptr);
    const zip_int64_t index = zip_file_add(z, name.c_str(), s, ZIP_FL_ENC_UTF_8);
    ASSERT_GE(index, 0) << name;
    if (store) {
      ASSERT_EQ(zip_set_file_compression(z, static_cast<zip_uint64_t>(index), ZIP_CM_STORE, 0), 0);
    }
  }
  ASSERT_EQ(zip_close(z), 0);
}

const char* kProduct = R"(<?xml version="1.0" encoding="UTF-8"?>
<Root>
  <Header>
    <Manufacturer>lumx tests</Manufacturer>
    <FormatVersion major="1" minor="0" pre-release="3" />
  </Header>
  <GeneralDefinitions>
    <Files>
      <File id="f1" contentType="ldc/eulumdat" type="localFileName">a.ldt</File>
    </Files>
    <Photometries>
      <Photometry id="p1"><PhotometryFileReference fileId="f1" /></Photometry>
    </Photometries>
    <Emitters>
      <Emitter id="e1"><FixedLightEmitter><PhotometryReference photometryId="p1" /></FixedLightEmitter></Emitter>
    </Emitters>
  </GeneralDefinitions>
  <ProductDefinitions>
    <ProductMetaData><Name><Locale language="en">Test</Locale></Name></ProductMetaData>
    <Variants>
      <Variant id="v1"><Geometry><EmitterReference emitterId="e1" /></Geometry></Variant>
    </Variants>
  </ProductDefinitions>
</Root>
)";

std::string fixture_ldt() { return lumx_test::read_text(lumx_test::data_dir() / "ldt" / "isym2_point.ldt"); }

Diagnostic error_of(const fs::path& p, const GldfReadOptions& o = {}) {
  try {
    (void)read_gldf(p.string(), o);
  } catch (const Error& e) {
    return e.diagnostic();
  }
  ADD_FAILURE() << "no error for " << p;
  return {};
}

}  // namespace

TEST(Gldf, EverySharedContainerIsListedCheckedAndItsPhotometryRead) {
  const auto containers = shared_containers();
  if (containers.empty()) LUMX_SKIP_WITHOUT_SHARED("data/gldf/containers");
  const std::string xsd = (gldf_dir() / "xsd" / "gldf.xsd").string();
  std::size_t photometry_files = 0;
  for (const auto& path : containers) {
    SCOPED_TRACE(path.string());
    const GldfContainer c = read_gldf(path.string());
    EXPECT_FALSE(c.product_name.empty());
    EXPECT_FALSE(c.variants.empty());
    EXPECT_FALSE(c.emitters.empty());
    for (const auto& f : c.files) {
      if (f.content_type.rfind("ldc/", 0) != 0) continue;
      ASSERT_FALSE(f.entry.empty()) << f.name;
      const Photometry p = read_gldf_photometry(c, f);
      EXPECT_GT(IntensityTable(p).flux_lm(), 0) << f.entry;
      EXPECT_EQ(p.source.file, path.string() + "!/" + f.entry);
      ++photometry_files;
    }
    // check: passes, or fails with findings located inside the container.
    for (const auto& d : check_gldf(path.string(), xsd)) {
      EXPECT_EQ(d.file.rfind(path.string() + "!/", 0), 0u) << d.str();
      if (d.severity == Severity::error) {
        EXPECT_GT(d.line, 0) << d.str();
      }
      if (d.field == "XSD") {
        EXPECT_EQ(d.file, path.string() + "!/product.xml") << d.str();
      }
    }
  }
  EXPECT_GE(photometry_files, 9u);  // 6 containers: 1 + 1 + 1 + 3 + 2 + 1 files
}

TEST(Gldf, ListsProductsVariantsEmittersAndTheirPhotometry) {
  if (shared_containers().empty()) LUMX_SKIP_WITHOUT_SHARED("data/gldf/containers");
  const GldfContainer c = read_gldf((gldf_dir() / "containers" / "SLV_-_Tria_2.gldf").string());
  EXPECT_EQ(c.manufacturer, "SLV");
  EXPECT_EQ(c.format_version, "1.0-rc.3");
  EXPECT_EQ(c.product_name, "NEW TRIA 2");
  EXPECT_EQ(c.product_number, "111352");
  EXPECT_EQ(c.photometries.size(), 3u);
  ASSERT_GE(c.emitters.size(), 5u);
  EXPECT_EQ(c.emitters[0].id, "em-n-n");
  EXPECT_EQ(c.emitters[0].photometry_ids, std::vector<std::string>{"LightEmitterNarrow"});
  ASSERT_GE(c.variants.size(), 2u);
  EXPECT_EQ(c.variants[0].emitter_ids, (std::vector<std::string>{"em-n-n", "em-w-c"}));
  EXPECT_EQ(c.variants[0].geometry_id, "ModelGeometry");
  const auto l3d = std::find_if(c.files.begin(), c.files.end(), [](const GldfFile& f) { return f.content_type == "geo/l3d"; });
  ASSERT_NE(l3d, c.files.end());
  EXPECT_EQ(l3d->entry, "geo/example_007.l3d");
  EXPECT_TRUE(c.findings.empty());
}

TEST(Gldf, XsdViolationsAndBadPhotometryAreLocatedInsideTheContainer) {
  if (shared_containers().empty()) LUMX_SKIP_WITHOUT_SHARED("data/gldf/xsd");
  const std::string xsd = (gldf_dir() / "xsd" / "gldf.xsd").string();
  const fs::path p = lumx_test::unique_temp_path("gldf_bad.gldf");
  std::string ldt = fixture_ldt();
  ldt = ldt.substr(0, ldt.size() / 2);  // truncated photometry
  std::string product = kProduct;
  product.replace(product.find("<Manufacturer>"), 0, "<Bogus/>\n    ");  // not in the schema (line 4)
  write_zip(p, {{"product.xml", product}, {"ldc/a.ldt", ldt}});
  const auto findings = check_gldf(p.string(), xsd);
  bool xsd_found = false, ldt_found = false;
  for (const auto& d : findings) {
    if (d.field == "XSD" && d.file == p.string() + "!/product.xml" && d.line == 4) xsd_found = true;
    if (d.file == p.string() + "!/ldc/a.ldt" && d.line > 0 && d.severity == Severity::error) ldt_found = true;
  }
  EXPECT_TRUE(xsd_found);
  EXPECT_TRUE(ldt_found);
  // A dangling reference is a finding at its line of product.xml.
  std::string dangling = kProduct;
  dangling.replace(dangling.find("photometryId=\"p1\""), 17, "photometryId=\"p9\"");
  write_zip(p, {{"product.xml", dangling}, {"ldc/a.ldt", fixture_ldt()}});
  const GldfContainer c = read_gldf(p.string());
  ASSERT_EQ(c.findings.size(), 1u);
  EXPECT_EQ(c.findings[0].field, "PhotometryReference");
  EXPECT_EQ(c.findings[0].line, 15);
  fs::remove(p);
}

TEST(Gldf, HostileArchivesAreRefusedBeforeExtraction) {
  const fs::path p = lumx_test::unique_temp_path("gldf_hostile.gldf");
  const std::string ldt = fixture_ldt();
  for (const char* name : {"../evil.ldt", "ldc/../../evil.ldt", "/etc/evil.ldt", "ldc\\evil.ldt", "C:/evil.ldt"}) {
    write_zip(p, {{"product.xml", kProduct}, {name, ldt}});
    const Diagnostic d = error_of(p);
    EXPECT_EQ(d.field, "entry name") << name << ": " << d.str();
    EXPECT_NE(d.file.find(std::string("!/") + name), std::string::npos) << d.str();
  }
  // A zip bomb: 4 MiB of zeros deflate to a few KiB.
  write_zip(p, {{"product.xml", kProduct}, {"ldc/a.ldt", std::string(4u << 20, '\0')}});
  EXPECT_EQ(error_of(p).field, "compression ratio");
  // Entries larger than the limits.
  GldfReadOptions small;
  small.limits.max_entry_bytes = 300;  // the LDT is 359 bytes
  write_zip(p, {{"product.xml", std::string(200, ' ') + "<Root/>"}, {"ldc/a.ldt", ldt}});
  const Diagnostic big = error_of(p, small);
  EXPECT_EQ(big.field, "entry size");
  EXPECT_EQ(big.file, p.string() + "!/ldc/a.ldt");
  small = {};
  small.limits.max_entries = 1;
  EXPECT_NE(error_of(p, small).message.find("entries exceed"), std::string::npos);
  // Not a ZIP; no product.xml.
  std::ofstream(p, std::ios::binary | std::ios::trunc) << "PK\x03\x04 not really";
  EXPECT_EQ(error_of(p).field, "ZIP");
  write_zip(p, {{"ldc/a.ldt", ldt}});
  EXPECT_EQ(error_of(p).field, "product.xml");
  fs::remove(p);
}

namespace {

std::string read_bytes(const fs::path& p) { return lumx_test::read_text(p); }
void write_bytes(const fs::path& p, const std::string& b) { std::ofstream(p, std::ios::binary | std::ios::trunc) << b; }

/// Offset of the `n`-th occurrence (from 0) of `needle` in `bytes`; fails the test if there is none.
std::size_t nth(const std::string& bytes, const std::string& needle, int n) {
  std::size_t at = bytes.find(needle);
  for (int i = 0; i < n && at != std::string::npos; ++i) at = bytes.find(needle, at + 1);
  EXPECT_NE(at, std::string::npos) << needle << " #" << n;
  return at;
}

}  // namespace

// Archive-level corruption (hard-cases.md §6 item 35): a CRC that does not match the data, a central
// directory that disagrees with a local header, two entries of the same name, and an entry count that
// disagrees with the directory. Each is a located error, at the archive or at the entry.
TEST(Gldf, CorruptedArchivesAreLocatedErrors) {
  const fs::path p = lumx_test::unique_temp_path("gldf_corrupt.gldf");
  const std::string ldt = fixture_ldt();
  write_zip(p, {{"product.xml", kProduct}, {"ldc/a.ldt", ldt}}, /*store=*/true);
  const std::string good = read_bytes(p);
  ASSERT_NO_THROW((void)read_gldf(p.string()));
  ASSERT_NO_THROW((void)read_gldf_entry(p.string(), "ldc/a.ldt"));

  // One changed byte in the stored data of the LDT: the CRC-32 no longer matches.
  std::string bad = good;
  const std::size_t data = good.find(ldt.substr(0, 40));
  ASSERT_NE(data, std::string::npos);
  bad[data + 10] ^= 0x01;
  write_bytes(p, bad);
  try {
    (void)read_gldf_entry(p.string(), "ldc/a.ldt");
    ADD_FAILURE() << "a CRC mismatch was read";
  } catch (const Error& e) {
    EXPECT_EQ(e.diagnostic().file, p.string() + "!/ldc/a.ldt") << e.what();
    EXPECT_NE(std::string(e.what()).find("CRC"), std::string::npos) << e.what();
  }

  // The local header names another file than the central directory ("ldc/a.ldt" → "ldc/b.ldt" in the
  // first occurrence, the local header): libzip's consistency check refuses the archive.
  bad = good;
  bad[nth(good, "ldc/a.ldt", 0) + 4] = 'b';
  write_bytes(p, bad);
  Diagnostic d = error_of(p);
  EXPECT_EQ(d.file, p.string()) << d.str();
  EXPECT_EQ(d.field, "ZIP") << d.str();

  // The local header's compressed size disagrees with the central directory's (local header: PK\3\4, the
  // compressed size at offset 18).
  bad = good;
  const std::size_t local = nth(good, std::string("PK\x03\x04", 4), 1);
  bad[local + 18] = static_cast<char>(bad[local + 18] + 1);
  write_bytes(p, bad);
  d = error_of(p);
  EXPECT_EQ(d.field, "ZIP") << d.str();

  // Two entries named product.xml, in both their local headers and the directory: refused, since readers
  // that take the first and readers that take the last would see different products.
  write_zip(p, {{"product.xml", kProduct}, {"product.xmX", "<Root/>"}, {"ldc/a.ldt", ldt}}, true);
  bad = read_bytes(p);
  for (std::size_t at = bad.find("product.xmX"); at != std::string::npos; at = bad.find("product.xmX", at))
    bad[at + 10] = 'l';
  write_bytes(p, bad);
  d = error_of(p);
  EXPECT_EQ(d.file, p.string()) << d.str();
  EXPECT_EQ(d.field, "ZIP") << d.str();
  EXPECT_NE(d.message.find("same name"), std::string::npos) << d.str();

  // The end-of-directory record's entry counts (offsets 8 and 10 after PK\5\6) one more, then one less,
  // than the directory holds.
  for (const int delta : {+1, -1}) {
    bad = good;
    const std::size_t end = nth(good, std::string("PK\x05\x06", 4), 0);
    bad[end + 8] = static_cast<char>(bad[end + 8] + delta);
    bad[end + 10] = static_cast<char>(bad[end + 10] + delta);
    write_bytes(p, bad);
    d = error_of(p);
    EXPECT_EQ(d.file, p.string()) << delta << ": " << d.str();
    EXPECT_EQ(d.field, "ZIP") << delta << ": " << d.str();
  }
  // Entry names with a control character are refused by name (hard-cases.md §6 item 33); libzip will not
  // write one, so the byte is patched into both headers of "ldc/aQ.ldt". (Other bytes below 0x20, such as
  // ESC, make libzip read a name without the UTF-8 flag as CP437, which maps them to printable characters.)
  for (const char control : {'\n', '\r', '\t', '\x7f'}) {
    write_zip(p, {{"product.xml", kProduct}, {"ldc/aQ.ldt", ldt}}, true);
    bad = read_bytes(p);
    for (std::size_t at = bad.find("ldc/aQ.ldt"); at != std::string::npos; at = bad.find("ldc/aQ.ldt", at)) bad[at + 5] = control;
    write_bytes(p, bad);
    d = error_of(p);
    EXPECT_EQ(d.field, "entry name") << int(control) << ": " << d.str();
  }
  // The data of an entry longer or shorter than both its headers state (the sizes changed in the local
  // header and the directory alike, the CRC left): an error at the entry when it is read, never a buffer
  // sized by the header and filled past its end (item 34).
  for (const int delta : {-1, +1}) {
    bad = good;
    const std::size_t local_ldt = nth(good, std::string("PK\x03\x04", 4), 1);
    const std::size_t central_ldt = nth(good, std::string("PK\x01\x02", 4), 1);
    for (const std::size_t size_field : {local_ldt + 22, central_ldt + 24}) {  // uncompressed size
      bad[size_field] = static_cast<char>(bad[size_field] + delta);
    }
    write_bytes(p, bad);
    try {
      (void)read_gldf_entry(p.string(), "ldc/a.ldt");
      ADD_FAILURE() << "an entry of the wrong size was read (" << delta << ")";
    } catch (const Error& e) {
      EXPECT_NE(e.diagnostic().file.find(p.string()), std::string::npos) << e.what();
    }
  }
  // Overlapping entries: the directory points the second entry at the first one's local header (the
  // classic overlapping zip bomb); the names then disagree and the archive is refused (item 34).
  bad = good;
  {
    const std::size_t central_ldt = nth(good, std::string("PK\x01\x02", 4), 1);
    for (int k = 0; k < 4; ++k) bad[central_ldt + 42 + k] = 0;  // relative offset of the local header → 0
  }
  write_bytes(p, bad);
  d = error_of(p);
  EXPECT_EQ(d.field, "ZIP") << d.str();
  // The archive cut short anywhere in its directory or end record.
  for (std::size_t cut = nth(good, std::string("PK\x01\x02", 4), 0); cut < good.size(); cut += 7) {
    write_bytes(p, good.substr(0, cut));
    EXPECT_EQ(error_of(p).field, "ZIP") << "cut at " << cut;
  }
  fs::remove(p);
}
