// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// python/src/build.cpp — lumx.build: rays in, a bundle out, by lumx::build_bundle (io/bundle_builder.h),
// the call `lumx build` makes, with the CLI's options and defaults; its notes become Python warnings.
#include "rays.h"

#include <lumx/io/bundle_builder.h>

#include <cmath>

namespace lumx_py {

namespace {

struct BuildResult {
  std::string bundle;
  std::vector<std::size_t> apl_counts;
  std::vector<int> map_resolutions, built_resolutions;
  std::uint64_t rays = 0, seeds = 0, bytes = 0;
  bool clustered_by_line = false;
  std::size_t point_sources = 0;
  bool error_tables = false;
  double far_field_flux_lm = NAN;
  double seconds = 0;
};

}  // namespace

void bind_build(py::module_& m) {
  py::class_<BuildResult>(m, "BuildResult", "What lumx.build made.")
      .def_readonly("bundle", &BuildResult::bundle, "the bundle folder written")
      .def_readonly("apl_counts", &BuildResult::apl_counts, "APLs per level")
      .def_readonly("map_resolutions", &BuildResult::map_resolutions, "map resolution R per level, as stored")
      .def_readonly("built_resolutions", &BuildResult::built_resolutions,
                    "map resolution R per level as built, before the fit on held-out rays")
      .def_readonly("rays", &BuildResult::rays, "rays assigned")
      .def_readonly("seeds", &BuildResult::seeds, "rays the cluster tree was built from")
      .def_readonly("bytes", &BuildResult::bytes, "bytes of the bundle (manifest and payloads)")
      .def_readonly("clustered_by_line", &BuildResult::clustered_by_line,
                    "rays were clustered by their lines' points nearest the convergence point")
      .def_readonly("point_sources", &BuildResult::point_sources,
                    "point sources found behind apertures (one masked APL each; 0: the clustered set stands)")
      .def_readonly("error_tables", &BuildResult::error_tables, "held-out error tables are stored in the bundle")
      .def_readonly("far_field_flux_lm", &BuildResult::far_field_flux_lm,
                    "flux of the attached far field, lm (NaN when none was attached)")
      .def_readonly("seconds", &BuildResult::seconds, "wall time: build, evaluation, far field and writing")
      .def("__repr__", [](const BuildResult& r) { return "<lumx.BuildResult '" + r.bundle + "'>"; });

  m.def(
      "build",
      [](const py::object& rays, const std::string& out, const std::vector<std::size_t>& levels, std::size_t seeds,
         int map_resolution, double rays_per_texel, int patches, bool evaluate, double c_step_deg,
         double gamma_step_deg, double efficacy_lm_per_w, bool converge, const std::string& cluster_by,
         double resolution_exponent, double smooth, bool point_sources, unsigned threads, const py::object& progress) {
        using LC = lumx::AplBuildOptions::LineClustering;
        if (cluster_by != "auto" && cluster_by != "start" && cluster_by != "line")
          throw py::value_error("cluster_by: 'auto', 'start' or 'line'");
        WarningCollector warnings;
        std::unique_ptr<lumx::RaySource> holder;
        std::unique_lock<std::mutex> file_lock;
        lumx::RaySource& source = rays_argument(rays, holder, file_lock, warnings);

        // The options `lumx build` gives (converters/build_command.cpp, bundle_options).
        lumx::BundleBuildOptions o;
        if (!levels.empty()) o.apl.level_counts = levels;
        o.apl.seed_rays = seeds;
        o.apl.map_resolution = map_resolution;
        o.apl.rays_per_texel = rays_per_texel;
        o.apl.place_at_convergence = converge;
        o.apl.point_sources.enabled = point_sources;
        o.apl.line_clustering = cluster_by == "start"  ? LC::start_points
                                : cluster_by == "line" ? LC::lines
                                                       : LC::automatic;
        o.apl.apl_exponent = resolution_exponent;
        o.apl.map_smoothing_rays = smooth;
        o.apl.threads = threads;
        o.evaluate = evaluate;
        o.errors.patch_resolution = patches;
        o.far_field.c_step_deg = c_step_deg;
        o.far_field.gamma_step_deg = gamma_step_deg;
        o.far_field.luminous_efficacy_lm_per_w = efficacy_lm_per_w;
        o.source_name = source.info().file;
        ProgressCallback report(progress);
        if (!report.empty()) o.progress = [&report](double f, const char* phase) { report(f, phase); };

        lumx::BundleBuildResult r;
        {
          py::gil_scoped_release release;
          r = lumx::build_bundle(source, out, o);
        }
        for (const std::string& note : r.notes) {
          lumx::Diagnostic d;
          d.severity = lumx::Severity::note;
          d.file = source.info().file;
          d.field = "build";
          d.message = note;
          warnings.sink()(d);
        }
        warnings.emit();
        if (py::isinstance<RayFile>(rays)) rays.cast<RayFile&>().emit_warnings();

        BuildResult b;
        b.bundle = out;
        b.apl_counts = r.apls;
        b.map_resolutions = r.resolution;
        b.built_resolutions = r.built_resolution;
        b.rays = r.build.rays;
        b.seeds = r.build.seeds;
        b.bytes = r.bytes;
        b.clustered_by_line = r.build.slid_to_convergence;
        b.point_sources = r.build.point_sources;
        b.error_tables = r.error_tables_stored;
        if (r.far_field_attached) b.far_field_flux_lm = r.far_field_lm;
        b.seconds = r.seconds_build + r.seconds_evaluation + r.seconds_far_field + r.seconds_write;
        return b;
      },
      py::arg("rays"), py::arg("out"), py::kw_only(), py::arg("levels") = std::vector<std::size_t>{1, 8, 64, 256, 512},
      py::arg("seeds") = 250000, py::arg("map_resolution") = 0, py::arg("rays_per_texel") = 8.0,
      py::arg("patches") = 16, py::arg("evaluate") = true, py::arg("c_step_deg") = 2.5, py::arg("gamma_step_deg") = 1.0,
      py::arg("efficacy_lm_per_w") = 0.0, py::arg("converge") = true, py::arg("cluster_by") = "auto",
      py::arg("resolution_exponent") = 0.0, py::arg("smooth") = 0.0, py::arg("point_sources") = true,
      py::arg("threads") = 0,
      py::arg("progress") = py::none(),
      "Builds a bundle from rays as `lumx build RAYS OUT` does (lumx::build_bundle; same options, same "
      "defaults, same bundle): APL levels by clustering, map resolutions and error tables from held-out rays "
      "(evaluate=False skips them), level 0's far field (c_step_deg, gamma_step_deg, degrees) attached as IES "
      "and EULUMDAT. `rays`: a path, a lumx.RayFile, a structured array or mapping of arrays (position m, "
      "direction, flux lm or W), or a callable returning an iterable of chunks (read several times). "
      "point_sources=False keeps the clustered set where every line passes through a few points (`--no-point-sources`). "
      "threads=0: every core; the bundle does not depend on it. `progress(fraction, phase)` is called from "
      "time to time, the fraction never decreasing; an exception in it (or Ctrl-C) stops the build and "
      "leaves `out` untouched. What the build leaves out (no far field for radiometric rays without an "
      "efficacy, no error tables when half the rays give other levels) comes as lumx.LumxWarning notes. The "
      "GIL is released while C++ works.");
}

}  // namespace lumx_py
