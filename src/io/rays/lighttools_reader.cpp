// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// LightTools ray data files (formats.md §3.2). Binary: a 44-byte header ("LTRF", version, data type,
// far-field flag, colour information, length unit, origin, total flux), records of x y z kx ky kz flux
// [λ nm] as float32, and "LTRFEND" at the end; there is no ray count, so the count is what fits between
// header and end marker, exactly. Text: '#' comment lines, "key: value" header lines, lt_startofdata,
// one ray per line, lt_endofdata.
#include "io/rays/rayset_common.h"
#include "io/text_scanner.h"

#include <cstdio>
#include <map>

LUMX_NAMESPACE_BEGIN
namespace detail {
namespace {

constexpr std::uint64_t kHeader = 44;
constexpr std::uint64_t kEndMarker = 7;  // "LTRFEND"

/// LightTools length-unit codes (0 = the model's system unit, not stated in the file).
std::optional<LengthUnit> lighttools_unit(std::uint32_t code) {
  return length_unit_coded(code, {"", "mm", "cm", "m", "in", "ft", "um", "nm"});
}

LengthUnit default_unit(const RaysetReadOptions& o, const std::string& file, std::int64_t offset, int line,
                        const std::string& field) {
  const auto u = length_unit_named(o.default_length_unit);
  if (!u)
    throw_at_field(file, "default length unit", "unknown unit '" + o.default_length_unit + "' in the read options");
  if (o.warnings) {
    Diagnostic d = line > 0 ? warning_at_line(file, line, field, "") : warning_at_offset(file, offset, field, "");
    d.message = "the file uses the LightTools system unit, which it does not state; read as " + u->name;
    o.warnings(d);
  }
  return *u;
}

}  // namespace

std::unique_ptr<RaySource> open_lighttools_binary(std::shared_ptr<const RayFile> file, const RaysetReadOptions& o) {
  const RayFile& f = *file;
  const std::string& path = f.path();
  unsigned char h[kHeader];
  const std::size_t got = f.read_some(0, h, sizeof h);
  const char* const fields[] = {"signature",      "major version",      "minor version", "data type",
                                "far-field flag", "colour information", "length units",  "origin x",
                                "origin y",       "origin z",           "total flux"};
  const auto need = [&](std::uint64_t off, std::uint64_t n, const std::string& field) {
    if (off + n > got)
      throw_at_offset(path, static_cast<std::int64_t>(std::min<std::uint64_t>(off, f.size())), field,
                      "file ends at byte " + std::to_string(f.size()) + ", inside the 44-byte header");
  };
  const auto u32 = [&](std::uint64_t off) {
    need(off, 4, fields[off / 4]);
    return le_u32(h + off);
  };
  need(0, 4, "signature");
  if (std::string_view(reinterpret_cast<const char*>(h), 4) != "LTRF")
    throw_at_offset(path, 0, "signature", "the file does not start with \"LTRF\"");
  const std::uint32_t major = u32(4), minor = u32(8);
  if (major == 3)
    throw_at_offset(path, 4, "major version",
                    "version 3 (rays with polarisation) is not supported; lumx reads version 2");
  if (major != 2)
    throw_at_offset(path, 4, "major version", "version " + std::to_string(major) + " is not supported (expected 2)");
  const std::uint32_t type = u32(12);
  if (type > 1)
    throw_at_offset(path, 12, "data type", "must be 0 (radiometric) or 1 (photometric), is " + std::to_string(type));
  if (u32(16) != 0)
    throw_at_offset(path, 16, "far-field flag",
                    "far-field ray data (no start points) is not supported: a rayset needs positions");
  const std::uint32_t colour = u32(20);
  if (colour == 1) throw_at_offset(path, 20, "colour information", "tristimulus ray data (1) is not supported");
  if (colour > 2)
    throw_at_offset(path, 20, "colour information", "must be 0 (none) or 2 (wavelength), is " + std::to_string(colour));
  const std::uint32_t unit_code = u32(24);
  std::optional<LengthUnit> unit = lighttools_unit(unit_code);
  if (!unit && unit_code != 0)
    throw_at_offset(path, 24, "length units", "unknown length unit code " + std::to_string(unit_code) + " (0..7)");
  if (!unit) unit = default_unit(o, path, 24, 0, "length units");
  need(28, 16, "origin x");
  const float ox = le_f32(h + 28), oy = le_f32(h + 32), oz = le_f32(h + 36);
  need(40, 4, "total flux");
  const float total = le_f32(h + 40);
  if (!(total >= 0) || std::isinf(total))
    throw_at_offset(path, 40, "total flux", "must be a non-negative number, is " + format_number_9(total));
  if ((ox != 0 || oy != 0 || oz != 0) && o.warnings)
    o.warnings(warning_at_offset(path, 28, "origin",
                                 "data origin (" + format_number_9(ox) + ", " + format_number_9(oy) + ", " + format_number_9(oz) +
                                     ") is reported, not added: positions are read as stored"));

  const unsigned cols = colour == 2 ? 8 : 7;
  const std::uint64_t rec = 4u * cols;
  if (f.size() < kHeader + kEndMarker)
    throw_at_offset(path, static_cast<std::int64_t>(f.size()), "end marker",
                    "file ends at byte " + std::to_string(f.size()) + " before the \"LTRFEND\" end marker");
  unsigned char tail[kEndMarker];
  f.read_exact(f.size() - kEndMarker, tail, kEndMarker, "end marker");
  if (std::string_view(reinterpret_cast<const char*>(tail), kEndMarker) != "LTRFEND")
    throw_at_offset(path, static_cast<std::int64_t>(f.size() - kEndMarker), "end marker",
                    "the file does not end with \"LTRFEND\" (truncated?)");
  const std::uint64_t data = f.size() - kHeader - kEndMarker;
  if (data % rec != 0)
    throw_at_offset(path, static_cast<std::int64_t>(kHeader + data / rec * rec), "ray data",
                    std::to_string(data) + " bytes between header and end marker are not a whole number of " +
                        std::to_string(rec) + "-byte rays (" + std::to_string(cols) + " floats)");

  RaysetInfo info;
  info.file = path;
  info.format = "LightTools binary";
  info.version = std::to_string(major) + "." + std::to_string(minor);
  info.ray_count = data / rec;
  if (info.ray_count > o.limits.max_rays)
    throw_at_offset(path, static_cast<std::int64_t>(kHeader), "ray data",
                    std::to_string(info.ray_count) + " rays exceed RaysetLimits::max_rays (" +
                        std::to_string(o.limits.max_rays) + ")");
  info.quantity = type == 1 ? PhotometricQuantity::photometric : PhotometricQuantity::radiometric;
  info.header_flux = total;
  info.source_length_unit = unit_code == 0 ? "system (" + unit->name + " assumed)" : unit->name;
  info.values["data type"] = type;
  info.values["colour information"] = colour;
  info.values["length unit code"] = unit_code;
  info.values["origin x"] = ox;
  info.values["origin y"] = oy;
  info.values["origin z"] = oz;

  FloatRecordLayout l;
  l.data_offset = kHeader;
  l.rays = info.ray_count;
  l.columns = cols;
  l.flux_column = 6;
  l.wavelength_column = colour == 2 ? 7 : -1;
  l.unit = *unit;
  l.flux_offset = 40;
  l.flux_field = "total flux";
  return make_float_record_source(std::move(file), std::move(info), o, RayFieldNames::binary_records(), std::move(l));
}

std::unique_ptr<RaySource> open_lighttools_text(std::shared_ptr<const RayFile> file, const RaysetReadOptions& o) {
  const RayFile& f = *file;
  const std::string& path = f.path();
  LineReader lines(f, o.limits.max_line_bytes);
  RaysetInfo info;
  info.file = path;
  info.format = "LightTools text";
  std::string comments, version, datatype, colour, units, far_field;
  int datatype_line = 0, colour_line = 0, units_line = 0, version_line = 0, far_line = 0;
  std::map<std::string, int> flux_lines;  // lt_radiant_flux, lt_luminous_flux: where stated
  bool started = false;
  std::string_view line;
  std::size_t header_lines = 0;
  while (lines.next(line)) {
    if (++header_lines > o.limits.max_header_lines)
      throw_at_line(path, lines.line_number(), "header",
                    "no lt_startofdata within RaysetLimits::max_header_lines (" + std::to_string(o.limits.max_header_lines) + ")");
    const std::string_view t = trim_blanks(line);
    if (t.empty()) continue;
    if (t.front() == '#') {
      const std::string_view c = trim_blanks(t.substr(1));
      if (!c.empty()) comments += (comments.empty() ? "" : "; ") + to_utf8(c);
      continue;
    }
    if (t == "lt_startofdata") {
      started = true;
      break;
    }
    const auto colon = t.find(':');
    if (colon == std::string_view::npos)
      throw_at_line(path, lines.line_number(), "header",
                    "expected 'key: value' or lt_startofdata, found '" + excerpt(t) + "'");
    const std::string key(trim_blanks(t.substr(0, colon)));
    const std::string value = to_utf8(trim_blanks(t.substr(colon + 1)));
    const int ln = lines.line_number();
    if (key == "lt_rdf_version") {
      version = value, version_line = ln;
    } else if (key == "lt_datatype") {
      datatype = value, datatype_line = ln;
    } else if (key == "lt_far_field_data") {
      far_field = value, far_line = ln;
    } else if (key == "lt_color_info") {
      colour = value, colour_line = ln;
    } else if (key == "lt_length_units") {
      units = value, units_line = ln;
    } else if (key == "lt_radiant_flux" || key == "lt_luminous_flux" || key == "lt_photometric_flux") {
      double v = 0;
      if (!parse_number(value, v) || v < 0)
        throw_at_line(path, ln, key, "'" + excerpt(value) + "' is not a non-negative number");
      info.values[key] = v;
      flux_lines[key] = ln;
    } else if (key == "lt_data_origin") {
      float xyz[3];
      std::size_t n = 0;
      std::string_view bad;
      if (!split_floats(value, xyz, 3, n, bad) || n != 3)
        throw_at_line(path, ln, key, "expected three numbers, found '" + excerpt(value) + "'");
      info.values["origin x"] = xyz[0], info.values["origin y"] = xyz[1], info.values["origin z"] = xyz[2];
      if ((xyz[0] != 0 || xyz[1] != 0 || xyz[2] != 0) && o.warnings)
        o.warnings(warning_at_line(path, ln, key, "data origin is reported, not added: positions are read as stored"));
    } else {
      info.text[key == "dataname" ? "data name" : key] = value;
    }
  }
  if (!started)
    throw_at_line(path, std::max(1, lines.line_number()), "lt_startofdata",
                  "the file ends before lt_startofdata (not a complete LightTools ray data file)");
  if (!comments.empty()) info.text["comment"] = comments;
  if (version.empty()) {
    if (o.warnings) o.warnings(warning_at_line(path, 1, "lt_rdf_version", "missing; read as version 2"));
    version = "2.0";
  } else if (version.rfind("2", 0) != 0) {
    throw_at_line(path, version_line, "lt_rdf_version",
                  "version '" + excerpt(version) + "' is not supported (lumx reads version 2)");
  }
  info.version = version;
  if (!far_field.empty() && far_field != "no")
    throw_at_line(path, far_line, "lt_far_field_data",
                  "far-field ray data (no start points) is not supported: a rayset needs positions");
  std::string dt = datatype;
  for (char& c : dt) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (dt.find("radi") != std::string::npos) {
    info.quantity = PhotometricQuantity::radiometric;
  } else if (dt.find("lum") != std::string::npos || dt.find("photometric") != std::string::npos) {
    info.quantity = PhotometricQuantity::photometric;
  } else {
    throw_at_line(path, datatype_line > 0 ? datatype_line : lines.line_number(), "lt_datatype",
                  datatype.empty() ? "missing (radiant_power or luminous_power)"
                                   : "'" + excerpt(datatype) + "' is neither radiant nor luminous power");
  }
  bool wavelength = false;
  if (colour == "wavelength") {
    wavelength = true;
  } else if (!colour.empty() && colour != "none" && colour != "no") {
    throw_at_line(path, colour_line, "lt_color_info",
                  "'" + excerpt(colour) + "' is not supported (none or wavelength)");
  }
  std::optional<LengthUnit> unit = units.empty() || units == "system" ? std::nullopt : length_unit_named(units);
  if (!unit && !units.empty() && units != "system")
    throw_at_line(path, units_line, "lt_length_units", "unknown length unit '" + excerpt(units) + "'");
  if (!unit) unit = default_unit(o, path, -1, units_line > 0 ? units_line : 1, "lt_length_units");
  info.source_length_unit = units.empty() || units == "system" ? "system (" + unit->name + " assumed)" : unit->name;
  // The header total in the rays' own quantity; a total in the other one stays in info.values only.
  std::string flux_key;
  const bool radiometric = info.quantity == PhotometricQuantity::radiometric;
  for (const char* k : {"lt_radiant_flux", "lt_luminous_flux", "lt_photometric_flux"})
    if (flux_key.empty() && flux_lines.count(k) && (std::string_view(k) == "lt_radiant_flux") == radiometric)
      flux_key = k;
  int flux_line = 0;
  if (!flux_key.empty()) {
    info.header_flux = info.values[flux_key];
    flux_line = flux_lines[flux_key];
  }

  TextRayLayout l;
  l.data_offset = lines.offset();
  l.header_lines = lines.line_number();
  l.columns = wavelength ? 8 : 7;
  l.column_names = wavelength ? "x y z kx ky kz flux wavelength" : "x y z kx ky kz flux";
  l.flux_column = 6;
  l.wavelength_column = wavelength ? 7 : -1;
  l.unit = *unit;
  l.end_marker = "lt_endofdata";
  l.max_line_bytes = o.limits.max_line_bytes;
  l.max_rays = o.limits.max_rays;
  l.flux_line = flux_line;
  l.flux_field = flux_key.empty() ? "total flux" : flux_key;
  info.ray_count = count_text_rays(f, l, o.warnings);
  RayFieldNames names;
  return make_text_ray_source(std::move(file), std::move(info), o, std::move(names), std::move(l));
}

}  // namespace detail
LUMX_NAMESPACE_END
