// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Zemax OpticStudio source files (formats.md §3.2). Binary: a 208-byte header (id 1010, ray count,
// description, fluxes, wavelength in µm, angular ranges, dimension units 0 m / 1 in / 2 cm / 3 ft / 4 mm,
// location, rotation, scale, ray format 0 flux only / 2 spectral, flux type 0 W / 1 lm) and records of
// x y z l m n flux [λ µm] as float32. Text: a first line whose first two numbers are the ray count and
// the dimension-unit code (the rest of that line is ignored), then one ray per line with 7 or 8 numbers.
#include "io/rays/rayset_common.h"
#include "io/text_scanner.h"

#include <cstdio>

LUMX_NAMESPACE_BEGIN
namespace detail {
namespace {

constexpr std::uint64_t kHeader = 208;

/// Zemax dimension-unit codes.
std::optional<LengthUnit> zemax_unit(std::int64_t code) { return length_unit_coded(code, {"m", "in", "cm", "ft", "mm"}); }

}  // namespace

std::unique_ptr<RaySource> open_zemax_binary(std::shared_ptr<const RayFile> file, const RaysetReadOptions& o) {
  const RayFile& f = *file;
  const std::string& path = f.path();
  unsigned char h[kHeader] = {};
  const std::size_t got = f.read_some(0, h, sizeof h);
  const auto need = [&](std::uint64_t off, std::uint64_t n, const std::string& field) {
    if (off + n > got)
      throw_at_offset(path, static_cast<std::int64_t>(std::min<std::uint64_t>(off, f.size())), field,
                      "file ends at byte " + std::to_string(f.size()) + ", inside the 208-byte header");
  };
  need(0, 4, "format identifier");
  const std::int32_t id = le_i32(h);
  if (id != 1010)
    throw_at_offset(path, 0, "format identifier", "must be 1010 (Zemax binary source file), is " + std::to_string(id));
  need(4, 4, "number of rays");
  const std::uint32_t rays = le_u32(h + 4);
  if (rays > o.limits.max_rays)
    throw_at_offset(path, 4, "number of rays",
                    std::to_string(rays) + " rays exceed RaysetLimits::max_rays (" + std::to_string(o.limits.max_rays) + ")");
  need(8, 100, "description");
  std::string description;
  for (int i = 0; i < 100 && h[8 + i] != 0; ++i) description += static_cast<char>(h[8 + i]);
  description = to_utf8(trim(description));
  need(108, 4, "source flux");
  const float source_flux = le_f32(h + 108);
  need(112, 4, "ray set flux");
  const float set_flux = le_f32(h + 112);
  need(116, 4, "wavelength");
  const float wavelength_um = le_f32(h + 116);
  need(120, 16, "angular range");
  need(136, 4, "dimension units");
  const std::uint32_t unit_code = le_u32(h + 136);
  const auto unit = zemax_unit(unit_code);
  if (!unit)
    throw_at_offset(path, 136, "dimension units",
                    "unknown code " + std::to_string(unit_code) + " (0 m, 1 in, 2 cm, 3 ft, 4 mm)");
  need(140, 52, "location, rotation and scale");
  need(192, 4, "ray format type");
  const std::int32_t format = le_i32(h + 192);
  if (format != 0 && format != 2)
    throw_at_offset(path, 192, "ray format type",
                    "must be 0 (flux only) or 2 (spectral), is " + std::to_string(format));
  need(196, 4, "flux type");
  const std::int32_t flux_type = le_i32(h + 196);
  if (flux_type != 0 && flux_type != 1)
    throw_at_offset(path, 196, "flux type", "must be 0 (W) or 1 (lm), is " + std::to_string(flux_type));
  if (format == 2 && flux_type == 1)
    throw_at_offset(path, 196, "flux type", "spectral ray data (format 2) is in W; flux type 1 (lm) contradicts it");
  need(200, 8, "reserved");
  if (!(set_flux >= 0) || std::isinf(set_flux))
    throw_at_offset(path, 112, "ray set flux", "must be a non-negative number, is " + format_number_9(set_flux));

  const unsigned cols = format == 2 ? 8 : 7;
  const std::uint64_t rec = 4u * cols;
  const std::uint64_t have = f.size() - kHeader;
  if (rays > have / rec)
    throw_at_offset(path, 4, "number of rays",
                    std::to_string(rays) + " rays of " + std::to_string(cols) + " floats need " +
                        std::to_string(rays * rec) + " bytes after the header, the file has " + std::to_string(have));
  if (rays * rec != have && o.warnings)
    o.warnings(warning_at_offset(path, static_cast<std::int64_t>(kHeader + rays * rec), "ray data",
                                 std::to_string(have - rays * rec) + " bytes after the last ray are ignored"));

  RaysetInfo info;
  info.file = path;
  info.format = "Zemax binary";
  info.version = "1010";
  info.ray_count = rays;
  info.quantity = flux_type == 1 ? PhotometricQuantity::photometric : PhotometricQuantity::radiometric;
  info.header_flux = set_flux;
  info.source_length_unit = unit->name;
  if (format == 0 && std::isfinite(wavelength_um) && wavelength_um > 0)
    info.wavelength_nm = static_cast<double>(wavelength_um) * 1000.0;
  if (!description.empty()) info.text["description"] = description;
  info.values["source flux"] = source_flux;
  info.values["ray set flux"] = set_flux;
  info.values["wavelength um"] = wavelength_um;
  info.values["ray format type"] = format;
  info.values["flux type"] = flux_type;
  info.values["dimension units"] = unit_code;
  const char* const angular[] = {"inclination begin deg", "inclination end deg", "azimuth begin deg",
                                 "azimuth end deg"};
  for (int i = 0; i < 4; ++i) info.values[angular[i]] = le_f32(h + 120 + 4 * i);
  const char* const placement[] = {"location x",     "location y", "location z", "rotation x rad", "rotation y rad",
                                   "rotation z rad", "scale x",    "scale y",    "scale z"};
  for (int i = 0; i < 9; ++i) info.values[placement[i]] = le_f32(h + 140 + 4 * i);

  FloatRecordLayout l;
  l.data_offset = kHeader;
  l.rays = rays;
  l.columns = cols;
  l.flux_column = 6;
  l.wavelength_column = format == 2 ? 7 : -1;
  l.wavelength_to_nm = 1000;
  l.unit = *unit;
  l.flux_offset = 112;
  l.flux_field = "ray set flux";
  return make_float_record_source(std::move(file), std::move(info), o, RayFieldNames::binary_records(), std::move(l));
}

std::unique_ptr<RaySource> open_zemax_text(std::shared_ptr<const RayFile> file, const RaysetReadOptions& o) {
  const RayFile& f = *file;
  const std::string& path = f.path();
  LineReader lines(f, o.limits.max_line_bytes);
  std::string_view line;
  std::string_view first;
  while (lines.next(line)) {
    first = trim_blanks(line);
    if (!first.empty()) break;
  }
  if (first.empty()) throw_at_line(path, std::max(1, lines.line_number()), "header", "the file holds no text");
  const int header_line = lines.line_number();
  // Header: ray count, dimension-unit code, anything else.
  std::vector<double> values;
  {
    std::size_t i = 0;
    const auto sep = [](char c) { return c == ' ' || c == '\t' || c == ','; };
    while (i < first.size() && values.size() < 16) {
      while (i < first.size() && sep(first[i])) ++i;
      std::size_t j = i;
      while (j < first.size() && !sep(first[j])) ++j;
      if (j == i) break;
      double v = 0;
      if (!parse_number(first.substr(i, j - i), v))
        throw_at_line(path, header_line, "header",
                      "'" + excerpt(first.substr(i, j - i)) +
                          "' is not a number (the first line holds the ray "
                          "count and the dimension-unit code)");
      values.push_back(v);
      i = j;
    }
  }
  if (values.size() < 2)
    throw_at_line(path, header_line, "header", "the first line must hold the ray count and the dimension-unit code");
  const double count = values[0];
  if (!(count >= 0 && count == std::floor(count)))
    throw_at_line(path, header_line, "number of rays", "'" + format_number_9(count) + "' is not a ray count");
  if (count > static_cast<double>(o.limits.max_rays))
    throw_at_line(path, header_line, "number of rays",
                  format_number_9(count) + " rays exceed RaysetLimits::max_rays (" + std::to_string(o.limits.max_rays) + ")");
  const double code = values[1];
  // A whole number within int64 range before the cast (5e21 or ±inf would make it undefined).
  const auto unit = code == std::floor(code) && std::abs(code) < 1e15 ? zemax_unit(static_cast<std::int64_t>(code))
                                                                      : std::nullopt;
  if (!unit)
    throw_at_line(path, header_line, "dimension units", "unknown code " + format_number_9(code) + " (0 m, 1 in, 2 cm, 3 ft, 4 mm)");

  TextRayLayout l;
  l.data_offset = lines.offset();
  l.header_lines = header_line;
  l.max_line_bytes = o.limits.max_line_bytes;
  l.max_rays = o.limits.max_rays;
  // Columns from the first ray line: 7 (flux only) or 8 (with wavelength in µm).
  std::size_t cols = 7;
  while (lines.next(line)) {
    const std::string_view t = trim_blanks(line);
    if (t.empty()) continue;
    float v[9];
    std::size_t n = 0;
    std::string_view bad;
    split_floats(t, v, 9, n, bad);
    if (n != 7 && n != 8)
      throw_at_line(path, lines.line_number(), "ray",
                    "expected 7 numbers (x y z l m n flux) or 8 (with wavelength in um), found " + std::to_string(n));
    cols = n;
    break;
  }
  l.columns = cols;
  l.column_names = cols == 8 ? "x y z l m n flux wavelength" : "x y z l m n flux";
  l.flux_column = 6;
  l.wavelength_column = cols == 8 ? 7 : -1;
  l.wavelength_to_nm = 1000;
  l.unit = *unit;
  const std::uint64_t found = count_text_rays(f, l, o.warnings);
  if (found != static_cast<std::uint64_t>(count))
    throw_at_line(path, header_line, "number of rays",
                  "the header says " + format_number_9(count) + " rays, the file has " + std::to_string(found) + " ray lines");

  RaysetInfo info;
  info.file = path;
  info.format = "Zemax text";
  info.ray_count = found;
  info.quantity = o.zemax_text_quantity;
  info.source_length_unit = unit->name;
  info.values["dimension units"] = code;
  for (std::size_t i = 2; i < values.size(); ++i) info.values["header value " + std::to_string(i + 1)] = values[i];
  RayFieldNames names;
  return make_text_ray_source(std::move(file), std::move(info), o, std::move(names), std::move(l));
}

}  // namespace detail
LUMX_NAMESPACE_END
