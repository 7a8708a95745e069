// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// A luminaire's geometry in, a bundle out (lumx/bake/bake.h).
#include <lumx/bake/bake.h>

#include "exit_spool.h"

#include <lumx/core/diagnostic.h>
#include <lumx/io/atomic_file.h>
#include <lumx/io/rayset_io.h>
#include <lumx/version.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <limits>
#include <memory>

LUMX_NAMESPACE_BEGIN
namespace bake {
namespace {

using Clock = std::chrono::steady_clock;

/// The first pass of an automatic schedule: enough exits for a first grading that means something
/// (~10⁵ per half), little enough that an easy target stops early.
constexpr std::uint64_t kFirstPass = std::uint64_t(1) << 18;

/// Receives every traced chunk once: exits to the spool, segments to the volume, progress to the caller.
struct BakeSink : ParticleSink {
  ExitSpool* spool = nullptr;
  RadianceVolume* volume = nullptr;
  std::function<void(std::uint64_t)> traced;  // particles of this pass traced so far
  std::uint64_t pass_particles = 0;
  void consume(const ParticleChunk& c) override {
    spool->consume(c);
    if (volume)
      for (const PathSegment& s : c.segments)
        volume->add_segment(glm::dvec3(s.origin), glm::dvec3(s.direction), double(s.length_m), s.flux_lm);
    pass_particles += c.particle_count;
    if (traced) traced(pass_particles);
  }
};

/// The radiance volume's grid: the luminaire's box, cubic voxels (000 §4.4).
std::unique_ptr<RadianceVolume> make_volume(const LuminaireScene& scene, const BakeOptions& o) {
  if (o.volume_voxels <= 0 || scene.positions.empty()) return nullptr;
  Aabb box;
  box.lo = glm::dvec3(std::numeric_limits<double>::infinity());
  box.hi = -box.lo;
  for (const auto& p : scene.positions) {
    box.lo = glm::min(box.lo, glm::dvec3(p));
    box.hi = glm::max(box.hi, glm::dvec3(p));
  }
  return std::make_unique<RadianceVolume>(box, o.volume_voxels, o.volume_bands, 3);
}

/// The scratch file of exits: a temporary sibling of the bundle ("out/" and "out" alike), so that the
/// next bake of the same bundle removes one a killed bake left.
std::string spool_path(const std::string& out) {
  std::filesystem::path p = std::filesystem::path(out).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  const std::string target = (p.parent_path() / (p.filename().string() + ".exits")).string();
  remove_stale_temporaries(target);
  return temporary_sibling_name(target);
}

void check_options(const std::string& file, const BakeOptions& o) {
  if (o.particles == 0) throw_at_field(file, "particles", "the particle budget must be at least 1");
  if (!(o.target_error >= 0) || !std::isfinite(o.target_error))
    throw_at_field(file, "target_error", "must be a finite fraction >= 0 (0: trace the whole budget)");
  if (!(o.target_distance > 0) || !std::isfinite(o.target_distance))
    throw_at_field(file, "target_distance", "must be a finite relative distance > 0");
  if (!(o.time_limit_seconds >= 0) || !std::isfinite(o.time_limit_seconds))
    throw_at_field(file, "time_limit_seconds", "must be finite and >= 0 (0: no limit)");
  if (o.threads < 0) throw_at_field(file, "threads", "must be >= 0 (0: every hardware thread)");
}

/// The grading's spheres with the target distance among them; returns its index.
std::size_t add_target_distance(AplErrorOptions& e, double d) {
  auto& ds = e.relative_distances;
  auto it = std::find_if(ds.begin(), ds.end(), [d](double x) { return std::abs(x - d) <= 1e-9 * d; });
  if (it == ds.end()) {
    ds.push_back(d);
    std::sort(ds.begin(), ds.end());
    it = std::find(ds.begin(), ds.end(), d);
  }
  return std::size_t(it - ds.begin());
}

/// What ε̂ at sphere s is known to be below; the raw error when no noise estimate exists.
double upper_error(const LevelErrors& row, std::size_t s) {
  if (s >= row.errors.size()) return NAN;
  const IrradianceErrors& e = row.errors[s];
  return std::isfinite(e.noise_removed_upper) ? e.noise_removed_upper : e.relative_rmse;
}

std::string passes_json(const std::vector<BakePass>& passes) {
  nlohmann::json j = nlohmann::json::array();
  for (const BakePass& p : passes) {
    nlohmann::json row = {{"particles", p.particles}, {"exits", p.exits}, {"seconds", p.seconds}};
    if (p.graded) {
      row["error_upper"] = p.error;
      row["error_estimate"] = p.error_estimate;
      row["far_field_error_upper"] = p.far_field_error;
    }
    j.push_back(row);
  }
  return j.dump();
}

}  // namespace

BakeResult bake_luminaire(const std::string& luminaire, const std::string& out, const BakeOptions& options) {
  const auto start = Clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  check_options(luminaire, options);
  BakeResult result;
  BakeProgress progress;
  progress.budget = options.particles;
  const auto report = [&](const char* phase, double fraction) {
    if (!options.progress) return;
    progress.phase = phase;
    progress.fraction = fraction;
    progress.elapsed_seconds = elapsed();
    options.progress(progress);
  };
  report("reading", 0);

  const std::string bytes = read_file_bounded(luminaire, options.read.max_file_bytes, "GltfReadOptions::max_file_bytes");
  const LuminaireScene scene = read_gltf_luminaire(luminaire, options.read);
  const Tracer tracer(scene);
  result.luminaire_name = scene.name;
  result.parts = scene.parts.size();
  result.triangles = scene.triangle_count();
  result.emitters = scene.emitters.size();
  result.emitted_lm = tracer.total_flux_lm();
  std::unique_ptr<RadianceVolume> volume = make_volume(scene, options);

  // The grading options: the bundle's, with the target distance among the spheres.
  BundleBuildOptions bundle = options.bundle;
  if (bundle.apl.threads == 0) bundle.apl.threads = unsigned(options.threads);  // 0: every core for both
  bundle.progress = nullptr;
  bundle.evaluated = nullptr;
  const bool stopping_rule = options.target_error > 0;
  const std::size_t target_sphere = add_target_distance(bundle.errors, options.target_distance);
  if (stopping_rule) bundle.evaluate = true;

  ExitSpool spool(spool_path(out));
  BakeSink sink;
  sink.spool = &spool;
  sink.volume = volume.get();
  RaysetInfo info;
  info.file = options.rays_out.empty() ? luminaire : options.rays_out;
  info.format = "lumx trace";
  info.version = "1";
  info.quantity = PhotometricQuantity::photometric;
  info.simulated = true;
  info.values["emitted luminous flux lm"] = tracer.total_flux_lm();
  info.text["light source"] = scene.name;
  info.text["creator"] = std::string("lumx ") + kLibraryVersion + " bake";

  TraceOptions to;
  to.seed = options.seed;
  to.threads = options.threads;
  to.max_depth = options.max_depth;
  to.record_segments = volume != nullptr;
  to.normalization_particles = 1;  // fluxes per particle; divided by the final count when read (exit_spool.h)

  std::uint64_t done = 0;
  std::uint64_t next = options.pass_particles > 0                                        ? options.pass_particles
                       : stopping_rule || options.time_limit_seconds > 0 ? kFirstPass
                                                                         : options.particles;
  double trace_seconds = 0, grade_seconds = 0;
  std::uint64_t graded_at = 0;
  HeldOutEvaluation last_grading;
  result.stopped_by = "particle budget";
  while (done < options.particles) {
    std::uint64_t n = std::min(next, options.particles - done);
    if (options.time_limit_seconds > 0 && done > 0) {
      // Start no pass that would end after the limit: its tracing at the rate so far, and its grading
      // scaled from the last one (∝ particles).
      const double rate = double(done) / std::max(trace_seconds, 1e-9);
      const double grade_per_particle = graded_at ? grade_seconds / double(graded_at) : 0.0;
      const double left = options.time_limit_seconds - elapsed();
      const double per_particle = 1.0 / rate + grade_per_particle;
      const double fits = left / per_particle - double(done) * grade_per_particle / per_particle;
      if (fits < double(n)) n = std::uint64_t(std::max(0.0, std::floor(fits)));
      if (n < to.chunk_particles) {
        result.stopped_by = "time limit";
        break;
      }
    }
    BakePass pass;
    ++progress.pass;
    const auto pass_start = Clock::now();
    sink.pass_particles = 0;
    sink.traced = [&](std::uint64_t k) {
      progress.particles = done + k;
      const double t = trace_seconds + std::chrono::duration<double>(Clock::now() - pass_start).count();
      progress.particles_per_second = double(progress.particles) / std::max(t, 1e-9);
      // To the budget's end (an upper bound when a target may stop the bake sooner), or the time limit.
      progress.eta_seconds = double(options.particles - progress.particles) / progress.particles_per_second;
      if (options.time_limit_seconds > 0)
        progress.eta_seconds = std::min(progress.eta_seconds, std::max(0.0, options.time_limit_seconds - elapsed()));
      report("tracing", double(k) / double(n));
    };
    to.first_particle = done;
    to.particles = n;
    result.counters.add(tracer.trace(to, sink));
    spool.flush();
    done += n;
    trace_seconds += std::chrono::duration<double>(Clock::now() - pass_start).count();
    pass.particles = done;
    pass.exits = spool.exits();

    if (stopping_rule) {
      const auto grade_start = Clock::now();
      SpoolRaySource rays(spool.path(), spool.exits(), done, info);
      BundleBuildOptions graded = bundle;
      graded.progress = [&](double f, const char*) { report("grading", f); };
      last_grading = evaluate_bundle_levels(rays, graded);
      graded_at = done;
      grade_seconds += std::chrono::duration<double>(Clock::now() - grade_start).count();
      pass.graded = true;
      const AplErrorReport& r = last_grading.report;
      for (const LevelErrors& row : r.levels) pass.level_error.push_back(upper_error(row, target_sphere));
      pass.error = pass.level_error.empty() ? NAN : pass.level_error.back();
      if (!r.levels.empty() && target_sphere < r.levels.back().errors.size())
        pass.error_estimate = r.levels.back().errors[target_sphere].relative_rmse_noise_removed;
      pass.far_field_error = upper_error(r.far_field, target_sphere);
      progress.error = pass.error;
    }
    pass.seconds = elapsed();
    result.passes.push_back(pass);
    if (options.on_pass) {
      SpoolRaySource exits(spool.path(), spool.exits(), done, info);
      options.on_pass(pass, exits);
    }
    if (stopping_rule && pass.error <= options.target_error) {
      result.target_met = true;
      result.stopped_by = "target error";
      break;
    }
    if (options.time_limit_seconds > 0 && elapsed() >= options.time_limit_seconds) {
      result.stopped_by = done < options.particles ? "time limit" : "particle budget";
      break;
    }
    if (options.pass_particles > 0) {
      next = options.pass_particles;
    } else if (stopping_rule && std::isfinite(pass.error) && pass.error > 0) {
      // ε² ∝ 1/N for the noise part: the total that would reach the target, with a 10 % margin, growing
      // between 1.5× and 4× (the estimate is itself noisy, and a bias floor would never be reached).
      const double wanted = double(done) * std::pow(pass.error / options.target_error, 2) * 1.1;
      next = std::uint64_t(std::clamp(wanted, 1.5 * double(done), 4.0 * double(done))) - done;
    } else {
      next = done;  // doubling
    }
    // A pass that would leave less than half its own size of the budget takes the rest now: a last
    // sliver would cost a whole grading for almost no particles.
    if (options.pass_particles == 0 && options.particles - done < next + next / 2) next = options.particles - done;
  }
  result.trace_seconds = elapsed();

  // Normalise to the final count: the volume's deposits were per particle.
  if (volume) {
    std::vector<float> c = volume->coefficients();
    const double scale = 1.0 / double(done);
    for (float& v : c) v = float(double(v) * scale);
    volume->set_coefficients(std::move(c));
  }
  SpoolRaySource rays(spool.path(), spool.exits(), done, info);
  if (!options.rays_out.empty()) {
    report("writing rays", 0);
    Tm25WriteOptions tm25;
    tm25.header_flux_from_rays = true;  // the exit flux, known once every particle is traced
    RaysetInfo written = info;
    written.ray_count = spool.exits();
    write_tm25(options.rays_out, written, rays, tm25);
    rays.rewind();
  }

  // The luminaire byte for byte, and provenance.
  std::string ext = std::filesystem::path(luminaire).extension().string();
  for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  const std::string attachment_name = ext == ".gltf" ? "luminaire.gltf" : "luminaire.glb";
  bundle.attachments.push_back({attachment_name, ext == ".gltf" ? "model/gltf+json" : "model/gltf-binary", bytes});
  const TraceCounters& c = result.counters;
  auto& p = bundle.provenance;
  p["source"] = info.file;  // the kept rays file, if any: lumx eval recognises its own rays by it
  p["generator"] = std::string("lumx ") + kLibraryVersion + " bake";
  p["luminaire"] = std::filesystem::path(luminaire).filename().string() + " (attachments/" + attachment_name +
                   ", byte for byte; its SHA-256 is in the manifest)";
  p["seed"] = std::to_string(options.seed);
  p["particles"] = std::to_string(c.emitted);
  p["passes"] = passes_json(result.passes);
  p["stopped_by"] = result.stopped_by;
  if (stopping_rule) {
    p["target_error"] = std::to_string(options.target_error);
    p["target_distance"] = std::to_string(options.target_distance);
    p["error_reached"] = std::to_string(result.passes.back().error);
  }
  p["trace_seconds"] = std::to_string(result.trace_seconds);  // reading, set-up, tracing, grading
  p["trace_counters"] = "exited " + std::to_string(c.exited) + ", absorbed " + std::to_string(c.absorbed) +
                        ", roulette " + std::to_string(c.roulette_killed) + ", depth-capped " +
                        std::to_string(c.depth_capped) + ", leaked " + std::to_string(c.leaked) + ", segments " +
                        std::to_string(c.segments);
  p["emitted_lm"] = std::to_string(c.emitted_lm / double(done));
  p["exited_lm"] = std::to_string(c.exited_lm / double(done));
  result.counters.emitted_lm /= double(done);
  result.counters.exited_lm /= double(done);

  bundle.volume = volume.get();
  bundle.source_name = info.file;
  bundle.evaluated = stopping_rule && graded_at == done ? &last_grading : nullptr;
  bundle.progress = [&](double f, const char* phase) { report(phase, f); };
  result.bundle = build_bundle(rays, out, bundle);
  const BundleReader written(out);
  for (const auto& [attachment, payload] : written.manifest().attachments)
    if (attachment.name == attachment_name) result.input_sha256 = payload.sha256;
  return result;
}

}  // namespace bake
LUMX_NAMESPACE_END
