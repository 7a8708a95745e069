// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Chooses a reader or writer by file extension, falling back to sniffing the content.
#include <lumx/io/atomic_file.h>
#include <lumx/io/photometry_io.h>
#include <lumx/io/tm33_io.h>

#include "io/text_scanner.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

LUMX_NAMESPACE_BEGIN
namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool looks_like_ies(std::string_view head) {
  const auto lines = detail::split_lines(head.substr(0, std::min<std::size_t>(head.size(), 1u << 16)));
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string_view t = detail::trim(lines[i].text);
    if (i == 0 && (t.rfind("IESNA", 0) == 0 || t.rfind("IES:", 0) == 0)) return true;
    if (t.rfind("TILT", 0) == 0 && t.find('=') != std::string_view::npos) return true;
  }
  return false;
}

/// EULUMDAT has no magic; its lines 2-7 are small numbers (Ityp, Isym, Mc, Dc, Ng, Dg).
bool looks_like_ldt(std::string_view head) {
  const auto lines = detail::split_lines(head.substr(0, std::min<std::size_t>(head.size(), 4096)));
  if (lines.size() < 8) return false;
  for (std::size_t i = 1; i <= 6; ++i) {
    std::string t(detail::trim(lines[i].text));
    std::replace(t.begin(), t.end(), ',', '.');
    double v = 0;
    if (!detail::parse_number(t, v)) return false;
  }
  return true;
}

/// TM-33: XML or its JSON form; the first non-blank byte (after a UTF-8 BOM) tells which.
std::optional<PhotometryFormat> looks_like_tm33(std::string_view head) {
  if (head.substr(0, 3) == "\xEF\xBB\xBF") head.remove_prefix(3);
  const std::size_t i = head.find_first_not_of(" \t\r\n");
  if (i == std::string_view::npos) return std::nullopt;
  if (head[i] == '<') return PhotometryFormat::tm33_xml;
  if (head[i] == '{') return PhotometryFormat::tm33_json;
  return std::nullopt;
}

}  // namespace

std::optional<PhotometryFormat> format_from_extension(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".ies") return PhotometryFormat::ies;
  if (ext == ".ldt") return PhotometryFormat::ldt;
  if (ext == ".xml") return PhotometryFormat::tm33_xml;
  if (ext == ".json") return PhotometryFormat::tm33_json;
  return std::nullopt;
}

PhotometryFormat detect_format(const std::string& path, std::string_view head) {
  if (const auto f = format_from_extension(path)) return *f;
  if (const auto f = looks_like_tm33(head)) return *f;
  if (looks_like_ies(head)) return PhotometryFormat::ies;
  if (looks_like_ldt(head)) return PhotometryFormat::ldt;
  Diagnostic d;
  d.file = path;
  d.line = 1;
  d.field = "format";
  d.message = "neither TM-33 (XML or JSON), IES LM-63 (no version or TILT= line) nor EULUMDAT (lines 2-7 are not numbers)";
  throw Error(std::move(d));
}

Photometry read_photometry(const std::string& path, const ReadOptions& options) {
  const std::string text = read_file_bounded(path, options.limits.max_file_bytes, "ReadLimits::max_file_bytes");
  ReadOptions opts = options;
  if (opts.base_dir.empty()) {
    const auto parent = std::filesystem::path(path).parent_path();
    opts.base_dir = parent.empty() ? "." : parent.string();
  }
  switch (detect_format(path, text)) {
    case PhotometryFormat::ies: return read_ies(text, path, opts);
    case PhotometryFormat::ldt: return read_ldt(text, path, opts);
    case PhotometryFormat::tm33_xml: return read_tm33_xml(text, path, opts);
    case PhotometryFormat::tm33_json: return read_tm33_json(text, path, opts);
  }
  return read_ldt(text, path, opts);
}

void write_photometry(const Photometry& p, const std::string& path, const WriteOptions& options) {
  const auto format = format_from_extension(path);
  if (!format) {
    Diagnostic d;
    d.file = path;
    d.field = "output format";
    d.message = "unknown extension '" + lower_extension(path) + "' (expected .ies, .ldt, or .xml / .json for TM-33)";
    throw Error(std::move(d));
  }
  std::string text;
  switch (*format) {
    case PhotometryFormat::ies: text = format_ies(p, options.ies); break;
    case PhotometryFormat::ldt: text = format_ldt(p, options.ldt); break;
    case PhotometryFormat::tm33_xml: text = format_tm33_xml(p, options.tm33); break;
    case PhotometryFormat::tm33_json: text = format_tm33_json(p, options.tm33); break;
  }
  write_file_atomically(path, text);
}

LUMX_NAMESPACE_END
