// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// `lumx bake`: traces a glTF luminaire's particles once into a TM-25 rayset (the exits) and a radiance volume
// (the internal segments), then builds the bundle from that rayset exactly as `lumx build` does, with the
// volume, the luminaire file and the tracer's provenance added.
#include "bake_command.h"

#include "cli_support.h"
#include "progress.h"

#include <lumx/bake/gltf_reader.h>
#include <lumx/bake/traced_rays.h>
#include <lumx/bake/tracer.h>
#include <lumx/io/rayset_io.h>
#include <lumx/version.h>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

namespace lumx_cli {
namespace {

/// Deposits each internal segment into the radiance volume (track-length estimator, volume/radiance_volume.h).
struct VolumeSink : lumx::bake::ParticleSink {
  lumx::RadianceVolume* volume = nullptr;
  ProgressBar* bar = nullptr;
  std::uint64_t particles = 0, total = 0;
  void consume(const lumx::bake::ParticleChunk& c) override {
    if (volume)
      for (const auto& s : c.segments)
        volume->add_segment(glm::dvec3(s.origin), glm::dvec3(s.direction), double(s.length_m), s.flux_lm);
    particles += c.particle_count;
    if (bar) bar->update(double(particles) / double(std::max<std::uint64_t>(1, total)), "tracing");
  }
};

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

int run_bake(BakeArgs a) {
  return guarded(a.luminaire, [&] {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    lumx::bake::GltfReadOptions ro;
    ro.warnings = [](const lumx::Diagnostic& d) { print_diag(d); };
    const lumx::bake::LuminaireScene scene = lumx::bake::read_gltf_luminaire(a.luminaire, ro);
    const lumx::bake::Tracer tracer(scene);
    std::printf("luminaire: %s, %zu parts, %zu triangles, %zu emitters, %.4g lm emitted\n", a.luminaire.c_str(),
                scene.parts.size(), scene.triangle_count(), scene.emitters.size(), tracer.total_flux_lm());

    // The volume spans the luminaire's box (cubic voxels, counts following its aspect, 000 §4.4).
    std::unique_ptr<lumx::RadianceVolume> volume;
    if (a.volume_voxels > 0 && !scene.positions.empty()) {
      lumx::Aabb box;
      box.lo = glm::dvec3(std::numeric_limits<double>::infinity());
      box.hi = -box.lo;
      for (const auto& p : scene.positions) {
        box.lo = glm::min(box.lo, glm::dvec3(p));
        box.hi = glm::max(box.hi, glm::dvec3(p));
      }
      volume = std::make_unique<lumx::RadianceVolume>(box, a.volume_voxels, 4, 3);
    }

    lumx::bake::TraceOptions to;
    to.particles = a.particles;
    to.seed = a.seed;
    to.threads = int(a.build.threads);
    to.max_depth = a.max_depth;
    to.record_segments = volume != nullptr;
    ProgressBar bar(double(a.particles), "particles", a.build.progress);
    VolumeSink observer;
    observer.volume = volume.get();
    observer.bar = &bar;
    observer.total = a.particles;
    lumx::bake::TracedRaySource traced(tracer, to, 1u << 17, &observer);

    // One trace, into a TM-25 file: --rays-out, or a temporary file beside the bundle.
    const bool keep_rays = !a.rays_out.empty();
    // Without --rays-out the exits go to a temporary file beside the bundle ("out/" and "out" alike).
    std::filesystem::path out_path = std::filesystem::path(a.out).lexically_normal();
    if (out_path.filename().empty()) out_path = out_path.parent_path();
    const std::string rays_path =
        keep_rays ? a.rays_out : (out_path.parent_path() / (out_path.filename().string() + ".rays.tm25ray")).string();
    lumx::RaysetInfo info = traced.info();
    info.text["creator"] = std::string("lumx ") + lumx::kLibraryVersion + " bake";
    lumx::Tm25WriteOptions tm25;
    tm25.header_flux_from_rays = true;  // the exit flux, known once every particle is traced
    lumx::write_tm25(rays_path, info, traced, tm25);
    bar.done();
    const double trace_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    const lumx::bake::TraceCounters& c = traced.counters();
    std::printf(
        "trace:     %llu particles in %.2f s (%.0f/s): %llu exited (%.4g lm), %llu absorbed, %llu ended by "
        "roulette, %llu at the depth cap, %llu leaked; %llu segments\n",
        (unsigned long long)c.emitted, trace_seconds, double(c.emitted) / std::max(trace_seconds, 1e-9),
        (unsigned long long)c.exited, c.exited_lm, (unsigned long long)c.absorbed,
        (unsigned long long)c.roulette_killed, (unsigned long long)c.depth_capped, (unsigned long long)c.leaked,
        (unsigned long long)c.segments);
    if (keep_rays) std::printf("rays:      %s (IES TM-25, the exits as a near-field rayset)\n", rays_path.c_str());

    BundleExtras extras;
    extras.volume = volume.get();
    const std::string name = std::filesystem::path(a.luminaire).filename().string();
    std::string attachment_name = "luminaire";
    std::string ext = std::filesystem::path(a.luminaire).extension().string();
    for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    attachment_name += ext == ".gltf" ? ".gltf" : ".glb";
    extras.attachments.push_back(
        {attachment_name, ext == ".gltf" ? "model/gltf+json" : "model/gltf-binary", read_bytes(a.luminaire)});
    auto& p = extras.provenance;
    if (!keep_rays) p["source"] = a.luminaire;  // else the kept rays file: lumx eval recognises its own rays by it
    p["generator"] = std::string("lumx ") + lumx::kLibraryVersion + " bake";
    p["luminaire"] = name + " (attachments/" + attachment_name + ", byte for byte; its SHA-256 is in the manifest)";
    p["seed"] = std::to_string(a.seed);
    p["particles"] = std::to_string(c.emitted);
    p["trace_seconds"] = std::to_string(trace_seconds);  // reading, scene set-up, tracing and the TM-25 file
    p["trace_counters"] = "exited " + std::to_string(c.exited) + ", absorbed " + std::to_string(c.absorbed) +
                          ", roulette " + std::to_string(c.roulette_killed) + ", depth-capped " +
                          std::to_string(c.depth_capped) + ", leaked " + std::to_string(c.leaked) + ", segments " +
                          std::to_string(c.segments);
    p["emitted_lm"] = std::to_string(c.emitted_lm);
    p["exited_lm"] = std::to_string(c.exited_lm);

    int status = 0;
    try {
      lumx::RaysetReadOptions rro;
      rro.warnings = [](const lumx::Diagnostic& d) { print_diag(d); };
      auto rays = lumx::open_rayset(rays_path, rro);
      a.build.rays = rays_path;
      a.build.out = a.out;
      status = build_bundle(*rays, a.build, extras);
    } catch (...) {
      if (!keep_rays) std::filesystem::remove(rays_path);
      throw;
    }
    if (!keep_rays) std::filesystem::remove(rays_path);
    return status;
  });
}

}  // namespace lumx_cli
