// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx's plain text ray format (docs/rays.md): a required first line
//     # lumx-rays length=<unit> flux=<lm|W> [total=<number>]
// then one ray per line, "x y z dx dy dz [flux [wavelength_nm]]" (blanks, tabs or commas between the
// numbers; every ray line has the same count). Lines starting with '#' are comments, blank lines ignored.
#include "io/rays/rayset_common.h"
#include "io/text_scanner.h"

#include <cstdio>

LUMX_NAMESPACE_BEGIN
namespace detail {

std::unique_ptr<RaySource> open_plain_rays(std::shared_ptr<const RayFile> file, const RaysetReadOptions& o) {
  const RayFile& f = *file;
  const std::string& path = f.path();
  LineReader lines(f, o.limits.max_line_bytes);
  std::string_view line, header;
  while (lines.next(line)) {
    header = trim_blanks(line);
    if (!header.empty()) break;
  }
  const int header_line = std::max(1, lines.line_number());
  constexpr std::string_view kMagic = "# lumx-rays";
  const char* const kUsage = "the first line must be '# lumx-rays length=UNIT flux=lm|W [total=NUMBER]'";
  if (header.substr(0, kMagic.size()) != kMagic ||
      (header.size() > kMagic.size() && header[kMagic.size()] != ' ' && header[kMagic.size()] != '\t'))
    throw_at_line(path, header_line, "header", kUsage);

  RaysetInfo info;
  info.file = path;
  info.format = "plain text";
  info.version = "1";
  std::optional<LengthUnit> unit;
  std::optional<PhotometricQuantity> quantity;
  std::string_view rest = header.substr(kMagic.size());
  while (!rest.empty()) {
    rest = trim_blanks(rest);
    if (rest.empty()) break;
    std::size_t end = 0;
    while (end < rest.size() && rest[end] != ' ' && rest[end] != '\t') ++end;
    const std::string_view item = rest.substr(0, end);
    rest.remove_prefix(end);
    const auto eq = item.find('=');
    if (eq == std::string_view::npos || eq == 0 || eq + 1 == item.size())
      throw_at_line(path, header_line, "header", "'" + excerpt(item) + "' is not key=value; " + kUsage);
    const std::string_view key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "length") {
      unit = length_unit_named(value);
      if (!unit)
        throw_at_line(path, header_line, "length",
                      "unknown length unit '" + excerpt(value) + "' (m, cm, mm, um, nm, in, ft)");
    } else if (key == "flux") {
      if (value == "lm") {
        quantity = PhotometricQuantity::photometric;
      } else if (value == "W") {
        quantity = PhotometricQuantity::radiometric;
      } else {
        throw_at_line(path, header_line, "flux", "unit '" + excerpt(value) + "' is neither lm nor W");
      }
    } else if (key == "total") {
      double v = 0;
      if (!parse_number(value, v) || v < 0)
        throw_at_line(path, header_line, "total", "'" + excerpt(value) + "' is not a non-negative number");
      info.header_flux = v;
    } else if (o.warnings) {
      o.warnings(warning_at_line(path, header_line, std::string(key), "unknown header key ignored"));
    }
  }
  if (!unit) throw_at_line(path, header_line, "length", std::string("missing; ") + kUsage);
  if (!quantity) throw_at_line(path, header_line, "flux", std::string("missing; ") + kUsage);
  info.quantity = *quantity;
  info.source_length_unit = unit->name;

  TextRayLayout l;
  l.data_offset = lines.offset();
  l.header_lines = lines.line_number();
  l.hash_comments = true;
  l.max_line_bytes = o.limits.max_line_bytes;
  l.max_rays = o.limits.max_rays;
  l.unit = *unit;
  l.flux_line = header_line;
  l.flux_field = "total";
  // Columns from the first ray line.
  std::size_t cols = 7;
  while (lines.next(line)) {
    const std::string_view t = trim_blanks(line);
    if (t.empty() || t.front() == '#') continue;
    float v[9];
    std::size_t n = 0;
    std::string_view bad;
    split_floats(t, v, 9, n, bad);
    if (n < 6 || n > 8)
      throw_at_line(path, lines.line_number(), "ray",
                    "expected 6 to 8 numbers (x y z dx dy dz [flux [wavelength_nm]]), found " + std::to_string(n));
    cols = n;
    break;
  }
  l.columns = cols;
  l.column_names = cols == 6   ? "x y z dx dy dz"
                   : cols == 7 ? "x y z dx dy dz flux"
                               : "x y z dx dy dz flux wavelength_nm";
  l.flux_column = cols >= 7 ? 6 : -1;
  l.wavelength_column = cols == 8 ? 7 : -1;
  info.ray_count = count_text_rays(f, l, o.warnings);
  if (cols == 6) {
    // No flux column: equal rays, sharing the stated total, else 1 each.
    l.constant_flux = !std::isnan(info.header_flux) && info.ray_count > 0
                          ? static_cast<float>(info.header_flux / static_cast<double>(info.ray_count))
                          : 1.0f;
  }
  RayFieldNames names;
  return make_text_ray_source(std::move(file), std::move(info), o, std::move(names), std::move(l));
}

}  // namespace detail
LUMX_NAMESPACE_END
