// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// What lumx's JSON readers (bundle manifests, glTF, TM-33 JSON) accept (hard-cases.md §6 items 29–31;
// docs/robustness.md "JSON"). RFC 8259 cases written for lumx in the spirit of JSONTestSuite (y_: must
// load, n_: must be a located error, i_: lumx's documented choice) are placed in a glTF document's
// "extras", which may hold any JSON value, so that only the JSON layer decides. Repeated member names, lone
// surrogates and integers beyond 2^53 are tested in all three readers.
#include <lumx/apl/apl_set.h>
#include <lumx/bake/gltf_reader.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/tm33_io.h>

#include <gtest/gtest.h>

#include "gltf_test_support.h"
#include "test_support.h"

#include <filesystem>
#include <fstream>
#include <string>

using namespace lumx;
namespace fs = std::filesystem;
using lumx_gltf_test::GltfBuilder;

namespace {

/// A valid one-quad .gltf document as text, with `extras` holding `value` (inserted verbatim).
std::string gltf_with_extras(const std::string& value) {
  GltfBuilder b;
  const int m = b.add_material({{"emissiveFactor", {1, 1, 1}}});
  const int mesh = b.add_mesh(lumx_gltf_test::unit_quad(), m);
  b.set_scene({b.add_node({{"mesh", mesh}})});
  const std::string doc = b.with_buffer("data:application/octet-stream;base64," + lumx_gltf_test::base64(b.bin)).dump();
  return "{\"extras\":" + value + "," + doc.substr(1);
}

/// The error reading a .gltf with this text gives, or nullopt-like empty diagnostic with `ok` true.
struct Outcome {
  bool ok = false;
  Diagnostic d;
};
Outcome read_gltf_text(const fs::path& dir, const std::string& text) {
  const fs::path p = dir / "case.gltf";
  std::ofstream(p, std::ios::binary | std::ios::trunc) << text;
  Outcome o;
  try {
    (void)bake::read_gltf_luminaire(p.string());
    o.ok = true;
  } catch (const Error& e) {
    o.d = e.diagnostic();
  }
  return o;
}

}  // namespace

TEST(JsonPolicy, Rfc8259CasesLoadOrAreLocatedErrors) {
  const auto dir = lumx_gltf_test::scratch_dir("json_policy");
  const std::vector<std::string> must_load = {
      "null", "true", "false", "0", "-0", "1.5e+3", "1E-3", "-0.0e0", "123456789012345678901234567890",
      "\"\"", "\"\\u00e9\\n\\t\\\\\\/\\\"\"", "\"\\ud83d\\ude00\"", "\"\xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80\"",
      "[]", "{}", "[[],[{}]]", "{\"\":0}", "{\"a\":[1,{\"b\":null}]}", " \t\r\n[ 1 , 2 ]\n ",
      "\"\\u0000\"", "{\"a\":1,\"A\":2}", "1e308", "-1e-400"};
  for (const std::string& y : must_load) {
    const Outcome o = read_gltf_text(dir.path, gltf_with_extras(y));
    EXPECT_TRUE(o.ok) << "y: " << y << ": " << o.d.str();
  }
  const std::vector<std::string> must_fail = {
      "[1,]", "{\"a\":1,}", "[,1]", "01", "-01", "+1", ".5", "1.", "1e", "1e+", "0x10", "NaN", "Infinity",
      "-Infinity", "'a'", "\"a", "\"\\x41\"", "\"\\u12\"", "\"tab\there\"", "\"line\nbreak\"", "[1 2]",
      "{\"a\" 1}", "{a:1}", "{\"a\":1 \"b\":2}", "[1]]", "/* c */ 1", "// c\n1", "tru", "nul", "[",
      "\"\\ud800\"", "\"\\udc00\"", "\"\\ud800\\u0041\"", "\"\xff\"", "\"\xc3\"", "\"\xed\xa0\x80\"",
      "\"\xc0\xaf\"", "1e400", "-1e400"};
  for (const std::string& n : must_fail) {
    const Outcome o = read_gltf_text(dir.path, gltf_with_extras(n));
    EXPECT_FALSE(o.ok) << "n: " << n;
    if (o.ok) continue;
    EXPECT_EQ(o.d.field, "JSON") << n << ": " << o.d.str();
    // Located at the byte where the text stops being JSON: inside or just after the case (it starts at 10).
    // (An unterminated string ends where the parser next finds text that cannot continue it: a few bytes on.)
    EXPECT_GE(o.d.byte_offset, 10) << n << ": " << o.d.str();
    EXPECT_LE(o.d.byte_offset, 10 + std::int64_t(n.size()) + 8) << n << ": " << o.d.str();
  }
}

// Implementation-defined cases (JSONTestSuite's i_), lumx's choices: a UTF-8 byte-order mark before the
// document is skipped; numbers beyond double's range are errors (above, "1e400"); lone surrogates are errors
// (above); integers are exact to 2^64 − 1 (JsonPolicy.IntegersBeyondTwoToThe53AreExactThenRangeChecked);
// nesting beyond 256 levels is an error (Robustness.JsonNestedDeeperThan256LevelsIsRefusedBeforeParsing).
TEST(JsonPolicy, ImplementationDefinedCasesFollowLumxsChoices) {
  const auto dir = lumx_gltf_test::scratch_dir("json_i");
  EXPECT_TRUE(read_gltf_text(dir.path, "\xEF\xBB\xBF" + gltf_with_extras("0")).ok);
  const Outcome twice = read_gltf_text(dir.path, "\xEF\xBB\xBF\xEF\xBB\xBF" + gltf_with_extras("0"));
  EXPECT_FALSE(twice.ok);
  EXPECT_EQ(twice.d.field, "JSON") << twice.d.str();
  const Outcome utf16 = read_gltf_text(dir.path, std::string("\xFF\xFE{\0}\0", 6));  // UTF-16 LE
  EXPECT_FALSE(utf16.ok);
  EXPECT_EQ(utf16.d.field, "JSON") << utf16.d.str();
}

// Repeated member names: nlohmann/json keeps the last, other parsers the first; lumx refuses, at the
// member's JSON pointer, in every reader. Names are escaped in the pointer ('/' as ~1, '~' as ~0).
TEST(JsonPolicy, RepeatedMemberNamesAreLocatedErrorsInEveryReader) {
  const auto dir = lumx_gltf_test::scratch_dir("json_repeated");
  Outcome o = read_gltf_text(dir.path, gltf_with_extras("{\"a\":{\"x/y\":1,\"x/y\":2}}"));
  ASSERT_FALSE(o.ok);
  EXPECT_EQ(o.d.field, "/extras/a/x~1y") << o.d.str();
  EXPECT_NE(o.d.message.find("twice"), std::string::npos) << o.d.str();
  o = read_gltf_text(dir.path, gltf_with_extras("[0,{},[{\"k~\":1,\"k~\":1}]]"));
  ASSERT_FALSE(o.ok);
  EXPECT_EQ(o.d.field, "/extras/2/0/k~0") << o.d.str();
  // The same name in two objects is not a repetition.
  EXPECT_TRUE(read_gltf_text(dir.path, gltf_with_extras("[{\"a\":1},{\"a\":2}]")).ok);
  // A repeated top-level member of glTF itself.
  std::string text = gltf_with_extras("0");
  text.insert(1, "\"asset\":{\"version\":\"2.0\"},");
  o = read_gltf_text(dir.path, text);
  ASSERT_FALSE(o.ok);
  EXPECT_EQ(o.d.field, "/asset") << o.d.str();

  // TM-33 JSON: the project's sample with "Manufacturer" given twice.
  std::string tm33 = lumx_test::read_text(lumx_test::data_dir() / "tm33" / "downlight_tm33_23.json");
  ASSERT_NO_THROW((void)read_tm33_json(tm33, "dl.json"));
  const std::size_t at = tm33.find("\"Manufacturer\"");
  ASSERT_NE(at, std::string::npos);
  tm33.insert(at, "\"Manufacturer\": \"someone else\", ");
  try {
    (void)read_tm33_json(tm33, "dl.json");
    ADD_FAILURE() << "a repeated TM-33 member was read";
  } catch (const Error& e) {
    EXPECT_EQ(e.diagnostic().field, "/IESTM33-22/Header/Manufacturer") << e.what();
  }

  // A bundle manifest with "format_version" twice.
  AplSet set;
  AplLevel level;
  level.map_resolution = 4;
  Apl a;
  a.map = SphereMap(4, 1);
  for (float& v : a.map.values()) v = 1.0f;
  level.apls.push_back(std::move(a));
  set.levels.push_back(std::move(level));
  update_fluxes(set);
  set.bounds = bounding_sphere_of(set);
  const fs::path bundle = dir / "b.lumx";
  write_bundle(bundle.string(), set);
  std::string manifest = lumx_test::read_text(bundle / "manifest.json");
  manifest.insert(manifest.find('{') + 1, "\"format_version\": 1,");
  std::ofstream(bundle / "manifest.json", std::ios::binary | std::ios::trunc) << manifest;
  try {
    BundleReader r(bundle.string());
    ADD_FAILURE() << "a repeated manifest member was read";
  } catch (const Error& e) {
    EXPECT_EQ(e.diagnostic().field, "/format_version") << e.what();
  }
}

// Integers: nlohmann/json reads integers exactly up to 2^64 − 1 (beyond that, as a double), and every lumx
// count is then range-checked, so 2^53 + 1 is never rounded to 2^53 and silently accepted: it is refused by
// its limit at its pointer. A count written 4.0 or 4e0 is the integer 4 (JSON Schema, draft 6 on: an
// integer is any number without a fractional part), 4.5 is refused.
TEST(JsonPolicy, IntegersBeyondTwoToThe53AreExactThenRangeChecked) {
  const auto dir = lumx_gltf_test::scratch_dir("json_integers");
  GltfBuilder b;
  const int mesh = b.add_mesh(lumx_gltf_test::unit_quad(), b.add_material({{"emissiveFactor", {1, 1, 1}}}));
  b.set_scene({b.add_node({{"mesh", mesh}})});
  auto with_count = [&](const std::string& count) {
    std::string text = b.with_buffer("data:application/octet-stream;base64," + lumx_gltf_test::base64(b.bin)).dump();
    const std::string key = "\"count\":4";
    const std::size_t at = text.find(key);
    EXPECT_NE(at, std::string::npos) << text;
    if (at != std::string::npos) text.replace(at, key.size(), "\"count\":" + count);
    return read_gltf_text(dir.path, text);
  };
  for (const std::string count : {"9007199254740993", "9007199254740992", "18446744073709551615", "18446744073709551616", "4.5", "-4"}) {
    const Outcome o = with_count(count);
    EXPECT_FALSE(o.ok) << count;
    EXPECT_EQ(o.d.field.rfind("/accessors/", 0), 0u) << count << ": " << o.d.str();
  }
  for (const std::string count : {"4", "4.0", "4e0", "0.4e1"}) EXPECT_TRUE(with_count(count).ok) << count;
}
