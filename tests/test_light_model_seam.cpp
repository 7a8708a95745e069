// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The representation seam (model/light_model.h, model/registry.h): a representation registered here, in
// the test alone — an isotropic point light — is built from rays, written into a bundle, checked, read
// back, graded on held-out rays and rendered in a room through the library's generic paths, with no
// library file knowing its type. The APL level and far field pass through the same seam and give the
// numbers of the APL queries they wrap.
#include "test_support.h"

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
#include <lumx/render/room_render.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

namespace {

constexpr double kPi = 3.14159265358979323846;

// ---- the toy representation: one isotropic point light, I = Φ / 4π toward every direction ----
class IsotropicPoint final : public lumx::LightModel {
 public:
  IsotropicPoint(const glm::dvec3& p, double flux) : p_(p), flux_(flux) {}
  const glm::dvec3& position() const { return p_; }
  double scalar_flux() const { return flux_; }

  std::string type() const override { return "test-isotropic-point"; }
  std::string description() const override { return "isotropic point light"; }
  lumx::PhotometricQuantity quantity() const override { return lumx::PhotometricQuantity::photometric; }
  lumx::ChannelLayout channels() const override { return lumx::ChannelLayout::luminance; }
  lumx::BoundingSphere bounds() const override {
    lumx::BoundingSphere b;
    b.center = p_;
    return b;
  }
  glm::dvec3 flux() const override { return glm::dvec3(flux_); }
  glm::dvec3 intensity(const glm::dvec3&) const override { return glm::dvec3(flux_ / (4 * kPi)); }
  glm::dvec3 irradiance(const glm::dvec3& x, const glm::dvec3& n, const lumx::Visibility* v) const override {
    const glm::dvec3 to_light = p_ - x;
    const double r2 = glm::dot(to_light, to_light);
    const double cosine = glm::dot(n, to_light) / std::sqrt(r2);
    if (!(cosine > 0) || (v && !v->visible(p_, x))) return glm::dvec3(0.0);
    return glm::dvec3(flux_ / (4 * kPi) * cosine / r2);
  }
  lumx::PositionMeasure position_measure() const override { return lumx::PositionMeasure::discrete; }
  lumx::ModelEmission sample_emission(const std::array<double, 4>& u) const override {
    lumx::ModelEmission e;
    const double z = 1 - 2 * u[1], phi = 2 * kPi * u[2], s = std::sqrt(std::max(0.0, 1 - z * z));
    e.position = p_;
    e.direction = {s * std::cos(phi), s * std::sin(phi), z};
    e.pdf_position = 1;
    e.pdf_direction = 1 / (4 * kPi);
    e.flux = glm::dvec3(flux_);
    return e;
  }
  lumx::EmissionDensity emission_pdf(std::size_t element, const glm::dvec3&, const glm::dvec3&) const override {
    return element == 0 ? lumx::EmissionDensity{1, 1 / (4 * kPi)} : lumx::EmissionDensity{};
  }
  std::size_t bytes() const override { return sizeof(*this); }

 private:
  glm::dvec3 p_;
  double flux_;
};

lumx::ModelType isotropic_point_type() {
  lumx::ModelType t;
  t.name = "test-isotropic-point";
  t.description = "an isotropic point light (registered by the seam's test)";
  t.write = [](const lumx::LightModel& m, lumx::ModelPayloadSink& sink) {
    const auto& point = dynamic_cast<const IsotropicPoint&>(m);
    const double f = point.scalar_flux();
    sink.add("flux.f64", std::string(reinterpret_cast<const char*>(&f), sizeof f));
    nlohmann::json j;
    j["position"] = {point.position().x, point.position().y, point.position().z};
    return j.dump();
  };
  t.read = [](const std::string& section, const lumx::ModelPayloadSource& payloads,
              const lumx::ModelLoadOptions&) -> std::unique_ptr<lumx::LightModel> {
    const nlohmann::json j = nlohmann::json::parse(section);
    const auto p = j.find("position");
    if (p == j.end() || !p->is_array() || p->size() != 3)
      lumx::throw_at_field(payloads.where(), "section/position", "must be three numbers");
    if (payloads.size("flux.f64") != sizeof(double))
      lumx::throw_at_field(payloads.where(), "payloads/flux.f64", "must be 8 bytes");
    const std::string bytes = payloads.read("flux.f64");
    double f = 0;
    std::memcpy(&f, bytes.data(), sizeof f);
    if (!(f >= 0) || !std::isfinite(f)) lumx::throw_at_field(payloads.where(), "payloads/flux.f64", "not a finite flux");
    return std::make_unique<IsotropicPoint>(glm::dvec3((*p)[0].get<double>(), (*p)[1].get<double>(), (*p)[2].get<double>()), f);
  };
  // Φ = Σ ray flux; the point is the flux-weighted mean of the start points.
  t.build = [](lumx::RaySource& rays, const lumx::ModelBuildOptions&) -> std::unique_ptr<lumx::LightModel> {
    lumx::RayChunk c;
    double f = 0;
    glm::dvec3 m(0.0);
    while (rays.next(c, 1 << 14))
      for (std::size_t i = 0; i < c.size(); ++i) f += c.flux[i], m += double(c.flux[i]) * glm::dvec3(c.position(i));
    return std::make_unique<IsotropicPoint>(f > 0 ? m / f : m, f);
  };
  return t;
}

const lumx::ModelRegistration kIsotropicPoint{isotropic_point_type()};

// An isotropic point source at `centre` of total flux `flux`: rays start 1 cm out along their direction
// (a recording sphere, as a goniophotometer's rays do), so their start points are not all one point.
lumx::MemoryRaySource isotropic_rays(const glm::dvec3& centre, double flux, std::size_t n, std::uint32_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  lumx::RayChunk c;
  c.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double z = 1 - 2 * u01(rng), phi = 2 * kPi * u01(rng), s = std::sqrt(std::max(0.0, 1 - z * z));
    const glm::dvec3 d(s * std::cos(phi), s * std::sin(phi), z);
    c.push_back(glm::vec3(centre + 0.01 * d), glm::vec3(d), float(flux / double(n)));
  }
  lumx::RaysetInfo info;
  info.file = "isotropic";
  return lumx::MemoryRaySource(std::move(c), std::move(info));
}

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

// A box below the light: every texel of the room lit through ModelRoomIlluminance gets the toy's exact
// E = I cosθ / r², or 0 where the box stands between (decided here by a slab test, not by the renderer).
TEST(LightModelSeam, TheToyLightsARoomThroughTheGenericIlluminance) {
  lumx::render::Room room;
  room.luminaire_position_m = {1.5, 1.4, 1.6};
  room.texel_size_m = 0.1;
  const lumx::render::Box box{{1.2, 1.1, 0.0}, {1.8, 1.7, 0.7}};
  room.occluders.push_back(box);
  const lumx::render::RoomScene scene(room);
  const IsotropicPoint light(glm::dvec3(0.0), kFlux);  // at the bundle frame's origin
  const lumx::render::ModelRoomIlluminance lit(light, room.luminaire_position_m, scene);
  const lumx::render::SurfaceMaps maps = lumx::render::illuminance_maps(scene, lit, 2);
  const glm::dvec3 p = room.luminaire_position_m;
  std::size_t shadowed = 0, compared = 0;
  for (std::size_t s = 0; s < scene.surfaces().size(); ++s) {
    const lumx::render::RoomSurface& surface = scene.surfaces()[s];
    for (int iv = 0; iv < surface.texels_v; ++iv)
      for (int iu = 0; iu < surface.texels_u; ++iu) {
        const glm::dvec2 uv = surface.texel_centre(iu, iv);
        const glm::dvec3 x = surface.point(uv.x, uv.y);
        // Slab test of the open segment p → x against the box, with the entry and exit parameters.
        double t0 = 1e-6, t1 = 1 - 1e-6;
        for (int a = 0; a < 3; ++a) {
          const double d = x[a] - p[a];
          if (std::abs(d) < 1e-15) {
            if (p[a] < box.lo[a] || p[a] > box.hi[a]) t0 = 2;
            continue;
          }
          double ta = (box.lo[a] - p[a]) / d, tb = (box.hi[a] - p[a]) / d;
          if (ta > tb) std::swap(ta, tb);
          t0 = std::max(t0, ta), t1 = std::min(t1, tb);
        }
        const double to_light_len = glm::length(p - x);
        // Skip texels whose segment grazes the box (within 1 mm) or lies on it: their verdict is rounding.
        if (std::abs(t1 - t0) * to_light_len < 1e-3) continue;
        const bool blocked = t0 < t1;
        const double cosine = glm::dot(surface.normal, p - x) / to_light_len;
        const double exact = blocked || cosine <= 0 ? 0.0 : kFlux / (4 * kPi) * cosine / (to_light_len * to_light_len);
        const double got = maps[s][std::size_t(iv) * std::size_t(surface.texels_u) + std::size_t(iu)];
        ASSERT_NEAR(got, exact, 1e-9 * kFlux) << surface.name << " " << iu << "," << iv;
        shadowed += blocked && cosine > 0;
        ++compared;
      }
  }
  EXPECT_GT(shadowed, 20u);  // the box's shadow on the floor is seen
  EXPECT_GT(compared, 1000u);
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
