// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Chooses a rayset reader by extension and content, and the operations every RaySource supports:
// summarising its rays and reading them all.
#include "io/rays/rayset_common.h"
#include "io/text_scanner.h"

#include <algorithm>
#include <filesystem>

LUMX_NAMESPACE_BEGIN

const char* to_string(RaysetFormat f) {
  switch (f) {
    case RaysetFormat::tm25:
      return "TM-25";
    case RaysetFormat::lighttools_binary:
      return "LightTools binary";
    case RaysetFormat::lighttools_text:
      return "LightTools text";
    case RaysetFormat::zemax_binary:
      return "Zemax binary";
    case RaysetFormat::zemax_text:
      return "Zemax text";
    case RaysetFormat::plain_text:
      return "plain text";
  }
  return "unknown";
}

namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

/// Numbers on a line (blanks, tabs or commas between them), or −1 if a token is not a number.
int count_numbers(std::string_view line) {
  int n = 0;
  std::size_t i = 0;
  const auto sep = [](char c) { return c == ' ' || c == '\t' || c == ','; };
  while (i < line.size()) {
    while (i < line.size() && sep(line[i])) ++i;
    std::size_t j = i;
    while (j < line.size() && !sep(line[j])) ++j;
    if (j == i) break;
    double v = 0;
    if (!detail::parse_number(line.substr(i, j - i), v)) return -1;
    ++n;
    i = j;
  }
  return n;
}

std::optional<RaysetFormat> sniff(const detail::RayFile& f) {
  char head[4096];
  const std::size_t n = f.read_some(0, head, sizeof head);
  const std::string_view h(head, n);
  if (h.substr(0, 4) == "TM25") return RaysetFormat::tm25;
  if (h.substr(0, 4) == "LTRF") return RaysetFormat::lighttools_binary;
  if (n >= 8 && detail::le_i32(reinterpret_cast<const unsigned char*>(head)) == 1010) return RaysetFormat::zemax_binary;
  if (h.find('\0') != std::string_view::npos) return std::nullopt;
  // Text: the first non-blank lines (a partial last line of the window is not used).
  std::vector<std::string_view> lines;
  std::size_t pos = 0;
  if (h.substr(0, 3) == "\xEF\xBB\xBF") pos = 3;
  while (pos < h.size() && lines.size() < 12) {
    std::size_t e = h.find_first_of("\r\n", pos);
    if (e == std::string_view::npos) {
      if (n < sizeof head) lines.push_back(detail::trim_blanks(h.substr(pos)));
      break;
    }
    const std::string_view t = detail::trim_blanks(h.substr(pos, e - pos));
    if (!t.empty()) lines.push_back(t);
    pos = e + 1;
  }
  if (lines.empty()) return std::nullopt;
  if (lines[0].rfind("# lumx-rays", 0) == 0) return RaysetFormat::plain_text;
  for (const auto& l : lines)
    if (l.rfind("lt_rdf_version", 0) == 0 || l == "lt_startofdata") return RaysetFormat::lighttools_text;
  if (lines[0].rfind("# LightTools", 0) == 0) return RaysetFormat::lighttools_text;
  if (lines.size() >= 2) {
    const int head_numbers = count_numbers(lines[0]);
    const int ray_numbers = count_numbers(lines[1]);
    if (head_numbers >= 2 && (ray_numbers == 7 || ray_numbers == 8)) return RaysetFormat::zemax_text;
  }
  return std::nullopt;
}

std::optional<RaysetFormat> format_of(const detail::RayFile& f, const std::string& path) {
  if (lower_extension(path) == ".tm25ray") return RaysetFormat::tm25;
  return sniff(f);
}

}  // namespace

std::optional<RaysetFormat> detect_rayset_format(const std::string& path) {
  try {
    const detail::RayFile f(path);
    return format_of(f, path);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::unique_ptr<RaySource> open_rayset(const std::string& path, const RaysetReadOptions& options) {
  auto file = std::make_shared<const detail::RayFile>(path);
  const auto format = options.format ? options.format : format_of(*file, path);
  if (!format)
    throw_at_offset(path, 0, "format",
                            "not a rayset lumx reads (TM-25, LightTools binary or text, Zemax binary or text, or "
                            "'# lumx-rays' plain text)");
  switch (*format) {
    case RaysetFormat::tm25:
      return detail::open_tm25(std::move(file), options);
    case RaysetFormat::lighttools_binary:
      return detail::open_lighttools_binary(std::move(file), options);
    case RaysetFormat::lighttools_text:
      return detail::open_lighttools_text(std::move(file), options);
    case RaysetFormat::zemax_binary:
      return detail::open_zemax_binary(std::move(file), options);
    case RaysetFormat::zemax_text:
      return detail::open_zemax_text(std::move(file), options);
    case RaysetFormat::plain_text:
      return detail::open_plain_rays(std::move(file), options);
  }
  throw_at_offset(path, 0, "format", "unknown format");
}

RaysetSummary summarize_rays(RaySource& rays, std::size_t chunk_rays) {
  chunk_rays = std::max<std::size_t>(chunk_rays, 1);
  RaysetSummary s;
  RayChunk c;
  double sum = 0, comp = 0;
  rays.rewind();
  while (rays.next(c, chunk_rays)) {
    for (std::size_t i = 0; i < c.size(); ++i) {
      const double f = c.flux[i];
      const double t = sum + f;
      comp += std::abs(sum) >= std::abs(f) ? (sum - t) + f : (f - t) + sum;
      sum = t;
      s.zero_flux_rays += c.flux[i] == 0;
      const glm::dvec3 p(c.x[i], c.y[i], c.z[i]);
      s.lo = glm::min(s.lo, p);
      s.hi = glm::max(s.hi, p);
    }
    s.rays += c.size();
  }
  s.flux_sum = sum + comp;
  if (s.rays == 0) return s;
  // Second pass: the radius about the box's centre.
  s.bounds.center = 0.5 * (s.lo + s.hi);
  double r2 = 0;
  rays.rewind();
  while (rays.next(c, chunk_rays))
    for (std::size_t i = 0; i < c.size(); ++i) {
      const glm::dvec3 d = glm::dvec3(c.x[i], c.y[i], c.z[i]) - s.bounds.center;
      r2 = std::max(r2, glm::dot(d, d));
    }
  s.bounds.radius = std::sqrt(r2);
  return s;
}

RayChunk read_all_rays(RaySource& rays, std::uint64_t max_rays) {
  const RaysetInfo& info = rays.info();
  if (info.ray_count > max_rays)
    throw_at_field(info.file, "number of rays",
                   std::to_string(info.ray_count) + " rays are more than the " + std::to_string(max_rays) +
                       " the caller accepts in memory");
  RayChunk all, c;
  all.reserve(static_cast<std::size_t>(info.ray_count));
  rays.rewind();
  while (rays.next(c, 65536)) {
    if (all.size() + c.size() > max_rays)
      throw_at_field(info.file, "number of rays",
                     "more than the " + std::to_string(max_rays) + " rays the caller accepts in memory");
    if (!c.wavelength_nm.empty() && all.wavelength_nm.size() != all.size())
      throw_at_field(info.file, "wavelength", "some chunks carry wavelengths and others do not");
    for (auto [dst, src] : {std::pair{&all.x, &c.x},
                            {&all.y, &c.y},
                            {&all.z, &c.z},
                            {&all.dx, &c.dx},
                            {&all.dy, &c.dy},
                            {&all.dz, &c.dz},
                            {&all.flux, &c.flux},
                            {&all.wavelength_nm, &c.wavelength_nm}})
      dst->insert(dst->end(), src->begin(), src->end());
  }
  return all;
}

LUMX_NAMESPACE_END
