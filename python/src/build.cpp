// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// python/src/build.cpp — lumx.build: rays in, a bundle out, as `lumx build` makes it.
//
// The CLI's pipeline lives in converters/build_command.cpp, outside the library; this composes the same
// library steps in the same order with the same defaults: build_apl_set (apl/builder.h), held-out error
// tables with map resolutions fitted on held-out rays (apl/error.h), level 0's far field as IES and
// EULUMDAT attachments (apl/far_field.h), write_bundle. The builder options go into the provenance as
// the same JSON, so `lumx eval --rays` rebuilds a bundle made here as it does one made by the CLI.
#include "rays.h"

#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/far_field.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/intensity_table.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <thread>

namespace lumx_py {

namespace {

struct BuildResult {
  std::string bundle;
  std::vector<std::size_t> apl_counts;
  std::vector<int> map_resolutions;
  std::uint64_t rays = 0, seeds = 0;
  bool clustered_by_line = false;
  bool error_tables = false;
  double far_field_flux_lm = NAN;
  double seconds = 0;
};

// The provenance entry `lumx build` writes ("build_options"), key for key.
std::string options_json(const lumx::AplBuildOptions& o) {
  using LC = lumx::AplBuildOptions::LineClustering;
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
                            {"smooth", o.map_smoothing_rays}};
  return j.dump();
}

// lm per W for the far field of a radiometric rayset: the caller's, else the header's luminous / radiant flux.
double efficacy_for(const lumx::RaysetInfo& info, double given) {
  if (given > 0) return given;
  const auto v = info.values.find("luminous flux lm"), e = info.values.find("radiant flux W");
  if (v != info.values.end() && e != info.values.end() && v->second > 0 && e->second > 0 && std::isfinite(v->second) &&
      std::isfinite(e->second))
    return v->second / e->second;
  return 0;
}

lumx::Diagnostic note(const std::string& file, const std::string& field, const std::string& message) {
  lumx::Diagnostic d;
  d.severity = lumx::Severity::warning;
  d.file = file;
  d.field = field;
  d.message = message;
  return d;
}

}  // namespace

void bind_build(py::module_& m) {
  py::class_<BuildResult>(m, "BuildResult", "What lumx.build made.")
      .def_readonly("bundle", &BuildResult::bundle, "the bundle folder written")
      .def_readonly("apl_counts", &BuildResult::apl_counts, "APLs per level")
      .def_readonly("map_resolutions", &BuildResult::map_resolutions, "map resolution R per level, as stored")
      .def_readonly("rays", &BuildResult::rays, "rays assigned")
      .def_readonly("seeds", &BuildResult::seeds, "rays the cluster tree was built from")
      .def_readonly("clustered_by_line", &BuildResult::clustered_by_line,
                    "rays were clustered by their lines' points nearest the convergence point")
      .def_readonly("error_tables", &BuildResult::error_tables, "held-out error tables are stored in the bundle")
      .def_readonly("far_field_flux_lm", &BuildResult::far_field_flux_lm,
                    "flux of the attached far field, lm (NaN when none was attached)")
      .def_readonly("seconds", &BuildResult::seconds, "wall time")
      .def("__repr__", [](const BuildResult& r) { return "<lumx.BuildResult '" + r.bundle + "'>"; });

  m.def(
      "build",
      [](const py::object& rays, const std::string& out, const std::vector<std::size_t>& levels, std::size_t seeds,
         int map_resolution, double rays_per_texel, int patches, bool evaluate, double c_step_deg,
         double gamma_step_deg, double efficacy_lm_per_w, bool converge, const std::string& cluster_by,
         double resolution_exponent, double smooth, unsigned threads, const py::object& progress) {
        using LC = lumx::AplBuildOptions::LineClustering;
        if (cluster_by != "auto" && cluster_by != "start" && cluster_by != "line")
          throw py::value_error("cluster_by: 'auto', 'start' or 'line'");
        WarningCollector warnings;
        std::unique_ptr<lumx::RaySource> holder;
        std::unique_lock<std::mutex> file_lock;
        lumx::RaySource& source = rays_argument(rays, holder, file_lock, warnings);
        const std::string name = source.info().file;
        ProgressCallback report(progress);
        auto stage = [&report](double from, double to) {
          return [&report, from, to](double f, const char* phase) { report(from + (to - from) * f, phase); };
        };
        BuildResult r;
        r.bundle = out;
        {
          py::gil_scoped_release release;
          const auto start = std::chrono::steady_clock::now();
          const lumx::RaysetInfo& info = source.info();
          lumx::AplBuildOptions bo;
          if (!levels.empty()) bo.level_counts = levels;
          bo.seed_rays = seeds;
          bo.map_resolution = map_resolution;
          bo.rays_per_texel = rays_per_texel;
          bo.place_at_convergence = converge;
          bo.line_clustering = cluster_by == "start"  ? LC::start_points
                               : cluster_by == "line" ? LC::lines
                                                      : LC::automatic;
          bo.apl_exponent = resolution_exponent;
          bo.map_smoothing_rays = smooth;
          bo.threads = threads > 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
          if (!report.empty()) bo.progress = stage(0.0, evaluate ? 0.3 : 0.9);
          lumx::AplBuildReport br;
          lumx::AplSet set = lumx::build_apl_set(source, bo, &br);
          bo.progress = nullptr;
          set.provenance["source"] = name;
          set.provenance["source_rays"] = std::to_string(info.ray_count);
          set.provenance["build_options"] = options_json(bo);
          r.rays = br.rays;
          r.seeds = br.seeds;
          r.clustered_by_line = br.slid_to_convergence;

          // Held-out error tables (and, unless the resolution is fixed, map resolutions fitted on held-out
          // rays), as `lumx build` stores them.
          lumx::ResolutionChoice choice;
          const lumx::AplLevel built_level0 = set.levels.at(0);
          if (evaluate) {
            lumx::AplErrorOptions eo;
            eo.patch_resolution = patches;
            lumx::AplBuildOptions half = bo;
            if (!report.empty()) {
              half.progress = stage(0.3, 0.6);
              eo.progress = stage(0.6, 0.95);
            }
            const auto build_half = [&](lumx::RaySource& train) { return lumx::build_apl_set(train, half); };
            const lumx::AplErrorReport er = map_resolution > 0
                                                ? lumx::evaluate_held_out(source, build_half, eo)
                                                : lumx::evaluate_held_out_fitted(source, build_half, eo, &choice);
            r.error_tables = lumx::apply_held_out_fit(set, er, map_resolution > 0 ? nullptr : &choice);
            if (r.error_tables) {
              set.provenance["error_tables"] =
                  map_resolution > 0 ? "held out: levels built from the even rays, irradiance at patch centres "
                                       "against the odd rays, their noise removed"
                                     : "held out: levels built from the even rays, map resolutions chosen on rays "
                                       "1, 5, 9, ..., irradiance at patch centres against rays 3, 7, 11, ..., "
                                       "their noise removed";
            } else {
              warnings.sink()(note(name, "error tables",
                                   "the half rayset gives other levels than the whole; no error table is stored"));
            }
          }
          report(0.95, "far field");

          // Level 0's far field as IES and EULUMDAT, at the resolution fitted for it on held-out rays.
          lumx::BundleWriteOptions wo;
          lumx::FarFieldGrid grid;
          grid.c_step_deg = c_step_deg;
          grid.gamma_step_deg = gamma_step_deg;
          grid.luminous_efficacy_lm_per_w = efficacy_for(info, efficacy_lm_per_w);
          if (info.quantity == lumx::PhotometricQuantity::radiometric && !(grid.luminous_efficacy_lm_per_w > 0)) {
            warnings.sink()(note(name, "efficacy",
                                 "the rays carry W and no luminous efficacy is known (give efficacy_lm_per_w); no "
                                 "IES/EULUMDAT far field is attached"));
          } else {
            lumx::AplSet far_set;
            far_set.quantity = set.quantity;
            far_set.channels = set.channels;
            far_set.provenance = set.provenance;
            far_set.levels.push_back(choice.far_field_resolution > 0 &&
                                             choice.far_field_resolution <= built_level0.map_resolution
                                         ? lumx::downsampled_level(built_level0, choice.far_field_resolution)
                                         : set.levels.at(0));
            const lumx::Photometry far = lumx::far_field_photometry(far_set, 0, grid);
            wo.attachments.push_back({"far_field.ies", "application/x-ies-lm63", lumx::format_ies(far)});
            wo.attachments.push_back({"far_field.ldt", "application/x-eulumdat", lumx::format_ldt(far)});
            r.far_field_flux_lm = lumx::IntensityTable(far).flux_lm();
          }
          report(0.97, "write");
          lumx::write_bundle(out, set, nullptr, wo);
          for (const lumx::AplLevel& l : set.levels) {
            r.apl_counts.push_back(l.size());
            r.map_resolutions.push_back(l.map_resolution);
          }
          report(1.0, "done");
          r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        }
        warnings.emit();
        if (py::isinstance<RayFile>(rays)) rays.cast<RayFile&>().emit_warnings();
        return r;
      },
      py::arg("rays"), py::arg("out"), py::kw_only(), py::arg("levels") = std::vector<std::size_t>{1, 8, 64, 256, 512},
      py::arg("seeds") = 250000, py::arg("map_resolution") = 0, py::arg("rays_per_texel") = 8.0,
      py::arg("patches") = 16, py::arg("evaluate") = true, py::arg("c_step_deg") = 2.5, py::arg("gamma_step_deg") = 1.0,
      py::arg("efficacy_lm_per_w") = 0.0, py::arg("converge") = true, py::arg("cluster_by") = "auto",
      py::arg("resolution_exponent") = 0.0, py::arg("smooth") = 0.0, py::arg("threads") = 0,
      py::arg("progress") = py::none(),
      "Builds a bundle from rays as `lumx build RAYS OUT` does (same options, same defaults, same result): "
      "APL levels by clustering, map resolutions and error tables from held-out rays (evaluate=False skips "
      "them), level 0's far field (c_step_deg, gamma_step_deg, degrees) attached as IES and EULUMDAT. `rays`: "
      "a path, a lumx.RayFile, a structured array or mapping of arrays (position m, direction, flux lm or W), "
      "or a callable returning an iterable of chunks (read several times). `progress(fraction, phase)` is "
      "called from time to time; an exception in it (or Ctrl-C) stops the build and leaves `out` untouched. "
      "The GIL is released while C++ works.");
}

}  // namespace lumx_py
