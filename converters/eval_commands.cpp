// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/eval_commands.cpp — `lumx eval` (see eval_commands.h).
//
//   lumx eval BUNDLE --points P.txt [--level K | --lod [--seed S]] [-o OUT]
//       One irradiance per point (lx or W/m², the bundle's unit; RGB bundles: Rec. 709 luminance), at full
//       precision (%.9g), in the order of the points. The file holds one point per line, "x y z nx ny nz"
//       (m; the normal is normalised; commas count as spaces); '#' starts a comment; blank lines are
//       skipped. A bad line is an error located at its line. --lod picks the level per point with
//       choose_level_by_distance (apl/lod.h, eq. 6.2), drawing its random number from a fixed-seed hash
//       of the line number, so a point's result depends only on its line, the seed and the bundle.
//   lumx eval BUNDLE --rays RAYS [--patches R] [--subsamples k|0] [--distances D,...] [--plots DIR]
//                    [--plot-format png|svg] [--json] [--store-errors]
//       The error of every level and of the far field against the rays on measurement spheres
//       (lumx/apl/error.h): relative RMSE (eq. 5.1) per relative distance with the rays' noise floor,
//       ns per irradiance evaluation and bytes per level; then the Hellinger and l² distances. --plots
//       writes error_vs_distance, error_vs_time and error_vs_bytes. --store-errors writes the relative
//       RMSE tables into the bundle (rewritten atomically, keeping its volume, attachments and stored
//       resolutions), where the LOD error-target rule reads them.
#include "eval_commands.h"

#include "cli_support.h"
#include "build_command.h"
#include "eval_plot.h"

#include <lumx/apl/error.h>
#include <lumx/apl/map_fit.h>
#include <lumx/apl/evaluation.h>
#include <lumx/apl/lod.h>
#include <lumx/io/atomic_file.h>
#include <lumx/io/bundle_io.h>
#include <lumx/io/rayset_io.h>
#include <lumx/volume/radiance_volume.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <thread>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

namespace lumx_cli {

namespace {

using nlohmann::json;

// ---------------------------------------------------------------------------------------------------------
// --points

constexpr std::size_t kMaxPointLine = 4096;

struct Point {
  glm::dvec3 x, n;
  int line;
};

/// Parses one number token strictly (the whole token, finite).
double parse_number(const std::string& token, const std::string& file, int line, const char* field) {
  const char* begin = token.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (end == begin || *end != '\0') lumx::throw_at_line(file, line, field, "'" + token + "' is not a number");
  if (!std::isfinite(v)) lumx::throw_at_line(file, line, field, "'" + token + "' is not a finite number");
  return v;
}

/// Every point of the file, in order; a bad line throws a located lumx::Error.
std::vector<Point> read_points(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) lumx::throw_at_field(path, "points", "cannot open the file");
  std::vector<Point> points;
  std::string text;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    if (text.size() > kMaxPointLine)
      lumx::throw_at_line(path, line, "points", "line longer than " + std::to_string(kMaxPointLine) + " bytes");
    const std::size_t hash = text.find('#');
    if (hash != std::string::npos) text.resize(hash);
    for (char& c : text)
      if (c == ',' || c == '\t' || c == '\r') c = ' ';
    std::vector<std::string> tokens;
    std::size_t i = 0;
    while (i < text.size()) {
      while (i < text.size() && text[i] == ' ') ++i;
      const std::size_t j = text.find(' ', i);
      const std::size_t e = j == std::string::npos ? text.size() : j;
      if (e > i) tokens.push_back(text.substr(i, e - i));
      i = e;
    }
    if (tokens.empty()) continue;
    if (tokens.size() != 6)
      lumx::throw_at_line(path, line, "point",
                          "expected 6 numbers 'x y z nx ny nz', found " + std::to_string(tokens.size()) + " fields");
    Point p;
    p.line = line;
    for (int k = 0; k < 3; ++k) p.x[k] = parse_number(tokens[std::size_t(k)], path, line, "position");
    for (int k = 0; k < 3; ++k) p.n[k] = parse_number(tokens[std::size_t(3 + k)], path, line, "normal");
    const double len = glm::length(p.n);
    if (!(len > 0) || !std::isfinite(len)) lumx::throw_at_line(path, line, "normal", "the normal has zero length");
    p.n /= len;
    if (std::abs(p.x.x) > 1e15 || std::abs(p.x.y) > 1e15 || std::abs(p.x.z) > 1e15)
      lumx::throw_at_line(path, line, "position", "coordinates beyond 1e15 m");
    points.push_back(p);
  }
  if (in.bad()) lumx::throw_at_field(path, "points", "read error");
  return points;
}

/// splitmix64 (Steele, Lea & Flood 2014): a fixed, portable hash from (seed, line) to u ∈ [0, 1).
double line_random(unsigned long long seed, int line) {
  std::uint64_t z = std::uint64_t(seed) * 0x9e3779b97f4a7c15ull + std::uint64_t(line);
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return double(z >> 11) * (1.0 / 9007199254740992.0);
}

int run_points(const EvalArgs& a) {
  const lumx::BundleReader reader(a.bundle);
  const lumx::BundleManifest& m = reader.manifest();
  if (m.levels.empty()) lumx::throw_at_field(a.bundle, "levels", "the bundle has no level");
  if (a.level >= 0 && std::size_t(a.level) >= m.levels.size())
    throw std::invalid_argument("--level " + std::to_string(a.level) + ": the bundle has levels 0.." +
                                std::to_string(m.levels.size() - 1));
  const std::vector<Point> points = read_points(a.points);
  // One level: load only it (index 0 of the loaded set). --lod: every level.
  const std::size_t fixed = a.level >= 0 ? std::size_t(a.level) : m.levels.size() - 1;
  const lumx::AplSet set = a.lod ? reader.load() : reader.load({fixed});
  std::string out;
  out.reserve(points.size() * 16);
  char buf[64];
  for (const Point& p : points) {
    const std::size_t k = a.lod ? lumx::choose_level_by_distance(set, p.x, line_random(a.seed, p.line)) : 0;
    const lumx::IrradianceResult r = lumx::irradiance(set, k, glm::vec3(p.x), glm::vec3(p.n));
    std::snprintf(buf, sizeof buf, "%.9g\n", lumx::luminance_of(set.channels, r.irradiance));
    out += buf;
  }
  if (a.out.empty()) {
    std::fwrite(out.data(), 1, out.size(), stdout);
  } else {
    lumx::write_file_atomically(a.out, out);
  }
  std::fprintf(stderr, "%s: %zu points, %s, irradiance in %s%s\n", a.points.c_str(), points.size(),
               a.lod ? "level by distance (eq. 6.2)"
                     : ("level " + std::to_string(fixed) + " (" + std::to_string(m.levels[fixed].apl_count()) +
                        " APLs)").c_str(),
               lumx::irradiance_unit(m.quantity),
               m.channels == lumx::ChannelLayout::rgb ? " (Rec. 709 luminance)" : "");
  return 0;
}

// ---------------------------------------------------------------------------------------------------------
// --rays

std::string format_cell(double v, const char* fmt, int width) {
  char buf[64];
  if (!std::isfinite(v))
    std::snprintf(buf, sizeof buf, "%*s", width, "-");
  else
    std::snprintf(buf, sizeof buf, fmt, width, v);
  return buf;
}

std::string level_name(const lumx::LevelErrors& row) {
  return row.level < 0 ? "far field" : std::to_string(row.level);
}

std::string apl_label(const lumx::LevelErrors& row) {
  if (row.level < 0) return "far field";
  return std::to_string(row.apls) + (row.apls == 1 ? " APL" : " APLs");
}

/// The metric of one row at sphere s: 0 relative RMSE with the noise removed, 1 raw relative RMSE,
/// 2 Hellinger, 3 l².
double metric(const lumx::LevelErrors& row, std::size_t s, int which) {
  const lumx::IrradianceErrors& e = row.errors[s];
  return which == 0 ? e.relative_rmse_noise_removed : which == 1 ? e.relative_rmse : which == 2 ? e.hellinger : e.l2;
}

std::string table_text(const lumx::AplErrorReport& r, const std::string& bundle, const std::string& rays,
                       lumx::PhotometricQuantity q) {
  const lumx::ReferenceIrradiance& ref = r.reference;
  const lumx::MeasurementSpheres& ms = ref.spheres;
  std::vector<const lumx::LevelErrors*> rows;
  for (const auto& l : r.levels) rows.push_back(&l);
  if (!r.far_field.errors.empty()) rows.push_back(&r.far_field);
  std::string s;
  char buf[512];
  std::snprintf(buf, sizeof buf, "%s against %s\n", bundle.c_str(), rays.c_str());
  s += buf;
  std::snprintf(buf, sizeof buf,
                "  %llu rays, %.6g %s; spheres around (%.4g, %.4g, %.4g) m, D = %.4g m; %zu patches per sphere "
                "(R %d)\n",
                static_cast<unsigned long long>(ref.rays), ref.flux, lumx::flux_unit(q), ms.centre().x, ms.centre().y,
                ms.centre().z, ms.diameter(), ms.patch_count(), ms.patch_resolution());
  s += buf;
  bool averaged = false;
  for (const lumx::LevelErrors* row : rows) averaged = averaged || row->subsamples > 1;
  const std::string where = averaged ? "irradiance averaged over k x k points per patch (hides texel noise)"
                                     : "irradiance at a point (the patch centre)";
  // Which spheres' reference is at the patch centres (lumx::checked_centred_reference) and which keeps
  // the patch means: each row's errors are against that.
  std::string centred, means;
  for (const lumx::SphereReference& sr : ref.sphere) {
    char d[32];
    std::snprintf(d, sizeof d, "%s%.4g", (sr.centred ? centred : means).empty() ? "" : ", ", sr.relative_distance);
    (sr.centred ? centred : means) += d;
  }
  std::string against;
  if (!centred.empty())
    against += "against the rays' irradiance at the patch centres (patch means moved by a pilot's shape) at d = " +
               centred + ";\n";
  if (!means.empty())
    against += "against the rays' mean irradiance over each patch at d = " + means +
               (centred.empty() ? ";\n" : " (a pilot's shape there failed the rays' own);\n");
  const std::string t0 = "relative RMSE (eq. 5.1) of " + where + ", % of the mean, at relative distance d,\n" +
                         against +
                         "rays not used to build the levels, their noise removed ('<': below what these rays resolve)";
  const std::string t1 = "the same with the rays' noise left in, and the noise floor (what an exact model would show)";
  const char* titles[4] = {t0.c_str(), t1.c_str(), "Hellinger distance of the normalised patch distributions, at d",
                           "l2 distance of the normalised patch distributions, at d"};
  for (int which = 0; which < 4; ++which) {
    s += "\n";
    s += titles[which];
    s += "\n";
    std::snprintf(buf, sizeof buf, "%-11s %6s %5s %3s", "level", "APLs", "R", "k");
    s += buf;
    for (double d : ms.relative_distances()) {
      std::snprintf(buf, sizeof buf, " %8.4g", d);
      s += buf;
    }
    if (which == 0) s += "   ns/point        bytes";
    s += "\n";
    const double scale = which <= 1 ? 100.0 : 1.0;
    const char* fmt = which <= 1 ? " %*.2f" : " %*.4f";
    for (const lumx::LevelErrors* row : rows) {
      std::snprintf(buf, sizeof buf, "%-11s %6zu %5d %3d", level_name(*row).c_str(), row->apls, row->map_resolution,
                    row->subsamples);
      s += buf;
      for (std::size_t i = 0; i < row->errors.size(); ++i) {
        const lumx::IrradianceErrors& e = row->errors[i];
        if (which == 0 && std::isfinite(e.relative_rmse_noise_removed) && !e.resolved) {
          char cell[32];
          std::snprintf(cell, sizeof cell, "<%.2f", 100 * e.noise_removed_upper);
          std::snprintf(buf, sizeof buf, " %8s", cell);
          s += buf;
        } else {
          s += format_cell(scale * metric(*row, i, which), fmt, 8);
        }
      }
      if (which == 0) {
        s += format_cell(row->ns_per_evaluation, " %*.0f", 10);
        std::snprintf(buf, sizeof buf, " %12zu", row->bytes);
        s += buf;
      }
      s += "\n";
    }
    if (which == 1) {
      std::snprintf(buf, sizeof buf, "%-11s %6s %5s %3s", "noise floor", "", "", "");
      s += buf;
      for (const auto& sr : ref.sphere) s += format_cell(100.0 * sr.noise_floor, fmt, 8);
      s += "\n";
      // Beam masks' borders the rays cannot place (lumx::border_allowance): in the '<' bounds, not in ε̂.
      if (std::any_of(ref.sphere.begin(), ref.sphere.end(), [](const auto& sr) { return !sr.border.empty(); })) {
        std::snprintf(buf, sizeof buf, "%-11s %6s %5s %3s", "border", "", "", "");
        s += buf;
        for (const auto& sr : ref.sphere) s += format_cell(100.0 * sr.border_share, fmt, 8);
        s += "\n";
      }
    }
  }
  // Rays that did not start inside a sphere.
  for (const auto& sr : ref.sphere)
    if (sr.started_outside > 0) {
      std::snprintf(buf, sizeof buf, "note: d = %g: %llu rays start outside the sphere, %llu of them never leave it\n",
                    sr.relative_distance, static_cast<unsigned long long>(sr.started_outside),
                    static_cast<unsigned long long>(sr.missed));
      s += "\n";
      s += buf;
    }
  if (std::any_of(ref.sphere.begin(), ref.sphere.end(), [](const auto& sr) { return !sr.border.empty(); }))
    s += "note: border: what a patch centre outside every beam mask may still receive, the rays being too few to "
         "place the border there (% of the mean, as an RMS); it widens the '<' bounds, not the estimates\n";
  if (ref.zero_flux_rays > 0) {
    std::snprintf(buf, sizeof buf, "note: %llu rays carry no flux\n", static_cast<unsigned long long>(ref.zero_flux_rays));
    s += buf;
  }
  return s;
}

json row_json(const lumx::LevelErrors& row) {
  json rmse = json::array(), removed = json::array(), upper = json::array(), resolved = json::array(),
       h = json::array(), l2 = json::array();
  for (const auto& e : row.errors) {
    rmse.push_back(e.relative_rmse);
    removed.push_back(e.relative_rmse_noise_removed);
    upper.push_back(e.noise_removed_upper);
    resolved.push_back(e.resolved);
    h.push_back(e.hellinger);
    l2.push_back(e.l2);
  }
  json j = {{"apls", row.apls},
            {"map_resolution", row.map_resolution},
            {"subsamples", row.subsamples},
            {"bytes", row.bytes},
            {"ns_per_evaluation", row.ns_per_evaluation},
            {"relative_rmse", rmse},
            {"relative_rmse_noise_removed", removed},
            {"noise_removed_upper", upper},
            {"resolved", resolved},
            {"hellinger", h},
            {"l2", l2},
            {"clamped", row.clamped}};
  if (row.level >= 0) j["level"] = row.level;
  return j;
}

json report_json(const lumx::AplErrorReport& r, const EvalArgs& a, lumx::PhotometricQuantity q) {
  const lumx::ReferenceIrradiance& ref = r.reference;
  json spheres = json::array();
  for (const auto& sr : ref.sphere)
    spheres.push_back({{"relative_distance", sr.relative_distance},
                       {"radius_m", sr.radius},
                       {"noise_floor", sr.noise_floor},
                       {"split_noise_floor", sr.split_noise_floor},
                       {"reference", sr.centred ? "patch centres" : "patch means"},
                       {"centring_shift", std::isfinite(sr.centring_shift) ? json(sr.centring_shift) : json()},
                       {"pilot_shape_error", std::isfinite(sr.pilot_shape_error) ? json(sr.pilot_shape_error) : json()},
                       {"border_allowance", sr.border.empty() ? json() : json(sr.border_share)},
                       {"rays", sr.rays},
                       {"started_outside", sr.started_outside},
                       {"missed", sr.missed}});
  json levels = json::array();
  for (const auto& l : r.levels) levels.push_back(row_json(l));
  json j = {{"bundle", a.bundle},
            {"rays", a.rays},
            {"ray_count", ref.rays},
            {"zero_flux_rays", ref.zero_flux_rays},
            {std::string("flux_") + lumx::flux_unit(q), ref.flux},
            {"irradiance_unit", lumx::irradiance_unit(q)},
            {"centre_m", {ref.spheres.centre().x, ref.spheres.centre().y, ref.spheres.centre().z}},
            {"diameter_m", ref.spheres.diameter()},
            {"patch_resolution", ref.spheres.patch_resolution()},
            {"patches", ref.spheres.patch_count()},
            {"spheres", spheres},
            {"levels", levels}};
  if (!r.far_field.errors.empty()) j["far_field"] = row_json(r.far_field);
  return j;
}

/// What the plots show: the noise-removed point error, its upper bound where the rays cannot resolve it.
double plotted(const lumx::IrradianceErrors& e) {
  if (!std::isfinite(e.relative_rmse_noise_removed)) return e.relative_rmse;
  return e.resolved ? e.relative_rmse_noise_removed : e.noise_removed_upper;
}

std::vector<std::string> write_plots(const lumx::AplErrorReport& r, const EvalArgs& a) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(a.plots_dir, ec);
  if (ec) lumx::throw_at_field(a.plots_dir, "plots", "cannot create the folder: " + ec.message());
  const std::string ext = "." + a.plot_format;
  const lumx::ReferenceIrradiance& ref = r.reference;
  const std::vector<double>& ds = ref.spheres.relative_distances();
  const std::string caption = std::to_string(ref.rays) + " rays, " + std::to_string(ref.spheres.patch_count()) +
                              " patches per sphere; " + fs::path(a.bundle).filename().string();
  std::vector<std::string> written;

  // 1. Error against distance, one curve per level (000 Figure 5.8), the far field dashed, the noise grey.
  lumx::LogLogChart dist;
  dist.title = "Relative RMSE against distance";
  dist.caption = caption;
  dist.x_label = "relative distance d (bounding diameters from the centre)";
  dist.y_label = "relative RMSE at a point, noise removed (%)";
  dist.y_display_scale = 100;
  for (std::size_t k = 0; k < r.levels.size(); ++k) {
    lumx::ChartSeries s;
    s.label = apl_label(r.levels[k]);
    s.color = int(k);
    s.x = ds;
    for (const auto& e : r.levels[k].errors) s.y.push_back(plotted(e));
    dist.series.push_back(s);
  }
  if (!r.far_field.errors.empty()) {
    lumx::ChartSeries s;
    s.label = "far field";
    s.color = 9;
    s.dashed = true;
    s.x = ds;
    for (const auto& e : r.far_field.errors) s.y.push_back(plotted(e));
    dist.series.push_back(s);
  }
  lumx::ChartSeries noise;
  noise.label = "noise floor of the rays";
  noise.color = -1;
  noise.dashed = true;
  noise.x = ds;
  for (const auto& sr : ref.sphere) noise.y.push_back(sr.noise_floor);
  dist.series.push_back(noise);
  written.push_back((fs::path(a.plots_dir) / ("error_vs_distance" + ext)).string());
  lumx::write_loglog_chart(dist, written.back());

  // 2.–3. Error against time and against bytes: one curve per distance through the levels.
  for (int which = 0; which < 2; ++which) {
    lumx::LogLogChart c;
    c.title = which == 0 ? "Relative RMSE against evaluation time" : "Relative RMSE against memory";
    c.caption = caption + "; one point per level, fewest APLs first";
    c.x_label = which == 0 ? "time per irradiance evaluation (ns)" : "bytes of the level's maps";
    c.y_label = "relative RMSE (%)";
    c.y_display_scale = 100;
    for (std::size_t s = 0; s < ds.size(); ++s) {
      lumx::ChartSeries series;
      char label[64];
      std::snprintf(label, sizeof label, "d = %g", ds[s]);
      series.label = label;
      series.color = int(s);
      for (const auto& l : r.levels) {
        series.x.push_back(which == 0 ? l.ns_per_evaluation : double(l.bytes));
        series.y.push_back(plotted(l.errors[s]));
      }
      c.series.push_back(series);
    }
    if (!r.far_field.errors.empty()) {
      // The far field as unlabelled markers in each distance's colour, and one grey legend entry.
      for (std::size_t s = 0; s < ds.size(); ++s) {
        lumx::ChartSeries ff;
        ff.color = int(s);
        ff.line = false;
        ff.x.push_back(which == 0 ? r.far_field.ns_per_evaluation : double(r.far_field.bytes));
        ff.y.push_back(plotted(r.far_field.errors[s]));
        c.series.push_back(ff);
      }
      lumx::ChartSeries key;
      key.label = "far field (large dots)";
      key.color = -1;
      key.line = false;
      c.series.push_back(key);
    }
    written.push_back((fs::path(a.plots_dir) / ((which == 0 ? "error_vs_time" : "error_vs_bytes") + ext)).string());
    lumx::write_loglog_chart(c, written.back());
  }
  return written;
}

/// Rewrites the bundle with the error tables, keeping what else it holds. `set` is the bundle as `reader`
/// loaded it (the reader keeps the folder it read open, so volume and attachments come from the same one).
void store_tables(const EvalArgs& a, const lumx::BundleReader& reader, const lumx::AplErrorReport& report,
                  lumx::AplSet set) {
  std::optional<lumx::RadianceVolume> volume;
  if (reader.has_volume()) volume = reader.load_volume();
  const lumx::BundleManifest& m = reader.manifest();
  lumx::BundleWriteOptions wo;
  // The same stored resolutions: down to the smallest reduced copy any level keeps (0: full only).
  int min_res = 0;
  for (const auto& l : m.levels)
    if (l.maps.size() > 1) min_res = min_res == 0 ? l.maps.back().resolution : std::min(min_res, l.maps.back().resolution);
  wo.min_stored_resolution = min_res;
  // Lossless: maps read from half payloads are exact in half again; a bundle with float payloads keeps
  // float everywhere (its writer may have forced it).
  for (const auto& l : m.levels)
    for (const auto& p : l.maps)
      if (p.pixel_type == "float") wo.pixel_type = lumx::MapPixelType::float32;
  for (std::size_t i = 0; i < m.attachments.size(); ++i) {
    lumx::BundleAttachment att = m.attachments[i].first;
    att.bytes = reader.read_attachment(i);
    wo.attachments.push_back(std::move(att));
  }
  lumx::store_error_tables(set, report);
  set.provenance["error_tables"] = "lumx eval against " + a.rays + " (" + std::to_string(report.reference.rays) +
                                   " rays, " + std::to_string(report.reference.spheres.patch_count()) + " patches)";
  lumx::write_bundle(a.bundle, set, volume ? &*volume : nullptr, wo);
}

json grades_json(const std::vector<lumx::ModelGrade>& grades) {
  json out = json::array();
  for (const lumx::ModelGrade& g : grades) {
    json spheres = json::array();
    for (const lumx::ModelSphereError& s : g.spheres)
      spheres.push_back({{"relative_distance", s.relative_distance}, {"relative_rmse", s.relative_rmse},
                         {"noise_removed", s.noise_removed}, {"noise_removed_upper", s.noise_removed_upper},
                         {"noise_floor", s.noise_floor}, {"resolved", s.resolved}});
    out.push_back({{"type", g.type}, {"description", g.description}, {"bytes", g.bytes},
                   {"ns_per_evaluation", g.ns_per_evaluation}, {"reference_rays", g.reference_rays},
                   {"spheres", spheres}});
  }
  return out;
}

// The bundle's models (BundleReader::representations() past the APL levels), each graded through the seam:
// on rays of another run as they are, or rebuilt from the even rays of the bundle's own and graded on the odd.
std::vector<lumx::ModelGrade> grade_bundle_models(const lumx::BundleReader& reader, lumx::RaySource& rays, bool own_rays,
                                                  const lumx::AplErrorOptions& o, const lumx::BoundingSphere& bounds) {
  std::vector<lumx::ModelGrade> grades;
  lumx::ModelGradeOptions go;
  go.relative_distances = o.relative_distances;
  go.patch_resolution = o.patch_resolution;
  go.bounds = bounds;
  for (std::size_t i = 0; i < reader.manifest().models.size(); ++i) {
    if (own_rays) {
      grades.push_back(lumx::grade_held_out(reader.manifest().models[i].type, rays, {}, go));
    } else {
      const std::unique_ptr<lumx::LightModel> m = reader.load_model(i);
      grades.push_back(lumx::grade_model(*m, rays, go));
    }
    grades.back().description = reader.manifest().models[i].name + ": " + grades.back().description;
  }
  return grades;
}

int run_rays(const EvalArgs& a) {
  const bool tty = ::isatty(2) != 0;
  const lumx::BundleReader reader(a.bundle);
  lumx::AplSet set = reader.load();
  lumx::RaysetReadOptions ro;
  ro.warnings = [](const lumx::Diagnostic& d) { print_diag(d); };
  const std::unique_ptr<lumx::RaySource> rays = lumx::open_rayset(a.rays, ro);
  if (rays->info().quantity != set.quantity)
    lumx::throw_at_field(a.rays, "quantity",
                         std::string("the rays carry ") + lumx::flux_unit(rays->info().quantity) + ", the bundle " +
                             lumx::flux_unit(set.quantity) + ": the irradiances are not comparable");
  lumx::AplErrorOptions o;
  if (!a.distances.empty()) o.relative_distances = a.distances;
  o.patch_resolution = a.patch_resolution;
  o.patch_subsamples = a.subsamples;
  if (tty)
    o.progress = [](double f, const char* phase) {
      std::fprintf(stderr, "\r%-8s %3d %%", phase, int(std::lround(100 * f)));
      std::fflush(stderr);
    };
  // Grading a set on the rays it was built from would share their noise and flatter it. When the rays are
  // the bundle's source (its provenance names them and their count), the levels are rebuilt the same way
  // from the even rays and graded on the odd ones; --independent grades the bundle itself.
  const auto source = set.provenance.find("source"), count = set.provenance.find("source_rays");
  const bool is_source =
      source != set.provenance.end() && count != set.provenance.end() &&
      std::filesystem::path(source->second).filename() == std::filesystem::path(a.rays).filename() &&
      count->second == std::to_string(rays->info().ray_count);
  lumx::AplErrorReport report;
  std::string graded = a.bundle, against = a.rays;
  if (is_source && !a.independent) {
    const auto opts = set.provenance.find("build_options");
    if (opts == set.provenance.end())
      lumx::throw_at_field(a.rays, "rays",
                           "these are the rays the bundle was built from and it does not record its build options: "
                           "give rays from another run, or --independent to grade it on its own rays anyway");
    lumx::AplBuildOptions bo = lumx::build_options_from_json(opts->second);
    bo.threads = std::max(1u, std::thread::hardware_concurrency());
    std::fprintf(stderr, "%s: note: these rays built the bundle; its levels are rebuilt from the even rays and graded "
                         "on the odd ones\n", a.rays.c_str());
    // As lumx build graded it: resolutions fitted on held-out rays unless the build fixed them.
    const lumx::AplBuildOptions half = lumx::half_rays_build_options(bo, rays->info().ray_count);
    const auto build_half = [&](lumx::RaySource& train) { return lumx::build_apl_set(train, half); };
    report = bo.map_resolution > 0 ? lumx::evaluate_held_out(*rays, build_half, o)
                                   : lumx::evaluate_held_out_fitted(*rays, build_half, o);
    graded += " (its levels rebuilt from the even rays)";
    against += " (odd rays the levels never saw)";
  } else if (!is_source && lumx::centring_applies(o)) {
    // The pilot that centres the reference: one level of 64 APLs from the even rays, built as the bundle
    // records (lumx::evaluate_independent); the levels are graded on the odd rays.
    const auto opts = set.provenance.find("build_options");
    lumx::AplBuildOptions bo = opts != set.provenance.end() ? lumx::build_options_from_json(opts->second)
                                                            : lumx::AplBuildOptions{};
    bo.level_counts = {64};
    bo.threads = std::max(1u, std::thread::hardware_concurrency());
    report = lumx::evaluate_independent(set, *rays, [&](lumx::RaySource& r) { return lumx::build_apl_set(r, bo); }, o);
    against += " (the odd rays; the even ones make the pilot that centres the reference)";
  } else {
    // The bundle's own rays (--independent) get no pilot: every pilot from them shares rays with the levels.
    report = lumx::evaluate_apl_errors(set, *rays, o);
    if (is_source) against += " (the rays it was built from: errors shared with them cancel)";
  }
  const std::vector<lumx::ModelGrade> grades =
      grade_bundle_models(reader, *rays, is_source && !a.independent, o, set.bounds);
  if (tty) std::fputs("\r              \r", stderr);
  if (a.json) {
    json j = report_json(report, a, set.quantity);
    if (!grades.empty()) j["models"] = grades_json(grades);
    std::printf("%s\n", j.dump(1).c_str());
  } else {
    std::fputs(table_text(report, graded, against, set.quantity).c_str(), stdout);
    if (!grades.empty())
      std::fputs(("\n" + format_model_grades(grades, is_source && !a.independent
                                                          ? "each rebuilt from the even rays, graded on the odd"
                                                          : "as stored, against " + a.rays))
                     .c_str(),
                 stdout);
  }
  if (!a.plots_dir.empty()) {
    const std::vector<std::string> files = write_plots(report, a);
    for (const std::string& f : files) std::fprintf(stderr, "wrote %s\n", f.c_str());
  }
  if (a.store_errors) {
    store_tables(a, reader, report, std::move(set));
    std::fprintf(stderr, "stored the error tables of %zu levels in %s\n", report.levels.size(), a.bundle.c_str());
  }
  return 0;
}

}  // namespace

std::string format_model_grades(const std::vector<lumx::ModelGrade>& grades, const std::string& how) {
  std::string out = "representations graded through the seam (" + how + "); noise-removed relative RMSE of "
                    "irradiance at patch centres, its upper bound, * resolved:\n";
  char buf[256];
  if (grades.empty()) return out;
  std::snprintf(buf, sizeof buf, "  %-14s", "type");
  out += buf;
  for (const lumx::ModelSphereError& s : grades.front().spheres) {
    std::snprintf(buf, sizeof buf, " %16s", ("d " + format_cell(s.relative_distance, "%*g", 0)).c_str());
    out += buf;
  }
  out += "        bytes  ns/point  model\n";
  for (const lumx::ModelGrade& g : grades) {
    std::snprintf(buf, sizeof buf, "  %-14s", g.type.c_str());
    out += buf;
    for (const lumx::ModelSphereError& s : g.spheres) {
      std::snprintf(buf, sizeof buf, " %6.2f%% <%6.2f%%%s", 100 * s.noise_removed, 100 * s.noise_removed_upper,
                    s.resolved ? "*" : " ");
      out += buf;
    }
    std::snprintf(buf, sizeof buf, " %12zu %9.1f  %s\n", g.bytes, g.ns_per_evaluation, g.description.c_str());
    out += buf;
  }
  return out;
}

std::string format_error_table(const lumx::AplErrorReport& r, const std::string& bundle, const std::string& rays,
                               lumx::PhotometricQuantity q) {
  return table_text(r, bundle, rays, q);
}

int run_eval(const EvalArgs& a) {
  return guarded(a.bundle, [&] {
    if (a.points.empty() == a.rays.empty()) throw std::invalid_argument("give exactly one of --points or --rays");
    if (!a.points.empty()) {
      if (a.level >= 0 && a.lod) throw std::invalid_argument("give --level or --lod, not both");
      return run_points(a);
    }
    if (a.level >= 0 || a.lod || !a.out.empty())
      throw std::invalid_argument("--level, --lod and -o apply to --points; --rays evaluates every level");
    return run_rays(a);
  });
}

}  // namespace lumx_cli
