// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The lumx subcommands applied to raysets (TM-25, LightTools, Zemax, plain text): info and check. Rays are
// streamed (lumx::summarize_rays), so a file of any size is summarised in a few MiB.
#include "commands.h"

#include "cli_support.h"

#include <lumx/io/photometry_io.h>
#include <lumx/io/rayset_io.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace lumx_cli {

using nlohmann::json;

bool is_rayset_path(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return false;
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".ies" || ext == ".ldt") return false;
  if (ext == ".tm25ray" || ext == ".ray") return true;  // the reader reports what is wrong with it
  return lumx::detect_rayset_format(path).has_value();
}

namespace {

struct Loaded {
  std::unique_ptr<lumx::RaySource> source;
  lumx::RaysetSummary summary;
  float wl_min = NAN, wl_max = NAN;  ///< per-ray wavelengths, when the rays carry them
};

Loaded load_rays(const std::string& path, std::vector<lumx::Diagnostic>& warnings) {
  lumx::RaysetReadOptions o;
  o.warnings = [&warnings](const lumx::Diagnostic& d) { warnings.push_back(d); };
  Loaded l;
  l.source = lumx::open_rayset(path, o);
  l.summary = lumx::summarize_rays(*l.source, o.chunk_rays);
  // Per-ray wavelength range: one more pass, only when the rays carry wavelengths.
  lumx::RayChunk c;
  l.source->rewind();
  if (l.source->next(c, 1) && !c.wavelength_nm.empty()) {
    float lo = INFINITY, hi = -INFINITY;
    l.source->rewind();
    while (l.source->next(c, o.chunk_rays))
      for (float w : c.wavelength_nm) lo = std::min(lo, w), hi = std::max(hi, w);
    l.wl_min = lo, l.wl_max = hi;
  }
  return l;
}

json nullable(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}

std::string spectrum_text(const lumx::RaysetInfo& info, const Loaded& l) {
  char buf[160];
  if (!std::isnan(l.wl_min)) {
    std::snprintf(buf, sizeof buf, "wavelength per ray, %g..%g nm", l.wl_min, l.wl_max);
    return buf;
  }
  std::string s;
  if (info.wavelength_nm) {
    std::snprintf(buf, sizeof buf, "single wavelength %g nm", *info.wavelength_nm);
    s = buf;
  }
  for (std::size_t i = 0; i < info.spectra.size(); ++i) {
    const auto& t = info.spectra[i];
    const auto [lo, hi] = std::minmax_element(t.wavelength_nm.begin(), t.wavelength_nm.end());
    std::snprintf(buf, sizeof buf, "%sspectral table %zu: %zu points, %g..%g nm", s.empty() ? "" : "; ", i + 1,
                  t.wavelength_nm.size(), *lo, *hi);
    s += buf;
  }
  return s.empty() ? "none stated" : s;
}

}  // namespace

int run_rayset_info(const InfoArgs& a) {
  return guarded(a.file, [&] {
    std::vector<lumx::Diagnostic> warnings;
    const Loaded l = load_rays(a.file, warnings);
    const lumx::RaysetInfo& info = l.source->info();
    const lumx::RaysetSummary& s = l.summary;
    const char* unit = lumx::flux_unit(info.quantity);
    if (a.json) {
      json spectra = json::array();
      for (const auto& t : info.spectra) {
        const auto [lo, hi] = std::minmax_element(t.wavelength_nm.begin(), t.wavelength_nm.end());
        spectra.push_back({{"points", t.wavelength_nm.size()}, {"min_nm", *lo}, {"max_nm", *hi}});
      }
      json values = json::object();
      for (const auto& [k, v] : info.values) values[k] = nullable(v);
      const bool any = s.rays > 0;
      json j = {{"file", a.file},
                {"format", info.format},
                {"version", info.version},
                {"rays", s.rays},
                {"quantity", info.quantity == lumx::PhotometricQuantity::photometric ? "photometric" : "radiometric"},
                {"flux_unit", unit},
                {"header_flux", nullable(info.header_flux)},
                {"flux_sum", s.flux_sum},
                {"zero_flux_rays", s.zero_flux_rays},
                {"source_length_unit", info.source_length_unit},
                {"bounding_box_m",
                 any ? json{{"min", {s.lo.x, s.lo.y, s.lo.z}}, {"max", {s.hi.x, s.hi.y, s.hi.z}}} : json(nullptr)},
                {"bounding_sphere_m", any ? json{{"center", {s.bounds.center.x, s.bounds.center.y, s.bounds.center.z}},
                                                 {"radius", s.bounds.radius}}
                                          : json(nullptr)},
                {"spectrum",
                 {{"single_wavelength_nm", info.wavelength_nm ? json(*info.wavelength_nm) : json(nullptr)},
                  {"per_ray_wavelength_nm", std::isnan(l.wl_min) ? json(nullptr) : json{l.wl_min, l.wl_max}},
                  {"tables", spectra}}},
                {"text", info.text},
                {"values", values},
                {"warnings", json::array()}};
      for (const auto& w : warnings) j["warnings"].push_back(diag_json(w));
      std::cout << j.dump(2, ' ', false, json::error_handler_t::replace) << "\n";
      return 0;
    }
    for (const auto& w : warnings) print_diag(w);
    std::printf("file:          %s\n", a.file.c_str());
    std::printf("format:        %s%s%s\n", info.format.c_str(), info.version.empty() ? "" : " ", info.version.c_str());
    std::printf("rays:          %llu\n", static_cast<unsigned long long>(s.rays));
    std::printf("flux per ray:  %s (%s); %llu rays carry none\n",
                info.quantity == lumx::PhotometricQuantity::photometric ? "luminous" : "radiant", unit,
                static_cast<unsigned long long>(s.zero_flux_rays));
    if (std::isnan(info.header_flux))
      std::printf("flux:          rays sum to %.6g %s; the header states no total\n", s.flux_sum, unit);
    else
      std::printf("flux:          rays sum to %.6g %s; the header states %.6g %s\n", s.flux_sum, unit, info.header_flux,
                  unit);
    std::printf("length unit:   %s in the file (positions shown in m)\n", info.source_length_unit.c_str());
    if (s.rays > 0) {
      std::printf("bounding box:  x %.6g..%.6g, y %.6g..%.6g, z %.6g..%.6g m\n", s.lo.x, s.hi.x, s.lo.y, s.hi.y, s.lo.z,
                  s.hi.z);
      std::printf("bounding sphere: centre (%.6g, %.6g, %.6g) m, radius %.6g m\n", s.bounds.center.x, s.bounds.center.y,
                  s.bounds.center.z, s.bounds.radius);
    }
    std::printf("spectrum:      %s\n", spectrum_text(info, l).c_str());
    for (const auto& [k, v] : info.text) {
      std::string shown = v.size() > 200 ? v.substr(0, 200) + "..." : v;
      for (char& c : shown)
        if (c == '\n' || c == '\r') c = ' ';
      std::printf("text:          %s: %s\n", k.c_str(), shown.c_str());
    }
    for (const auto& [k, v] : info.values) std::printf("header value:  %s = %.9g\n", k.c_str(), v);
    return 0;
  });
}

std::vector<lumx::Diagnostic> check_rayset(const std::string& path) {
  std::vector<lumx::Diagnostic> findings;
  try {
    lumx::RaysetReadOptions o;
    o.warnings = [&findings](const lumx::Diagnostic& d) { findings.push_back(d); };
    auto src = lumx::open_rayset(path, o);
    lumx::RayChunk c;
    while (src->next(c, o.chunk_rays)) {
    }
  } catch (const lumx::Error& e) {
    findings.push_back(e.diagnostic());
  }
  return findings;
}

}  // namespace lumx_cli
