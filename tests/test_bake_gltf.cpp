// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The glTF 2.0 luminaire reader (lumx/bake/gltf_reader.h) and the scene checks (lumx/bake/luminaire_check.h):
// synthetic files written here (transforms, materials, every emitter kind and its flux, extensions, bad
// input with the exact JSON pointer or byte offset) and the real flower pendant in ../shared, plain and Draco.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gltf_test_support.h"
#include "test_support.h"

#include <lumx/bake/gltf_reader.h>
#include <lumx/bake/gltf_writer.h>
#include <lumx/bake/luminaire_builder.h>
#include <lumx/bake/luminaire_check.h>
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/intensity_table.h>

#include <glm/geometric.hpp>

#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <random>

namespace fs = std::filesystem;
namespace bake = lumx::bake;
using lumx_gltf_test::GltfBuilder;
using lumx_gltf_test::Json;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// The error reading `path` throws (fails the test when it reads).
lumx::Diagnostic read_error(const fs::path& path) {
  try {
    bake::read_gltf_luminaire(path.string());
  } catch (const lumx::Error& e) {
    return e.diagnostic();
  }
  ADD_FAILURE() << path << " was read without error";
  return {};
}

bool has_warning(const bake::LuminaireScene& s, const std::string& field) {
  for (const auto& w : s.warnings)
    if (w.field == field) return true;
  return false;
}

double part_area(const bake::LuminaireScene& s, const bake::Part& p) {
  double a = 0.0;
  for (std::uint32_t t = 0; t < p.triangle_count; ++t) a += bake::triangle_area(s, p.first_triangle + t);
  return a;
}

/// A one-quad luminaire with one emissive material, for the bad-input tests to break.
GltfBuilder emissive_quad() {
  GltfBuilder b;
  const int m = b.add_material({{"emissiveFactor", {1, 1, 1}}});
  const int mesh = b.add_mesh(lumx_gltf_test::unit_quad(), m);
  b.set_scene({b.add_node({{"mesh", mesh}})});
  return b;
}

const char* kIesProfile =
    "IESNA:LM-63-2002\n"
    "[TEST] lumx glTF reader\n"
    "TILT=NONE\n"
    "1 1000 1 5 1 1 2 0 0 0\n"
    "1 1 10\n"
    "0 45 90 135 180\n"
    "0\n"
    "100 80 50 20 0\n";

}  // namespace

// ---- geometry and transforms ------------------------------------------------------------------------------------

TEST(GltfReader, NodeTransformsComposeIntoWorldPositionsAndNormals) {
  const auto dir = lumx_gltf_test::scratch_dir("transforms");
  GltfBuilder b;
  const int mesh = b.add_mesh(lumx_gltf_test::unit_quad(), -1, true, "quad");
  // Parent: translate (1, 2, 3), scale 2. Child: rotate 90° about +z, translate (0, 0, 1) (in the parent's frame).
  const double h = std::sqrt(0.5);
  const int child = b.add_node({{"name", "child"}, {"mesh", mesh}, {"rotation", {0, 0, h, h}}, {"translation", {0, 0, 1}}});
  const int parent = b.add_node({{"name", "parent"}, {"children", {child}}, {"translation", {1, 2, 3}}, {"scale", {2, 2, 2}}});
  // A matrix node (column-major) mirroring x: negative determinant flips the winding.
  const int mirror = b.add_node({{"name", "mirror"}, {"mesh", mesh},
                                 {"matrix", {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 0, 0, 1}}});
  b.set_scene({parent, mirror});
  b.write_gltf(dir / "t.gltf");
  const auto s = bake::read_gltf_luminaire((dir / "t.gltf").string());
  ASSERT_EQ(s.parts.size(), 2u);
  EXPECT_EQ(s.parts[0].name, "child");
  EXPECT_EQ(s.parts[0].source, "/meshes/0/primitives/0");
  EXPECT_EQ(s.parts[0].node, child);
  EXPECT_EQ(s.parts[1].name, "mirror");
  // Child vertex (1, 0, 0) → rotate → (0, 1, 0) → +(0,0,1) → (0, 1, 1) → ×2 + (1,2,3) → (1, 4, 5).
  const glm::vec3 expect[4] = {{1, 2, 5}, {1, 4, 5}, {-1, 4, 5}, {-1, 2, 5}};
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(s.positions[i][k], expect[i][k], 1e-6) << i << " " << k;
  ASSERT_EQ(s.normals.size(), s.positions.size());
  EXPECT_NEAR(s.normals[0].z, 1.0, 1e-6);
  EXPECT_NEAR(glm::length(s.normals[0]), 1.0, 1e-6);  // renormalised after the scale of 2
  // Mirrored quad: x → 10 − x exactly; the winding is flipped so the geometric normal stays +z.
  EXPECT_EQ(s.positions[5], glm::vec3(9, 0, 0));
  const std::size_t t = s.parts[1].first_triangle;
  const glm::vec3 a = s.positions[s.indices[3 * t]], bb = s.positions[s.indices[3 * t + 1]],
                  c = s.positions[s.indices[3 * t + 2]];
  EXPECT_GT(glm::cross(bb - a, c - a).z, 0.0f);
  EXPECT_NEAR(s.normals[5].z, 1.0, 1e-6);
  EXPECT_NEAR(part_area(s, s.parts[0]), 4.0, 1e-6);
  EXPECT_NEAR(part_area(s, s.parts[1]), 1.0, 1e-6);
  EXPECT_FALSE(s.parts[0].closed);
}

TEST(GltfReader, GlbExternalBufferAndDataUriReadTheSameScene) {
  const auto dir = lumx_gltf_test::scratch_dir("containers");
  GltfBuilder b;
  const int mesh = b.add_mesh(lumx_gltf_test::unit_cube(), b.add_material({{"name", "white"}}));
  b.set_scene({b.add_node({{"mesh", mesh}, {"translation", {0.5, 0, 0}}})});
  b.write_gltf(dir / "a.gltf");
  b.write_gltf_external(dir / "b.gltf", "b%20data.bin");  // percent-encoded URI of "b data.bin"
  fs::rename(dir / "b%20data.bin", dir / "b data.bin");
  b.write_glb(dir / "c.glb");
  const auto sa = bake::read_gltf_luminaire((dir / "a.gltf").string());
  const auto sb = bake::read_gltf_luminaire((dir / "b.gltf").string());
  const auto sc = bake::read_gltf_luminaire((dir / "c.glb").string());
  for (const auto* s : {&sa, &sb, &sc}) {
    EXPECT_EQ(s->triangle_count(), 12u);
    EXPECT_EQ(s->positions, sa.positions);
    EXPECT_EQ(s->indices, sa.indices);
    ASSERT_EQ(s->parts.size(), 1u);
    EXPECT_TRUE(s->parts[0].closed);
    EXPECT_NEAR(part_area(*s, s->parts[0]), 6.0, 1e-6);
    EXPECT_EQ(s->materials[0].name, "white");
  }
}

TEST(GltfReader, StripsFansNonIndexedAndMissingNormals) {
  const auto dir = lumx_gltf_test::scratch_dir("modes");
  GltfBuilder b;
  const auto quad = lumx_gltf_test::unit_quad();
  const int pos = b.add_vec3(quad.positions);
  const int strip_idx = b.add_indices({0, 1, 3, 2});
  const int fan_idx = b.add_indices({0, 1, 2, 3});
  const int nrm = b.add_vec3(quad.normals, false);
  const int mesh = b.push("meshes", {{"primitives",
                                      {{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}}, {"indices", strip_idx}, {"mode", 5}},
                                       {{"attributes", {{"POSITION", pos}}}, {"indices", fan_idx}, {"mode", 6}}}}});
  b.set_scene({b.add_node({{"mesh", mesh}, {"name", "n"}})});
  b.write_gltf(dir / "m.gltf");
  const auto s = bake::read_gltf_luminaire((dir / "m.gltf").string());
  ASSERT_EQ(s.parts.size(), 2u);
  EXPECT_EQ(s.parts[0].name, "n[0]");
  EXPECT_EQ(s.parts[1].name, "n[1]");
  for (const auto& p : s.parts) {
    EXPECT_EQ(p.triangle_count, 2u);
    EXPECT_NEAR(part_area(s, p), 1.0, 1e-6);
    for (std::uint32_t t = 0; t < p.triangle_count; ++t) {  // every triangle faces +z
      const std::size_t i = p.first_triangle + t;
      const glm::vec3 a = s.positions[s.indices[3 * i]], c1 = s.positions[s.indices[3 * i + 1]],
                      c2 = s.positions[s.indices[3 * i + 2]];
      EXPECT_GT(glm::cross(c1 - a, c2 - a).z, 0.0f);
    }
  }
  // The fan has no normals while the strip does: it gets flat normals on unshared vertices.
  ASSERT_EQ(s.normals.size(), s.positions.size());
  EXPECT_EQ(s.positions.size(), 4u + 6u);
  EXPECT_EQ(s.normals.back(), glm::vec3(0, 0, 1));

  // No normals anywhere: the scene has none (flat shading).
  GltfBuilder nb;
  nb.set_scene({nb.add_node({{"mesh", nb.add_mesh(quad, -1, false)}})});
  nb.write_gltf(dir / "n.gltf");
  EXPECT_TRUE(bake::read_gltf_luminaire((dir / "n.gltf").string()).normals.empty());
}

TEST(GltfReader, WithoutScenesEveryRootNodeIsPlaced) {
  const auto dir = lumx_gltf_test::scratch_dir("roots");
  GltfBuilder b;
  const int mesh = b.add_mesh(lumx_gltf_test::unit_quad(), -1);
  const int child = b.add_node({{"mesh", mesh}});
  b.add_node({{"children", {child}}});
  b.add_node({{"mesh", mesh}, {"translation", {0, 0, 2}}});
  b.write_gltf(dir / "r.gltf");
  const auto s = bake::read_gltf_luminaire((dir / "r.gltf").string());
  EXPECT_EQ(s.parts.size(), 2u);
  // Scene 1 is the default: only its node is placed.
  b.doc["scenes"] = Json::array({{{"nodes", {1}}}, {{"nodes", {2}}}});
  b.doc["scene"] = 1;
  b.write_gltf(dir / "s.gltf");
  const auto s1 = bake::read_gltf_luminaire((dir / "s.gltf").string());
  ASSERT_EQ(s1.parts.size(), 1u);
  EXPECT_EQ(s1.positions[0].z, 2.0f);
}

// ---- materials --------------------------------------------------------------------------------------------------

TEST(GltfReader, MaterialsTakeEveryExtensionValueAndTheDefaults) {
  const auto dir = lumx_gltf_test::scratch_dir("materials");
  GltfBuilder b;
  const int glass = b.add_material(
      {{"name", "glass"},
       {"pbrMetallicRoughness", {{"baseColorFactor", {1.0, 0.9, 0.98, 1.0}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.25}}},
       {"doubleSided", true},
       {"extensions",
        {{"KHR_materials_ior", {{"ior", 1.5046}}},
         {"KHR_materials_specular", {{"specularFactor", 0.5}, {"specularColorFactor", {1.0, 0.8, 2.0}}}},
         {"KHR_materials_transmission", {{"transmissionFactor", 0.75}}},
         {"KHR_materials_volume", {{"thicknessFactor", 0.01}, {"attenuationDistance", 0.2}, {"attenuationColor", {0.5, 0.6, 0.7}}}}}}});
  const int diffuser = b.add_material(
      {{"name", "diffuser"},
       {"extensions",
        {{"KHR_materials_diffuse_transmission",
          {{"diffuseTransmissionFactor", 0.4}, {"diffuseTransmissionColorFactor", {0.9, 0.8, 0.7}}}},
         {"KHR_materials_emissive_strength", {{"emissiveStrength", 250.0}}}}},
       {"emissiveFactor", {0.2, 0.4, 0.6}},
       {"emissiveTexture", {{"index", 0}}},
       {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}},
       {"alphaMode", "BLEND"}});
  const int plain = b.add_material(Json::object());
  const auto quad = lumx_gltf_test::unit_quad();
  b.set_scene({b.add_node({{"mesh", b.add_mesh(quad, glass)}}), b.add_node({{"mesh", b.add_mesh(quad, diffuser)}}),
               b.add_node({{"mesh", b.add_mesh(quad, plain)}}), b.add_node({{"mesh", b.add_mesh(quad, -1)}})});
  b.doc["materials"][glass]["extensions"]["KHR_materials_clearcoat"] = {{"clearcoatFactor", 1}};
  b.write_gltf(dir / "m.gltf");
  const auto s = bake::read_gltf_luminaire((dir / "m.gltf").string());
  ASSERT_EQ(s.materials.size(), 4u);  // three from the file and glTF's default for the fourth quad
  const bake::Material& g = s.materials[0];
  EXPECT_EQ(g.name, "glass");
  EXPECT_EQ(g.base_color, bake::Rgb(1.0, 0.9, 0.98));
  EXPECT_EQ(g.metallic, 0.0);
  EXPECT_EQ(g.roughness, 0.25);
  EXPECT_EQ(g.ior, 1.5046);
  EXPECT_EQ(g.specular, 0.5);
  EXPECT_EQ(g.specular_color, bake::Rgb(1.0, 0.8, 2.0));
  EXPECT_EQ(g.transmission, 0.75);
  EXPECT_TRUE(g.volume);
  EXPECT_EQ(g.thickness_m, 0.01);
  EXPECT_EQ(g.attenuation_distance_m, 0.2);
  EXPECT_EQ(g.attenuation_color, bake::Rgb(0.5, 0.6, 0.7));
  EXPECT_TRUE(g.double_sided);
  EXPECT_FALSE(g.emissive_any());
  const bake::Material& d = s.materials[1];
  EXPECT_EQ(d.diffuse_transmission, 0.4);
  EXPECT_EQ(d.diffuse_transmission_color, bake::Rgb(0.9, 0.8, 0.7));
  EXPECT_EQ(d.emissive, bake::Rgb(0.2, 0.4, 0.6));
  EXPECT_EQ(d.emissive_strength, 250.0);
  EXPECT_TRUE(d.emissive_any());
  for (const bake::Material* m : {&s.materials[2], &s.materials[3]}) {  // glTF defaults
    EXPECT_EQ(m->base_color, bake::Rgb(1.0));
    EXPECT_EQ(m->metallic, 1.0);
    EXPECT_EQ(m->roughness, 1.0);
    EXPECT_EQ(m->ior, 1.5);
    EXPECT_EQ(m->specular, 1.0);
    EXPECT_EQ(m->transmission, 0.0);
    EXPECT_EQ(m->diffuse_transmission, 0.0);
    EXPECT_FALSE(m->volume);
    EXPECT_TRUE(std::isinf(m->attenuation_distance_m));
    EXPECT_EQ(m->emissive, bake::Rgb(0.0));
    EXPECT_EQ(m->emissive_strength, 1.0);
    EXPECT_FALSE(m->double_sided);
  }
  EXPECT_EQ(s.materials[3].name, "glTF default");
  EXPECT_EQ(s.parts[3].material, 3u);
  // Textures, the alpha mode and an unimplemented material extension are warnings naming them.
  EXPECT_TRUE(has_warning(s, "/materials/1/emissiveTexture"));
  EXPECT_TRUE(has_warning(s, "/materials/1/pbrMetallicRoughness/baseColorTexture"));
  EXPECT_TRUE(has_warning(s, "/materials/1/alphaMode"));
  EXPECT_TRUE(has_warning(s, "/materials/0/extensions/KHR_materials_clearcoat"));
  // The emissive material makes its part a surface emitter: π L A with L = luminance(0.2, 0.4, 0.6) × 250.
  ASSERT_EQ(s.emitters.size(), 1u);
  EXPECT_EQ(s.emitters[0].kind, bake::EmitterKind::surface);
  EXPECT_EQ(s.emitters[0].part, 1u);
  EXPECT_EQ(s.emitters[0].source, "/materials/1");
  EXPECT_NEAR(bake::emitter_flux_lm(s, s.emitters[0]), kPi * 250.0 * bake::luminance({0.2, 0.4, 0.6}), 1e-9);
}

TEST(GltfReader, MaterialValuesOutsideTheirRangeAreLocatedErrors) {
  const auto dir = lumx_gltf_test::scratch_dir("material_range");
  auto with = [&](const char* name, Json material) {
    GltfBuilder b = emissive_quad();
    b.doc["materials"][0] = material;
    b.write_gltf(dir / name);
    return read_error(dir / name).field;
  };
  EXPECT_EQ(with("a.gltf", {{"pbrMetallicRoughness", {{"roughnessFactor", 1.5}}}}), "/materials/0/pbrMetallicRoughness/roughnessFactor");
  EXPECT_EQ(with("b.gltf", {{"emissiveFactor", {1, 1}}}), "/materials/0/emissiveFactor");
  EXPECT_EQ(with("c.gltf", {{"extensions", {{"KHR_materials_ior", {{"ior", 0.5}}}}}}), "/materials/0/extensions/KHR_materials_ior/ior");
  EXPECT_EQ(with("d.gltf", {{"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", -1}}}}}}),
            "/materials/0/extensions/KHR_materials_emissive_strength/emissiveStrength");
  EXPECT_EQ(with("e.gltf", {{"doubleSided", "yes"}}), "/materials/0/doubleSided");
}

// ---- emitters ---------------------------------------------------------------------------------------------------

TEST(GltfReader, PunctualLightsAndSurfaceEmittersHaveTheirFlux) {
  const auto dir = lumx_gltf_test::scratch_dir("lights");
  GltfBuilder b;
  b.use_extension("KHR_lights_punctual");
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"type", "point"}, {"name", "bulb"}, {"intensity", 10.0}, {"color", {1.0, 0.5, 0.25}}},
      {{"type", "spot"}, {"intensity", 100.0}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.6}}}},
      {{"type", "directional"}}};
  const int one_sided = b.add_material({{"emissiveFactor", {1, 1, 1}}, {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 1000}}}}}});
  const int two_sided = b.add_material({{"emissiveFactor", {1, 1, 1}}, {"doubleSided", true}});
  const int point = b.add_node({{"name", "p"}, {"translation", {1, 2, 3}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  const int spot = b.add_node({{"name", "s"}, {"rotation", {1, 0, 0, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  const int sun = b.add_node({{"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
  const int disk = b.add_node({{"mesh", b.add_mesh(lumx_gltf_test::disk(64, 0.1f), one_sided)}, {"name", "disk"}});
  const int quad = b.add_node({{"mesh", b.add_mesh(lumx_gltf_test::unit_quad(), two_sided)}, {"scale", {2, 1, 1}}});
  b.set_scene({point, spot, sun, disk, quad});
  b.write_gltf(dir / "l.gltf");
  const auto s = bake::read_gltf_luminaire((dir / "l.gltf").string());
  EXPECT_TRUE(has_warning(s, "/nodes/2/extensions/KHR_lights_punctual/light"));  // directional: ignored
  ASSERT_EQ(s.emitters.size(), 4u);
  const auto& p = s.emitters[0];
  EXPECT_EQ(p.kind, bake::EmitterKind::point);
  EXPECT_EQ(p.name, "bulb");
  EXPECT_EQ(p.source, "/extensions/KHR_lights_punctual/lights/0");
  EXPECT_EQ(p.intensity_cd, bake::Rgb(10.0, 5.0, 2.5));
  EXPECT_EQ(glm::dvec3(p.to_world[3]), glm::dvec3(1, 2, 3));
  EXPECT_NEAR(bake::emitter_flux_lm(s, p), 4 * kPi * bake::luminance({10.0, 5.0, 2.5}), 1e-9);
  const auto& sp = s.emitters[1];
  EXPECT_EQ(sp.kind, bake::EmitterKind::spot);
  EXPECT_EQ(sp.name, "s");
  EXPECT_EQ(sp.inner_cone_rad, 0.2);
  EXPECT_EQ(sp.outer_cone_rad, 0.6);
  // Rotated 180° about x: the spot's −z axis points along +z in the world.
  EXPECT_NEAR((sp.to_world * glm::dvec4(0, 0, -1, 0)).z, 1.0, 1e-12);
  // Spot flux: 2π ∫ I falloff(cos θ) sin θ dθ, integrated numerically here.
  double integral = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double mu = -1.0 + (i + 0.5) * 2.0 / n;
    integral += bake::spot_falloff(mu, 0.2, 0.6) * 2.0 / n;
  }
  EXPECT_NEAR(bake::emitter_flux_lm(s, sp), 2 * kPi * 100.0 * integral, 1e-6 * 2 * kPi * 100.0 * integral);
  // Surfaces: π L A, one-sided disk (area of the 64-gon), double-sided quad scaled to 2 m² (× 2 sides).
  const auto& d = s.emitters[2];
  EXPECT_EQ(d.kind, bake::EmitterKind::surface);
  EXPECT_EQ(d.name, "disk");
  const double ngon = 0.5 * 64 * 0.01 * std::sin(2 * kPi / 64);
  EXPECT_NEAR(bake::emitter_flux_lm(s, d), kPi * 1000.0 * ngon, 1e-6 * kPi * 1000.0 * ngon);
  EXPECT_NEAR(bake::emitter_flux_lm(s, s.emitters[3]), kPi * 1.0 * 2.0 * 2.0, 1e-6);
}

TEST(GltfReader, IesProfilesFromAFileADataUriAndABufferView) {
  const auto dir = lumx_gltf_test::scratch_dir("ies");
  lumx_gltf_test::write_text(dir / "profile.ies", kIesProfile);
  GltfBuilder b;
  b.use_extension("EXT_lights_ies");
  const std::string text = kIesProfile;
  const int view = b.add_view(text.data(), text.size());
  b.doc["extensions"]["EXT_lights_ies"]["lights"] = {
      {{"uri", "profile.ies"}, {"name", "downlight"}},
      {{"uri", "data:application/x-ies-lm-63;base64," +
                   lumx_gltf_test::base64(std::vector<std::uint8_t>(text.begin(), text.end()))}},
      {{"bufferView", view}, {"mimeType", "application/x-ies-lm-63"}}};
  std::vector<int> nodes;
  for (int i = 0; i < 3; ++i)
    nodes.push_back(b.add_node({{"translation", {0, 0, i}},
                                {"extensions", {{"EXT_lights_ies", {{"light", i}, {"multiplier", 2.0}, {"color", {1.0, 0.5, 2.0}}}}}}}));
  b.set_scene(nodes);
  b.write_gltf(dir / "i.gltf");
  const auto s = bake::read_gltf_luminaire((dir / "i.gltf").string());
  ASSERT_EQ(s.emitters.size(), 3u);
  const lumx::Photometry ref = lumx::read_ies(kIesProfile, "profile.ies");
  const double profile_flux = lumx::IntensityTable(ref).flux_lm();
  EXPECT_GT(profile_flux, 0.0);
  for (int i = 0; i < 3; ++i) {
    const auto& e = s.emitters[i];
    EXPECT_EQ(e.kind, bake::EmitterKind::ies);
    EXPECT_EQ(e.source, "/extensions/EXT_lights_ies/lights/" + std::to_string(i));
    ASSERT_TRUE(e.photometry);
    EXPECT_EQ(e.multiplier, 2.0);
    EXPECT_EQ(e.color, bake::Rgb(1.0, 0.5, 1.0));  // clamped to [0, 1] as the extension says
    EXPECT_EQ(e.to_world[3][2], double(i));
    EXPECT_NEAR(bake::emitter_flux_lm(s, e), profile_flux * 2.0 * bake::luminance({1.0, 0.5, 1.0}), 1e-9 * profile_flux);
  }
  EXPECT_EQ(s.emitters[0].name, "downlight");
}

TEST(GltfReader, RaysetEmitterExtension) {
  const auto dir = lumx_gltf_test::scratch_dir("rayset");
  lumx_gltf_test::write_text(dir / "rays.txt",
                             "# lumx-rays length=mm flux=lm total=3\n0 0 0 0 0 1 1\n0 0 0 0 1 0 1\n0 0 0 1 0 0 1\n");
  GltfBuilder b;
  b.use_extension("LUMX_lights_rayset", true);
  b.set_scene({b.add_node({{"name", "led"}, {"translation", {0, 0.5, 0}},
                           {"extensions", {{"LUMX_lights_rayset", {{"uri", "rays.txt"}, {"color", {1.0, 1.0, 0.5}}}}}}})});
  b.write_gltf(dir / "r.gltf");
  const auto s = bake::read_gltf_luminaire((dir / "r.gltf").string());
  ASSERT_EQ(s.emitters.size(), 1u);
  const auto& e = s.emitters[0];
  EXPECT_EQ(e.kind, bake::EmitterKind::rayset);
  EXPECT_EQ(e.name, "led");
  EXPECT_EQ(e.source, "/nodes/0/extensions/LUMX_lights_rayset");
  EXPECT_EQ(fs::path(e.rayset_path), dir / "rays.txt");
  EXPECT_EQ(e.to_world[3][1], 0.5);
  EXPECT_NEAR(bake::emitter_flux_lm(s, e), 3.0 * bake::luminance({1.0, 1.0, 0.5}), 1e-9);
  // A missing ray file is an error at the uri.
  b.doc["nodes"][0]["extensions"]["LUMX_lights_rayset"]["uri"] = "missing.txt";
  b.write_gltf(dir / "m.gltf");
  EXPECT_EQ(read_error(dir / "m.gltf").field, "/nodes/0/extensions/LUMX_lights_rayset/uri");
}

// ---- extensions -------------------------------------------------------------------------------------------------

TEST(GltfReader, RequiredExtensionsLumxLacksAreErrorsUsedOnesWarnings) {
  const auto dir = lumx_gltf_test::scratch_dir("extensions");
  GltfBuilder b = emissive_quad();
  b.use_extension("KHR_materials_emissive_strength", true);
  b.use_extension("KHR_materials_sheen");
  b.use_extension("KHR_texture_transform");
  b.write_gltf(dir / "used.gltf");
  const auto s = bake::read_gltf_luminaire((dir / "used.gltf").string());
  EXPECT_TRUE(has_warning(s, "/extensionsUsed/1"));
  EXPECT_FALSE(has_warning(s, "/extensionsUsed/0"));
  EXPECT_FALSE(has_warning(s, "/extensionsUsed/2"));
  std::vector<lumx::Diagnostic> sunk;
  bake::GltfReadOptions o;
  o.warnings = [&sunk](const lumx::Diagnostic& d) { sunk.push_back(d); };
  bake::read_gltf_luminaire((dir / "used.gltf").string(), o);
  EXPECT_EQ(sunk.size(), s.warnings.size());

  b.use_extension("EXT_meshopt_compression", true);
  b.write_gltf(dir / "required.gltf");
  const auto d = read_error(dir / "required.gltf");
  EXPECT_EQ(d.field, "/extensionsRequired/1");
  EXPECT_NE(d.message.find("EXT_meshopt_compression"), std::string::npos);
  EXPECT_EQ(d.file, (dir / "required.gltf").string());
}

TEST(GltfReader, QuantizedPositionsAndNormals) {
  const auto dir = lumx_gltf_test::scratch_dir("quantized");
  GltfBuilder b;
  b.use_extension("KHR_mesh_quantization", true);
  // Unnormalised shorts (positions in mm, scaled by the node) and normalised bytes (normals), stride 8 and 4.
  const std::int16_t p[16] = {0, 0, 0, 0, 1000, 0, 0, 0, 1000, 1000, 0, 0, 0, 1000, 0, 0};
  const std::int8_t n[16] = {0, 0, 127, 0, 0, 0, 127, 0, 0, 0, 127, 0, 0, 0, 127, 0};
  const std::uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
  const int pv = b.add_view(p, sizeof p);
  b.doc["bufferViews"][pv]["byteStride"] = 8;
  const int nv = b.add_view(n, sizeof n);
  b.doc["bufferViews"][nv]["byteStride"] = 4;
  const int iv = b.add_view(idx, sizeof idx);
  const int pa = b.push("accessors", {{"bufferView", pv}, {"componentType", 5122}, {"count", 4}, {"type", "VEC3"}});
  const int na = b.push("accessors", {{"bufferView", nv}, {"componentType", 5120}, {"normalized", true}, {"count", 4}, {"type", "VEC3"}});
  const int ia = b.push("accessors", {{"bufferView", iv}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}});
  const int mesh = b.push("meshes", {{"primitives", {{{"attributes", {{"POSITION", pa}, {"NORMAL", na}}}, {"indices", ia}}}}});
  b.set_scene({b.add_node({{"mesh", mesh}, {"scale", {0.001, 0.001, 0.001}}})});
  b.write_glb(dir / "q.glb");
  const auto s = bake::read_gltf_luminaire((dir / "q.glb").string());
  ASSERT_EQ(s.triangle_count(), 2u);
  EXPECT_NEAR(s.positions[2].x, 1.0, 1e-6);
  EXPECT_NEAR(s.positions[2].y, 1.0, 1e-6);
  EXPECT_NEAR(part_area(s, s.parts[0]), 1.0, 1e-6);
  EXPECT_NEAR(s.normals[0].z, 1.0, 1e-6);
}

// ---- bad input --------------------------------------------------------------------------------------------------

TEST(GltfBadInput, EachProblemIsALocatedError) {
  const auto dir = lumx_gltf_test::scratch_dir("bad");
  int case_number = 0;
  // Writes the quad luminaire after `edit`, reads it, and returns the error's field.
  auto broken = [&](const std::function<void(GltfBuilder&)>& edit, bool glb = false) {
    GltfBuilder b = emissive_quad();
    edit(b);
    const fs::path p = dir / ("case" + std::to_string(++case_number) + (glb ? ".glb" : ".gltf"));
    glb ? b.write_glb(p) : b.write_gltf(p);
    const auto d = read_error(p);
    EXPECT_EQ(d.file, p.string());
    EXPECT_FALSE(d.message.empty());
    return d.field;
  };
  // Accessors: count × stride past the view, huge counts, a bad component type, a missing buffer view.
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["accessors"][0]["count"] = 5; }), "/accessors/0/count");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["accessors"][1]["count"] = 4000000000ull; }), "/accessors/1/count");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["accessors"][0]["byteOffset"] = 4; }), "/accessors/0/count");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["accessors"][0]["componentType"] = 5127; }), "/accessors/0/componentType");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["accessors"][0]["type"] = "VEC2"; }), "/accessors/0/type");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["accessors"][0].erase("bufferView"); }), "/accessors/0/bufferView");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["accessors"][0]["bufferView"] = 9; }), "/accessors/0/bufferView");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["accessors"][0]["sparse"] = Json::object(); }), "/accessors/0/sparse");
  // Buffer views and buffers.
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["bufferViews"][0]["byteLength"] = 1000; }), "/bufferViews/0/byteLength");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["bufferViews"][0]["byteOffset"] = 100000; }), "/bufferViews/0/byteOffset");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["bufferViews"][0]["byteStride"] = 8; }), "/bufferViews/0/byteStride");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.bin.resize(b.bin.size() - 8); }), "/bufferViews/2/byteLength");
  {
    GltfBuilder b = emissive_quad();
    Json d = b.with_buffer("data:application/octet-stream;base64," + lumx_gltf_test::base64(b.bin));
    d["buffers"][0]["byteLength"] = b.bin.size() + 100;
    lumx_gltf_test::write_text(dir / "short_buffer.gltf", d.dump());
    EXPECT_EQ(read_error(dir / "short_buffer.gltf").field, "/buffers/0/byteLength");
    d["buffers"][0]["uri"] = "missing.bin";
    lumx_gltf_test::write_text(dir / "missing_buffer.gltf", d.dump());
    EXPECT_EQ(read_error(dir / "missing_buffer.gltf").field, "/buffers/0/uri");
    d["buffers"][0]["uri"] = "data:application/octet-stream;base64,@@@";
    lumx_gltf_test::write_text(dir / "bad_base64.gltf", d.dump());
    EXPECT_EQ(read_error(dir / "bad_base64.gltf").field, "/buffers/0/uri");
  }
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["bufferViews"][0]["byteLength"] = 1000; }, true), "/bufferViews/0/byteLength");
  // Indices out of range, not whole triangles, POINTS and LINES.
  EXPECT_EQ(broken([](GltfBuilder& b) {
              const std::uint32_t bad[6] = {0, 1, 2, 0, 2, 7};
              b.doc["meshes"][0]["primitives"][0]["indices"] = b.push(
                  "accessors", {{"bufferView", b.add_view(bad, sizeof bad)}, {"componentType", 5125}, {"count", 6}, {"type", "SCALAR"}});
            }),
            "/meshes/0/primitives/0/indices");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["accessors"][1]["count"] = 5; }), "/meshes/0/primitives/0/indices");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["mode"] = 0; }), "/meshes/0/primitives/0/mode");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["mode"] = 1; }), "/meshes/0/primitives/0/mode");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["mode"] = 9; }), "/meshes/0/primitives/0/mode");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["attributes"].erase("POSITION"); }),
            "/meshes/0/primitives/0/attributes/POSITION");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["meshes"][0]["primitives"][0]["material"] = 3; }), "/meshes/0/primitives/0/material");
  // NaN / infinite positions (written as float bits) and non-finite or huge transforms.
  EXPECT_EQ(broken([](GltfBuilder& b) {
              const float nan = std::nanf("");
              std::memcpy(b.bin.data() + 4, &nan, 4);
            }),
            "/accessors/0");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["nodes"][0]["translation"] = {0, 0, 1e300}; }), "/nodes/0");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["nodes"][0]["scale"] = {1e200, 1e200, 1}; b.doc["nodes"][0]["children"] = {1};
                                        b.add_node({{"scale", {1e200, 1, 1}}}); }),
            "/nodes/1");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["nodes"][0]["matrix"] = {1, 0, 0}; }), "/nodes/0/matrix");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["nodes"][0]["rotation"] = {0, 0, 0, 0}; }), "/nodes/0/rotation");
  // The node graph: cycles, a second parent, bad indices.
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["nodes"][0]["children"] = {0}; }), "/nodes/0/children/0");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["nodes"][0]["mesh"] = 4; }), "/nodes/0/mesh");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["scenes"][0]["nodes"] = {3}; }), "/scenes/0/nodes/0");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["scene"] = 2; }), "/scene");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["scenes"][0]["nodes"] = {0, 0}; }), "/scenes/0/nodes/1");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["scenes"][0]["nodes"] = {0, b.add_node({{"children", {0}}})}; }),
            "/nodes/1/children/0");
  // Asset and lights.
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["asset"]["version"] = "1.0"; }), "/asset/version");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc.erase("asset"); }), "/asset");
  EXPECT_EQ(broken([](GltfBuilder& b) {
              b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "spot"}, {"spot", {{"innerConeAngle", 0.8}, {"outerConeAngle", 0.5}}}}};
            }),
            "/extensions/KHR_lights_punctual/lights/0/spot/innerConeAngle");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "area"}}}; }),
            "/extensions/KHR_lights_punctual/lights/0/type");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["nodes"][0]["extensions"]["KHR_lights_punctual"]["light"] = 0; }),
            "/nodes/0/extensions/KHR_lights_punctual/light");
  EXPECT_EQ(broken([](GltfBuilder& b) {
              b.doc["extensions"]["EXT_lights_ies"]["lights"] = {{{"uri", "none.ies"}}};
              b.doc["nodes"][0]["extensions"]["EXT_lights_ies"]["light"] = 0;
            }),
            "/extensions/EXT_lights_ies/lights/0/uri");
  EXPECT_EQ(broken([](GltfBuilder& b) { b.doc["nodes"][0]["extensions"]["EXT_lights_ies"]["light"] = 0; }),
            "/nodes/0/extensions/EXT_lights_ies/light");
}

TEST(GltfBadInput, SizeLimitsComeFromTheOptions) {
  const auto dir = lumx_gltf_test::scratch_dir("limits");
  GltfBuilder b = emissive_quad();
  b.doc["scenes"][0]["nodes"].push_back(b.add_node({{"mesh", 0}, {"translation", {0, 0, 1}}}));
  b.write_glb(dir / "two.glb");
  auto error_with = [&](const std::function<void(bake::GltfReadOptions&)>& limit) {
    bake::GltfReadOptions o;
    limit(o);
    try {
      bake::read_gltf_luminaire((dir / "two.glb").string(), o);
    } catch (const lumx::Error& e) {
      return e.diagnostic();
    }
    ADD_FAILURE() << "read within the limits";
    return lumx::Diagnostic{};
  };
  auto d = error_with([](auto& o) { o.max_file_bytes = 100; });
  EXPECT_EQ(d.field, "file size");
  EXPECT_EQ(d.byte_offset, 0);
  EXPECT_EQ(error_with([](auto& o) { o.max_buffer_bytes = 10; }).field, "/buffers/0/byteLength");
  EXPECT_EQ(error_with([](auto& o) { o.max_vertices = 3; }).field, "/accessors/0/count");
  EXPECT_EQ(error_with([](auto& o) { o.max_triangles = 1; }).field, "/accessors/1/count");
  // Each placement counts: two quads of 2 triangles (4 vertices) each.
  EXPECT_EQ(error_with([](auto& o) { o.max_triangles = 3; }).field, "/nodes/1");
  EXPECT_EQ(error_with([](auto& o) { o.max_vertices = 7; }).field, "/nodes/1");
  EXPECT_EQ(error_with([](auto& o) { o.max_parts = 1; }).field, "/nodes/1/mesh");
  EXPECT_EQ(error_with([](auto& o) { o.max_nodes_placed = 1; }).field, "/nodes");
  // Each error names the option to raise.
  const std::vector<std::pair<std::function<void(bake::GltfReadOptions&)>, std::string>> named = {
      {[](bake::GltfReadOptions& o) { o.max_file_bytes = 100; }, "GltfReadOptions::max_file_bytes (100)"},
      {[](bake::GltfReadOptions& o) { o.max_buffer_bytes = 10; }, "GltfReadOptions::max_buffer_bytes (10)"},
      {[](bake::GltfReadOptions& o) { o.max_vertices = 3; }, "GltfReadOptions::max_vertices (3)"},
      {[](bake::GltfReadOptions& o) { o.max_triangles = 1; }, "GltfReadOptions::max_triangles + 2 (5)"},
      {[](bake::GltfReadOptions& o) { o.max_triangles = 3; }, "GltfReadOptions::max_triangles (3)"},
      {[](bake::GltfReadOptions& o) { o.max_vertices = 7; }, "GltfReadOptions::max_vertices (7)"},
      {[](bake::GltfReadOptions& o) { o.max_parts = 1; }, "GltfReadOptions::max_parts (1)"},
      {[](bake::GltfReadOptions& o) { o.max_nodes_placed = 1; }, "GltfReadOptions::max_nodes_placed (1)"}};
  for (const auto& [limit, name] : named) {
    const std::string message = error_with(limit).message;
    EXPECT_NE(message.find(name), std::string::npos) << message;
  }
  bake::GltfReadOptions exact;
  exact.max_triangles = 4;
  exact.max_vertices = 8;
  EXPECT_EQ(bake::read_gltf_luminaire((dir / "two.glb").string(), exact).triangle_count(), 4u);
}

TEST(GltfBadInput, MalformedJsonAndGlbContainersAreLocatedByByteOffset) {
  const auto dir = lumx_gltf_test::scratch_dir("container");
  lumx_gltf_test::write_text(dir / "syntax.gltf", "{\"asset\": {\"version\": \"2.0\"},, }");
  auto d = read_error(dir / "syntax.gltf");
  EXPECT_EQ(d.field, "JSON");
  EXPECT_EQ(d.byte_offset, 29);  // the second comma
  lumx_gltf_test::write_text(dir / "truncated.gltf", "{\"asset\": {\"version\": \"2.");
  EXPECT_EQ(read_error(dir / "truncated.gltf").field, "JSON");
  lumx_gltf_test::write_text(dir / "bytes.gltf", "{\"asset\": \x89\xFF}");
  d = read_error(dir / "bytes.gltf");
  EXPECT_EQ(d.byte_offset, 10);
  EXPECT_NE(d.message.find("\\x89"), std::string::npos) << d.message;  // raw bytes shown escaped
  lumx_gltf_test::write_text(dir / "array.gltf", "[1, 2]");
  EXPECT_EQ(read_error(dir / "array.gltf").field, "");
  lumx_gltf_test::write_text(dir / "deep.gltf", std::string(200000, '[') + std::string(200000, ']'));
  d = read_error(dir / "deep.gltf");  // refused before parsing: each bracket would cost ~80 bytes of heap
  EXPECT_EQ(d.field, "JSON");
  EXPECT_EQ(d.byte_offset, 256);  // the bracket that opens level 257

  const std::vector<std::uint8_t> good = emissive_quad().glb_bytes();
  auto variant = [&](const char* name, const std::function<void(std::vector<std::uint8_t>&)>& edit) {
    std::vector<std::uint8_t> bytes = good;
    edit(bytes);
    lumx_gltf_test::write_bytes(dir / name, bytes);
    return read_error(dir / name);
  };
  auto put32 = [](std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) b[at + k] = static_cast<std::uint8_t>(v >> (8 * k));
  };
  d = variant("short.glb", [](auto& b) { b.resize(10); });
  EXPECT_EQ(d.byte_offset, 0);
  d = variant("magic.glb", [](auto& b) { b[0] = 'x'; });
  EXPECT_EQ(d.field, "GLB magic");
  d = variant("version.glb", [&](auto& b) { put32(b, 4, 1); });
  EXPECT_EQ(d.byte_offset, 4);
  d = variant("cut.glb", [](auto& b) { b.resize(b.size() - 20); });
  EXPECT_EQ(d.field, "GLB length");
  EXPECT_EQ(d.byte_offset, 8);
  d = variant("json_length.glb", [&](auto& b) { put32(b, 12, 0x7FFFFFF0u); });
  EXPECT_EQ(d.field, "GLB chunk length");
  EXPECT_EQ(d.byte_offset, 12);
  const std::uint32_t json_length = good[12] | good[13] << 8 | good[14] << 16 | good[15] << 24;
  const std::size_t bin_header = 20 + json_length;
  d = variant("bin_length.glb", [&](auto& b) { put32(b, bin_header, 0xFFFFFFF0u); });
  EXPECT_EQ(d.field, "GLB chunk length");
  EXPECT_EQ(d.byte_offset, std::int64_t(bin_header));
  d = variant("json_unaligned.glb", [&](auto& b) { put32(b, 12, json_length - 1); });
  EXPECT_EQ(d.field, "GLB chunk length");
  EXPECT_EQ(d.byte_offset, 12);
  EXPECT_NE(d.message.find("multiple of 4"), std::string::npos) << d.str();
  d = variant("bin_unaligned.glb", [&](auto& b) {
    const std::uint32_t bin_length = b[bin_header] | b[bin_header + 1] << 8 | b[bin_header + 2] << 16 | b[bin_header + 3] << 24;
    put32(b, bin_header, bin_length - 2);
  });
  EXPECT_EQ(d.field, "GLB chunk length");
  EXPECT_EQ(d.byte_offset, std::int64_t(bin_header));
  d = variant("bin_missing.glb", [&](auto& b) { b.resize(bin_header); put32(b, 8, std::uint32_t(bin_header)); });
  EXPECT_EQ(d.field, "/buffers/0");
  d = variant("json_bad.glb", [](auto& b) { b[20] = '['; });
  EXPECT_EQ(d.field, "JSON");
  EXPECT_GE(d.byte_offset, 20);
  d = variant("chunk_type.glb", [&](auto& b) { put32(b, 16, 0x12345678u); });
  EXPECT_EQ(d.byte_offset, 16);
}

TEST(GltfBadInput, CorruptDracoPayloadsAreLocatedErrors) {
  const auto dir = lumx_gltf_test::scratch_dir("draco");
  GltfBuilder b = emissive_quad();
  b.use_extension("KHR_draco_mesh_compression", true);
  const std::uint8_t garbage[64] = {'D', 'R', 'A', 'C', 'O', 2, 2, 1, 1, 0, 0xFF, 0xFF, 0xFF, 0x7F};
  const int view = b.add_view(garbage, sizeof garbage);
  b.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"] = {{"bufferView", view},
                                                                                     {"attributes", {{"POSITION", 0}}}};
  b.write_glb(dir / "garbage.glb");
  EXPECT_EQ(read_error(dir / "garbage.glb").field, "/meshes/0/primitives/0/extensions/KHR_draco_mesh_compression/bufferView");
  b.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["bufferView"] = 40;
  b.write_glb(dir / "view.glb");
  EXPECT_EQ(read_error(dir / "view.glb").field, "/meshes/0/primitives/0/extensions/KHR_draco_mesh_compression/bufferView");
  // The accessors' counts are checked against the limits before Draco decodes (the payload is garbage, so
  // a decode would fail at the buffer view instead).
  bake::GltfReadOptions few;
  few.max_vertices = 3;
  try {
    bake::read_gltf_luminaire((dir / "garbage.glb").string(), few);
    ADD_FAILURE() << "read within the limits";
  } catch (const lumx::Error& e) {
    EXPECT_EQ(e.diagnostic().field, "/accessors/0/count");
    EXPECT_NE(e.diagnostic().message.find("GltfReadOptions::max_vertices (3)"), std::string::npos) << e.what();
  }
}

// A Draco payload that decodes, but to other counts than its accessors declare (hard-cases.md §6 item 24):
// the POSITION accessor's count one more or one fewer than the decoded mesh's vertices, and the indices
// accessor's likewise, are errors at those accessors; the untouched file reads.
TEST(GltfBadInput, DracoCountsThatDisagreeWithTheAccessorsAreLocatedErrors) {
  const auto dir = lumx_gltf_test::scratch_dir("draco_counts");
  bake::LuminaireBuilder b("box");
  bake::Material m;
  m.emissive = bake::Rgb{1.0};
  b.begin_part("box", b.add_material(m));
  b.box(glm::dmat4(1.0), {0.1, 0.05, 0.02});
  bake::GltfWriteOptions o;
  o.draco = true;
  const fs::path good = dir / "good.glb";
  bake::write_gltf_luminaire(b.scene(), good.string(), o);
  ASSERT_NO_THROW(bake::read_gltf_luminaire(good.string()));
  // Split the GLB, edit its JSON, pack it again with correct chunk lengths.
  const std::string bytes = lumx_test::read_text(good);
  auto u32 = [&](std::size_t at) {
    return std::uint32_t(std::uint8_t(bytes[at])) | std::uint32_t(std::uint8_t(bytes[at + 1])) << 8 |
           std::uint32_t(std::uint8_t(bytes[at + 2])) << 16 | std::uint32_t(std::uint8_t(bytes[at + 3])) << 24;
  };
  const std::uint32_t json_length = u32(12);
  const nlohmann::json doc = nlohmann::json::parse(bytes.substr(20, json_length));
  const std::string bin_chunk = bytes.substr(20 + json_length);  // header and data of the BIN chunk
  auto pack = [&](const nlohmann::json& d, const fs::path& path) {
    std::string json = d.dump();
    while (json.size() % 4) json += ' ';
    std::string out = "glTF";
    auto put = [&out](std::uint32_t v) {
      for (int k = 0; k < 4; ++k) out += char(v >> (8 * k));
    };
    put(2);
    put(std::uint32_t(12 + 8 + json.size() + bin_chunk.size()));
    put(std::uint32_t(json.size()));
    put(0x4E4F534Au);
    out += json + bin_chunk;
    std::ofstream(path, std::ios::binary) << out;
  };
  const nlohmann::json& primitive = doc["meshes"][0]["primitives"][0];
  ASSERT_TRUE(primitive["extensions"].contains("KHR_draco_mesh_compression"));
  const int position = primitive["attributes"]["POSITION"], indices = primitive["indices"];
  for (const int accessor : {position, indices})
    for (const int delta : {-1, +1}) {
      nlohmann::json d = doc;
      d["accessors"][accessor]["count"] = d["accessors"][accessor]["count"].get<int>() + delta * (accessor == indices ? 3 : 1);
      const fs::path path = dir / ("count" + std::to_string(accessor) + "_" + std::to_string(delta) + ".glb");
      pack(d, path);
      const lumx::Diagnostic e = read_error(path);
      EXPECT_EQ(e.field, "/accessors/" + std::to_string(accessor) + "/count") << e.str();
      EXPECT_NE(e.message.find("Draco mesh has"), std::string::npos) << e.str();
    }
  pack(doc, dir / "repacked.glb");
  EXPECT_NO_THROW(bake::read_gltf_luminaire((dir / "repacked.glb").string()));
}

namespace {
/// Reads `count` random corruptions of `good` (bytes overwritten at random positions from `first` on, or the
/// file cut short): each must read or throw lumx::Error, nothing else. Returns how many were errors.
int corrupt_and_read(const fs::path& dir, const std::vector<std::uint8_t>& good, std::size_t first, int count,
                     unsigned seed) {
  std::mt19937 rng(seed);
  int errors = 0;
  for (int i = 0; i < count; ++i) {
    std::vector<std::uint8_t> bytes = good;
    if (rng() % 8 == 0) {
      bytes.resize(rng() % bytes.size());
    } else {
      const int flips = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < flips; ++k) {
        const std::size_t at = first + rng() % (bytes.size() - first);
        bytes[at] = rng() % 2 ? static_cast<std::uint8_t>(rng()) : static_cast<std::uint8_t>("0123456789\"\\{}[],:"[rng() % 19]);
      }
    }
    const fs::path p = dir / ("corrupt" + std::to_string(i) + ".glb");
    lumx_gltf_test::write_bytes(p, bytes);
    try {
      bake::read_gltf_luminaire(p.string());
    } catch (const lumx::Error&) {
      ++errors;
    }
    fs::remove(p);
  }
  return errors;
}
}  // namespace

TEST(GltfBadInput, RandomCorruptionsAreErrorsNeverCrashes) {
  const auto dir = lumx_gltf_test::scratch_dir("corrupt");
  GltfBuilder b = emissive_quad();
  b.use_extension("KHR_lights_punctual");
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "spot"}, {"intensity", 3}, {"spot", {{"outerConeAngle", 0.5}}}}};
  b.doc["nodes"][0]["children"] = {b.add_node({{"mesh", b.add_mesh(lumx_gltf_test::unit_cube(), 0)}, {"scale", {2, 2, 2}},
                                              {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}})};
  const int errors = corrupt_and_read(dir.path, b.glb_bytes(), 0, 1500, 20261126);
  EXPECT_GT(errors, 500);
  // Corrupt Draco bitstreams (bytes after the JSON chunk of the real file).
  const fs::path draco = lumx_test::shared_dir().empty()
                             ? fs::path()
                             : lumx_test::shared_dir() / "data" / "luminaires" / "zhu2021-flower" / "flower_draco.glb";
  if (draco.empty() || !fs::exists(draco)) return;
  const std::string text = lumx_test::read_text(draco);
  const std::vector<std::uint8_t> bytes(text.begin(), text.end());
  const std::size_t json_end = 20 + (bytes[12] | bytes[13] << 8 | bytes[14] << 16 | std::size_t(bytes[15]) << 24);
  corrupt_and_read(dir.path, bytes, json_end, 150, 7);
}

// ---- the flower pendant (../shared) -----------------------------------------------------------------------------

namespace {
fs::path flower(const char* name) {
  const auto root = lumx_test::shared_dir();
  return root.empty() ? fs::path() : root / "data" / "luminaires" / "zhu2021-flower" / name;
}
}  // namespace

TEST(GltfFlower, PlainAndDracoFilesAgree) {
  const fs::path plain = flower("flower.glb"), draco = flower("flower_draco.glb");
  if (plain.empty() || !fs::exists(plain)) LUMX_SKIP_WITHOUT_SHARED("data/luminaires/zhu2021-flower");
  const auto t0 = std::chrono::steady_clock::now();
  const auto a = bake::read_gltf_luminaire(plain.string());
  const auto t1 = std::chrono::steady_clock::now();
  const auto b = bake::read_gltf_luminaire(draco.string());
  const auto t2 = std::chrono::steady_clock::now();
  std::printf("flower.glb read in %.1f ms, flower_draco.glb in %.1f ms\n",
              std::chrono::duration<double, std::milli>(t1 - t0).count(),
              std::chrono::duration<double, std::milli>(t2 - t1).count());
  for (const auto* s : {&a, &b}) {
    EXPECT_EQ(s->triangle_count(), 7898u);
    ASSERT_EQ(s->parts.size(), 5u);
    EXPECT_EQ(s->normals.size(), s->positions.size());
    EXPECT_TRUE(s->warnings.empty()) << s->warnings.front().str();
  }
  const std::map<std::string, std::pair<std::uint32_t, bool>> expect = {{"metalpart", {2678, false}},
                                                                       {"emitter", {760, true}},
                                                                       {"glass_part", {2860, true}},
                                                                       {"glass_middle", {1520, true}},
                                                                       {"hanger", {80, true}}};
  for (std::size_t i = 0; i < 5; ++i) {
    const auto& pa = a.parts[i];
    const auto& pb = b.parts[i];
    ASSERT_EQ(pa.name, pb.name);
    ASSERT_TRUE(expect.count(pa.name)) << pa.name;
    EXPECT_EQ(pa.triangle_count, expect.at(pa.name).first) << pa.name;
    EXPECT_EQ(pb.triangle_count, expect.at(pa.name).first) << pa.name;
    EXPECT_EQ(pa.closed, expect.at(pa.name).second) << pa.name;
    const double area_a = part_area(a, pa), area_b = part_area(b, pb);
    // The 0.9 mm hanger rod in a 43 mm box quantised to 14 bits: 2.6 µm steps, 6.1e-4 of its area.
    const double tolerance = pa.name == "hanger" ? 6.5e-4 : 1e-5;
    EXPECT_NEAR(area_b / area_a, 1.0, tolerance) << pa.name;
    std::printf("  %-12s %5u triangles, area %.7g m² plain, %.7g m² Draco (relative %.2e)\n", pa.name.c_str(),
                pa.triangle_count, area_a, area_b, area_b / area_a - 1.0);
  }
  // Materials as SOURCES.md maps them.
  for (const auto* s : {&a, &b}) {
    for (const auto& p : s->parts) {
      const auto& m = s->materials[p.material];
      if (p.name == "glass_part" || p.name == "glass_middle") {
        EXPECT_EQ(m.transmission, 1.0);
        EXPECT_EQ(m.ior, 1.5046);
        EXPECT_TRUE(m.volume);
      } else if (p.name == "metalpart" || p.name == "hanger") {
        EXPECT_EQ(m.metallic, 1.0);
      } else {
        EXPECT_EQ(m.emissive_strength, 1000.0);
      }
    }
    ASSERT_EQ(s->emitters.size(), 1u);
    EXPECT_EQ(s->emitters[0].kind, bake::EmitterKind::surface);
    const double flux = bake::emitter_flux_lm(*s, s->emitters[0]);
    EXPECT_NEAR(flux, kPi * 1000 * 0.002411, 0.005 * kPi * 1000 * 0.002411);
    std::printf("  emitter flux %.5f lm\n", flux);
  }
  // Checks: the copper strips are open but not volumes; nothing is an error.
  for (const auto* s : {&a, &b})
    for (const auto& d : bake::check_luminaire(*s)) EXPECT_NE(d.severity, lumx::Severity::error) << d.str();
}

// ---- check_luminaire ---------------------------------------------------------------------------------------------

namespace {
/// A scene built in code: one part of the given triangles and material.
bake::LuminaireScene scene_of(const lumx_gltf_test::Shape& shape, const bake::Material& m) {
  bake::LuminaireScene s;
  s.name = "test scene";
  s.positions = shape.positions;
  s.indices = shape.indices;
  s.triangle_part.assign(s.indices.size() / 3, 0);
  s.materials.push_back(m);
  bake::Part p;
  p.name = "solid";
  p.source = "/meshes/0/primitives/0";
  p.triangle_count = static_cast<std::uint32_t>(s.indices.size() / 3);
  s.parts.push_back(p);
  if (m.emissive_any()) {
    bake::Emitter e;
    e.kind = bake::EmitterKind::surface;
    e.source = "/materials/0";
    s.emitters.push_back(e);
  }
  return s;
}

const lumx::Diagnostic* find(const std::vector<lumx::Diagnostic>& ds, lumx::Severity sev, const std::string& field,
                             const std::string& text) {
  for (const auto& d : ds)
    if (d.severity == sev && d.field == field && d.message.find(text) != std::string::npos) return &d;
  return nullptr;
}
}  // namespace

TEST(LuminaireCheck, ClosedCubeIsCleanOpenVolumeIsAnError) {
  bake::Material glass;
  glass.transmission = 1.0;
  glass.volume = true;
  glass.thickness_m = 0.01;
  bake::LuminaireScene s = scene_of(lumx_gltf_test::unit_cube(), glass);
  auto topo = bake::part_topology(s, s.parts[0]);
  EXPECT_TRUE(topo.closed());
  EXPECT_EQ(topo.edges, 18u);
  bake::Emitter point;
  point.kind = bake::EmitterKind::point;
  point.intensity_cd = bake::Rgb(1.0);
  point.source = "/extensions/KHR_lights_punctual/lights/0";
  s.emitters.push_back(point);
  EXPECT_TRUE(bake::check_luminaire(s).empty());
  // Remove one face: 4 boundary edges, the volume is open.
  s.indices.resize(s.indices.size() - 6);
  s.triangle_part.resize(10);
  s.parts[0].triangle_count = 10;
  topo = bake::part_topology(s, s.parts[0]);
  EXPECT_EQ(topo.boundary_edges, 4u);
  const auto findings = bake::check_luminaire(s);
  const auto* d = find(findings, lumx::Severity::error, "/meshes/0/primitives/0", "not closed");
  ASSERT_NE(d, nullptr);
  EXPECT_NE(d->message.find("4 boundary edge"), std::string::npos) << d->message;
  EXPECT_EQ(d->file, "test scene");
}

TEST(LuminaireCheck, DegenerateAndNonFiniteTrianglesNoEmitterZeroFlux) {
  bake::Material white;
  auto shape = lumx_gltf_test::unit_quad();
  shape.indices.insert(shape.indices.end(), {0, 1, 1, 2, 2, 2});  // two degenerate triangles
  bake::LuminaireScene s = scene_of(shape, white);
  auto findings = bake::check_luminaire(s);
  const auto* deg = find(findings, lumx::Severity::warning, "/meshes/0/primitives/0", "zero-area");
  ASSERT_NE(deg, nullptr);
  EXPECT_NE(deg->message.find("2 (triangles 2, 3 of the part)"), std::string::npos) << deg->message;
  EXPECT_NE(find(findings, lumx::Severity::error, "", "no emitter"), nullptr);

  s.positions[3].x = std::nanf("");
  findings = bake::check_luminaire(s);
  const auto* nan = find(findings, lumx::Severity::error, "/meshes/0/primitives/0", "non-finite");
  ASSERT_NE(nan, nullptr);
  EXPECT_NE(nan->message.find("1 (triangle 1 of the part)"), std::string::npos) << nan->message;

  bake::Emitter dark;
  dark.kind = bake::EmitterKind::spot;
  dark.source = "/extensions/KHR_lights_punctual/lights/3";
  s.emitters.push_back(dark);
  findings = bake::check_luminaire(s);
  EXPECT_NE(find(findings, lumx::Severity::error, "/extensions/KHR_lights_punctual/lights/3", "no flux"), nullptr);
  EXPECT_EQ(find(findings, lumx::Severity::error, "", "no emitter"), nullptr);
}

TEST(LuminaireCheck, EmissiveSidesAndClosedness) {
  bake::Material lamp;
  lamp.emissive = bake::Rgb(1.0);
  lamp.double_sided = true;
  const auto closed = bake::check_luminaire(scene_of(lumx_gltf_test::unit_cube(), lamp));
  EXPECT_NE(find(closed, lumx::Severity::warning, "/meshes/0/primitives/0", "double-sided and closed"), nullptr);
  lamp.double_sided = false;
  const auto open = bake::check_luminaire(scene_of(lumx_gltf_test::unit_quad(), lamp));
  EXPECT_NE(find(open, lumx::Severity::note, "/meshes/0/primitives/0", "single-sided"), nullptr);
  for (const auto& d : open) EXPECT_NE(d.severity, lumx::Severity::error) << d.str();
}

// Files a .gltf names (hard-cases.md §6 item 23): only the glTF file's folder and below. '../', an absolute
// path, a symbolic link out of the folder and file:// are located errors even when the file exists; shell
// syntax in a name is a file name, never run; a trusted caller may allow the folder's outside.
TEST(GltfBadInput, FilesOutsideTheGltfFolderAreRefused) {
  const auto root = lumx_gltf_test::scratch_dir("uri_policy");
  const fs::path dir = root / "lamp";
  fs::create_directories(dir / "sub");
  GltfBuilder b = emissive_quad();
  // The buffer exists outside the folder, inside it and in a sub-folder.
  b.write_gltf_external(root / "outside.gltf", "outside.bin");
  b.write_gltf_external(dir / "inside.gltf", "inside.bin");
  b.write_gltf_external(dir / "sub" / "deeper.gltf", "deeper.bin");
  fs::create_symlink(root / "outside.bin", dir / "link.bin");
  auto with_uri = [&](const std::string& name, const std::string& uri) {
    lumx_gltf_test::write_text(dir / name, b.with_buffer(uri).dump());
    return dir / name;
  };
  EXPECT_NO_THROW(bake::read_gltf_luminaire(with_uri("ok.gltf", "inside.bin").string()));
  EXPECT_NO_THROW(bake::read_gltf_luminaire(with_uri("ok_sub.gltf", "sub/deeper.bin").string()));
  EXPECT_NO_THROW(bake::read_gltf_luminaire(with_uri("ok_dots.gltf", "sub/../inside.bin").string()));
  EXPECT_NO_THROW(bake::read_gltf_luminaire(with_uri("ok_escaped.gltf", "sub%2Fdeeper.bin").string()));
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"parent.gltf", "../outside.bin"},
      {"parent_escaped.gltf", "%2E%2E/outside.bin"},
      {"deep_parent.gltf", "sub/../../outside.bin"},
      {"absolute.gltf", (root / "outside.bin").string()},
      {"link.gltf", "link.bin"},
      {"file_scheme.gltf", "file://" + (dir / "inside.bin").string()},
  };
  for (const auto& [name, uri] : refused) {
    const lumx::Diagnostic d = read_error(with_uri(name, uri));
    EXPECT_EQ(d.field, "/buffers/0/uri") << uri << ": " << d.str();
    EXPECT_EQ(d.file, (dir / name).string()) << d.str();
  }
  EXPECT_NE(read_error(with_uri("why.gltf", "../outside.bin")).message.find("allow_files_outside_folder"), std::string::npos);
  // Shell syntax is part of a file name: the file does not exist, and nothing runs.
  for (const std::string uri : {"$(touch ran_dollar).bin", "`touch ran_backtick`.bin", "x.bin; touch ran_semicolon"}) {
    EXPECT_EQ(read_error(with_uri("shell.gltf", uri)).field, "/buffers/0/uri") << uri;
  }
  for (const char* marker : {"ran_dollar", "ran_backtick", "ran_semicolon"}) {
    EXPECT_FALSE(fs::exists(dir / marker)) << marker;
    EXPECT_FALSE(fs::exists(fs::current_path() / marker)) << marker;
  }
  // IES profiles (EXT_lights_ies) and ray files (LUMX_lights_rayset) are resolved by the same code
  // (Document::resolve_uri). A trusted caller may follow paths out of the folder.
  bake::GltfReadOptions trusted;
  trusted.allow_files_outside_folder = true;
  EXPECT_NO_THROW(bake::read_gltf_luminaire(with_uri("parent.gltf", "../outside.bin").string(), trusted));
  EXPECT_NO_THROW(bake::read_gltf_luminaire(with_uri("absolute.gltf", (root / "outside.bin").string()).string(), trusted));
}
