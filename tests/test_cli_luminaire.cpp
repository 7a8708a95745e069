// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// `lumx info` and `lumx check` on glTF luminaires, as a user runs them: the flower pendant (plain and Draco),
// a luminaire with an open volume (a finding, exit 1) and a broken file (located error, exit 1), with --json.
#include <gtest/gtest.h>

#include "cli_test_support.h"
#include "gltf_test_support.h"
#include "test_support.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace fs = std::filesystem;

namespace {

using lumx_test::CliRun;
CliRun run(const std::string& args, bool stderr_too = true) { return lumx_test::run_cli(args, stderr_too); }
std::string q(const fs::path& p) { return lumx_test::quoted(p); }
bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

fs::path flower(const char* name) {
  const auto root = lumx_test::shared_dir();
  return root.empty() ? fs::path() : root / "data" / "luminaires" / "zhu2021-flower" / name;
}

}  // namespace

TEST(CliLuminaire, InfoDescribesTheFlowerPendant) {
  const fs::path f = flower("flower_draco.glb");
  if (f.empty() || !fs::exists(f)) LUMX_SKIP_WITHOUT_SHARED("data/luminaires/zhu2021-flower");
  const CliRun r = run("info " + q(f));
  EXPECT_EQ(r.status, 0) << r.out;
  for (const char* part : {"7898 triangles in 5 parts", "bounding box:", "metalpart", "rough conductor α=0.03",
                           "rough dielectric volume η=1.5046", "emitter 1000 cd/m² one-sided", "surface",
                           "total flux:    7.5"})
    EXPECT_TRUE(has(r.out, part)) << part << "\n" << r.out;

  const CliRun j = run("info --json " + q(f), false);
  ASSERT_EQ(j.status, 0) << j.out;
  const auto doc = nlohmann::json::parse(j.out);
  EXPECT_EQ(doc["triangles"], 7898);
  ASSERT_EQ(doc["parts"].size(), 5u);
  EXPECT_EQ(doc["parts"][0]["name"], "metalpart");
  EXPECT_EQ(doc["parts"][0]["closed"], false);
  ASSERT_EQ(doc["emitters"].size(), 1u);
  EXPECT_EQ(doc["emitters"][0]["kind"], "surface");
  EXPECT_NEAR(doc["emitters"][0]["flux_lm"].get<double>(), 7.574, 0.04);
  EXPECT_NEAR(doc["bounding_box_m"]["min"][0].get<double>(), -0.1398, 2e-4);
  EXPECT_NEAR(doc["bounding_box_m"]["max"][1].get<double>(), 0.1591, 2e-4);
  EXPECT_TRUE(doc["warnings"].empty());
}

TEST(CliLuminaire, CheckPassesTheFlowerAndFlagsAnOpenVolume) {
  const fs::path f = flower("flower.glb");
  if (f.empty() || !fs::exists(f)) LUMX_SKIP_WITHOUT_SHARED("data/luminaires/zhu2021-flower");
  const CliRun ok = run("check " + q(f));
  EXPECT_EQ(ok.status, 0) << ok.out;
  EXPECT_TRUE(has(ok.out, "OK")) << ok.out;

  // A glass quad used as a volume, lit by a point light: an error located at the primitive.
  const auto dir = lumx_gltf_test::scratch_dir("cli_check");
  lumx_gltf_test::GltfBuilder b;
  b.use_extension("KHR_lights_punctual");
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", 5}}};
  const int glass = b.add_material({{"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1}}},
                                                    {"KHR_materials_volume", {{"thicknessFactor", 0.01}}}}}});
  b.set_scene({b.add_node({{"mesh", b.add_mesh(lumx_gltf_test::unit_quad(), glass)}}),
               b.add_node({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}})});
  b.write_glb(dir / "open.glb");
  const CliRun bad = run("check " + q(dir / "open.glb"));
  EXPECT_EQ(bad.status, 1) << bad.out;
  EXPECT_TRUE(has(bad.out, "open.glb: error: /meshes/0/primitives/0: part 'part 0' uses the volume material")) << bad.out;
  const CliRun j = run("check --json " + q(dir / "open.glb") + " " + q(f), false);
  EXPECT_EQ(j.status, 1);
  const auto doc = nlohmann::json::parse(j.out);
  ASSERT_EQ(doc.size(), 2u);
  EXPECT_EQ(doc[0]["ok"], false);
  EXPECT_EQ(doc[0]["findings"][0]["field"], "/meshes/0/primitives/0");
  EXPECT_EQ(doc[1]["ok"], true);
}

TEST(CliLuminaire, BrokenFilesAreLocatedErrors) {
  const auto dir = lumx_gltf_test::scratch_dir("cli_broken");
  lumx_gltf_test::GltfBuilder b;
  b.set_scene({b.add_node({{"mesh", b.add_mesh(lumx_gltf_test::unit_quad(), -1)}})});
  b.doc["accessors"][0]["count"] = 1000;
  b.write_gltf(dir / "broken.gltf");
  const CliRun info = run("info " + q(dir / "broken.gltf"));
  EXPECT_EQ(info.status, 1);
  EXPECT_TRUE(has(info.out, "broken.gltf: error: /accessors/0/count: is 1000")) << info.out;
  const CliRun check = run("check --json " + q(dir / "broken.gltf"), false);
  EXPECT_EQ(check.status, 1);
  const auto doc = nlohmann::json::parse(check.out);
  EXPECT_EQ(doc[0]["findings"][0]["field"], "/accessors/0/count");
  EXPECT_EQ(doc[0]["findings"][0]["severity"], "error");

  lumx_gltf_test::write_text(dir / "cut.glb", "glTF\x02");
  const CliRun cut = run("check " + q(dir / "cut.glb"));
  EXPECT_EQ(cut.status, 1);
  EXPECT_TRUE(has(cut.out, "cut.glb:@0: error: GLB header")) << cut.out;
}
