// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Bundles on disk: round trips, half/float choice, partial loading (bytes read), atomic replacement,
// and located rejection of corrupted, truncated, inconsistent or hostile bundles.
#include <lumx/apl/far_field.h>
#include <lumx/apl/apl_set.h>
#include <lumx/apl/evaluation.h>
#include <lumx/io/bundle_builder.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/photometry_io.h>
#include <lumx/volume/radiance_volume.h>

#include <gtest/gtest.h>
#include <Imath/half.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include "io/bundle/exr_image.h"
#include "io/bundle/sha256.h"
#include "test_support.h"

using namespace lumx;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("lumx_test_bundle_" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

/// A three-level set (1, 8, 64 APLs) that is a cut of one tree: each fine APL is a random lobe, each
/// parent's map is the sum of its children's maps.
AplSet three_level_set(int R = 32, ChannelLayout channels = ChannelLayout::rgb, float peak = 500.0f) {
  const int nc = channel_count(channels);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  AplSet set;
  set.channels = channels;
  set.provenance["test"] = "three_level_set";
  AplLevel fine;
  fine.map_resolution = R;
  for (int i = 0; i < 64; ++i) {
    Apl a;
    a.position = {u(rng) * 0.4f - 0.2f, u(rng) * 0.4f - 0.2f, u(rng) * 0.1f};
    a.parent = i / 8;
    a.map = SphereMap(R, nc);
    const glm::vec3 axis = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, -1.0f));
    const float sharp = 1.0f + 20.0f * u(rng);
    for (int y = 0; y < a.map.height(); ++y)
      for (int x = 0; x < a.map.width(); ++x) {
        const glm::vec3 w = sphere_map::uv_to_direction({(x + 0.5f) / a.map.width(), (y + 0.5f) / a.map.height()});
        const float v = peak * (std::pow(std::max(0.0f, glm::dot(w, axis)), sharp) + 2e-4f);
        for (int c = 0; c < nc; ++c) a.map.at(x, y, c) = v * (1.0f + 0.1f * float(c));
      }
    fine.apls.push_back(std::move(a));
  }
  auto coarser = [&](const AplLevel& children, int count, int parent_group) {
    AplLevel l;
    l.map_resolution = R;
    for (int p = 0; p < count; ++p) {
      Apl a;
      a.parent = parent_group > 0 ? p / parent_group : -1;
      a.map = SphereMap(R, nc);
      glm::vec3 centre(0.0f);
      int n = 0;
      for (const Apl& c : children.apls)
        if (c.parent == p) {
          for (std::size_t t = 0; t < a.map.values().size(); ++t) a.map.values()[t] += c.map.values()[t];
          centre += c.position;
          ++n;
        }
      a.position = centre / float(n);
      l.apls.push_back(std::move(a));
    }
    return l;
  };
  AplLevel mid = coarser(fine, 8, 8);
  AplLevel root = coarser(mid, 1, 0);
  set.levels = {std::move(root), std::move(mid), std::move(fine)};
  update_fluxes(set);
  set.bounds = bounding_sphere_of(set);
  return set;
}

std::string slurp(const fs::path& p) { return lumx_test::read_text(p); }
void spit(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary | std::ios::trunc) << s; }

nlohmann::json read_manifest(const fs::path& bundle) { return nlohmann::json::parse(slurp(bundle / "manifest.json")); }
void write_manifest(const fs::path& bundle, const nlohmann::json& j) { spit(bundle / "manifest.json", j.dump(1)); }

/// The located error a bad bundle produces when opened and fully loaded.
std::string load_error(const fs::path& bundle) {
  try {
    BundleReader r(bundle.string());
    r.load();
    if (r.has_volume()) r.load_volume();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

/// Copies of a good bundle with one manifest edit each, and the located error each must produce.
struct ManifestEdits {
  fs::path root, good;
  nlohmann::json manifest;
  int n = 0;
  void operator()(const std::function<void(nlohmann::json&)>& edit, const std::string& needle) {
    const fs::path b = root / ("case" + std::to_string(n++) + ".lumx");
    fs::copy(good, b, fs::copy_options::recursive);
    nlohmann::json j = manifest;
    edit(j);
    write_manifest(b, j);
    const std::string e = load_error(b);
    EXPECT_NE(e.find(needle), std::string::npos) << "expected \"" << needle << "\" in: " << e;
  }
};

}  // namespace

TEST(Bundle, RoundTripKeepsTheSet) {
  const AplSet set = three_level_set();
  const fs::path dir = scratch("roundtrip") / "lamp.lumx";
  write_bundle(dir.string(), set);
  BundleReader reader(dir.string());
  const BundleManifest& m = reader.manifest();
  ASSERT_EQ(m.levels.size(), 3u);
  EXPECT_EQ(m.levels[2].apl_count(), 64u);
  EXPECT_EQ(m.levels[0].maps.size(), 3u);  // 32, 16, 8
  EXPECT_EQ(m.levels[0].maps[0].pixel_type, "half");
  const AplSet back = reader.load();
  EXPECT_TRUE(check_apl_set(back).empty());
  EXPECT_EQ(back.provenance.at("test"), "three_level_set");
  EXPECT_EQ(back.bounds.radius, set.bounds.radius);
  for (std::size_t k = 0; k < 3; ++k)
    for (std::size_t i = 0; i < set.levels[k].size(); ++i) {
      const Apl &a = set.levels[k].apls[i], &b = back.levels[k].apls[i];
      EXPECT_EQ(a.position, b.position);
      EXPECT_EQ(a.flux, b.flux);
      EXPECT_EQ(a.parent, b.parent);
      // Half keeps 11 significant bits: relative rounding ≤ 2^-11 per value.
      for (std::size_t t = 0; t < a.map.values().size(); ++t)
        ASSERT_NEAR(a.map.values()[t], b.map.values()[t], std::ldexp(std::abs(a.map.values()[t]), -11));
    }
}

TEST(Bundle, FloatIsUsedWhereHalfWouldOverflowOrLosePrecision) {
  // A narrow beam: 2e5 cd peaks exceed half's 65504.
  const AplSet bright = three_level_set(16, ChannelLayout::luminance, 2e5f);
  const fs::path dir = scratch("bright") / "b.lumx";
  write_bundle(dir.string(), bright);
  BundleReader r(dir.string());
  EXPECT_EQ(r.manifest().levels[0].maps[0].pixel_type, "float");
  const AplSet back = r.load();
  for (std::size_t k = 0; k < 3; ++k)
    for (std::size_t i = 0; i < bright.levels[k].size(); ++i)
      EXPECT_EQ(bright.levels[k].apls[i].map.values(), back.levels[k].apls[i].map.values());  // exact
  // Forcing half refuses instead of writing Inf, and leaves nothing behind.
  BundleWriteOptions forced_half;
  forced_half.pixel_type = MapPixelType::half;
  const fs::path dir2 = scratch("forced") / "f.lumx";
  EXPECT_THROW(write_bundle(dir2.string(), bright, nullptr, forced_half), Error);
  EXPECT_FALSE(fs::exists(dir2));
  EXPECT_TRUE(fs::is_empty(dir2.parent_path()));
  // A dim radiometric set (peak 1e-3 W/sr) would sit in half's subnormal range: float.
  const AplSet dim = three_level_set(16, ChannelLayout::luminance, 1e-3f);
  const fs::path dir3 = scratch("dim") / "d.lumx";
  write_bundle(dir3.string(), dim);
  EXPECT_EQ(BundleReader(dir3.string()).manifest().levels[2].maps[0].pixel_type, "float");
}

namespace {

/// One APL whose 2R × R map holds `value` everywhere except texel (0, 0), which holds `first`.
AplSet one_map_set(float value, float first, int R = 8) {
  AplSet set;
  AplLevel level;
  level.map_resolution = R;
  Apl a;
  a.map = SphereMap(R, 1);
  for (float& v : a.map.values()) v = value;
  a.map.at(0, 0, 0) = first;
  level.apls.push_back(std::move(a));
  set.levels.push_back(std::move(level));
  update_fluxes(set);
  set.bounds = bounding_sphere_of(set);
  return set;
}

}  // namespace

// Half's edges (hard-cases.md §6 item 26). OpenEXR's half (Imath) rounds to nearest, ties to even: 65504 is
// its largest value, 65519 rounds down to it, 65520 overflows to +Inf; 2⁻²⁴ is its smallest subnormal and
// 2⁻²⁵ (a tie) rounds to 0; 2049 (a tie between 2048 and 2050) rounds to 2048. The bundle writer stores
// every map exactly or as half only where rounding keeps the value in range and the flux within 1e-4.
TEST(Bundle, HalfConversionsAtTheEdgesOfItsRange) {
  EXPECT_EQ(float(Imath::half(65504.0f)), 65504.0f);
  EXPECT_EQ(float(Imath::half(65519.0f)), 65504.0f);
  EXPECT_TRUE(std::isinf(float(Imath::half(65520.0f))));
  EXPECT_EQ(float(Imath::half(0x1.0p-24f)), 0x1.0p-24f);
  EXPECT_EQ(float(Imath::half(0x1.0p-25f)), 0.0f);
  EXPECT_EQ(float(Imath::half(2049.0f)), 2048.0f);
  EXPECT_EQ(float(Imath::half(2051.0f)), 2052.0f);

  struct Case {
    float value, first;
    const char* pixel_type;  // what automatic chooses
  };
  const Case cases[] = {
      {1.0f, 65504.0f, "half"},    // every value exact in half
      {1.0f, 65519.0f, "float"},   // above half's largest value: half would change it
      {1.0f, 65520.0f, "float"},   // half would overflow
      {2049.0f, 2049.0f, "float"}, // every texel would lose 1 in 2049: the flux by 4.9e-4
      {2048.0f, 2050.0f, "half"},  // exact in half
  };
  int n = 0;
  for (const Case& c : cases) {
    const AplSet set = one_map_set(c.value, c.first);
    const fs::path dir = scratch("half_edges") / ("c" + std::to_string(n++) + ".lumx");
    write_bundle(dir.string(), set);
    BundleReader r(dir.string());
    EXPECT_EQ(r.manifest().levels[0].maps[0].pixel_type, c.pixel_type) << c.first;
    const AplSet back = r.load();
    EXPECT_EQ(back.levels[0].apls[0].map.values(), set.levels[0].apls[0].map.values()) << c.first;  // exact
    // Forced half: refused above 65504, even where rounding would give 65504, rather than store another value.
    BundleWriteOptions forced_half;
    forced_half.pixel_type = MapPixelType::half;
    const fs::path forced = dir.parent_path() / ("forced" + std::to_string(n) + ".lumx");
    if (c.first > 65504.0f) {
      EXPECT_THROW(write_bundle(forced.string(), set, nullptr, forced_half), Error) << c.first;
    } else {
      write_bundle(forced.string(), set, nullptr, forced_half);
      EXPECT_EQ(BundleReader(forced.string()).manifest().levels[0].maps[0].pixel_type, "half");
    }
  }
}

TEST(Bundle, PartialLoadingReadsOnlyWhatItNeeds) {
  const AplSet set = three_level_set(64);
  const fs::path dir = scratch("partial") / "p.lumx";
  write_bundle(dir.string(), set);
  BundleReader manifest_only(dir.string());
  const std::uint64_t total = manifest_only.manifest().total_bytes();
  EXPECT_EQ(manifest_only.bytes_read(), manifest_only.manifest().manifest_bytes);
  EXPECT_LT(manifest_only.bytes_read(), total / 20);

  // The 8-APL level at full resolution: its own payload plus the manifest, nothing else.
  BundleReader r8(dir.string());
  const AplLevel level8 = r8.load_level(1);
  EXPECT_EQ(level8.size(), 8u);
  const std::uint64_t expected8 = r8.manifest().manifest_bytes + r8.manifest().levels[1].maps[0].bytes;
  EXPECT_EQ(r8.bytes_read(), expected8);
  EXPECT_LT(double(r8.bytes_read()), 0.2 * double(total));
  std::cout << "level-8 load read " << r8.bytes_read() << " of " << total << " bytes ("
            << 100.0 * double(r8.bytes_read()) / double(total) << " %)\n";

  // The same level at a reduced resolution reads a smaller payload, and keeps the flux.
  BundleReader r8low(dir.string());
  const AplLevel low = r8low.load_level(1, 16);
  EXPECT_EQ(low.map_resolution, 16);
  EXPECT_LT(r8low.bytes_read(), r8.bytes_read() / 4);
  for (std::size_t i = 0; i < 8; ++i) {
    const double f = luminance_of(set.channels, set.levels[1].apls[i].flux);
    EXPECT_NEAR(luminance_of(set.channels, low.apls[i].map.integral()), f, 1e-3 * f);
  }
  // A limit below the coarsest stored resolution gives the coarsest.
  EXPECT_EQ(BundleReader(dir.string()).load_level(1, 3).map_resolution, 8);
}

TEST(Bundle, ReplacementIsAtomic) {
  const fs::path root = scratch("atomic");
  const fs::path dir = root / "lamp.lumx";
  const AplSet first = three_level_set(16);
  write_bundle(dir.string(), first);
  const std::string manifest_before = slurp(dir / "manifest.json");
  // A set that fails validation after nothing was written.
  AplSet bad = first;
  bad.levels[2].apls[5].map.at(1, 1, 0) = NAN;
  EXPECT_THROW(write_bundle(dir.string(), bad), Error);
  // A radiance volume with a NaN fails after every map payload was already written.
  RadianceVolume volume(Aabb{glm::dvec3(-0.2), glm::dvec3(0.2)}, 64, 2, 1);
  std::vector<float> coefficients = volume.coefficients();
  coefficients[3] = NAN;
  volume.set_coefficients(coefficients);
  EXPECT_THROW(write_bundle(dir.string(), three_level_set(16, ChannelLayout::luminance), &volume), Error);
  EXPECT_EQ(slurp(dir / "manifest.json"), manifest_before);
  EXPECT_TRUE(check_bundle(dir.string()).empty());
  // No temporary folder is left behind.
  int entries = 0;
  for (const auto& e : fs::directory_iterator(root)) entries += e.path() != dir;
  EXPECT_EQ(entries, 0);
  // A successful rewrite replaces the bundle (a different set is visible).
  write_bundle(dir.string(), three_level_set(8, ChannelLayout::luminance));
  EXPECT_EQ(BundleReader(dir.string()).manifest().levels[0].map_resolution, 8);
  // A folder that is not a bundle is never replaced.
  const fs::path other = root / "photos";
  fs::create_directories(other);
  spit(other / "keep.txt", "precious");
  EXPECT_THROW(write_bundle(other.string(), first), Error);
  EXPECT_EQ(slurp(other / "keep.txt"), "precious");
}

TEST(Bundle, CorruptedPayloadsAreRejectedWithTheirLocation) {
  const AplSet set = three_level_set(16);
  const fs::path root = scratch("corrupt");
  const fs::path good = root / "good.lumx";
  write_bundle(good.string(), set);
  const nlohmann::json m = read_manifest(good);
  const std::string level1 = m["levels"][1]["maps"][0]["file"];
  auto copy = [&](const std::string& name) {
    const fs::path p = root / name;
    fs::copy(good, p, fs::copy_options::recursive);
    return p;
  };
  {  // one flipped byte: checksum
    const fs::path b = copy("flip.lumx");
    std::string bytes = slurp(b / level1);
    bytes[bytes.size() / 2] ^= 0x20;
    spit(b / level1, bytes);
    const std::string e = load_error(b);
    EXPECT_NE(e.find(level1), std::string::npos) << e;
    EXPECT_NE(e.find("/levels/1/maps/0/sha256"), std::string::npos) << e;
  }
  {  // truncated payload: size
    const fs::path b = copy("trunc.lumx");
    const std::string bytes = slurp(b / level1);
    spit(b / level1, bytes.substr(0, bytes.size() - 100));
    const std::string e = load_error(b);
    EXPECT_NE(e.find("/levels/1/maps/0/bytes"), std::string::npos) << e;
  }
  {  // missing payload
    const fs::path b = copy("missing.lumx");
    fs::remove(b / level1);
    EXPECT_NE(load_error(b).find("payload missing"), std::string::npos);
  }
  {  // a payload swapped for another level's, with a matching checksum: the image size disagrees
    const fs::path b = copy("swapped.lumx");
    nlohmann::json j = m;
    j["levels"][1]["maps"][0] = j["levels"][2]["maps"][0];
    j["levels"][1]["maps"][0]["file"] = level1;
    fs::copy_file(b / std::string(m["levels"][2]["maps"][0]["file"]), b / level1, fs::copy_options::overwrite_existing);
    write_manifest(b, j);
    const std::string e = load_error(b);
    EXPECT_NE(e.find("dataWindow"), std::string::npos) << e;
  }
  {  // check_bundle collects the findings instead of throwing
    const fs::path b = copy("check.lumx");
    fs::remove(b / std::string(m["levels"][2]["maps"][1]["file"]));
    const auto findings = check_bundle(b.string());
    ASSERT_EQ(findings.size(), 1u);
    EXPECT_NE(findings[0].str().find("payload missing"), std::string::npos);
  }
}

TEST(Bundle, NanOrNegativeTexelsWithValidChecksumsAreRejected) {
  // A payload that is a well-formed EXR with a correct checksum, but holds NaN (or a negative value):
  // the reader names the APL and texel.
  const fs::path root = scratch("nan_payload");
  const fs::path good = root / "good.lumx";
  write_bundle(good.string(), three_level_set(8, ChannelLayout::luminance));
  for (float bad : {NAN, -1.0f}) {
    const fs::path b = root / (std::isnan(bad) ? "nan.lumx" : "negative.lumx");
    fs::copy(good, b, fs::copy_options::recursive);
    nlohmann::json j = read_manifest(b);
    const BundleLevelInfo info = BundleReader(b.string()).manifest().levels[1];
    detail::ExrImage image;
    image.width = 2 * 8;
    image.height = 8 * int(info.apl_count());
    image.channels = {"Y"};
    image.half = false;
    image.pixels.assign(std::size_t(image.width) * image.height, 1.0f);
    image.pixels[std::size_t(3 * 8 + 2) * image.width + 5] = bad;  // APL 3, texel (5, 2)
    const std::string bytes = detail::encode_exr(image);
    spit(b / std::string(j["levels"][1]["maps"][0]["file"]), bytes);
    j["levels"][1]["maps"][0]["bytes"] = bytes.size();
    j["levels"][1]["maps"][0]["sha256"] = detail::sha256_hex(bytes);
    j["levels"][1]["maps"][0]["pixel_type"] = "float";
    write_manifest(b, j);
    const std::string e = load_error(b);
    EXPECT_NE(e.find("APL 3 texel (5, 2)"), std::string::npos) << e;
  }
}

TEST(Bundle, InconsistentOrHostileManifestsAreRejected) {
  const AplSet set = three_level_set(16, ChannelLayout::luminance);
  const fs::path root = scratch("manifest");
  const fs::path good = root / "good.lumx";
  write_bundle(good.string(), set);
  const nlohmann::json m = read_manifest(good);
  ManifestEdits expect{root, good, m};
  expect([](auto& j) { j["levels"][1]["apl_count"] = 9; }, "/levels/1/position");
  expect([](auto& j) { j["levels"][2]["apl_count"] = 1000000; }, "/levels/2/position");  // no allocation first
  expect([](auto& j) { j["levels"][2]["parent"][3] = 8; }, "/levels/2/parent/3");
  expect([](auto& j) { j["levels"][1]["flux"][2][0] = 1e9; }, "/levels/1/flux/2");
  expect([](auto& j) { j["levels"][1]["flux"][2][0] = -1; }, "/levels/1/flux/2/0");
  expect([](auto& j) { j["levels"][0]["position"][0][1] = "x"; }, "/levels/0/position/0/1");
  expect([](auto& j) { j["levels"][0]["maps"][0]["file"] = "../../etc/passwd"; }, "/levels/0/maps/0/file");
  expect([](auto& j) { j["levels"][0]["maps"][0]["sha256"] = "abc"; }, "/levels/0/maps/0/sha256");
  expect([](auto& j) { j["levels"][0]["maps"][1]["resolution"] = 3; }, "/levels/0/maps/1/resolution");
  expect([](auto& j) { j["format_version"] = lumx::bundle::kFormatVersion + 1; }, "/format_version");
  expect([](auto& j) { j["format_version"] = 0; }, "/format_version");
  expect([](auto& j) { j["units"]["intensity"] = "W/sr"; }, "/units/flux");
  expect([](auto& j) { j["channels"] = {"R", "G"}; }, "/channels");
  expect([](auto& j) { j.erase("levels"); }, "/levels");
  expect([](auto& j) { j["levels"][1]["map_resolution"] = 100000; }, "/levels/1/map_resolution");
  expect([](auto& j) { j["levels"][1]["apl_count"] = 1; }, "/levels/1/apl_count");
  // Not JSON at all (NaN is not a JSON number): the byte offset is reported.
  const fs::path b = root / "nan.lumx";
  fs::copy(good, b, fs::copy_options::recursive);
  std::string text = slurp(b / "manifest.json");
  text.replace(text.find("\"radius\": ") + 10, 1, "NaN,");
  spit(b / "manifest.json", text);
  const std::string e = load_error(b);
  EXPECT_NE(e.find("manifest.json:@"), std::string::npos) << e;
  // A payload reached through a symbolic link that leaves the bundle.
  const fs::path s = root / "symlink.lumx";
  fs::copy(good, s, fs::copy_options::recursive);
  const std::string file = m["levels"][0]["maps"][0]["file"];
  fs::copy_file(s / file, root / "outside.exr");
  fs::remove(s / file);
  fs::create_symlink(root / "outside.exr", s / file);
  EXPECT_NE(load_error(s).find("symbolic link"), std::string::npos);
  // Numbers beyond double's range, members the format does not define, a wrong radiance unit.
  const fs::path big = root / "big.lumx";
  fs::copy(good, big, fs::copy_options::recursive);
  std::string t = slurp(big / "manifest.json");
  t.replace(t.find("\"radius\": ") + 10, 1, "1e400,");
  spit(big / "manifest.json", t);
  EXPECT_NE(load_error(big).find("manifest.json"), std::string::npos);
  expect([](auto& j) { j["levels"][0]["surprise"] = 1; }, "/levels/0/surprise");
  expect([](auto& j) { j["units"]["colour"] = "red"; }, "/units/colour");
}

TEST(Bundle, MapFramesRoundTripAndAreChecked) {
  // A turned frame on every level (as the builder writes a beam's maps) is stored bit for bit, and the
  // levels read back look up the same intensity in every photometric direction.
  AplSet set = three_level_set(16, ChannelLayout::luminance);
  const MapFrame frame = map_frame_for(glm::dvec3(0.2, -0.1, -1.0));
  for (AplLevel& l : set.levels) l.frame = frame;
  const fs::path root = scratch("frames");
  const fs::path good = root / "turned.lumx";
  BundleWriteOptions exact;
  exact.pixel_type = MapPixelType::float32;  // texels bit for bit, so lookups can be compared exactly
  write_bundle(good.string(), set, nullptr, exact);
  const nlohmann::json m = read_manifest(good);
  EXPECT_EQ(m["format_version"], 2);
  ASSERT_TRUE(m["levels"][0].contains("map_frame"));
  const BundleReader reader(good.string());
  for (std::size_t k = 0; k < set.levels.size(); ++k) {
    const AplLevel back = reader.load_level(k);
    EXPECT_TRUE(back.frame.to_map == frame.to_map) << k;
    ASSERT_EQ(back.size(), set.levels[k].size());
    const std::size_t i = back.size() - 1;
    for (const glm::vec3& w : {glm::vec3(0, 0, -1), glm::normalize(glm::vec3(0.3f, 0.4f, -0.8f)), glm::vec3(1, 0, 0)})
      EXPECT_EQ(intensity(back, back.apls[i], w).x, intensity(set.levels[k], set.levels[k].apls[i], w).x) << k;
  }
  ManifestEdits expect{root, good, m};
  expect([](auto& j) { j["levels"][1]["map_frame"][2][0] = 0.5; }, "/levels/1/map_frame");   // not a rotation
  expect([](auto& j) {  // a reflection: orthonormal, determinant −1
    for (int c = 0; c < 3; ++c) j["levels"][0]["map_frame"][2][c] = -double(j["levels"][0]["map_frame"][2][c]);
  }, "/levels/0/map_frame");
  expect([](auto& j) { j["levels"][2]["map_frame"][1] = {1, 2}; }, "/levels/2/map_frame/1");
  expect([](auto& j) { j["levels"][0]["map_frame"][0][0] = "1"; }, "/levels/0/map_frame/0/0");
  expect([](auto& j) { j["levels"][0]["map_frame"][0][0] = 1e300; }, "/levels/0/map_frame/0/0");  // no float cast
  expect([](auto& j) { j["format_version"] = 1; }, "/levels/0/map_frame");  // version 1 has no frames
  // A version 1 bundle (no frames) is read with the photometric frame.
  const AplSet plain = three_level_set(16, ChannelLayout::luminance);
  const fs::path old = root / "version1.lumx";
  write_bundle(old.string(), plain);
  nlohmann::json j1 = read_manifest(old);
  EXPECT_FALSE(j1["levels"][0].contains("map_frame"));
  j1["format_version"] = 1;
  write_manifest(old, j1);
  const BundleReader r1(old.string());
  EXPECT_EQ(r1.manifest().format_version, 1);
  EXPECT_TRUE(r1.load_level(2).frame.is_identity());
}

TEST(Bundle, RecordedBuildOptionsKeepTheMapFrameChoice) {
  // lumx eval rebuilds a bundle's levels from its recorded options: a bundle from before the map frame
  // (no "orient_maps") was drawn in the photometric frame, and is rebuilt so.
  AplBuildOptions o;
  for (bool orient : {true, false}) {
    o.orient_maps = orient;
    EXPECT_EQ(build_options_from_json(build_options_json(o)).orient_maps, orient);
  }
  nlohmann::json old = nlohmann::json::parse(build_options_json(AplBuildOptions{}));
  old.erase("orient_maps");
  EXPECT_FALSE(build_options_from_json(old.dump()).orient_maps);
  old["orient_maps"] = "yes";
  EXPECT_THROW(build_options_from_json(old.dump()), std::invalid_argument);
}

TEST(Bundle, VolumeManifestRulesAreEnforced) {
  const fs::path root = scratch("volume_manifest");
  const fs::path good = root / "good.lumx";
  RadianceVolume volume(Aabb{glm::dvec3(-0.1), glm::dvec3(0.1)}, 64, 2, 1);
  write_bundle(good.string(), three_level_set(8, ChannelLayout::luminance), &volume);
  const nlohmann::json m = read_manifest(good);
  ManifestEdits expect{root, good, m};
  expect([](auto& j) { j["volume"]["counts"] = {2, 4096, 4096}; }, "/volume/counts");  // > 2^24 voxels
  expect([](auto& j) { j["volume"]["radiance_unit"] = "W/(m^2 sr)"; }, "/volume/radiance_unit");
  expect([](auto& j) { j["volume"].erase("window"); }, "/volume/window");
  expect([](auto& j) { j["volume"]["voxel_size"] = 1.0; }, "/volume/bounds");
}

TEST(Bundle, WriterRefusesSetsItsReaderWouldReject) {
  const fs::path dir = scratch("refuse") / "r.lumx";
  AplSet set = three_level_set(8, ChannelLayout::luminance);
  {
    AplSet s = set;
    s.levels[1].apls[0].flux = glm::dvec3(NAN);
    EXPECT_THROW(write_bundle(dir.string(), s), Error);
  }
  {
    AplSet s = set;
    s.bounds.center.x = INFINITY;
    EXPECT_THROW(write_bundle(dir.string(), s), Error);
  }
  {
    AplSet s = set;
    s.levels[2].error.relative_distance = {0.0, 1.0};  // d must be > 0
    s.levels[2].error.relative_rmse = {0.1, 0.05};
    EXPECT_THROW(write_bundle(dir.string(), s), Error);
  }
  EXPECT_FALSE(fs::exists(dir));
}

TEST(Bundle, HalfIsNotUsedWhenItsRoundingWouldChangeTheFlux) {
  // One texel at 1.0 and all others at 8.5·2^-24, deep in half's subnormal range: half would round
  // the background down by ~6 % and the flux by ~0.4 %.
  AplSet set;
  AplLevel level;
  level.map_resolution = 64;
  Apl a;
  a.map = SphereMap(64, 1);
  std::fill(a.map.values().begin(), a.map.values().end(), 8.5f * std::ldexp(1.0f, -24));
  a.map.at(3, 3, 0) = 1.0f;
  a.flux = a.map.integral();
  level.apls.push_back(a);
  set.levels.push_back(level);
  const fs::path dir = scratch("subnormal") / "s.lumx";
  write_bundle(dir.string(), set);
  BundleReader r(dir.string());
  EXPECT_EQ(r.manifest().levels[0].maps[0].pixel_type, "float");
  EXPECT_NO_THROW(r.load());
}

TEST(Bundle, SkippedLevelsKeepAValidTree) {
  const AplSet set = three_level_set(8, ChannelLayout::luminance);
  const fs::path dir = scratch("skip") / "k.lumx";
  write_bundle(dir.string(), set);
  const AplSet partial = BundleReader(dir.string()).load({0, 2});
  ASSERT_EQ(partial.levels.size(), 2u);
  EXPECT_TRUE(check_apl_set(partial).empty());
  for (std::size_t i = 0; i < 64; ++i) EXPECT_EQ(partial.levels[1].apls[i].parent, 0);  // the root's grandchildren
  // A limit on what one load may decode is enforced before reading.
  BundleLimits tiny;
  tiny.max_loaded_bytes = 1000;
  EXPECT_THROW(BundleReader(dir.string(), tiny).load(), Error);
}

TEST(Bundle, WriterOnlyReplacesLumxBundlesAndFollowsLinks) {
  const fs::path root = scratch("targets");
  const AplSet set = three_level_set(8, ChannelLayout::luminance);
  // A folder with a manifest.json that is not a lumx manifest (a web app, say) is never replaced.
  const fs::path app = root / "myapp";
  fs::create_directories(app);
  spit(app / "manifest.json", "{\"name\": \"my app\"}");
  spit(app / "index.html", "<html></html>");
  EXPECT_THROW(write_bundle(app.string(), set), Error);
  EXPECT_EQ(slurp(app / "index.html"), "<html></html>");
  // A bundle someone added a file to is not replaced either.
  const fs::path bundle = root / "lamp.lumx";
  write_bundle(bundle.string(), set);
  spit(bundle / "notes.txt", "mine");
  EXPECT_THROW(write_bundle(bundle.string(), set), Error);
  fs::remove(bundle / "notes.txt");
  // A trailing separator names the same folder.
  EXPECT_NO_THROW(write_bundle(bundle.string() + "/", set));
  // A symbolic link to a bundle: the bundle it points to is replaced and the link is kept.
  const fs::path link = root / "current.lumx";
  fs::create_directory_symlink(bundle, link);
  write_bundle(link.string(), three_level_set(16, ChannelLayout::luminance));
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(BundleReader(bundle.string()).manifest().levels[0].map_resolution, 16);
}

TEST(Bundle, WriterOutputValidatesAgainstTheJsonSchema) {
  const fs::path root = scratch("schema");
  const fs::path dir = root / "s.lumx";
  RadianceVolume volume(Aabb{glm::dvec3(-0.2, -0.2, 0.0), glm::dvec3(0.2, 0.2, 0.1)}, 512, 4, 3);
  AplSet set = three_level_set(8);
  set.levels[2].frame = map_frame_for(glm::dvec3(0.1, 0.2, -1.0));  // a turned level: map_frame in the schema
  set.levels[1].error.relative_distance = {0.5, 1, 2};
  set.levels[1].error.relative_rmse = {0.2, 0.1, 0.05};
  BundleWriteOptions with_files;
  with_files.attachments.push_back({"far_field.ies", "application/x-ies-lm63", format_ies(far_field_photometry(set, 0))});
  write_bundle(dir.string(), set, &volume, with_files);
  const std::string validator = std::string(LUMX_SOURCE_DIR) + "/schema/validate.py";
  const std::string cmd = "/usr/bin/python3 " + validator + " " + dir.string() + " > " + (root / "out.txt").string() + " 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << slurp(root / "out.txt");
  // The schema is not vacuous: a manifest with a wrong unit and a bad checksum fails it.
  nlohmann::json j = read_manifest(dir);
  j["units"]["flux"] = "W";
  j["levels"][0]["maps"][0]["sha256"] = "XYZ";
  j["levels"][0]["surprise"] = 1;
  ASSERT_TRUE(j["levels"][2].contains("map_frame"));
  j["levels"][2]["map_frame"][1] = {0.5, 0.5};
  write_manifest(dir, j);
  EXPECT_NE(std::system(cmd.c_str()), 0);
  const std::string out = slurp(root / "out.txt");
  EXPECT_NE(out.find("/units"), std::string::npos) << out;
  EXPECT_NE(out.find("/levels/0/maps/0/sha256"), std::string::npos) << out;
  EXPECT_NE(out.find("surprise"), std::string::npos) << out;
  EXPECT_NE(out.find("/levels/2/map_frame/1"), std::string::npos) << out;
}

TEST(Bundle, AttachmentsShipWithTheSet) {
  const AplSet set = three_level_set(8, ChannelLayout::luminance);
  const fs::path root = scratch("attachments");
  const fs::path dir = root / "a.lumx";
  BundleWriteOptions o;
  const std::string ies = format_ies(far_field_photometry(set, 0));
  const std::string ldt = format_ldt(far_field_photometry(set, 0));
  o.attachments = {{"far_field.ies", "application/x-ies-lm63", ies}, {"far_field.ldt", "application/x-eulumdat", ldt}};
  write_bundle(dir.string(), set, nullptr, o);
  BundleReader r(dir.string());
  ASSERT_EQ(r.manifest().attachments.size(), 2u);
  EXPECT_EQ(r.manifest().attachments[1].first.name, "far_field.ldt");
  EXPECT_EQ(r.read_attachment(0), ies);
  EXPECT_EQ(r.read_attachment(1), ldt);
  EXPECT_TRUE(check_bundle(dir.string()).empty());
  // Rewriting the bundle (attachments/ is part of a bundle) works; a corrupted attachment is found.
  write_bundle(dir.string(), set, nullptr, o);
  spit(dir / "attachments" / "far_field.ies", ies + " ");
  const auto findings = check_bundle(dir.string());
  ASSERT_EQ(findings.size(), 1u);
  EXPECT_NE(findings[0].str().find("/attachments/0"), std::string::npos) << findings[0].str();
  // Names that could leave the folder are refused.
  BundleWriteOptions bad;
  bad.attachments = {{"../x.ies", "text/plain", "x"}};
  EXPECT_THROW(write_bundle((root / "b.lumx").string(), set, nullptr, bad), Error);
  EXPECT_FALSE(fs::exists(root / "b.lumx"));
}

TEST(Bundle, VolumeRoundTrips) {
  RadianceVolume volume(Aabb{glm::dvec3(-0.3, -0.2, -0.1), glm::dvec3(0.3, 0.2, 0.4)}, 4096, 4, 3);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int i = 0; i < 2000; ++i)
    volume.add_segment({u(rng), u(rng), u(rng) + 0.15}, glm::normalize(glm::dvec3(u(rng), u(rng), u(rng))), 0.5,
                       glm::vec3(1.0f, 0.5f, 0.25f));
  const fs::path dir = scratch("volume") / "v.lumx";
  write_bundle(dir.string(), three_level_set(8), &volume);
  BundleReader r(dir.string());
  ASSERT_TRUE(r.has_volume());
  const RadianceVolume back = r.load_volume();
  EXPECT_EQ(back.counts(), volume.counts());
  EXPECT_EQ(back.voxel_size(), volume.voxel_size());
  EXPECT_EQ(back.coefficients(), volume.coefficients());  // float32: exact
  EXPECT_EQ(back.radiance({0.05, 0.02, 0.1}, {0, 0, 1}), volume.radiance({0.05, 0.02, 0.1}, {0, 0, 1}));
  EXPECT_TRUE(check_bundle(dir.string()).empty());
}

TEST(Bundle, RealPhotometryBecomesAOneLevelBundle) {
  const Photometry p = read_photometry((fs::path(LUMX_SOURCE_DIR) / "samples" / "downlight.ies").string());
  const AplSet set = apl_set_from_photometry(p, 64);
  const fs::path dir = scratch("ies") / "downlight.lumx";
  write_bundle(dir.string(), set);
  const auto findings = check_bundle(dir.string());
  EXPECT_TRUE(findings.empty()) << findings.front().str();
  const AplSet back = BundleReader(dir.string()).load();
  const double flux = set.levels[0].flux().x;
  EXPECT_NEAR(back.levels[0].apls[0].map.integral().x, flux, 1e-3 * flux);
}
