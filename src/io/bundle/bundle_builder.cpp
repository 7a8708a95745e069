// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// From a rayset to a bundle on disk (lumx/io/bundle_builder.h).
#include <lumx/io/bundle_builder.h>

#include <lumx/apl/far_field.h>
#include <lumx/core/diagnostic.h>
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/intensity_table.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <thread>

LUMX_NAMESPACE_BEGIN

namespace {

using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

/// lm per W for the far field of a radiometric rayset: the caller's, else the header's Φv / Φe.
double efficacy_for(const RaysetInfo& info, double given) {
  if (given > 0) return given;
  const auto v = info.values.find("luminous flux lm"), e = info.values.find("radiant flux W");
  if (v != info.values.end() && e != info.values.end() && v->second > 0 && e->second > 0 && std::isfinite(v->second) &&
      std::isfinite(e->second))
    return v->second / e->second;
  return 0;
}

/// Maps a sub-step's progress into [from, to] of the whole call's.
std::function<void(double, const char*)> progress_span(const BundleBuildOptions& o, double from, double to) {
  if (!o.progress) return {};
  return [&o, from, to](double f, const char* phase) { o.progress(from + (to - from) * f, phase); };
}

AplBuildOptions with_threads(AplBuildOptions bo) {
  if (bo.threads == 0) bo.threads = std::max(1u, std::thread::hardware_concurrency());
  return bo;
}

}  // namespace

/// How the held-out fit left the maps of every level and of the far field, in words, for the manifest's
/// provenance ("level 0: R 64, von Mises-Fisher kernel sigma 3.4 deg; ...; far field: ...").
std::string map_smoothing_note(const ResolutionChoice& c) {
  const auto one = [](int R, double kappa, KernelMode mode) {
    std::string t = "R " + std::to_string(R);
    if (!(kappa > 0)) return t + ", not smoothed";
    char sigma[32];
    std::snprintf(sigma, sizeof sigma, "%.2f", 180.0 / kPi / std::sqrt(kappa));
    return t + ", von Mises-Fisher kernel sigma " + sigma + " deg" +
           (mode == KernelMode::plain ? std::string() : std::string(", ") + kernel_mode_name(mode));
  };
  std::string out;
  for (std::size_t k = 0; k < c.resolution.size(); ++k)
    out += "level " + std::to_string(k) + ": " +
           one(c.resolution[k], k < c.kappa.size() ? c.kappa[k] : 0.0, k < c.mode.size() ? c.mode[k] : KernelMode::plain) + "; ";
  if (c.far_field_resolution > 0)
    out += "far field: " + one(c.far_field_resolution, c.far_field_kappa, c.far_field_mode);
  else if (!out.empty())
    out.resize(out.size() - 2);
  return out;
}

std::string build_options_json(const AplBuildOptions& o) {
  using LC = AplBuildOptions::LineClustering;
  const nlohmann::json j = {{"levels", o.level_counts},
                            {"seed_rays", o.seed_rays},
                            {"cluster_window", o.cluster_window},
                            {"map_resolution", o.map_resolution},
                            {"min_resolution", o.min_resolution},
                            {"max_resolution", o.max_resolution},
                            {"rays_per_texel", o.rays_per_texel},
                            {"apl_exponent", o.apl_exponent},
                            {"converge", o.place_at_convergence},
                            {"cluster_by", o.line_clustering == LC::start_points ? "start"
                                           : o.line_clustering == LC::lines      ? "line"
                                                                                 : "auto"},
                            {"smooth", o.map_smoothing_rays},
                            {"orient_maps", o.orient_maps}};
  return j.dump();
}

AplBuildOptions build_options_from_json(const std::string& text) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (!j.is_object()) throw std::invalid_argument("build_options: not a JSON object");
  AplBuildOptions o;
  auto get = [&](const char* key, auto& value) {
    if (!j.contains(key)) return;
    try {
      value = j.at(key).get<std::decay_t<decltype(value)>>();
    } catch (const nlohmann::json::exception&) {
      throw std::invalid_argument(std::string("build_options: /") + key + " has the wrong type");
    }
  };
  get("levels", o.level_counts);
  get("seed_rays", o.seed_rays);
  get("cluster_window", o.cluster_window);
  get("map_resolution", o.map_resolution);
  get("min_resolution", o.min_resolution);
  get("max_resolution", o.max_resolution);
  get("rays_per_texel", o.rays_per_texel);
  get("apl_exponent", o.apl_exponent);
  get("converge", o.place_at_convergence);
  get("smooth", o.map_smoothing_rays);
  // Bundles written before the map frame recorded no "orient_maps": their maps are in the photometric
  // frame, and a rebuild from their options must draw them so too.
  o.orient_maps = false;
  get("orient_maps", o.orient_maps);
  std::string by = "auto";
  get("cluster_by", by);
  using LC = AplBuildOptions::LineClustering;
  o.line_clustering = by == "start" ? LC::start_points : by == "line" ? LC::lines : LC::automatic;
  return o;
}

HeldOutEvaluation evaluate_bundle_levels(RaySource& rays, const BundleBuildOptions& o) {
  HeldOutEvaluation result;
  result.fitted = o.apl.map_resolution == 0;
  result.rays = rays.info().ray_count;
  AplErrorOptions eo = o.errors;
  // Maps at the resolutions the whole rayset's set will have (the fit only coarsens).
  AplBuildOptions half = half_rays_build_options(with_threads(o.apl), rays.info().ray_count);
  half.progress = progress_span(o, 0.0, 0.5);
  if (eo.threads == 0) eo.threads = unsigned(half.threads);  // the grading's points: the build's threads
  eo.progress = progress_span(o, 0.5, 1.0);
  const auto build_half = [&](RaySource& train) { return build_apl_set(train, half); };
  result.report = result.fitted ? evaluate_held_out_fitted(rays, build_half, eo, &result.choice)
                                : evaluate_held_out(rays, build_half, eo);
  return result;
}

BundleBuildResult build_bundle(RaySource& rays, const std::string& out, const BundleBuildOptions& o) {
  // Unknown or unbuildable representations are refused before any work.
  for (std::size_t i = 0; i < o.representations.size(); ++i) {
    const std::string& type = o.representations[i];
    const ModelType* t = find_model_type(type);
    if (!t) throw_at_field(out, "representations", "no representation is registered as \"" + type + "\"");
    if (type != "apl" && (!t->build || !t->write))
      throw_at_field(out, "representations", "\"" + type + "\" cannot be built from rays and stored as a model");
    for (std::size_t j = 0; j < i; ++j)
      if (o.representations[j] == type) throw_at_field(out, "representations", "\"" + type + "\" is given twice");
  }
  const auto start = Clock::now();
  const RaysetInfo& info = rays.info();
  BundleBuildResult result;

  // Levels by clustering.
  AplBuildOptions bo = with_threads(o.apl);
  bo.progress = progress_span(o, 0.0, 0.4);
  AplSet set = build_apl_set(rays, bo, &result.build);
  const auto built = Clock::now();
  set.provenance["source"] = o.source_name.empty() ? info.file : o.source_name;
  set.provenance["source_rays"] = std::to_string(info.ray_count);
  set.provenance["build_options"] = build_options_json(bo);
  for (const auto& [key, value] : o.provenance) set.provenance[key] = value;
  for (const AplLevel& level : set.levels) {
    result.apls.push_back(level.size());
    result.built_resolution.push_back(level.map_resolution);
  }

  // Error tables from held-out rays (or the grading the caller already made on these rays).
  const AplLevel built_level0 = set.levels.at(0);  // for the far field (choice.far_field_resolution)
  if (o.evaluate) {
    if (o.evaluated) {
      result.held_out = *o.evaluated;
    } else {
      BundleBuildOptions graded = o;
      graded.progress = progress_span(o, 0.4, 0.9);
      result.held_out = evaluate_bundle_levels(rays, graded);
    }
    result.evaluated = true;
    if (apply_held_out_fit(set, result.held_out.report, result.held_out.fitted ? &result.held_out.choice : nullptr)) {
      result.error_tables_stored = true;
      set.provenance["error_tables"] = result.held_out.fitted
                                           ? "held out: levels built from the even rays, map resolutions chosen "
                                             "on rays 1, 5, 9, ..., irradiance at patch centres against rays 3, "
                                             "7, 11, ..., their noise removed"
                                           : "held out: levels built from the even rays, irradiance at patch "
                                             "centres against the odd rays, their noise removed";
      if (result.held_out.fitted) set.provenance["map_smoothing"] = map_smoothing_note(result.held_out.choice);
    } else {
      result.notes.push_back("the half rayset gives other levels than the whole; no error table is stored");
    }
  }
  for (const AplLevel& level : set.levels) result.resolution.push_back(level.map_resolution);
  const auto evaluated = Clock::now();

  // The rays' far field as IES and EULUMDAT, shipped inside the bundle: level 0's maps at the resolution
  // fitted on held-out rays for the far field alone (d = 5, 10), tabulated on the Type C grid. The ray
  // histogram on that grid would give each of its ~26 000 cells a few hundred rays of a million (a
  // Lambertian disk's IES from 1 M rays: 15 % off at d = 10 binned, 3.5 % from the fitted map).
  BundleWriteOptions wo;
  FarFieldGrid grid = o.far_field;
  grid.luminous_efficacy_lm_per_w = efficacy_for(info, o.far_field.luminous_efficacy_lm_per_w);
  if (info.quantity == PhotometricQuantity::radiometric && !(grid.luminous_efficacy_lm_per_w > 0)) {
    result.notes.push_back(
        "the rays carry W and no luminous efficacy is known; no IES/EULUMDAT far field is attached");
  } else {
    AplSet far_set;  // level 0 alone, not a copy of every level's maps
    far_set.quantity = set.quantity;
    far_set.channels = set.channels;
    far_set.provenance = set.provenance;
    const int fitted_r = result.held_out.choice.far_field_resolution;
    const double fitted_kappa = result.held_out.choice.far_field_kappa;
    far_set.levels.push_back(fitted_r > 0 && fitted_r <= built_level0.map_resolution
                                 ? fitted_level(built_level0, fitted_r, fitted_kappa, result.held_out.choice.far_field_mode)
                                 : set.levels.at(0));
    const Photometry far = far_field_photometry(far_set, 0, grid);
    wo.attachments.push_back({"far_field.ies", "application/x-ies-lm63", format_ies(far)});
    wo.attachments.push_back({"far_field.ldt", "application/x-eulumdat", format_ldt(far)});
    result.far_field_attached = true;
    result.far_field_lm = IntensityTable(far).flux_lm();
    result.far_field_resolution = far_set.levels[0].map_resolution;
    result.far_field_kernel_sigma_deg =
        fitted_r > 0 && fitted_kappa > 0 ? 180.0 / kPi / std::sqrt(fitted_kappa) : 0.0;
    result.far_field_kernel_mode =
        result.far_field_kernel_sigma_deg > 0 ? result.held_out.choice.far_field_mode : KernelMode::plain;
  }
  const auto far_done = Clock::now();
  for (const auto& attachment : o.attachments) wo.attachments.push_back(attachment);
  for (const std::string& type : o.representations) {
    if (type == "apl") continue;  // the levels above
    if (o.progress) o.progress(0.9, type.c_str());
    ModelBuildOptions mo = o.representation_options;
    if (mo.execution.threads == 0) mo.execution.threads = o.apl.threads;
    wo.models.emplace_back(type, std::shared_ptr<const LightModel>(build_model(type, rays, mo)));
    if (o.evaluate) {
      ModelGradeOptions go;
      go.relative_distances = o.errors.relative_distances;
      go.patch_resolution = o.errors.patch_resolution;
      go.bounds = set.bounds;
      go.execution.threads = mo.execution.threads;
      result.representation_grades.push_back(grade_held_out(type, rays, mo, go));
    }
  }
  if (o.progress) o.progress(0.95, "writing");
  write_bundle(out, set, o.volume, wo);
  result.bytes = BundleReader(out).manifest().total_bytes();
  const auto written = Clock::now();
  result.seconds_build = seconds_between(start, built);
  result.seconds_evaluation = seconds_between(built, evaluated);
  result.seconds_far_field = seconds_between(evaluated, far_done);
  result.seconds_write = seconds_between(far_done, written);
  if (o.progress) o.progress(1.0, "written");
  return result;
}

LUMX_NAMESPACE_END
