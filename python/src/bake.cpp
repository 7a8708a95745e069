// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// python/src/bake.cpp — lumx.bake: a glTF luminaire traced into a bundle by lumx::bake::bake_luminaire
// (lumx/bake/bake.h), the call `lumx bake` makes, with its options and defaults; progress as a Python
// callable, reader warnings and bundle notes as Python warnings, the GIL released while C++ works.
#include "common.h"

#include <lumx/bake/bake.h>

#include <cmath>

namespace lumx_py {

namespace {

struct BakePassRow {
  std::uint64_t particles = 0, exits = 0;
  double seconds = 0, error = NAN, error_estimate = NAN, far_field_error = NAN;
  std::vector<double> level_error;
};

struct BakeResultPy {
  std::string bundle;
  std::uint64_t particles = 0, exits = 0;
  double emitted_lm = 0, exited_lm = 0, seconds = 0;
  std::vector<BakePassRow> passes;
  bool target_met = false;
  std::string stopped_by;
  std::vector<std::size_t> apl_counts;
  std::vector<int> map_resolutions;
  bool error_tables = false;
  double far_field_flux_lm = NAN;
  std::uint64_t bytes = 0;
  std::string luminaire_sha256;
};

}  // namespace

void bind_bake(py::module_& m) {
  py::class_<BakePassRow>(m, "BakePass", "One pass of a bake (cumulative counts).")
      .def_readonly("particles", &BakePassRow::particles, "particles traced after this pass")
      .def_readonly("exits", &BakePassRow::exits, "particles that left the luminaire, after this pass")
      .def_readonly("seconds", &BakePassRow::seconds, "elapsed since the bake began, s")
      .def_readonly("error", &BakePassRow::error,
                    "finest level's relative RMSE at the target distance, held out, upper bound (fraction; NaN "
                    "when not graded)")
      .def_readonly("error_estimate", &BakePassRow::error_estimate, "the same, the noise-removed estimate")
      .def_readonly("far_field_error", &BakePassRow::far_field_error, "the far field's, upper bound (fraction)")
      .def_readonly("level_error", &BakePassRow::level_error, "per level, upper bound (fraction)");
  py::class_<BakeResultPy>(m, "BakeResult", "What lumx.bake made.")
      .def_readonly("bundle", &BakeResultPy::bundle, "the bundle folder written")
      .def_readonly("particles", &BakeResultPy::particles, "particles traced")
      .def_readonly("exits", &BakeResultPy::exits, "particles that left the luminaire")
      .def_readonly("emitted_lm", &BakeResultPy::emitted_lm, "the emitters' flux, lm")
      .def_readonly("exited_lm", &BakeResultPy::exited_lm, "the exits' flux, lm")
      .def_readonly("seconds", &BakeResultPy::seconds, "wall time of reading, tracing and grading, s")
      .def_readonly("passes", &BakeResultPy::passes, "the passes, in order")
      .def_readonly("target_met", &BakeResultPy::target_met, "the target error was reached")
      .def_readonly("stopped_by", &BakeResultPy::stopped_by, "'target error', 'particle budget' or 'time limit'")
      .def_readonly("apl_counts", &BakeResultPy::apl_counts, "APLs per level")
      .def_readonly("map_resolutions", &BakeResultPy::map_resolutions, "map resolution R per level, as stored")
      .def_readonly("error_tables", &BakeResultPy::error_tables, "held-out error tables are stored")
      .def_readonly("far_field_flux_lm", &BakeResultPy::far_field_flux_lm, "flux of the attached far field, lm")
      .def_readonly("bytes", &BakeResultPy::bytes, "bytes of the bundle (manifest and payloads)")
      .def_readonly("luminaire_sha256", &BakeResultPy::luminaire_sha256, "SHA-256 of the luminaire file stored")
      .def("__repr__", [](const BakeResultPy& r) { return "<lumx.BakeResult '" + r.bundle + "'>"; });

  m.def(
      "bake",
      [](const std::string& luminaire, const std::string& out, std::uint64_t particles, double target_error,
         double target_distance, double time_limit_s, std::uint64_t pass_particles, std::uint64_t seed, int threads,
         const std::vector<std::size_t>& levels, int volume_voxels, int max_depth, const std::string& rays_out,
         bool evaluate, const py::object& progress) {
        WarningCollector warnings;
        lumx::bake::BakeOptions o;
        o.particles = particles;
        o.target_error = evaluate ? target_error : 0.0;
        o.target_distance = target_distance;
        o.time_limit_seconds = time_limit_s;
        o.pass_particles = pass_particles;
        o.seed = seed;
        o.threads = threads;
        o.max_depth = max_depth;
        o.volume_voxels = volume_voxels;
        o.rays_out = rays_out;
        if (!levels.empty()) o.bundle.apl.level_counts = levels;
        o.bundle.evaluate = evaluate;
        o.read.warnings = warnings.sink();
        ProgressCallback report(progress);
        if (!report.empty())
          o.progress = [&report](const lumx::bake::BakeProgress& p) { report(p.fraction, p.phase); };
        lumx::bake::BakeResult r;
        {
          py::gil_scoped_release release;
          r = lumx::bake::bake_luminaire(luminaire, out, o);
        }
        for (const std::string& note : r.bundle.notes) {
          lumx::Diagnostic d;
          d.severity = lumx::Severity::note;
          d.file = luminaire;
          d.field = "bake";
          d.message = note;
          warnings.sink()(d);
        }
        warnings.emit();

        BakeResultPy b;
        b.bundle = out;
        b.particles = r.counters.emitted;
        b.exits = r.counters.exited;
        b.emitted_lm = r.counters.emitted_lm;
        b.exited_lm = r.counters.exited_lm;
        b.seconds = r.trace_seconds;
        for (const lumx::bake::BakePass& p : r.passes)
          b.passes.push_back({p.particles, p.exits, p.seconds, p.error, p.error_estimate, p.far_field_error,
                              p.level_error});
        b.target_met = r.target_met;
        b.stopped_by = r.stopped_by;
        b.apl_counts = r.bundle.apls;
        b.map_resolutions = r.bundle.resolution;
        b.error_tables = r.bundle.error_tables_stored;
        if (r.bundle.far_field_attached) b.far_field_flux_lm = r.bundle.far_field_lm;
        b.bytes = r.bundle.bytes;
        b.luminaire_sha256 = r.input_sha256;
        return b;
      },
      py::arg("luminaire"), py::arg("out"), py::kw_only(), py::arg("particles") = 1000000,
      py::arg("target_error") = 0.05, py::arg("target_distance") = 1.0, py::arg("time_limit_s") = 0.0,
      py::arg("pass_particles") = 0, py::arg("seed") = 1, py::arg("threads") = 0,
      py::arg("levels") = std::vector<std::size_t>{1, 8, 64, 256, 512}, py::arg("volume_voxels") = 32768,
      py::arg("max_depth") = 256, py::arg("rays_out") = "", py::arg("evaluate") = true,
      py::arg("progress") = py::none(),
      "Bakes a glTF 2.0 luminaire (.glb/.gltf, Draco allowed) into a bundle as `lumx bake LUMINAIRE OUT` does "
      "(lumx::bake::bake_luminaire; same options, same defaults, same bundle): particles traced in passes "
      "until the finest level's held-out relative RMSE at `target_distance` (luminaire diameters) is known to "
      "be below `target_error` (a fraction; 0: trace the whole budget), or `particles` or `time_limit_s` "
      "(seconds; 0: none) is spent; then APL levels, error tables, the far field (IES/EULUMDAT), the radiance "
      "volume (`volume_voxels`, 0: none) and the luminaire file stored. `rays_out`: also write the exits as an "
      "IES TM-25 file. The bundle does not depend on `threads` (0: every core) nor on `pass_particles`. "
      "`progress(fraction, phase)` is called from time to time; an exception in it (or Ctrl-C) stops the bake "
      "and leaves `out` untouched. The GIL is released while C++ works.");
}

}  // namespace lumx_py
