// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Hard cases of the bake path: primitives sharing one large accessor (memory bounded by the limits, not by the
// number of primitives), a spot light on a zero-scale node (refused by name, by check and by the tracer), the
// radiance volume's deposits inside absorbing glass (mean flux over each segment), and `lumx bake` into an
// output path ending in a separator.
#include "cli_test_support.h"
#include "gltf_test_support.h"
#include "luminaire_test_scenes.h"

#include <lumx/bake/gltf_reader.h>
#include <lumx/bake/gltf_writer.h>
#include <lumx/bake/luminaire_check.h>
#include <lumx/bake/tracer.h>

#include "test_support.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace {

namespace fs = std::filesystem;
using lumx_gltf_test::GltfBuilder;
using lumx_gltf_test::Json;

TEST(BakeHardCases, PrimitivesSharingAnAccessorCountAgainstTheLimits) {
  GltfBuilder g;
  std::vector<glm::vec3> positions(3000);
  for (std::size_t i = 0; i < positions.size(); ++i) positions[i] = {float(i), float(i % 7), float(i % 3)};
  std::vector<std::uint32_t> indices;
  for (std::uint32_t i = 0; i + 2 < 3000; i += 3) indices.insert(indices.end(), {i, i + 1, i + 2});
  const int pos = g.add_vec3(positions), idx = g.add_indices(indices);
  Json prims = Json::array();
  for (int k = 0; k < 50; ++k) prims.push_back({{"attributes", {{"POSITION", pos}}}, {"indices", idx}});
  g.push("meshes", {{"primitives", prims}});
  g.set_scene({g.add_node({{"mesh", 0}})});
  const fs::path path = lumx_test::unique_temp_path("lumx_shared_accessor.glb");
  g.write_glb(path);
  lumx::bake::GltfReadOptions o;
  o.max_vertices = 100000;  // 50 primitives × 3 000 vertices = 150 000 decoded
  try {
    (void)lumx::bake::read_gltf_luminaire(path.string(), o);
    FAIL() << "expected lumx::Error";
  } catch (const lumx::Error& e) {
    EXPECT_NE(std::string(e.what()).find("/meshes/0/primitives/"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("100000"), std::string::npos) << e.what();
  }
  o.max_vertices = 200000;
  EXPECT_EQ(lumx::bake::read_gltf_luminaire(path.string(), o).triangle_count(), 50u * 1000u);
  fs::remove(path);
}

TEST(BakeHardCases, SpotOnAZeroScaleNodeIsRefusedByName) {
  lumx_test::SceneBuilder b("zero-scale spot");
  lumx::bake::Emitter e;
  e.kind = lumx::bake::EmitterKind::spot;
  e.name = "flat spot";
  e.source = "/nodes/3";
  e.intensity_cd = lumx::bake::Rgb{10.0};
  e.to_world = glm::dmat4(0.0);
  e.to_world[3] = glm::dvec4(0, 0, 0, 1);
  b.scene().emitters.push_back(e);
  bool flagged = false;
  for (const auto& d : lumx::bake::check_luminaire(b.scene()))
    flagged |= d.severity == lumx::Severity::error && d.field == "/nodes/3" && d.message.find("singular") != std::string::npos;
  EXPECT_TRUE(flagged);
  try {
    const lumx::bake::Tracer tracer(b.scene());
    FAIL() << "expected lumx::Error";
  } catch (const lumx::Error& err) {
    EXPECT_NE(std::string(err.what()).find("flat spot"), std::string::npos) << err.what();
  }
  // A sheared, scaled frame still has a direction: the spot shines along its −z, intensities unscaled.
  e.to_world = glm::dmat4(1.0);
  e.to_world[0] = glm::dvec4(3.0, 0.0, 0.0, 0.0);
  e.to_world[1] = glm::dvec4(1.0, 2.0, 0.0, 0.0);
  e.to_world[2] = glm::dvec4(0.0, 0.0, 5.0, 0.0);
  b.scene().emitters[0] = e;
  const lumx::bake::Tracer tracer(b.scene());
  struct AxisSink : lumx::bake::ParticleSink {
    double min_cos = 1.0;
    void consume(const lumx::bake::ParticleChunk& c) override {
      for (const auto& x : c.exits) min_cos = std::min(min_cos, -double(x.direction.z));
    }
  } sink;
  lumx::bake::TraceOptions o;
  o.particles = 20000;
  tracer.trace(o, sink);
  EXPECT_GE(sink.min_cos, std::cos(e.outer_cone_rad) - 1e-6);
}

// A point light in an absorbing glass ball, segments on: the flux deposited along the radius inside the glass
// is Φ ∫₀ᴿ e^{−σs} ds = Φ (1 − e^{−σR}) / σ per unit of emitted flux's first crossing — the mean flux times
// the length, not the start flux times the length.
TEST(BakeHardCases, SegmentsInsideGlassCarryTheirMeanFlux) {
  lumx_test::SceneBuilder b("glass ball");
  const double radius = 0.05, colour = 0.6;
  b.begin_part("ball", b.add_material(lumx_test::smooth_glass(1.5, colour, radius)));
  lumx_test::add_sphere(b, radius, 64, 128, 0.0, true);
  b.point_light({0, 0, 0}, 1.0);
  const lumx::bake::Tracer tracer(b.scene());
  struct FirstSegments : lumx::bake::ParticleSink {
    double flux_length = 0.0, start_flux_length = 0.0;
    void consume(const lumx::bake::ParticleChunk& c) override {
      for (const auto& s : c.segments)
        if (glm::length(s.origin) < 1e-6f) {  // the first segment, from the centre to the surface
          flux_length += double(s.flux_lm.x) * s.length_m;
        }
    }
  } sink;
  lumx::bake::TraceOptions o;
  o.particles = 20000;
  o.record_segments = true;
  tracer.trace(o, sink);
  const double phi = tracer.total_flux_lm(), sigma = -std::log(colour) / radius;
  const double exact = phi * (1 - std::exp(-sigma * radius)) / sigma;  // Σ Φ_i ∫ e^{−σs} ds over the first legs
  EXPECT_NEAR(sink.flux_length, exact, 2e-3 * exact);  // the facets' chords differ from R by < 3·10⁻⁴ R
}

TEST(BakeHardCases, BakeIntoAPathEndingInASeparator) {
  const fs::path dir = lumx_test::unique_temp_path("lumx_bake_slash");
  fs::remove_all(dir);
  fs::create_directories(dir);
  lumx_test::SceneBuilder b("disk");
  b.begin_part("disk", b.add_material(lumx_test::emissive(100.0)));
  lumx_test::add_disk(b, 0.05, 32);
  lumx::bake::write_gltf_luminaire(b.scene(), (dir / "disk.glb").string());
  const lumx_test::CliRun r = lumx_test::run_cli("bake " + lumx_test::quoted(dir / "disk.glb") + " " +
                                                 lumx_test::quoted(dir / "out.lumx") + "/ --particles 5000 --levels 1 8 --no-eval");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(fs::exists(dir / "out.lumx" / "manifest.json"));
  for (const auto& entry : fs::directory_iterator(dir))  // the temporary rays file is gone
    EXPECT_EQ(entry.path().extension().string().find("tm25ray"), std::string::npos) << entry.path();
  fs::remove_all(dir);
}

}  // namespace
