// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// IES LM-63 writer: LM-63-2019 by default, LM-63-2002 on request (formats.md §1).
//
// Candela values are written as absolute cd with multiplier 1. The stored subset is written with the
// horizontal range that states its symmetry (formats.md §1.4). Lines end in CR LF as the standard asks,
// and value lists are wrapped well below the 132/256-character line limits of the editions.
#include <lumx/io/photometry_io.h>
#include <lumx/photometry/symmetry.h>

#include "io/text_scanner.h"

#include <cmath>
#include <sstream>

LUMX_NAMESPACE_BEGIN
namespace {

constexpr const char* kEol = "\r\n";

[[noreturn]] void fail(const std::string& field, const std::string& msg) {
  Diagnostic d;
  d.field = field;
  d.message = msg;
  throw Error(std::move(d));
}

void write_list(std::ostringstream& out, const std::vector<double>& v, std::size_t begin, std::size_t end,
                int digits) {
  constexpr std::size_t kPerLine = 10;
  for (std::size_t i = begin, k = 0; i < end; ++i, ++k) {
    if (k > 0) out << (k % kPerLine == 0 ? kEol : " ");
    out << detail::format_number(v[i], digits);
  }
  out << kEol;
}

/// A keyword value, one physical line each: the first with [KEY], continuations with [MORE].
void write_keyword(std::ostringstream& out, const std::string& key, const std::string& value) {
  std::size_t start = 0;
  bool first = true;
  do {
    const std::size_t nl = value.find('\n', start);
    const std::string part = value.substr(start, nl == std::string::npos ? std::string::npos : nl - start);
    out << '[' << (first ? key : std::string("MORE")) << ']';
    if (!part.empty()) out << ' ' << part;
    out << kEol;
    first = false;
    start = nl == std::string::npos ? std::string::npos : nl + 1;
  } while (start != std::string::npos);
}

}  // namespace

std::string format_ies(const Photometry& p, const IesWriteOptions& options) {
  const std::size_t nv = p.vertical_deg.size();
  if (p.candela.size() != p.horizontal_deg.size() * nv || nv < 2 || p.horizontal_deg.empty())
    fail("candela", "table is " + std::to_string(p.candela.size()) + " values for " +
                        std::to_string(p.horizontal_deg.size()) + " x " + std::to_string(nv) + " angles");
  for (double c : p.candela)
    if (!std::isfinite(c)) fail("candela", "non-finite value");
  for (const auto* angles : {&p.vertical_deg, &p.horizontal_deg})
    for (std::size_t i = 0; i < angles->size(); ++i)
      if (!std::isfinite((*angles)[i]) || (i > 0 && !((*angles)[i] > (*angles)[i - 1])))
        fail(angles == &p.vertical_deg ? "vertical angle" : "horizontal angle",
             "angles must be finite and strictly increasing");
  double first = 0, last = 0;
  if (p.type == PhotometricType::C && stored_range(p.symmetry, first, last) &&
      (std::abs(p.horizontal_deg.front() - first) > 1e-9 || std::abs(p.horizontal_deg.back() - last) > 1e-9))
    fail("horizontal angle", std::string("stored planes do not span the range of symmetry ") + to_string(p.symmetry));
  const int digits = options.significant_digits;

  // Horizontal planes as IES states them: a Type C table with no symmetry must run 0..360.
  AngleTable table = stored_table(p);
  Symmetry symmetry = p.symmetry;
  if (p.type == PhotometricType::C && symmetry == Symmetry::plane_c90_c270 && options.expand_c90_c270) {
    table = expand(table, symmetry);  // 0..<360, closed to 360 below
    symmetry = Symmetry::none;
  }
  if (p.type == PhotometricType::C && symmetry == Symmetry::none) {
    if (std::abs(table.horizontal_deg.front()) > 1e-9)
      fail("horizontal angle", "a Type C table without symmetry must start at C0");
    if (std::abs(table.horizontal_deg.back() - 360.0) > 1e-9) {
      table.horizontal_deg.push_back(360.0);  // close the circle with a copy of C0
      const std::vector<double> c0(table.candela.begin(), table.candela.begin() + static_cast<long>(nv));
      table.candela.insert(table.candela.end(), c0.begin(), c0.end());
    }
  }
  const std::size_t nh = table.horizontal_deg.size();

  std::ostringstream out;
  out << (options.version == IesVersion::lm63_2019 ? "IES:LM-63-2019" : "IESNA:LM-63-2002") << kEol;

  // Keywords: the file's own, else those derived from EULUMDAT fields; the required ones always present.
  std::vector<Keyword> kw;
  for (const auto& k : p.keywords) kw.push_back({k.name.empty() ? "OTHER" : k.name, k.value});
  auto ensure = [&](const std::string& key, const std::string& value) {
    for (const auto& k : kw)
      if (k.name == key) return;
    kw.push_back({key, value});
  };
  ensure("TEST", p.ldt.report_number);
  ensure("TESTLAB", "");
  ensure("ISSUEDATE", p.ldt.date_user);
  ensure("MANUFAC", p.ldt.company);
  if (!p.ldt.luminaire_name.empty()) ensure("LUMINAIRE", p.ldt.luminaire_name);
  if (!p.ldt.luminaire_number.empty()) ensure("LUMCAT", p.ldt.luminaire_number);
  if (!p.lamp_sets.empty() && !p.lamp_sets.front().type.empty()) ensure("LAMP", p.lamp_sets.front().type);
  if (options.version == IesVersion::lm63_2019 && !p.source.version.empty() && p.source.version != file_format::kIes2019)
    ensure("FILEGENINFO", "Converted by lumx " + std::string(kLibraryVersion) + " from " +
                              (p.source.format == "IES" ? "IES " + p.source.version : p.source.format));
  for (const auto& k : kw) write_keyword(out, k.name, k.value);

  if (p.tilt) {
    const TiltTable& t = *p.tilt;
    if (t.angles_deg.size() != t.multipliers.size() || t.angles_deg.empty())
      fail("TILT", "angle and multiplier counts differ or are zero");
    out << "TILT=INCLUDE" << kEol << t.lamp_geometry << kEol << t.angles_deg.size() << kEol;
    write_list(out, t.angles_deg, 0, t.angles_deg.size(), digits);
    write_list(out, t.multipliers, 0, t.multipliers.size(), digits);
  } else {
    out << "TILT=NONE" << kEol;
  }

  const int lamps = std::max(1, p.lamp_count());
  const double lumens = p.absolute ? -1.0 : p.rated_lamp_flux_lm() / lamps;
  const double from_m = p.units == IesUnits::feet ? 1.0 / kMetresPerFoot : 1.0;
  out << lamps << ' ' << detail::format_number(lumens, digits) << " 1 " << nv << ' ' << nh << ' '
      << static_cast<int>(p.type) << ' ' << static_cast<int>(p.units) << ' '
      << detail::format_number(p.opening.width_m * from_m, digits) << ' '
      << detail::format_number(p.opening.length_m * from_m, digits) << ' '
      << detail::format_number(p.opening.height_m * from_m, digits) << kEol;
  double second = p.ies_second_factor;
  if (options.version == IesVersion::lm63_2019) {
    if (p.source.version != file_format::kIes2019 || !is_lm63_2019_file_generation_type(second)) second = 1.00001;
  } else if (p.source.version == file_format::kIes2019) {
    second = 1.0;  // "future use" in 2002
  }
  out << detail::format_number(p.ballast_factor, digits) << ' ' << detail::format_number(second, 6) << ' '
      << detail::format_number(p.input_watts, digits) << kEol;
  write_list(out, table.vertical_deg, 0, nv, digits);
  write_list(out, table.horizontal_deg, 0, nh, digits);
  for (std::size_t ih = 0; ih < nh; ++ih) write_list(out, table.candela, ih * nv, (ih + 1) * nv, digits);
  return out.str();
}

LUMX_NAMESPACE_END
