// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The lumx subcommands applied to bundles (APL sets on disk): info, convert to and from photometry, plot.
// `check` on a bundle is lumx::check_bundle, called from commands.cpp.
#include "commands.h"

#include "bundle_plot.h"
#include "cli_support.h"

#include <lumx/apl/far_field.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/photometry_io.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace lumx_cli {

using nlohmann::json;

bool is_bundle_path(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_directory(path, ec);
}

namespace {

/// Bytes the level's maps take in memory at full resolution (float texels).
std::uint64_t level_memory_bytes(const lumx::BundleLevelInfo& l, lumx::ChannelLayout c) {
  const std::uint64_t masked = std::uint64_t(l.masked_apl_count());
  return (std::uint64_t(l.apl_count()) * lumx::channel_count(c) + masked) * 2 * std::uint64_t(l.map_resolution) *
         l.map_resolution * sizeof(float);
}

double level_flux(const lumx::BundleLevelInfo& l, lumx::ChannelLayout c) {
  double f = 0;
  for (const glm::dvec3& v : l.flux) f += lumx::luminance_of(c, v);
  return f;
}

std::size_t pick_level(const lumx::BundleManifest& m, int requested, std::size_t fallback) {
  if (requested < 0) return fallback;
  if (std::size_t(requested) >= m.levels.size())
    throw std::invalid_argument("--level " + std::to_string(requested) + ": the bundle has levels 0.." +
                                std::to_string(m.levels.size() - 1));
  return std::size_t(requested);
}

}  // namespace

int run_bundle_info(const InfoArgs& a) {
  return guarded(a.file, [&] {
    const lumx::BundleReader reader(a.file);
    const lumx::BundleManifest& m = reader.manifest();
    const char* flux_unit = lumx::flux_unit(m.quantity);
    if (a.json) {
      json levels = json::array();
      for (const auto& l : m.levels) {
        json stored = json::array();
        std::uint64_t disk = 0;
        for (const auto& p : l.maps) {
          stored.push_back({{"resolution", p.resolution}, {"bytes", p.bytes}, {"pixel_type", p.pixel_type}});
          disk += p.bytes;
        }
        json frame = json::array();
        for (int r = 0; r < 3; ++r) {
          const glm::vec3 row = l.frame.row(r);
          frame.push_back({row.x, row.y, row.z});
        }
        levels.push_back({{"apls", l.apl_count()},
                          {"map_resolution", l.map_resolution},
                          {"map_frame", frame},
                          {"stored", stored},
                          {"bytes_on_disk", disk},
                          {"bytes_in_memory", level_memory_bytes(l, m.channels)},
                          {std::string("flux_") + flux_unit, level_flux(l, m.channels)},
                          {"has_error_table", !l.error.empty()},
                          {"masked_apls", l.masked_apl_count()}});
      }
      json j = {{"bundle", a.file},
                {"format_version", m.format_version},
                {"generator", m.generator},
                {"units", {{"intensity", lumx::intensity_unit(m.quantity)}, {"flux", flux_unit}, {"length", "m"}}},
                {"channels", m.channels == lumx::ChannelLayout::rgb ? "RGB" : "Y"},
                {"bounding_sphere_m", {{"center", {m.bounds.center.x, m.bounds.center.y, m.bounds.center.z}}, {"radius", m.bounds.radius}}},
                {"provenance", m.provenance},
                {"levels", levels},
                {"total_bytes", m.total_bytes()}};
      if (!m.masks.empty()) j["beam_masks"] = m.masks.size();
      json reps = json::array();
      for (const lumx::BundleRepresentation& r : reader.representations())
        reps.push_back({{"name", r.name}, {"type", r.type}, {"description", r.description}, {"bytes_on_disk", r.bytes}});
      j["representations"] = reps;
      if (m.volume)
        j["volume"] = {{"counts", {m.volume->counts.x, m.volume->counts.y, m.volume->counts.z}},
                       {"voxel_size_m", m.volume->voxel_size},
                       {"sh_bands", m.volume->bands},
                       {"channels", m.volume->channels},
                       {"bytes", m.volume->payload.bytes}};
      std::cout << j.dump(2, ' ', false, json::error_handler_t::replace) << "\n";
      return 0;
    }
    std::printf("bundle:      %s\n", a.file.c_str());
    std::printf("format:      lumx bundle %d, written by %s\n", m.format_version, m.generator.c_str());
    std::printf("units:       intensity %s, flux %s, length m; channels %s\n", lumx::intensity_unit(m.quantity),
                flux_unit, m.channels == lumx::ChannelLayout::rgb ? "RGB (Rec. 709)" : "Y");
    std::printf("bounds:      sphere at (%g, %g, %g) m, radius %g m\n", m.bounds.center.x, m.bounds.center.y,
                m.bounds.center.z, m.bounds.radius);
    for (const auto& [k, v] : m.provenance) std::printf("provenance:  %s = %s\n", k.c_str(), v.c_str());
    bool one_frame = true;
    for (const auto& l : m.levels) one_frame = one_frame && l.frame.to_map == m.levels.front().frame.to_map;
    for (std::size_t k = 0; k < m.levels.size(); ++k) {
      const lumx::MapFrame& f = m.levels[k].frame;
      if (k > 0 && f.to_map == m.levels[k - 1].frame.to_map) continue;
      const std::string which = one_frame ? "" : " (level " + std::to_string(k) + " on)";
      if (f.is_identity()) {
        std::printf("map frame:   photometric%s\n", which.c_str());
      } else {
        const glm::vec3 mid = f.world_direction(lumx::map_frame_target());
        std::printf("map frame:   turned%s: photometric direction (%.4f, %.4f, %.4f) lies mid-wedge\n", which.c_str(),
                    mid.x, mid.y, mid.z);
      }
    }
    std::printf("levels:\n  %-5s %6s %6s  %-24s %14s %13s %13s  %s\n", "level", "APLs", "map R", "stored R (pixel type)",
                (std::string("flux (") + flux_unit + ")").c_str(), "disk bytes", "memory bytes", "error table");
    for (std::size_t k = 0; k < m.levels.size(); ++k) {
      const auto& l = m.levels[k];
      std::string stored;
      std::uint64_t disk = 0;
      for (const auto& p : l.maps) {
        stored += (stored.empty() ? "" : ",") + std::to_string(p.resolution);
        disk += p.bytes;
      }
      stored += " (" + l.maps.front().pixel_type + ")";
      std::printf("  %-5zu %6zu %6d  %-24s %14.2f %13llu %13llu  %s\n", k, l.apl_count(), l.map_resolution,
                  stored.c_str(), level_flux(l, m.channels), (unsigned long long)disk,
                  (unsigned long long)level_memory_bytes(l, m.channels), l.error.empty() ? "no" : "yes");
    }
    if (!m.masks.empty()) {
      std::size_t caps = 0;
      for (const auto& mask : m.masks) caps += mask->caps().size();
      std::printf("beam masks:  %zu (point sources behind apertures, %zu caps); masked APLs per level:", m.masks.size(), caps);
      for (const auto& l : m.levels) std::printf(" %zu", l.masked_apl_count());
      std::printf("\n");
    }
    if (!m.models.empty()) {
      std::printf("models:      (further representations, by registered type)\n");
      for (const lumx::BundleRepresentation& r : reader.representations())
        if (r.model >= 0)
          std::printf("  %-16s %-14s %12llu bytes  %s\n", r.name.c_str(), r.type.c_str(), (unsigned long long)r.bytes,
                      r.description.c_str());
    }
    if (m.volume)
      std::printf("volume:      %d x %d x %d voxels of %g m, %d SH bands, %d channel(s), %llu bytes\n",
                  m.volume->counts.x, m.volume->counts.y, m.volume->counts.z, m.volume->voxel_size, m.volume->bands,
                  m.volume->channels, (unsigned long long)m.volume->payload.bytes);
    else
      std::printf("volume:      none\n");
    std::printf("total:       %llu bytes on disk\n", (unsigned long long)m.total_bytes());
    return 0;
  });
}

int run_convert_to_bundle(const ConvertArgs& a) {
  return guarded(a.in, [&] {
    lumx::ReadOptions o;
    o.warnings = [](const lumx::Diagnostic& d) { print_diag(d); };
    const lumx::Photometry p = lumx::read_photometry(a.in, o);
    const lumx::AplSet set = lumx::apl_set_from_photometry(p, a.map_resolution);
    lumx::write_bundle(a.out, set);
    std::printf("%s -> %s (1 APL, map %d x %d, flux %.2f lm)\n", a.in.c_str(), a.out.c_str(), 2 * a.map_resolution,
                a.map_resolution, set.levels[0].flux().x);
    return 0;
  });
}

int run_convert_from_bundle(const ConvertArgs& a) {
  return guarded(a.in, [&] {
    if (!lumx::format_from_extension(a.out))
      throw std::invalid_argument(a.out + ": the output of a bundle conversion must be .ies, .ldt, .xml or .json");
    const lumx::BundleReader reader(a.in);
    const std::size_t k = pick_level(reader.manifest(), a.level, 0);
    lumx::AplSet set = reader.empty_set();
    set.levels.push_back(reader.load_level(k));
    lumx::FarFieldGrid grid;
    grid.c_step_deg = a.c_step_deg;
    grid.gamma_step_deg = a.gamma_step_deg;
    grid.luminous_efficacy_lm_per_w = a.efficacy_lm_per_w;
    const lumx::Photometry p = lumx::far_field_photometry(set, 0, grid);
    const double flux = lumx::IntensityTable(p).flux_lm();
    lumx::write_photometry(p, a.out);
    std::printf("%s level %zu (%zu APLs) -> %s (far field, flux %.2f lm; maps %.2f %s)\n", a.in.c_str(), k,
                set.levels[0].size(), a.out.c_str(), flux, lumx::luminance_of(set.channels, set.levels[0].flux()),
                lumx::flux_unit(set.quantity));
    return 0;
  });
}

int run_bundle_plot(const PlotArgs& a) {
  return guarded(a.file, [&] {
    const lumx::BundleReader reader(a.file);
    const lumx::BundleManifest& m = reader.manifest();
    const std::size_t k = pick_level(m, a.level, m.levels.size() - 1);
    const lumx::AplLevel level = reader.load_level(k);
    if (a.apl >= 0) {
      if (std::size_t(a.apl) >= level.size())
        throw std::invalid_argument("--apl " + std::to_string(a.apl) + ": level " + std::to_string(k) + " has APLs 0.." +
                                    std::to_string(level.size() - 1));
      lumx::MapImageOptions o;
      o.title = a.title.empty() ? "level " + std::to_string(k) + ", APL " + std::to_string(a.apl) : a.title;
      o.unit = lumx::intensity_unit(m.quantity);
      const lumx::SphereMap& map = level.apls[std::size_t(a.apl)].map;
      // The image shows the photometric frame's hemispheres: maps drawn in a turned frame are read at
      // each texel's direction (bilinear, for display only; the flux printed elsewhere is the stored map's).
      if (level.frame.is_identity()) {
        lumx::write_sphere_map_image(map, a.out, o);
      } else {
        lumx::SphereMap view(map.resolution(), map.channels());
        for (int y = 0; y < view.height(); ++y)
          for (int x = 0; x < view.width(); ++x) {
            const glm::vec3 w = lumx::sphere_map::uv_to_direction(
                {(float(x) + 0.5f) / float(view.width()), (float(y) + 0.5f) / float(view.height())});
            const glm::vec3 v = map.lookup(level.frame.map_direction(w));
            for (int c = 0; c < view.channels(); ++c) view.at(x, y, c) = v[c];
          }
        lumx::write_sphere_map_image(view, a.out, o);
      }
    } else {
      lumx::AplPlotOptions o;
      o.title = a.title.empty() ? "level " + std::to_string(k) + ": " + std::to_string(level.size()) + " APLs" : a.title;
      o.flux_unit = lumx::flux_unit(m.quantity);
      lumx::write_apl_positions_plot(level, m.channels, m.bounds, a.out, o);
    }
    std::printf("%s\n", a.out.c_str());
    return 0;
  });
}

}  // namespace lumx_cli
