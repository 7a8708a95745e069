// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Luminaires written by write_gltf_luminaire read back by read_gltf_luminaire with the same triangles,
// materials and emitters (their fluxes to float precision), as .glb and as .gltf with a data URI.
#include "luminaire_test_scenes.h"

#include <lumx/bake/gltf_reader.h>
#include <lumx/bake/gltf_writer.h>
#include <lumx/io/photometry_io.h>

#include "test_support.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <sys/wait.h>

namespace {

using namespace lumx_test;
namespace fs = std::filesystem;

double part_area(const LuminaireScene& scene, std::size_t part) {
  double area = 0.0;
  for (std::uint32_t t = 0; t < scene.parts[part].triangle_count; ++t)
    area += lumx::bake::triangle_area(scene, scene.parts[part].first_triangle + t);
  return area;
}

LuminaireScene sample_scene() {
  SceneBuilder b("round trip");
  Material glass = smooth_glass(1.52, 0.7, 0.03);
  glass.roughness = 0.2;
  b.begin_part("ball", b.add_material(glass));
  add_sphere(b, 0.05, 8, 16, 0.0, true);
  Material opal = lambertian(0.9);
  opal.diffuse_transmission = 0.6;
  opal.diffuse_transmission_color = Rgb{0.9, 0.8, 0.7};
  opal.specular_color = Rgb{0.5, 0.6, 0.7};
  b.begin_part("opal", b.add_material(opal));
  add_disk(b, 0.1, 16);
  Material tube = emissive(5000.0, true);
  tube.emissive = Rgb{1.0, 0.8, 0.5};
  b.begin_part("tube", b.add_material(tube));
  add_disk(b, 0.02, 12);
  b.point_light({0.0, 0.0, 0.01}, 3.0);
  lumx::bake::Emitter spot;
  spot.kind = lumx::bake::EmitterKind::spot;
  spot.name = "spot";
  spot.intensity_cd = Rgb{40.0, 20.0, 10.0};
  spot.inner_cone_rad = 0.2;
  spot.outer_cone_rad = 0.45;
  spot.to_world = glm::translate(glm::rotate(glm::dmat4(1.0), 0.4, glm::dvec3(0, 1, 0)), glm::dvec3(0.1, 0.0, 0.0));
  b.scene().emitters.push_back(spot);
  lumx::bake::Emitter ies;
  ies.kind = lumx::bake::EmitterKind::ies;
  ies.name = "ies";
  ies.photometry = std::make_shared<lumx::Photometry>(
      lumx::read_photometry(std::string(LUMX_SOURCE_DIR) + "/samples/downlight.ies"));
  ies.multiplier = 0.25;
  ies.color = Rgb{1.0, 0.9, 0.8};
  b.scene().emitters.push_back(ies);
  return b.scene();
}

TEST(BakeGltfWriter, RoundTripKeepsGeometryMaterialsAndEmitters) {
  const LuminaireScene scene = sample_scene();
  const fs::path dir = lumx_test::unique_temp_path("lumx_gltf_writer");
  fs::create_directories(dir);
  for (const bool binary : {true, false}) {
    lumx::bake::GltfWriteOptions o;
    o.binary = binary;
    const fs::path path = dir / (binary ? "lamp.glb" : "lamp.gltf");
    lumx::bake::write_gltf_luminaire(scene, path.string(), o);
    const LuminaireScene back = lumx::bake::read_gltf_luminaire(path.string());
    ASSERT_EQ(back.triangle_count(), scene.triangle_count());
    ASSERT_EQ(back.parts.size(), scene.parts.size());
    for (std::size_t p = 0; p < scene.parts.size(); ++p) {
      const double a0 = part_area(scene, p);
      EXPECT_NEAR(part_area(back, p), a0, 1e-6 * a0) << p;
      const Material& m0 = scene.materials[scene.parts[p].material];
      const Material& m1 = back.materials[back.parts[p].material];
      EXPECT_NEAR(m1.roughness, m0.roughness, 1e-12);
      EXPECT_NEAR(m1.metallic, m0.metallic, 1e-12);
      EXPECT_NEAR(m1.ior, m0.ior, 1e-12);
      EXPECT_NEAR(m1.specular, m0.specular, 1e-12);
      EXPECT_NEAR(m1.transmission, m0.transmission, 1e-12);
      EXPECT_NEAR(m1.diffuse_transmission, m0.diffuse_transmission, 1e-12);
      EXPECT_EQ(m1.volume, m0.volume);
      EXPECT_EQ(m1.double_sided, m0.double_sided);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(m1.emitted_luminance()[c], m0.emitted_luminance()[c], 1e-9 * (1 + m0.emitted_luminance()[c]));
        EXPECT_NEAR(m1.specular_color[c], m0.specular_color[c], 1e-12);
        EXPECT_NEAR(m1.attenuation_color[c], m0.attenuation_color[c], 1e-12);
        EXPECT_NEAR(m1.diffuse_transmission_color[c], m0.diffuse_transmission_color[c], 1e-12);
      }
      if (m0.volume) {
        EXPECT_NEAR(m1.attenuation_distance_m, m0.attenuation_distance_m, 1e-12);
      }
    }
    // Emitters may come back in another order (surface emitters with their parts): compare fluxes by kind.
    auto fluxes = [](const LuminaireScene& s) {
      std::map<std::string, double> f;
      for (const auto& e : s.emitters) f[lumx::bake::to_string(e.kind)] += lumx::bake::emitter_flux_lm(s, e);
      return f;
    };
    const auto f0 = fluxes(scene), f1 = fluxes(back);
    ASSERT_EQ(f0.size(), f1.size());
    for (const auto& [kind, flux] : f0) EXPECT_NEAR(f1.at(kind), flux, 1e-5 * flux) << kind;
    for (const auto& e : back.emitters)
      if (e.kind == lumx::bake::EmitterKind::spot) {
        EXPECT_NEAR(e.to_world[3][0], scene.emitters[2].to_world[3][0], 1e-9);
        EXPECT_NEAR(e.to_world[2][0], scene.emitters[2].to_world[2][0], 1e-9);  // the axis −z turned with the node
      }
  }
  fs::remove_all(dir);
}

// Draco-compressed: positions quantised to 14 bits over each mesh's box (a 0.2 m box: 12 µm steps), so areas
// agree to ~10⁻⁴ and the triangle count exactly.
TEST(BakeGltfWriter, DracoRoundTrip) {
  const LuminaireScene scene = sample_scene();
  const fs::path path = lumx_test::unique_temp_path("lumx_gltf_writer_draco.glb");
  lumx::bake::GltfWriteOptions o;
  o.draco = true;
  lumx::bake::write_gltf_luminaire(scene, path.string(), o);
  const LuminaireScene back = lumx::bake::read_gltf_luminaire(path.string());
  ASSERT_EQ(back.triangle_count(), scene.triangle_count());
  ASSERT_EQ(back.parts.size(), scene.parts.size());
  for (std::size_t p = 0; p < scene.parts.size(); ++p) {
    const double a0 = part_area(scene, p);
    EXPECT_NEAR(part_area(back, p), a0, 1e-3 * a0) << p;
  }
  double f0 = 0.0, f1 = 0.0;
  for (const auto& e : scene.emitters) f0 += lumx::bake::emitter_flux_lm(scene, e);
  for (const auto& e : back.emitters) f1 += lumx::bake::emitter_flux_lm(back, e);
  EXPECT_NEAR(f1, f0, 1e-3 * f0);
  fs::remove(path);
}

TEST(BakeGltfWriter, RaysetEmittersAreRefusedByName) {
  LuminaireScene scene = sample_scene();
  lumx::bake::Emitter e;
  e.kind = lumx::bake::EmitterKind::rayset;
  e.name = "led";
  e.rayset_path = "/nonexistent.tm25ray";
  scene.emitters.push_back(e);
  const fs::path path = lumx_test::unique_temp_path("lumx_gltf_writer_rayset.glb");
  try {
    lumx::bake::write_gltf_luminaire(scene, path.string());
    FAIL() << "expected lumx::Error";
  } catch (const lumx::Error& err) {
    EXPECT_NE(std::string(err.what()).find("led"), std::string::npos) << err.what();
  }
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace

namespace {

/// The Khronos glTF-Validator's module folder: $LUMX_GLTF_VALIDATOR, else out/tools/node_modules/gltf-validator
/// (installed there by scripts/gltf_validator.sh). Empty if neither exists.
fs::path gltf_validator_module() {
  if (const char* env = std::getenv("LUMX_GLTF_VALIDATOR"); env && *env) return env;
  const fs::path p = fs::path(LUMX_SOURCE_DIR) / "out" / "tools" / "node_modules" / "gltf-validator";
  return fs::exists(p / "package.json") ? p : fs::path();
}

/// Runs tests/tools/gltf_validate.mjs on `files`; its exit status and output.
std::pair<int, std::string> run_validator(const fs::path& module, const std::vector<fs::path>& files, const fs::path& log) {
  std::string cmd = "node " + (fs::path(LUMX_SOURCE_DIR) / "tests" / "tools" / "gltf_validate.mjs").string() + " '" +
                    module.string() + "'";
  for (const auto& f : files) cmd += " '" + f.string() + "'";
  cmd += " > '" + log.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_text(log)};
}

}  // namespace

// What write_gltf_luminaire writes is valid glTF 2.0 for the Khronos glTF-Validator (hard-cases.md §6 item
// 25): .glb, .gltf with a data URI, and Draco-compressed, with no error and no warning.
TEST(BakeGltfWriter, OutputPassesTheKhronosValidator) {
  const fs::path module = gltf_validator_module();
  if (module.empty() || std::system("node --version > /dev/null 2>&1") != 0) {
    if (in_ci()) FAIL() << "the glTF-Validator is missing (bash scripts/gltf_validator.sh installs it), but CI has it";
    GTEST_SKIP() << "no Node.js or glTF-Validator (bash scripts/gltf_validator.sh installs it)";
  }
  const LuminaireScene scene = sample_scene();
  const fs::path dir = unique_temp_path("lumx_gltf_validator");
  fs::create_directories(dir);
  std::vector<fs::path> files;
  for (const int variant : {0, 1, 2}) {
    lumx::bake::GltfWriteOptions o;
    o.binary = variant != 1;
    o.draco = variant == 2;
    files.push_back(dir / (variant == 0 ? "lamp.glb" : variant == 1 ? "lamp.gltf" : "lamp_draco.glb"));
    lumx::bake::write_gltf_luminaire(scene, files.back().string(), o);
  }
  const auto [status, report] = run_validator(module, files, dir / "report.txt");
  EXPECT_EQ(status, 0) << report;
  for (const auto& f : files) EXPECT_NE(report.find(f.string() + " errors 0 warnings 0 "), std::string::npos) << report;
  // The check can fail: a GLB whose JSON chunk is one byte short is an error for the validator.
  std::string bad = read_text(files[0]);
  bad[12] = static_cast<char>(bad[12] - 1);
  const fs::path broken = dir / "broken.glb";
  std::ofstream(broken, std::ios::binary) << bad;
  const auto [bad_status, bad_report] = run_validator(module, {broken}, dir / "bad_report.txt");
  EXPECT_EQ(bad_status, 1) << bad_report;
  EXPECT_EQ(bad_report.find(broken.string() + " errors 0 "), std::string::npos) << bad_report;
  fs::remove_all(dir);
}
