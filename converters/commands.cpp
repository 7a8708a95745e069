// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Implementations of the lumx subcommands. Library errors (lumx::Error) are printed as located
// diagnostics on stderr and turn into exit status 1.
#include "commands.h"

#include "cli_support.h"
#include "metrics_commands.h"
#include "polar_plot.h"

#include <lumx/io/bundle_io.h>
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/metrics.h>
#include <lumx/photometry/resample.h>
#include <lumx/photometry/validate.h>
#include <lumx/version.h>

#include <nlohmann/json.hpp>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace lumx_cli {
namespace {

using nlohmann::json;

/// Reads a file, printing warnings to stderr (or collecting them into `warnings` if given).
lumx::Photometry load(const std::string& path, std::vector<lumx::Diagnostic>* warnings = nullptr) {
  lumx::ReadOptions o;
  o.warnings = [warnings](const lumx::Diagnostic& d) {
    if (warnings)
      warnings->push_back(d);
    else
      print_diag(d);
  };
  return lumx::read_photometry(path, o);
}

json spread_json(const lumx::Spread& s) {
  return {{"beam_deg", s.beam_deg},
          {"field_deg", s.field_deg},
          {"peak_cd", s.peak_cd},
          {"peak_angle_deg", s.peak_angle_deg}};
}

}  // namespace

void print_version() {
  std::printf("lumx %s (ABI namespace lumx::%s)\n", lumx::kLibraryVersion, lumx::kAbiNamespace);
  std::printf("file formats read: IES %s, %s, %s, %s, %s; %s; IES %s and %s (XML, JSON)\n",
              lumx::file_format::kIes1986, lumx::file_format::kIes1991, lumx::file_format::kIes1995,
              lumx::file_format::kIes2002, lumx::file_format::kIes2019, lumx::file_format::kEulumdat,
              lumx::file_format::kTm33_18, lumx::file_format::kTm33_23);
  std::printf("file formats written: IES %s (default), %s; %s; IES %s (default), %s (XML, JSON)\n",
              lumx::file_format::kIes2019, lumx::file_format::kIes2002, lumx::file_format::kEulumdat,
              lumx::file_format::kTm33_23, lumx::file_format::kTm33_18);
}

int run_info(const InfoArgs& a) {
  if (is_bundle_path(a.file)) return run_bundle_info(a);
  if (is_gldf_path(a.file)) return run_gldf_info(a);
  if (is_luminaire_path(a.file)) return run_luminaire_info(a);
  if (is_rayset_path(a.file)) return run_rayset_info(a);
  return guarded(a.file, [&] {
    std::vector<lumx::Diagnostic> warnings;
    const lumx::Photometry p = load(a.file, a.json ? &warnings : nullptr);
    const lumx::PhotometricSummary s = lumx::summarize(p);
    const auto& h = p.horizontal_deg;
    const auto& v = p.vertical_deg;
    if (a.json) {
      json lamps = json::array();
      for (const auto& l : p.lamp_sets)
        lamps.push_back({{"count", l.count},
                         {"type", l.type},
                         {"flux_lm", l.flux_lm},
                         {"watts_W", l.watts},
                         {"color", l.color},
                         {"cri", l.cri}});
      json j = {
          {"file", a.file},
          {"format", p.source.format},
          {"version", p.source.version},
          {"photometric_type", lumx::to_string(p.type)},
          {"symmetry", lumx::to_string(p.symmetry)},
          {"horizontal_angles", {{"count", h.size()}, {"first_deg", h.front()}, {"last_deg", h.back()}}},
          {"vertical_angles", {{"count", v.size()}, {"first_deg", v.front()}, {"last_deg", v.back()}}},
          {"absolute_photometry", p.absolute},
          {"flux_lm", s.flux_lm},
          {"rated_lamp_flux_lm", s.rated_lamp_flux_lm},
          {"max_cd", s.max_cd},
          {"max_direction_deg", {s.max_horizontal_deg, s.max_vertical_deg}},
          {"c0_c180", spread_json(s.c0_c180)},
          {"c90_c270", spread_json(s.c90_c270)},
          {"downward_flux_fraction", s.downward_fraction},
          {"light_output_ratio", s.light_output_ratio ? json(*s.light_output_ratio) : json(nullptr)},
          {"ballast_factor", p.ballast_factor},
          {"input_watts_W", p.input_watts},
          {"efficacy_lm_per_W", s.efficacy_lm_per_w},
          {"opening_m",
           {{"width", p.opening.width_m},
            {"length", p.opening.length_m},
            {"height", p.opening.height_m},
            {"shape", lumx::to_string(p.opening.shape())}}},
          {"lamps", lamps},
          {"tilt", p.tilt ? json{{"source", p.tilt->source}, {"pairs", p.tilt->angles_deg.size()}} : json(nullptr)},
          {"metrics", metrics_json(p)},
          {"warnings", json::array()}};
      for (const auto& w : warnings) j["warnings"].push_back(diag_json(w));
      std::cout << j.dump(2, ' ', false, json::error_handler_t::replace) << "\n";
      return 0;
    }
    std::printf("file:          %s\n", a.file.c_str());
    std::printf("format:        %s %s\n", p.source.format.c_str(), p.source.version.c_str());
    std::printf("type:          %s, symmetry %s\n", lumx::to_string(p.type), lumx::to_string(p.symmetry));
    std::printf("grid:          %zu horizontal (%g..%g deg) x %zu vertical (%g..%g deg) stored\n", h.size(), h.front(),
                h.back(), v.size(), v.front(), v.back());
    if (p.absolute) {
      std::printf("flux:          %.1f lm (absolute photometry)\n", s.flux_lm);
    } else {
      std::printf("flux:          %.1f lm; rated lamp flux %.1f lm", s.flux_lm, s.rated_lamp_flux_lm);
      if (s.light_output_ratio) std::printf(", light output ratio %.1f %%", 100 * *s.light_output_ratio);
      std::printf("\n");
    }
    std::printf("max intensity: %.1f cd at (%g, %g) deg\n", s.max_cd, s.max_horizontal_deg, s.max_vertical_deg);
    std::printf("beam (50 %%):   %.1f deg in C0-C180, %.1f deg in C90-C270\n", s.c0_c180.beam_deg, s.c90_c270.beam_deg);
    std::printf("field (10 %%):  %.1f deg in C0-C180, %.1f deg in C90-C270\n", s.c0_c180.field_deg,
                s.c90_c270.field_deg);
    std::printf("downward flux: %.1f %%\n", 100 * s.downward_fraction);
    std::printf("opening:       %g x %g x %g m (width x length x height), %s\n", p.opening.width_m, p.opening.length_m,
                p.opening.height_m, lumx::to_string(p.opening.shape()));
    for (const auto& l : p.lamp_sets)
      std::printf("lamps:         %d x %s%s%.1f lm, %.1f W\n", l.count, l.type.c_str(), l.type.empty() ? "" : ", ",
                  l.flux_lm, l.watts);
    std::printf("ballast:       factor %g; input %.1f W", p.ballast_factor, p.input_watts);
    if (s.efficacy_lm_per_w > 0) std::printf("; efficacy %.1f lm/W", s.efficacy_lm_per_w);
    std::printf("\n");
    if (p.tilt)
      std::printf("tilt:          %s, %zu angles, lamp geometry %d\n", p.tilt->source.c_str(),
                  p.tilt->angles_deg.size(), p.tilt->lamp_geometry);
    print_metrics_summary(p);
    return 0;
  });
}

int run_check(const CheckArgs& a) {
  int status = 0;
  json all = json::array();
  for (const auto& file : a.files) {
    std::vector<lumx::Diagnostic> findings;
    try {
      if (is_bundle_path(file)) {
        findings = lumx::check_bundle(file);
      } else if (is_gldf_path(file)) {
        findings = check_gldf_file(file, a.xsd);
      } else if (is_luminaire_path(file)) {
        findings = check_luminaire_file(file);
      } else if (is_rayset_path(file)) {
        findings = check_rayset(file);
      } else {
        const lumx::Photometry p = load(file, &findings);
        for (auto& d : lumx::validate(p)) findings.push_back(d);
      }
    } catch (const lumx::Error& e) {
      findings.push_back(e.diagnostic());
    } catch (const std::exception& e) {  // e.g. out of memory: report it as a finding of this file
      findings.push_back(lumx::Diagnostic{lumx::Severity::error, file, 0, -1, "file", e.what()});
    }
    bool bad = false;
    for (auto& d : findings) {
      if (d.file.empty()) d.file = file;
      bad = bad || d.severity == lumx::Severity::error || (a.strict && d.severity == lumx::Severity::warning);
    }
    if (bad) status = 1;
    if (a.json) {
      json j = {{"file", file}, {"ok", !bad}, {"findings", json::array()}};
      for (const auto& d : findings) j["findings"].push_back(diag_json(d));
      all.push_back(j);
    } else if (findings.empty()) {
      std::printf("%s: OK\n", file.c_str());
    } else {
      for (const auto& d : findings) std::printf("%s\n", d.str().c_str());
      if (!bad) std::printf("%s: OK (with %zu warning(s))\n", file.c_str(), findings.size());
    }
  }
  if (a.json) std::cout << all.dump(2, ' ', false, json::error_handler_t::replace) << "\n";
  return status;
}

/// Lower-case extension of a path ("" if none).
std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

int run_convert(const ConvertArgs& a) {
  if (is_bundle_path(a.in)) return run_convert_from_bundle(a);
  if (is_gldf_path(a.in)) return run_gldf_extract(a);
  // The output's extension names its format; a bundle folder is written only for .lumx or --bundle.
  if (a.bundle || lower_extension(a.out) == ".lumx") return run_convert_to_bundle(a);
  if (!lumx::format_from_extension(a.out)) {
    lumx::Diagnostic d;
    d.file = a.out;
    d.field = "output format";
    d.message = lower_extension(a.out) == ".gldf"
                    ? "lumx reads GLDF containers but does not write them yet"
                    : "unknown extension '" + lower_extension(a.out) +
                          "': use .ies, .ldt, .xml or .json (TM-33), .lumx (bundle), or --bundle for a bundle folder";
    print_diag(d);
    return 1;
  }
  return guarded(a.in, [&] {
    lumx::Photometry p = load(a.in);
    if (a.apply_tilt) {
      if (!p.tilt)
        std::fprintf(stderr, "%s: warning: TILT: the file has no TILT data; --apply-tilt ignored\n", a.in.c_str());
      p = lumx::apply_tilt(p, a.tilt_deg);
      p.tilt.reset();
    }
    const bool to_ldt = lumx::format_from_extension(a.out) == lumx::PhotometryFormat::ldt;
    if (to_ldt && p.tilt)
      std::fprintf(stderr,
                   "%s: warning: TILT: EULUMDAT cannot store TILT multipliers; they are dropped (use "
                   "--apply-tilt DEG to fold them in at an installed tilt)\n",
                   a.in.c_str());
    if (to_ldt && p.type != lumx::PhotometricType::C) {
      std::fprintf(stderr, "%s: note: Type %s resampled to Type C on a 1 x 1 degree grid for EULUMDAT\n", a.in.c_str(),
                   lumx::to_string(p.type));
      p = lumx::to_type_c(p, 1.0, 1.0);
    }
    if (a.rotate_c_deg != 0) p = lumx::rotate_c_planes(p, a.rotate_c_deg);
    lumx::WriteOptions w;
    w.ies.version = a.ies_version == "2002" ? lumx::IesVersion::lm63_2002 : lumx::IesVersion::lm63_2019;
    w.ies.significant_digits = a.digits;
    w.ies.expand_c90_c270 = !a.keep_c90_c270;
    w.ldt.significant_digits = a.digits;
    w.tm33.version = a.tm33_version == "18" ? lumx::Tm33Version::tm33_18 : lumx::Tm33Version::tm33_23;
    const double f0 = lumx::IntensityTable(p).flux_lm();  // before writing: a failure must not replace the output
    lumx::write_photometry(p, a.out, w);
    std::printf("%s -> %s (flux %.2f lm)\n", a.in.c_str(), a.out.c_str(), f0);
    return 0;
  });
}

int run_plot(const PlotArgs& a) {
  if (is_bundle_path(a.file)) {
    if (a.kind != "polar") {
      std::fprintf(stderr, "%s: error: kind: --kind %s is for photometry files; bundles plot their APLs\n",
                   a.file.c_str(), a.kind.c_str());
      return 1;
    }
    return run_bundle_plot(a);
  }
  return guarded(a.file, [&] {
    const lumx::Photometry p = load(a.file);
    if (a.kind != "polar") return run_metric_plot(a, p);
    lumx::PolarPlotOptions o;
    o.title = a.title;  // empty: the diagram's own default (luminaire name, else file name)
    o.size_px = a.size_px;
    o.force_cd = a.force_cd;
    lumx::write_polar_plot(p, a.out, o);
    std::printf("%s\n", a.out.c_str());
    return 0;
  });
}

}  // namespace lumx_cli
