// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/render/room_illuminance.h>

#include <lumx/apl/evaluation.h>
#include <lumx/apl/far_field.h>
#include <lumx/apl/lod.h>
#include <lumx/bake/gltf_reader.h>
#include <lumx/bake/material.h>
#include <lumx/core/diagnostic.h>
#include <lumx/io/atomic_file.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/photometry_io.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>

LUMX_NAMESPACE_BEGIN
namespace render {

namespace {

/// SplitMix64 of (seed, key): a uniform number in [0, 1) that depends on the query only.
double uniform_of(std::uint64_t seed, std::uint64_t key) {
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + key + 0x632BE59BD9B4E019ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return double(z >> 11) * 0x1.0p-53;
}

[[noreturn]] void throw_bundle_error(const BundleReader& bundle, const std::string& field, const std::string& message) {
  Diagnostic d;
  d.file = bundle.path();
  d.field = field;
  d.message = message;
  throw Error(d);
}

template <class F>
void parallel_range(int threads, std::size_t n, std::size_t grain, F&& body) {
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, std::max<std::size_t>(1, grain)),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
                      });
  });
}

}  // namespace

AplRoomIlluminance::AplRoomIlluminance(const AplSet& set, int level, const glm::dvec3& offset, const RoomScene& scene,
                                       std::uint64_t seed, bool shadows)
    : set_(set), level_(level), offset_(offset), scene_(scene), seed_(seed), shadows_(shadows),
      any_occluder_(!scene.room().occluders.empty()) {
  if (set.levels.empty()) throw std::invalid_argument("AplRoomIlluminance: the set has no level");
  if (level != kLevelOfDetail && (level < 0 || std::size_t(level) >= set.levels.size()))
    throw std::invalid_argument("AplRoomIlluminance: level " + std::to_string(level) + " does not exist");
  if (set.quantity != PhotometricQuantity::photometric)
    throw std::invalid_argument("AplRoomIlluminance: the set is radiometric (W/sr); illuminance needs cd");
}

double AplRoomIlluminance::at(int, const glm::dvec3& x, const glm::dvec3& n, double, double, std::uint64_t key) const {
  const glm::dvec3 local = x - offset_;  // the point in the bundle's frame
  const std::size_t level =
      level_ == kLevelOfDetail ? choose_level_by_distance(set_, local, uniform_of(seed_, key)) : std::size_t(level_);
  IrradianceResult e;
  if (shadows_ && any_occluder_) {
    e = irradiance(set_, level, glm::vec3(local), glm::vec3(n),
                   [&](std::size_t, const glm::vec3& apl, const glm::vec3&) {
                     return scene_.visible(glm::dvec3(apl) + offset_, x) ? 1.0f : 0.0f;
                   });
  } else {
    e = irradiance(set_, level, glm::vec3(local), glm::vec3(n));
  }
  return luminance_of(set_.channels, e.irradiance);
}

namespace {
// The room's shadow rays, from a point of the model (its frame) to a receiver (the room's).
class RoomVisibility final : public Visibility {
 public:
  RoomVisibility(const RoomScene& scene, const glm::dvec3& offset) : scene_(scene), offset_(offset) {}
  bool visible(const glm::dvec3& from, const glm::dvec3& to) const override {
    return scene_.visible(from + offset_, to + offset_);
  }

 private:
  const RoomScene& scene_;
  glm::dvec3 offset_;
};
}  // namespace

ModelRoomIlluminance::ModelRoomIlluminance(const LightModel& model, const glm::dvec3& offset, const RoomScene& scene,
                                           bool shadows)
    : model_(model), offset_(offset), scene_(scene), shadows_(shadows && !scene.room().occluders.empty()) {
  if (model.quantity() != PhotometricQuantity::photometric)
    throw std::invalid_argument("ModelRoomIlluminance: the model is radiometric (W/sr); illuminance needs cd");
}

double ModelRoomIlluminance::at(int, const glm::dvec3& x, const glm::dvec3& n, double, double, std::uint64_t) const {
  const glm::dvec3 local = x - offset_;  // the point in the model's frame
  if (!shadows_) return luminance_of(model_.channels(), model_.irradiance(local, n));
  const RoomVisibility visibility(scene_, offset_);
  return luminance_of(model_.channels(), model_.irradiance(local, n, &visibility));
}

AplSet far_field_set_of_bundle(const BundleReader& bundle, int map_resolution) {
  const auto& attachments = bundle.manifest().attachments;
  std::size_t chosen = attachments.size();
  for (std::size_t i = 0; i < attachments.size(); ++i) {
    const std::string& name = attachments[i].first.name;
    const bool ies = name.size() > 4 && name.compare(name.size() - 4, 4, ".ies") == 0;
    if (name == "far_field.ies") {
      chosen = i;
      break;
    }
    if (ies && chosen == attachments.size()) chosen = i;
  }
  if (chosen < attachments.size()) {
    const std::string text = bundle.read_attachment(chosen);
    const Photometry p = read_ies(text, bundle.path() + "/attachments/" + attachments[chosen].first.name);
    return apl_set_from_photometry(p, map_resolution);
  }
  const std::size_t levels = bundle.manifest().levels.size();
  if (levels == 0) throw_bundle_error(bundle, "levels", "the bundle has no level and no far-field attachment");
  AplSet finest = bundle.empty_set();
  finest.levels.push_back(bundle.load_level(levels - 1));
  return apl_set_from_photometry(far_field_photometry(finest, 0), map_resolution);
}

bake::LuminaireScene luminaire_of_bundle(const BundleReader& bundle, const std::string& scratch_dir) {
  const auto& attachments = bundle.manifest().attachments;
  for (std::size_t i = 0; i < attachments.size(); ++i) {
    const std::string& name = attachments[i].first.name;
    if (name != "luminaire.glb" && name != "luminaire.gltf") continue;
    std::filesystem::create_directories(scratch_dir);
    const std::string path = (std::filesystem::path(scratch_dir) / name).string();
    write_file_atomically(path, bundle.read_attachment(i));
    return bake::read_gltf_luminaire(path);
  }
  throw_bundle_error(bundle, "attachments",
                     "the bundle ships no luminaire geometry (attachments/luminaire.glb or .gltf, as lumx bake "
                     "writes): the reference needs it");
}

namespace {

struct ExitCollector : bake::ParticleSink {
  std::vector<bake::ExitParticle> exits;
  void consume(const bake::ParticleChunk& chunk) override {
    exits.insert(exits.end(), chunk.exits.begin(), chunk.exits.end());
  }
};

}  // namespace

RoomDeposits trace_room_particles(const bake::Tracer& tracer, const RoomScene& scene, const glm::dvec3& offset,
                                  const ReferenceOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t surfaces = scene.surfaces().size();
  RoomDeposits out;
  out.even.resize(surfaces);
  out.odd.resize(surfaces);
  out.emitted_lm = tracer.total_flux_lm();
  const std::uint64_t total = std::max<std::uint64_t>(1, options.particles);
  // Passes of about 1/16 of the budget (whole chunks), so progress and the time limit are checked often.
  bake::TraceOptions to;
  to.seed = options.seed;
  to.threads = options.threads;
  to.normalization_particles = total;
  const std::uint64_t chunk = to.chunk_particles;
  const std::uint64_t pass = std::max<std::uint64_t>(chunk, (total / 16 + chunk - 1) / chunk * chunk);
  std::uint64_t done = 0;
  std::vector<RoomHit> hits;
  while (done < total) {
    ExitCollector sink;
    to.first_particle = done;
    to.particles = std::min(pass, total - done);
    tracer.trace(to, sink);
    done += to.particles;
    // Each exit flies straight on from where it left the luminaire; the hits are found in parallel into
    // their own slots, then deposited in particle order, so the result is independent of the threads.
    hits.assign(sink.exits.size(), RoomHit{});
    parallel_range(options.threads, sink.exits.size(), 1024, [&](std::size_t i) {
      const bake::ExitParticle& e = sink.exits[i];
      hits[i] = scene.intersect(glm::dvec3(e.position) + offset, glm::normalize(glm::dvec3(e.direction)));
    });
    for (std::size_t i = 0; i < sink.exits.size(); ++i) {
      const bake::ExitParticle& e = sink.exits[i];
      const double flux = bake::luminance(bake::Rgb(e.flux_lm));
      out.exited_lm += flux;
      const RoomHit& h = hits[i];
      if (h.surface < 0 || !h.front) continue;  // escaped (luminaire outside the room) or a back face
      out.deposited_lm += flux;
      auto& half = (e.index % 2 == 0) ? out.even : out.odd;
      half[std::size_t(h.surface)].push_back({h.u, h.v, flux});
    }
    if (options.progress) options.progress(double(done) / double(total));
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (options.time_limit_s > 0 && elapsed > options.time_limit_s) break;
  }
  out.particles = done;
  if (done < total) {  // cut short: every particle carried Φ/total, so scale to Φ/done
    const double scale = double(total) / double(done);
    for (auto* half : {&out.even, &out.odd})
      for (auto& s : *half)
        for (Deposit2D& d : s) d.flux_lm *= scale;
    out.exited_lm *= scale;
    out.deposited_lm *= scale;
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

ReferenceRoomIlluminance::ReferenceRoomIlluminance(const RoomScene& scene, const RoomDeposits& deposits,
                                                   const AdaptiveKernelOptions& kernel) {
  const auto& surfaces = scene.surfaces();
  kde_.resize(surfaces.size());
  full_.resize(surfaces.size());
  even_.resize(surfaces.size());
  odd_.resize(surfaces.size());
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    const RoomSurface& f = surfaces[s];
    const std::size_t texels = f.texel_count();
    std::vector<Deposit2D> all = deposits.even[s];
    all.insert(all.end(), deposits.odd[s].begin(), deposits.odd[s].end());
    if (all.empty()) {
      full_[s].assign(texels, 0.0);
      even_[s].assign(texels, 0.0);
      odd_[s].assign(texels, 0.0);
      continue;
    }
    kde_[s] = std::make_unique<AdaptiveKernelDensity2D>(std::move(all), f.width_m, f.height_m, kernel);
    full_[s] = kde_[s]->evaluate_grid(f.texels_u, f.texels_v);
    // Each half alone estimates the whole: its deposits count twice.
    auto half_map = [&](const std::vector<Deposit2D>& half) {
      if (half.empty()) return std::vector<double>(texels, 0.0);
      std::vector<Deposit2D> doubled = half;
      for (Deposit2D& d : doubled) d.flux_lm *= 2.0;
      return AdaptiveKernelDensity2D(std::move(doubled), f.width_m, f.height_m, kernel).evaluate_grid(f.texels_u,
                                                                                                       f.texels_v);
    };
    even_[s] = half_map(deposits.even[s]);
    odd_[s] = half_map(deposits.odd[s]);
  }
}

ReferenceRoomIlluminance::~ReferenceRoomIlluminance() = default;

double ReferenceRoomIlluminance::at(int surface, const glm::dvec3&, const glm::dvec3&, double u, double v,
                                    std::uint64_t) const {
  const auto& kde = kde_.at(std::size_t(surface));
  return kde ? kde->evaluate(u, v) : 0.0;
}

}  // namespace render
LUMX_NAMESPACE_END
