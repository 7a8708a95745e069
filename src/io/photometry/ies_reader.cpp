// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// IES LM-63 reader (1986, 1991, 1995, 2002, 2019). Layout: formats.md §1.2; quirks: §1.6.
//
// The header (version line, keywords) is read line by line up to the line that starts with "TILT=".
// Everything after it is a stream of numbers separated by blanks, tabs, commas or line breaks
// (LM-63-2002 §3), so it is tokenised once and consumed in order; every token keeps its line number for
// diagnostics. Counts from the file are checked against limits and against the tokens actually present
// before anything is sized from them.
#include <lumx/io/atomic_file.h>
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/symmetry.h>

#include "io/photometry/intensity_checks.h"
#include "io/number_stream.h"
#include "io/text_scanner.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

LUMX_NAMESPACE_BEGIN
namespace {

using detail::Line;
using detail::NumberStream;
using detail::trim;

bool starts_with(std::string_view s, std::string_view prefix) {
  return s.size() >= prefix.size() && s.substr(0, prefix.size()) == prefix;
}

std::string num(double v) { return detail::format_number(v, 10); }

std::string upper(std::string_view s) {
  std::string u(s);
  for (char& c : u) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return u;
}

/// True for the TILT line: "TILT" at the start of the line (after blanks), then optional blanks and '='.
bool is_tilt_line(std::string_view line, std::string_view& value) {
  line = trim(line);
  if (!starts_with(line, "TILT")) return false;
  std::string_view rest = trim(line.substr(4));
  if (rest.empty() || rest.front() != '=') return false;
  value = trim(rest.substr(1));
  return true;
}

/// Reads the TILT block (lamp geometry, pair count, angles, multipliers) from a number stream.
TiltTable read_tilt_block(NumberStream& in, const ReadLimits& limits) {
  TiltTable t;
  t.lamp_geometry = static_cast<int>(in.next_integer("TILT lamp-to-luminaire geometry", 1, 3));
  const long n = in.next_count("TILT number of angle/multiplier pairs", 1, limits.max_angles, "ReadLimits::max_angles");
  in.require_remaining(static_cast<std::size_t>(2 * n), "TILT angles and multipliers");
  t.angles_deg = in.next_values(static_cast<std::size_t>(n), "TILT angle", nullptr);
  t.multipliers = in.next_values(static_cast<std::size_t>(n), "TILT multiplier", nullptr);
  for (std::size_t i = 1; i < t.angles_deg.size(); ++i)
    if (!(t.angles_deg[i] > t.angles_deg[i - 1]))
      in.fail_at_last("TILT angle", "angles must increase (angle " + std::to_string(i) + ")");
  for (double m : t.multipliers)
    if (m < 0) in.fail_at_last("TILT multiplier", "multipliers must not be negative");
  return t;
}

std::string version_of_first_line(std::string_view first, bool& has_version_line, const NumberStream::Warn& warn,
                                  int line) {
  std::string u = upper(trim(first));
  std::string compact;
  for (char c : u)
    if (c != ' ' && c != '\t') compact.push_back(c);
  has_version_line = true;
  auto note_spaces = [&] {
    if (compact != u) warn(line, "version", "blanks inside the version line '" + detail::excerpt(u, 80) + "' (LM-63 forbids them)");
  };
  if (compact == "IESNA91" || compact == "IESNA:LM-63-1991") return note_spaces(), file_format::kIes1991;
  if (compact == "IESNA:LM-63-1995") return note_spaces(), file_format::kIes1995;
  if (compact == "IESNA:LM-63-2002") return note_spaces(), file_format::kIes2002;
  if (compact == "IES:LM-63-2019" || compact == "IESNA:LM-63-2019") return note_spaces(), file_format::kIes2019;
  if (starts_with(compact, "IESNA") || starts_with(compact, "IES:LM-63")) {
    warn(line, "version", "unknown LM-63 version line '" + detail::excerpt(trim(first), 80) + "'; read as LM-63-2002");
    return file_format::kIes2002;
  }
  has_version_line = false;
  return file_format::kIes1986;
}

}  // namespace

Photometry read_ies(std::string_view text, const std::string& name, const ReadOptions& options) {
  if (text.size() > options.limits.max_file_bytes)
    throw Error(Diagnostic{Severity::error, name, 0, 0, "file size",
                           "file is " + std::to_string(text.size()) + " bytes, above ReadLimits::max_file_bytes (" +
                               std::to_string(options.limits.max_file_bytes) + ")"});
  const NumberStream::Warn warn = [&](int line, const std::string& field, const std::string& msg) {
    if (options.warnings) options.warnings(Diagnostic{Severity::warning, name, line, -1, field, msg});
  };

  Photometry p;
  p.source.file = name;
  p.source.format = "IES";

  // ---- version line and keywords, up to TILT= ----
  // Real headers are a few dozen lines; a file with no TILT= line among its first kMaxHeaderLines is
  // not read further (and never kept whole as keyword text).
  constexpr int kMaxHeaderLines = 10000;
  detail::LineCursor cursor(text);
  Line line;
  bool any = false;
  while ((any = cursor.next(line)) && trim(line.text).empty()) {
  }
  if (!any) throw_at_line(name, 1, "version", "empty file");
  bool has_version = false;
  p.source.version = version_of_first_line(line.text, has_version, warn, line.number);
  bool have_line = !has_version;  // a 1986 file's first line is header text, to be read below
  std::string_view tilt_value;
  bool found_tilt = false;
  int tilt_line = 0;
  while (have_line || cursor.next(line)) {
    have_line = false;
    if (line.number > kMaxHeaderLines)
      throw_at_line(name, line.number, "TILT", "no 'TILT=' line within the first " +
                                                   std::to_string(kMaxHeaderLines) + " lines");
    const std::string_view raw = line.text;
    if (is_tilt_line(raw, tilt_value)) {
      found_tilt = true;
      tilt_line = line.number;
      break;
    }
    const std::string_view t = trim(raw);
    if (t.empty()) continue;
    if (!has_version) {  // LM-63-1986: free text before TILT
      p.keywords.push_back({"", detail::to_utf8(t)});
      continue;
    }
    if (t.front() == '[') {
      const std::size_t close = t.find(']');
      if (close == std::string_view::npos) {
        warn(line.number, "keyword", "no closing ']'; line kept as [OTHER] text");
        p.keywords.push_back({"OTHER", detail::to_utf8(t)});
        continue;
      }
      std::string key = upper(trim(t.substr(1, close - 1)));
      std::string value = detail::to_utf8(trim(t.substr(close + 1)));
      if (key == "MORE") {
        if (p.keywords.empty()) {
          warn(line.number, "keyword", "[MORE] without a preceding keyword; kept as [OTHER]");
          p.keywords.push_back({"OTHER", value});
        } else {
          p.keywords.back().value += "\n" + value;
        }
      } else {
        p.keywords.push_back({key, value});
      }
      continue;
    }
    warn(line.number, "keyword", "line is not a [KEYWORD]; kept as continuation of the previous one");
    if (p.keywords.empty()) p.keywords.push_back({"OTHER", detail::to_utf8(t)});
    else p.keywords.back().value += "\n" + detail::to_utf8(t);
  }
  if (!found_tilt)
    throw_at_line(name, std::max(1, cursor.number() - 1), "TILT",
                  "no line starting with 'TILT=' (every LM-63 file has one before the photometric data)");

  // The numbers start on the line after TILT= (the cursor stands there).
  NumberStream in(text, cursor.offset(), cursor.number(), name);

  // ---- TILT ----
  const std::string tilt_upper = upper(tilt_value);
  if (tilt_upper == "INCLUDE") {
    p.tilt = read_tilt_block(in, options.limits);
    p.tilt->source = "INCLUDE";
  } else if (tilt_upper != "NONE") {
    const std::string file(tilt_value);
    // Resolved only inside the IES file's own folder: no separators, no parent references, no drive.
    if (file.empty() || file.find('/') != std::string::npos || file.find('\\') != std::string::npos ||
        file.find(':') != std::string::npos || file == "." || file == "..")
      throw_at_line(name, tilt_line, "TILT",
                    "external TILT file '" + detail::excerpt(file, 200) + "' must be a plain file name in the IES file's folder");
    if (options.base_dir.empty())
      throw_at_line(name, tilt_line, "TILT",
                    "external TILT file '" + detail::excerpt(file, 200) + "' cannot be resolved: no folder given (read from memory)");
    const std::string path = options.base_dir + "/" + file;
    // A symbolic link could still lead out of the folder: the resolved file must live in it.
    std::error_code ec;
    const auto real_dir = std::filesystem::canonical(options.base_dir, ec);
    const auto real_file = ec ? std::filesystem::path() : std::filesystem::canonical(path, ec);
    if (ec)
      throw_at_line(name, tilt_line, "TILT", "external TILT file '" + detail::excerpt(file, 200) + "' not found");
    if (real_file.parent_path() != real_dir)
      throw_at_line(name, tilt_line, "TILT",
                    "external TILT file '" + detail::excerpt(file, 200) + "' resolves outside the IES file's folder");
    std::string tilt_text;
    try {
      tilt_text = read_file_bounded(path, 1u << 20);
    } catch (const Error& e) {
      throw_at_line(name, tilt_line, "TILT", "external TILT file: " + e.diagnostic().message);
    }
    NumberStream tin(tilt_text, detail::LineCursor(tilt_text).offset(), 1, path);
    p.tilt = read_tilt_block(tin, options.limits);
    p.tilt->source = file;
  }

  // ---- line 10 values: lamps, lumens, multiplier, counts, type, units, opening ----
  const long n_lamps = in.next_integer("number of lamps", 0, 1000000);
  if (n_lamps == 0) warn(in.last_line(), "number of lamps", "0 lamps; read as 1");
  const double lumens = in.next_number("lumens per lamp");
  const double multiplier = in.next_number("candela multiplier");
  if (!(multiplier > 0)) in.fail_at_last("candela multiplier", "must be positive");
  const long nv = in.next_count("number of vertical angles", 1, options.limits.max_angles, "ReadLimits::max_angles");
  if (nv < 2) in.fail_at_last("number of vertical angles", "at least 2 vertical angles are needed");
  const long nh = in.next_count("number of horizontal angles", 1, options.limits.max_angles, "ReadLimits::max_angles");
  const long type = in.next_integer("photometric type", 1, 3);
  const long units = in.next_integer("units type", 1, 2);
  const double width = in.next_number("luminous opening width");
  const double length = in.next_number("luminous opening length");
  const double height = in.next_number("luminous opening height");
  p.ballast_factor = in.next_number("ballast factor");
  p.ies_second_factor = in.next_number(p.source.version == file_format::kIes2019 ? "file generation type"
                                                                                 : "ballast-lamp photometric factor");
  p.input_watts = in.next_number("input watts");
  if (!(p.ballast_factor > 0)) warn(in.last_line(), "ballast factor", "not positive; reported as read");

  p.type = static_cast<PhotometricType>(type);
  p.units = static_cast<IesUnits>(units);
  const double to_m = p.units == IesUnits::feet ? kMetresPerFoot : 1.0;
  p.opening = {width * to_m, length * to_m, height * to_m};
  p.candela_multiplier = multiplier;

  LampSet lamp;
  lamp.count = static_cast<int>(std::max<long>(n_lamps, 1));
  if (const Keyword* k = p.find_keyword("LAMP")) lamp.type = k->value;
  lamp.watts = p.input_watts;
  if (lumens == -1.0) {
    p.absolute = true;
  } else if (lumens > 0) {
    lamp.flux_lm = lumens * static_cast<double>(std::max<long>(n_lamps, 1));
  } else {
    p.absolute = true;
    warn(in.last_line(), "lumens per lamp",
         "value " + num(lumens) + " is neither -1 nor positive; read as absolute photometry");
  }
  p.lamp_sets.push_back(lamp);

  // ---- angles ----
  const std::size_t nvs = static_cast<std::size_t>(nv), nhs = static_cast<std::size_t>(nh);
  p.vertical_deg = in.next_values(nvs, "vertical angle", &p.source.vertical_lines);
  p.horizontal_deg = in.next_values(nhs, "horizontal angle", &p.source.horizontal_lines);
  auto require_increasing = [&](const std::vector<double>& a, const std::vector<std::uint32_t>& lines,
                                const char* field) {
    for (std::size_t i = 1; i < a.size(); ++i)
      if (!(a[i] > a[i - 1]))
        throw_at_line(name, static_cast<int>(lines[i]), field,
                      "angles must strictly increase (value " + std::to_string(i + 1) + " is " + num(a[i]) +
                          " after " + num(a[i - 1]) + ")");
  };
  require_increasing(p.vertical_deg, p.source.vertical_lines, "vertical angle");
  require_increasing(p.horizontal_deg, p.source.horizontal_lines, "horizontal angle");
  const double vlo = p.type == PhotometricType::C ? 0.0 : -90.0, vhi = p.type == PhotometricType::C ? 180.0 : 90.0;
  if (p.vertical_deg.front() < vlo - 1e-9 || p.vertical_deg.back() > vhi + 1e-9)
    throw_at_line(name, static_cast<int>(p.source.vertical_lines.front()), "vertical angle",
                  "range " + num(p.vertical_deg.front()) + ".." + num(p.vertical_deg.back()) +
                      " outside " + num(vlo) + ".." + num(vhi) + " for Type " +
                      to_string(p.type));
  const double hlo = p.type == PhotometricType::C ? 0.0 : -180.0, hhi = p.type == PhotometricType::C ? 360.0 : 180.0;
  if (p.horizontal_deg.front() < hlo - 1e-9 || p.horizontal_deg.back() > hhi + 1e-9)
    throw_at_line(name, static_cast<int>(p.source.horizontal_lines.front()), "horizontal angle",
                  "range " + num(p.horizontal_deg.front()) + ".." +
                      num(p.horizontal_deg.back()) + " outside " + num(hlo) + ".." +
                      num(hhi) + " for Type " + to_string(p.type));
  const auto sym = symmetry_from_ies_range(p.type, p.horizontal_deg.front(), p.horizontal_deg.back(), nhs);
  if (!sym)
    throw_at_line(name, static_cast<int>(p.source.horizontal_lines.front()), "horizontal angle",
                  "range " + num(p.horizontal_deg.front()) + ".." +
                      num(p.horizontal_deg.back()) +
                      " states no LM-63 symmetry (Type C: a single 0, 0..90, 0..180, 90..270 or 0..360)");
  p.symmetry = *sym;
  if (p.type == PhotometricType::C && !(p.vertical_deg.front() == 0.0 || p.vertical_deg.front() == 90.0) )
    warn(static_cast<int>(p.source.vertical_lines.front()), "vertical angle",
         "first vertical angle is neither 0 nor 90; intensity below it is taken as 0");

  // ---- candela ----
  const std::size_t ncd = nvs * nhs;
  p.candela = in.next_values(ncd, "candela value", &p.source.candela_lines);
  for (std::size_t i = 0; i < ncd; ++i) {
    double& c = p.candela[i];
    c *= multiplier;
    if (!std::isfinite(c))  // finite value x finite multiplier can still overflow
      throw_at_line(name, static_cast<int>(p.source.candela_lines[i]),
                    "candela[h=" + std::to_string(i / nvs) + "][v=" + std::to_string(i % nvs) + "]",
                    "value times the candela multiplier overflows");
  }
  const detail::NegativeIntensities neg = detail::find_negative_intensities(p.candela, p.source.candela_lines);
  if (neg.bad != SIZE_MAX)
    throw_at_line(name, static_cast<int>(p.source.candela_lines[neg.bad]),
                  "candela[h=" + std::to_string(neg.bad / nvs) + "][v=" + std::to_string(neg.bad % nvs) + "]",
                  "negative intensity " + num(p.candela[neg.bad]) + " cd exceeds 0.1 % of the peak " +
                      num(neg.peak) + " cd");
  if (neg.count > 0)
    warn(neg.first_line, "candela value",
         std::to_string(neg.count) + " small negative value(s) (measurement noise, <= 0.1 % of peak) kept");
  if (in.remaining() > 0)
    warn(in.peek_line(), "candela value",
         std::to_string(in.remaining()) + " extra value(s) after the candela table ignored");
  return p;
}

LUMX_NAMESPACE_END
