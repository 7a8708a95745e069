// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The representation seam (model/light_model.h, model/registry.h): a representation registered here, in
// the test alone — an isotropic point light — is built from rays, written into a bundle, checked, read
// back, graded on held-out rays and (test_light_model_seam_room.cpp) rendered in a room through the library's generic paths, with no
// library file knowing its type. The APL level and far field pass through the same seam and give the
// numbers of the APL queries they wrap.
#include "test_support.h"
#include "toy_light_model.h"

#include <lumx/apl/builder.h>
#include <lumx/apl/evaluation.h>
#include <lumx/apl/sampling.h>
#include <lumx/io/bundle_io.h>
#include <lumx/model/apl_model.h>
#include <lumx/model/far_field_model.h>
#include <lumx/model/grading.h>
#include <lumx/model/registry.h>
#include <lumx/rays/far_field.h>
#include <lumx/rays/holdout.h>
#include <lumx/rays/rayset.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

namespace {

using lumx_test::IsotropicPoint;
using lumx_test::isotropic_point_type;
using lumx_test::isotropic_rays;
using lumx_test::kPi;

std::shared_ptr<lumx::AplSet> apl_set_of(lumx::RaySource& rays) {
  lumx::AplBuildOptions o;
  o.level_counts = {1, 4};
  o.map_resolution = 16;
  rays.rewind();
  return std::make_shared<lumx::AplSet>(lumx::build_apl_set(rays, o));
}

const glm::dvec3 kCentre(0.1, -0.05, 0.02);
constexpr double kFlux = 1000.0;

TEST(LightModelSeam, TheRegistryKnowsTheLibrarysTypesAndTheTestsOwn) {
  const std::vector<std::string> names = lumx::model_type_names();
  for (const char* n : {"apl", "far-field", "test-isotropic-point"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
  EXPECT_TRUE(std::is_sorted(names.begin(), names.end()));
  EXPECT_EQ(lumx::find_model_type("no-such-type"), nullptr);
  EXPECT_THROW(lumx::register_model_type(isotropic_point_type()), std::invalid_argument);  // taken
  lumx::ModelType bad = isotropic_point_type();
  bad.name = "Not A Name";
  EXPECT_THROW(lumx::register_model_type(bad), std::invalid_argument);
  lumx::MemoryRaySource rays = isotropic_rays(kCentre, kFlux, 100, 1);
  EXPECT_THROW(lumx::build_model("no-such-type", rays), std::invalid_argument);
}

TEST(LightModelSeam, AToyRepresentationIsBuiltWrittenCheckedAndReadBack) {
  lumx::MemoryRaySource rays = isotropic_rays(kCentre, kFlux, 20000, 2);
  std::unique_ptr<lumx::LightModel> built = lumx::build_model("test-isotropic-point", rays);
  ASSERT_EQ(built->type(), "test-isotropic-point");
  // Σ of 20 000 float fluxes in double: exact to float rounding of each ray's Φ/N.
  EXPECT_NEAR(built->flux().x, kFlux, 1e-6 * kFlux);
  // The mean of 20 000 start points 1 cm out: within 5 standard errors (0.01/√(3N) per axis) of the centre.
  const double se = 0.01 / std::sqrt(3.0 * 20000);
  EXPECT_LT(glm::length(built->bounds().center - kCentre), 5 * std::sqrt(3.0) * se);

  const std::shared_ptr<lumx::AplSet> set = apl_set_of(rays);
  rays.rewind();
  auto far = lumx::build_model("far-field", rays);
  const auto dir = lumx_test::fresh_temp_dir("seam_bundle");
  const std::string path = (dir / "b.lumx").string();
  lumx::BundleWriteOptions wo;
  wo.models = {{"point", std::shared_ptr<const lumx::LightModel>(built.release())},
               {"far", std::shared_ptr<const lumx::LightModel>(std::move(far))}};
  lumx::write_bundle(path, *set, nullptr, wo);

  // A bundle with models is replaced like any other.
  lumx::write_bundle(path, *set, nullptr, wo);
  const std::vector<lumx::Diagnostic> findings = lumx::check_bundle(path);
  EXPECT_TRUE(findings.empty()) << (findings.empty() ? "" : findings.front().message);
  const lumx::BundleReader reader(path);
  EXPECT_EQ(reader.manifest().format_version, 4);
  ASSERT_EQ(reader.manifest().models.size(), 2u);
  const std::vector<lumx::BundleRepresentation> reps = reader.representations();
  ASSERT_EQ(reps.size(), set->levels.size() + 2);
  EXPECT_EQ(reps[0].name, "apl:0");
  EXPECT_EQ(reps[0].type, "apl");
  EXPECT_EQ(reps[set->levels.size()].name, "point");
  EXPECT_EQ(reps[set->levels.size()].type, "test-isotropic-point");
  EXPECT_EQ(reps[set->levels.size() + 1].type, "far-field");

  const auto& written = dynamic_cast<const IsotropicPoint&>(*wo.models[0].second);
  const std::unique_ptr<lumx::LightModel> read = reader.load_model(0);
  const auto& point = dynamic_cast<const IsotropicPoint&>(*read);
  EXPECT_EQ(point.position(), written.position());  // bit for bit: JSON numbers round-trip doubles
  EXPECT_EQ(point.scalar_flux(), written.scalar_flux());
  // Every listed representation loads through the one generic call, with the flux it was written with.
  for (std::size_t i = 0; i < reps.size(); ++i) {
    const std::unique_ptr<lumx::LightModel> m = reader.load_representation(i);
    EXPECT_EQ(m->type(), reps[i].type);
    EXPECT_NEAR(m->flux().x, kFlux, 2e-3 * kFlux) << reps[i].name;  // the far field's table: its flux to 0.2 %
  }
}

TEST(LightModelSeam, BadModelsAreRefusedByPointerAndField) {
  lumx::MemoryRaySource rays = isotropic_rays(kCentre, kFlux, 2000, 3);
  const std::shared_ptr<lumx::AplSet> set = apl_set_of(rays);
  const auto dir = lumx_test::fresh_temp_dir("seam_bad");
  const std::string path = (dir / "b.lumx").string();
  lumx::BundleWriteOptions wo;
  wo.models = {{"point", std::make_shared<IsotropicPoint>(kCentre, kFlux)}};
  lumx::write_bundle(path, *set, nullptr, wo);
  const std::string manifest_path = path + "/manifest.json";
  const std::string good = lumx_test::read_text(manifest_path);
  auto rewrite = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json j = nlohmann::json::parse(good);
    edit(j);
    std::ofstream(manifest_path, std::ios::binary | std::ios::trunc) << j.dump(1);
  };
  auto load_error = [&]() -> std::string {
    try {
      lumx::BundleReader(path).load_model(0);
    } catch (const lumx::Error& e) {
      return e.what();
    }
    return "";
  };
  rewrite([](nlohmann::json& j) { j["models"][0]["type"] = "unregistered-type"; });
  EXPECT_NE(load_error().find("/models/0/type"), std::string::npos) << load_error();
  rewrite([](nlohmann::json& j) { j["models"][0]["section"].erase("position"); });
  EXPECT_NE(load_error().find("section/position"), std::string::npos) << load_error();
  rewrite([](nlohmann::json& j) { j["models"][0]["payloads"][0]["file"] = "../escape"; });
  EXPECT_THROW(lumx::BundleReader{path}, lumx::Error);
  rewrite([](nlohmann::json& j) { j["format_version"] = 3; });
  EXPECT_THROW(lumx::BundleReader{path}, lumx::Error);
  rewrite([](nlohmann::json&) {});
  EXPECT_EQ(load_error(), "");
  {  // a payload changed after writing: the checksum names its pointer
    std::ofstream(path + "/models/point/flux.f64", std::ios::binary | std::ios::trunc) << "12345678";
    EXPECT_NE(load_error().find("/models/0/payloads/0"), std::string::npos) << load_error();
    const auto findings = lumx::check_bundle(path);
    ASSERT_FALSE(findings.empty());
  }
  // A writer refuses an unregistered or unnamed model and leaves the bundle that was there.
  class Unregistered final : public lumx::LightModel {
   public:
    std::string type() const override { return "never-registered"; }
    std::string description() const override { return ""; }
    lumx::PhotometricQuantity quantity() const override { return lumx::PhotometricQuantity::photometric; }
    lumx::ChannelLayout channels() const override { return lumx::ChannelLayout::luminance; }
    lumx::BoundingSphere bounds() const override { return {}; }
    glm::dvec3 flux() const override { return {}; }
    glm::dvec3 intensity(const glm::dvec3&) const override { return {}; }
    glm::dvec3 irradiance(const glm::dvec3&, const glm::dvec3&, const lumx::Visibility*) const override { return {}; }
    lumx::PositionMeasure position_measure() const override { return lumx::PositionMeasure::discrete; }
    lumx::ModelEmission sample_emission(const std::array<double, 4>&) const override { return {}; }
    lumx::EmissionDensity emission_pdf(std::size_t, const glm::dvec3&, const glm::dvec3&) const override { return {}; }
    std::size_t bytes() const override { return 0; }
  };
  lumx::BundleWriteOptions bad;
  bad.models = {{"x", std::make_shared<Unregistered>()}};
  EXPECT_THROW(lumx::write_bundle(path, *set, nullptr, bad), lumx::Error);
  bad.models = {{"a/b", std::make_shared<IsotropicPoint>(kCentre, kFlux)}};
  EXPECT_THROW(lumx::write_bundle(path, *set, nullptr, bad), lumx::Error);
  EXPECT_EQ(lumx::BundleReader(path).manifest().models.size(), 1u);
}

// Graded on the odd rays of an exact isotropic source, the toy built from the even ones is exact up to the
// half's noise in its centre (~10⁻⁵ m): no sphere may resolve an error. The same grading of the toy with
// its flux 8 % high must resolve 8 % on every sphere (ε = 0.08 exactly for a uniform scale), so the ruler
// neither flatters nor overstates.
TEST(LightModelSeam, TheToyIsGradedOnHeldOutRaysInBothDirections) {
  lumx::MemoryRaySource rays = isotropic_rays(kCentre, kFlux, 200000, 4);
  lumx::ModelGradeOptions go;
  go.relative_distances = {1, 2, 5};
  go.patch_resolution = 8;
  const lumx::ModelGrade g = lumx::grade_held_out("test-isotropic-point", rays, {}, go);
  ASSERT_EQ(g.spheres.size(), 3u);
  EXPECT_EQ(g.type, "test-isotropic-point");
  EXPECT_EQ(g.reference_rays, 100000u);
  for (const lumx::ModelSphereError& s : g.spheres) {
    // σ for 100 000 rays on 128 patches: √(128/10⁵) ≈ 3.6 %.
    EXPECT_NEAR(s.noise_floor, std::sqrt(128.0 / 100000), 0.2 * std::sqrt(128.0 / 100000));
    EXPECT_FALSE(s.resolved) << "d " << s.relative_distance << ": " << s.noise_removed;
    EXPECT_LT(s.noise_removed, s.noise_removed_upper + 1e-12);
  }
  // The wrong flux, graded against the same odd half.
  lumx::RayHalf even(rays, 0), odd(rays, 1);
  const std::unique_ptr<lumx::LightModel> m = lumx::build_model("test-isotropic-point", even);
  const auto& point = dynamic_cast<const IsotropicPoint&>(*m);
  const IsotropicPoint high(point.position(), 1.08 * point.scalar_flux());
  const lumx::ModelGrade wrong = lumx::grade_model(high, odd, go);
  for (const lumx::ModelSphereError& s : wrong.spheres) {
    EXPECT_TRUE(s.resolved) << "d " << s.relative_distance;
    // ε̂ of a uniform 8 % excess is 8 % of the mean ratio; the noise removed leaves it within ±1.5 points
    // (two standard errors of ε̂² at σ 3.6 % over 128 patches: u ≈ 2·0.08·σ/√128 ≈ 5·10⁻⁴ → ±0.6 points).
    EXPECT_NEAR(s.noise_removed, 0.08, 0.015) << "d " << s.relative_distance;
  }
}

// The APL level through the seam gives the APL queries' numbers bit for bit, and its emission samples carry
// the density emission_pdf() states.
TEST(LightModelSeam, TheAplLevelModelIsTheAplQueries) {
  lumx::MemoryRaySource rays = isotropic_rays(kCentre, kFlux, 20000, 5);
  const std::shared_ptr<lumx::AplSet> set = apl_set_of(rays);
  const lumx::AplLevelModel model(set, 1);
  EXPECT_EQ(model.type(), "apl");
  EXPECT_EQ(model.flux(), set->levels[1].flux());
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  double mean_flux = 0;
  constexpr int kSamples = 20000;
  for (int i = 0; i < kSamples; ++i) {
    const glm::dvec3 x(2 * u01(rng) - 1, 2 * u01(rng) - 1, 2 * u01(rng) - 1);
    const glm::dvec3 n = glm::normalize(glm::dvec3(u01(rng) - 0.5, u01(rng) - 0.5, u01(rng) - 0.5));
    ASSERT_EQ(model.irradiance(x, n), lumx::irradiance(*set, 1, glm::vec3(x), glm::vec3(n)).irradiance);
    const lumx::ModelEmission e = model.sample_emission({u01(rng), u01(rng), u01(rng), u01(rng)});
    if (!e.valid()) continue;
    const lumx::EmissionDensity d = model.emission_pdf(e.element, e.position, e.direction);
    ASSERT_EQ(d.position, e.pdf_position);
    ASSERT_EQ(d.direction, e.pdf_direction);
    mean_flux += e.flux.x / kSamples;
  }
  // The samples' mean flux is the level's (the sampler is unbiased); a near-constant map makes each
  // sample's flux ≈ Φ, so 20 000 samples pin it to well under 1 %.
  EXPECT_NEAR(mean_flux, model.flux().x, 0.01 * model.flux().x);
}

}  // namespace
