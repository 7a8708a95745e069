// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx info / check / convert on GLDF containers (read-only; lumx/io/gldf_io.h).
#include "commands.h"

#include "cli_support.h"

#include <lumx/io/atomic_file.h>
#include <lumx/io/gldf_io.h>
#include <lumx/photometry/intensity_table.h>

#include <nlohmann/json.hpp>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace lumx_cli {

bool is_gldf_path(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".gldf";
}

namespace {

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

}  // namespace

int run_gldf_info(const InfoArgs& a) {
  return guarded(a.file, [&] {
    const lumx::GldfContainer c = lumx::read_gldf(a.file);
    // Flux of each photometry file, read with lumx's own readers (errors shown, not fatal here).
    std::vector<std::pair<const lumx::GldfFile*, std::string>> photometry;
    for (const auto& f : c.files) {
      if (f.content_type.rfind("ldc/", 0) != 0) continue;
      std::string summary;
      try {
        const lumx::Photometry p = lumx::read_gldf_photometry(c, f);
        char buf[160];
        std::snprintf(buf, sizeof buf, "%s, %.1f lm, %zu x %zu angles", p.source.format.c_str(),
                      lumx::IntensityTable(p).flux_lm(), p.horizontal_deg.size(), p.vertical_deg.size());
        summary = buf;
      } catch (const std::exception& e) {
        summary = std::string("unreadable: ") + e.what();
      }
      photometry.emplace_back(&f, summary);
    }
    if (a.json) {
      nlohmann::json j = {{"file", a.file},
                          {"format", "GLDF"},
                          {"format_version", c.format_version},
                          {"manufacturer", c.manufacturer},
                          {"product", {{"name", c.product_name}, {"number", c.product_number}}},
                          {"files", nlohmann::json::array()},
                          {"photometries", nlohmann::json::array()},
                          {"emitters", nlohmann::json::array()},
                          {"geometries", nlohmann::json::array()},
                          {"variants", nlohmann::json::array()},
                          {"findings", nlohmann::json::array()}};
      for (const auto& f : c.files)
        j["files"].push_back({{"id", f.id}, {"content_type", f.content_type}, {"name", f.name}, {"entry", f.entry}});
      for (const auto& [f, s] : photometry) j["photometries"].push_back({{"file_id", f->id}, {"entry", f->entry}, {"summary", s}});
      for (const auto& e : c.emitters) j["emitters"].push_back({{"id", e.id}, {"photometry_ids", e.photometry_ids}});
      for (const auto& g : c.geometries) j["geometries"].push_back({{"id", g.id}, {"file_ids", g.file_ids}});
      for (const auto& v : c.variants)
        j["variants"].push_back({{"id", v.id}, {"name", v.name}, {"emitter_ids", v.emitter_ids}, {"geometry_id", v.geometry_id}});
      for (const auto& d : c.findings) j["findings"].push_back(diag_json(d));
      std::cout << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
      return 0;
    }
    std::printf("file:          %s\n", a.file.c_str());
    std::printf("format:        GLDF %s, %zu entries\n", c.format_version.c_str(), c.entries.size());
    std::printf("product:       %s (%s) by %s\n", c.product_name.c_str(), c.product_number.c_str(), c.manufacturer.c_str());
    for (const auto& [f, s] : photometry)
      std::printf("photometry:    %s  %s  (%s)\n", f->id.c_str(), f->entry.empty() ? f->name.c_str() : f->entry.c_str(), s.c_str());
    for (const auto& f : c.files)
      if (f.content_type.rfind("geo/", 0) == 0)
        std::printf("geometry file: %s  %s (%s)\n", f.id.c_str(), f.entry.empty() ? f.name.c_str() : f.entry.c_str(),
                    f.content_type.c_str());
    for (const auto& e : c.emitters) std::printf("emitter:       %s -> photometry %s\n", e.id.c_str(), join(e.photometry_ids).c_str());
    for (const auto& v : c.variants)
      std::printf("variant:       %s \"%s\": emitters %s%s%s\n", v.id.c_str(), v.name.c_str(), join(v.emitter_ids).c_str(),
                  v.geometry_id.empty() ? "" : ", geometry ", v.geometry_id.c_str());
    for (const auto& d : c.findings) print_diag(d);
    return 0;
  });
}

std::vector<lumx::Diagnostic> check_gldf_file(const std::string& path, const std::string& xsd) {
  std::vector<lumx::Diagnostic> out = lumx::check_gldf(path, xsd);
  if (xsd.empty()) {
    lumx::Diagnostic d;
    d.severity = lumx::Severity::note;
    d.file = path + "!/product.xml";
    d.field = "XSD";
    d.message = "not validated against the GLDF schema (give --xsd gldf.xsd)";
    out.insert(out.begin(), d);
  }
  return out;
}

int run_gldf_extract(const ConvertArgs& a) {
  return guarded(a.in, [&] {
    const lumx::GldfContainer c = lumx::read_gldf(a.in);
    std::filesystem::create_directories(a.out);
    std::size_t n = 0;
    for (const auto& f : c.files) {
      if (f.content_type.rfind("ldc/", 0) != 0 || f.entry.empty()) continue;
      const lumx::Photometry p = lumx::read_gldf_photometry(c, f);  // refuse what lumx cannot read
      // The entry's file name only: entry names were checked (no absolute paths, no "..").
      const std::filesystem::path out = std::filesystem::path(a.out) / std::filesystem::path(f.entry).filename();
      lumx::write_file_atomically(out.string(), lumx::read_gldf_entry(a.in, f.entry));
      std::printf("%s!/%s -> %s (%.2f lm)\n", a.in.c_str(), f.entry.c_str(), out.string().c_str(),
                  lumx::IntensityTable(p).flux_lm());
      ++n;
    }
    if (n == 0) std::fprintf(stderr, "%s: note: no photometry file in the container\n", a.in.c_str());
    return 0;
  });
}

}  // namespace lumx_cli
