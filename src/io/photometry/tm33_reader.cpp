// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// IES TM-33 / ATLA S001 reader: the element tree (tm33_tree.h) mapped to the photometry model.
//
// Field by field mapping and document versions: docs/tm33.md. Elements with no place in the model are
// kept as data (Photometry::tm33.kept) with the path of their parent; the writer puts them back.
#include <lumx/io/tm33_io.h>
#include <lumx/photometry/symmetry.h>
#include <lumx/version.h>

#include "io/photometry/tm33_fields.h"
#include "io/photometry/tm33_tree.h"
#include "io/text_scanner.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

LUMX_NAMESPACE_BEGIN
namespace {

using detail::Tm33Node;

class Tm33Parser {
 public:
  Tm33Parser(const std::string& file, const ReadOptions& options, bool json)
      : file_(file), opt_(options), json_(json) {}

  Photometry parse(const Tm33Node& root);

 private:
  [[noreturn]] void fail(const Tm33Node& n, const std::string& field, const std::string& msg) const {
    if (json_) throw_at_field(file_, n.pointer.empty() ? field : n.pointer, msg);
    throw_at_line(file_, n.line, field, msg);
  }
  void warn(const Tm33Node& n, const std::string& field, const std::string& msg) const {
    if (!opt_.warnings) return;
    Diagnostic d;
    d.severity = Severity::warning;
    d.file = file_;
    d.line = json_ ? 0 : n.line;
    d.field = json_ ? n.pointer : field;
    d.message = msg;
    opt_.warnings(d);
  }
  double number(const Tm33Node& n) const {
    double v = 0;
    const std::string_view t = detail::trim_space(n.text);
    if (!detail::parse_number(t, v)) fail(n, n.name, "'" + detail::excerpt(t) + "' is not a finite number");
    return v;
  }
  double attribute_number(const Tm33Node& n, const char* name) const {
    for (const auto& [k, v] : n.attributes)
      if (k == name) {
        double d = 0;
        if (!detail::parse_number(detail::trim_space(v), d))
          fail(n, n.name + "@" + name, "attribute " + std::string(name) + "='" + detail::excerpt(v) + "' is not a finite number");
        return d;
      }
    fail(n, n.name + "@" + name, std::string("attribute '") + name + "' is missing");
  }
  /// `limit_name` names the option `hi` comes from, if it does ("ReadLimits::max_angles").
  long integer(const Tm33Node& n, long lo, long hi, const char* limit_name = nullptr) const {
    const double v = number(n);
    if (v != std::floor(v) || v < static_cast<double>(lo) || v > static_cast<double>(hi))
      fail(n, n.name, "'" + detail::excerpt(detail::trim_space(n.text)) + "' is not an integer in " + std::to_string(lo) +
                          ".." + std::to_string(hi) +
                          (limit_name && v > static_cast<double>(hi) ? std::string(" (") + limit_name + ")" : ""));
    return static_cast<long>(v);
  }
  bool boolean(const Tm33Node& n) const {
    std::string t(detail::trim_space(n.text));
    for (char& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (t == "true" || t == "1") return true;
    if (t == "false" || t == "0") return false;
    fail(n, n.name, "'" + detail::excerpt(n.text) + "' is not a boolean (true, false, 1 or 0)");
  }
  std::string text(const Tm33Node& n) const { return std::string(detail::trim_space(n.text)); }
  void keep(Photometry& p, const std::string& parent, const Tm33Node& n) const {
    p.tm33.kept.push_back({parent, detail::to_data_element(n)});
  }

  void read_header(Photometry& p, const Tm33Node& h);
  void read_luminaire(Photometry& p, const Tm33Node& l);
  void read_emitter(Photometry& p, const Tm33Node& e, std::size_t index);
  void read_intensity(Photometry& p, const Tm33Node& li, double rated_lm);
  void read_lm63_block(Photometry& p, const Tm33Node& c);
  void read_eulumdat_block(Photometry& p, const Tm33Node& c);

  const std::string& file_;
  const ReadOptions& opt_;
  bool json_;
  bool have_table_ = false;
  bool have_lm63_ = false, have_eulumdat_ = false;
  std::vector<std::string> header_keywords_;  // mapped header keywords, first of each
  std::vector<Keyword> header_kw_, comments_;
  std::vector<Keyword> extra_kw_;
  std::optional<LuminousOpening> opening_from_areas_;
  double dims_m_[3] = {0, 0, 0};
  bool have_dims_ = false;
  std::optional<double> input_watts_;
  std::string header_from_fields_;  // header keywords a writer derived from EULUMDAT fields
};

void Tm33Parser::read_header(Photometry& p, const Tm33Node& h) {
  std::set<std::string> seen;
  for (const auto& c : h.children) {
    const char* kw = tm33::header_keyword(c.name);
    if (c.name == "Comment") {
      if (!text(c).empty()) comments_.push_back({"OTHER", text(c)});
    } else if (kw && seen.insert(c.name).second) {
      if (!text(c).empty()) header_kw_.push_back({kw, text(c)});
    } else {
      keep(p, "Header", c);
    }
  }
}

void Tm33Parser::read_luminaire(Photometry& p, const Tm33Node& l) {
  for (const auto& c : l.children) {
    if (c.name == "Dimensions") {
      const char* names[3] = {"Length", "Width", "Height"};
      for (int i = 0; i < 3; ++i)
        if (const Tm33Node* d = c.child(names[i])) dims_m_[i] = number(*d);
      have_dims_ = true;
    } else if (c.name == "NumEmitter") {
      (void)integer(c, 0, 1000000);  // checked against the emitters after reading them
    } else {
      keep(p, "Luminaire", c);
    }
  }
}

void Tm33Parser::read_intensity(Photometry& p, const Tm33Node& li, double rated_lm) {
  const std::size_t max_angles = opt_.limits.max_angles;
  std::optional<long> nh_decl, nv_decl, nm_decl;
  std::string symm;
  const Tm33Node* symm_node = &li;
  double multiplier = 1;
  std::optional<bool> absolute;
  std::vector<const Tm33Node*> data;
  for (const auto& c : li.children) {
    if (c.name == "IntData") data.push_back(&c);
    else if (c.name == "NumberHorz") nh_decl = integer(c, 1, static_cast<long>(max_angles), "ReadLimits::max_angles");
    else if (c.name == "NumberVert") nv_decl = integer(c, 1, static_cast<long>(max_angles), "ReadLimits::max_angles");
    else if (c.name == "NumberMeasured") nm_decl = integer(c, 1, static_cast<long>(max_angles * max_angles), "ReadLimits::max_angles squared");
    else if (c.name == "Multiplier") {
      multiplier = number(c);
      if (!(multiplier > 0)) fail(c, c.name, "must be positive");
    } else if (c.name == "AbsolutePhotometry" || c.name == "Absolute") absolute = boolean(c);
    else if (c.name == "Symm") {
      symm = text(c);
      symm_node = &c;
    } else keep(p, "Emitter[0]/LuminousData/LuminousIntensity", c);
  }
  if (data.empty()) fail(li, li.name, "no IntData values");
  if (nm_decl && static_cast<std::size_t>(*nm_decl) != data.size())
    fail(li, "NumberMeasured", "states " + std::to_string(*nm_decl) + " values but " + std::to_string(data.size()) +
                                   " IntData elements follow");
  // Distinct angles, bounded by the values actually present (never by a stated count).
  std::vector<double> hs, vs;
  hs.reserve(std::min(data.size(), max_angles + 1));
  std::vector<std::pair<double, double>> hv(data.size());
  for (std::size_t i = 0; i < data.size(); ++i) hv[i] = {attribute_number(*data[i], "h"), attribute_number(*data[i], "v")};
  for (const auto& [h, v] : hv) {
    hs.push_back(h);
    vs.push_back(v);
  }
  auto unique_sorted = [](std::vector<double>& a) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  };
  unique_sorted(hs);
  unique_sorted(vs);
  if (hs.size() > max_angles) fail(li, "IntData@h", std::to_string(hs.size()) + " horizontal angles exceed ReadLimits::max_angles (" + std::to_string(max_angles) + ")");
  if (vs.size() > max_angles) fail(li, "IntData@v", std::to_string(vs.size()) + " vertical angles exceed ReadLimits::max_angles (" + std::to_string(max_angles) + ")");
  if (nh_decl && static_cast<std::size_t>(*nh_decl) != hs.size())
    fail(*li.child("NumberHorz"), "NumberHorz", "states " + std::to_string(*nh_decl) + " horizontal angles but IntData has " + std::to_string(hs.size()));
  if (nv_decl && static_cast<std::size_t>(*nv_decl) != vs.size())
    fail(*li.child("NumberVert"), "NumberVert", "states " + std::to_string(*nv_decl) + " vertical angles but IntData has " + std::to_string(vs.size()));
  if (vs.size() < 2) fail(li, "IntData@v", "at least 2 vertical angles are needed");
  if (hs.size() * vs.size() != data.size())
    fail(li, "IntData", std::to_string(data.size()) + " values do not fill the " + std::to_string(hs.size()) + " x " +
                            std::to_string(vs.size()) + " grid of their angles (missing or repeated pairs)");
  const std::size_t nv = vs.size();
  std::vector<double> candela(data.size(), 0.0);
  std::vector<char> filled(data.size(), 0);
  std::vector<std::uint32_t> lines(json_ ? 0 : data.size(), 0);
  for (std::size_t i = 0; i < data.size(); ++i) {
    const std::size_t ih = static_cast<std::size_t>(std::lower_bound(hs.begin(), hs.end(), hv[i].first) - hs.begin());
    const std::size_t iv = static_cast<std::size_t>(std::lower_bound(vs.begin(), vs.end(), hv[i].second) - vs.begin());
    const std::size_t k = ih * nv + iv;
    if (filled[k]) fail(*data[i], "IntData", "angle pair (h " + detail::format_number(hv[i].first, 10) + ", v " +
                                                 detail::format_number(hv[i].second, 10) + ") appears twice");
    filled[k] = 1;
    const double cd = number(*data[i]) * multiplier;
    if (!std::isfinite(cd)) fail(*data[i], "IntData", "value times Multiplier is not finite");
    if (cd < 0) warn(*data[i], "IntData", "negative intensity " + detail::format_number(cd, 7) + " cd");
    candela[k] = cd;
    if (!json_) lines[k] = static_cast<std::uint32_t>(std::max(0, data[i]->line));
  }
  p.horizontal_deg = hs;
  p.vertical_deg = vs;
  p.candela = std::move(candela);
  p.candela_multiplier = multiplier;
  if (!json_) p.source.candela_lines = std::move(lines);
  if (absolute) p.absolute = *absolute;
  else p.absolute = !(rated_lm > 0);

  // Symmetry: TM-33-23 states it (Symm); TM-33-18 implies it by the horizontal range, as LM-63 does.
  std::string s;
  for (char c : symm)
    if (c != ' ') s += c;
  const double first = hs.front(), last = hs.back();
  std::optional<Symmetry> sym;
  if (p.type == PhotometricType::C && !s.empty() && s != "Symm_Arbitrary") {
    if (s == "Symm_None") sym = Symmetry::none;
    else if (s == "Symm_Full") sym = Symmetry::rotational;
    else if (s == "Symm_Bi_0") sym = Symmetry::plane_c0_c180;
    else if (s == "Symm_Bi_90") sym = Symmetry::plane_c90_c270;
    else if (s == "Symm_Quad") sym = Symmetry::quadrant;
    else fail(*symm_node, "Symm", "'" + detail::excerpt(symm) + "' is not one of Symm_None, Symm_Bi_0, Symm_Bi_90, Symm_Quad, Symm_Full, Symm_Arbitrary");
    if (*sym == Symmetry::plane_c90_c270 && !(first == 90 && last == 270) && first >= 0 && last <= 360) {
      // Stored as C270..C360 and C0..C90: the mirror I(C) = I(180 - C) gives the model's C90..C270.
      AngleTable t{p.horizontal_deg, p.vertical_deg, p.candela}, m;
      m.vertical_deg = t.vertical_deg;
      for (std::size_t i = 0; i < t.horizontal_deg.size(); ++i)
        detail::append_plane(m, detail::wrap360(180.0 - t.horizontal_deg[i] + 360.0), t, i);
      m = detail::sort_planes(m);
      p.horizontal_deg = m.horizontal_deg;
      p.candela = m.candela;
      p.source.candela_lines.clear();
    }
    double a = 0, b = 0;
    if (*sym == Symmetry::none) {
      if (p.horizontal_deg.front() != 0 || p.horizontal_deg.back() > 360)
        fail(*symm_node, "Symm", "Symm_None needs horizontal angles from 0 up to at most 360");
    } else if (stored_range(*sym, a, b) &&
               (p.horizontal_deg.front() != a || p.horizontal_deg.back() != b)) {
      fail(*symm_node, "Symm", symm + " needs horizontal angles " + detail::format_number(a, 6) + ".." +
                                   detail::format_number(b, 6) + ", the IntData run " +
                                   detail::format_number(p.horizontal_deg.front(), 6) + ".." +
                                   detail::format_number(p.horizontal_deg.back(), 6));
    }
  } else {
    sym = symmetry_from_ies_range(p.type, first, last, hs.size());
    if (!sym && p.type == PhotometricType::C && first == 0 && last < 360) sym = Symmetry::none;  // 0..345 style
    if (!sym)
      fail(li, "IntData@h", "horizontal angles " + detail::format_number(first, 6) + ".." + detail::format_number(last, 6) +
                                " imply no symmetry (expected 0, 0..90, 0..180, 90..270 or 0..360)");
  }
  p.symmetry = *sym;
}

void Tm33Parser::read_emitter(Photometry& p, const Tm33Node& e, std::size_t index) {
  const std::string path = "Emitter[" + std::to_string(index) + "]";
  LampSet lamp;
  lamp.count = 1;
  double rated = 0;
  const bool first_table = !have_table_;
  for (const auto& c : e.children) {
    if (c.name == "Quantity") lamp.count = static_cast<int>(integer(c, 0, 1000000));
    else if (c.name == "Description") lamp.type = text(c);
    else if (c.name == "RatedLumens") {
      rated = number(c);
      if (rated < 0) fail(c, c.name, "negative rated flux");
    } else if (c.name == "InputWattage") lamp.watts = number(c);
    else if (c.name == "BallastFactor" && index == 0) p.ballast_factor = number(c);
    else if (c.name == "TiltAngles" && index == 0) {
      TiltTable t;
      std::optional<long> declared;
      for (const auto& a : c.children) {
        if (a.name == "NumberAngles") declared = integer(a, 1, static_cast<long>(opt_.limits.max_angles), "ReadLimits::max_angles");
        else if (a.name == "Tilt") {
          if (t.angles_deg.size() >= opt_.limits.max_angles) fail(a, "Tilt", "more tilt angles than ReadLimits::max_angles (" + std::to_string(opt_.limits.max_angles) + ")");
          t.angles_deg.push_back(attribute_number(a, "angle"));
          t.multipliers.push_back(number(a));
        }
      }
      if (t.angles_deg.empty()) fail(c, "TiltAngles", "no Tilt values");
      if (declared && static_cast<std::size_t>(*declared) != t.angles_deg.size())
        fail(c, "NumberAngles", "states " + std::to_string(*declared) + " angles but " + std::to_string(t.angles_deg.size()) + " Tilt elements follow");
      for (std::size_t i = 1; i < t.angles_deg.size(); ++i)
        if (!(t.angles_deg[i] > t.angles_deg[i - 1])) fail(c, "Tilt@angle", "tilt angles must increase");
      p.tilt = t;
    } else if (c.name == "LuminousData" && first_table && !have_table_) {
      const Tm33Node* li = c.child("LuminousIntensity");
      if (!li) fail(c, "LuminousIntensity", "LuminousData without LuminousIntensity");
      // Without AbsolutePhotometry, the table is absolute when this emitter states no rated flux.
      double rated_here = 0;
      for (const auto& d : e.children)
        if (d.name == "RatedLumens") rated_here = number(d);
      read_intensity(p, *li, rated_here);
      have_table_ = true;
      for (const auto& d : c.children) {
        if (d.name == "LuminousIntensity") continue;
        if (d.name == "LuminousFlux") p.tm33.luminous_flux_lm = number(d);
        else keep(p, path + "/LuminousData", d);
      }
    } else {
      if (c.name == "LuminousData") warn(c, "LuminousData", "a second luminous intensity table is kept as data; lumx maps the first");
      if (c.name == "EmissionAreas" && !opening_from_areas_) {
        // A single bottom area, rectangular or circular, is an LM-63 luminous opening.
        const Tm33Node* bottom = c.child("BottomFace");
        const Tm33Node* area = bottom ? bottom->child("BottomArea") : nullptr;
        if (area && area->child("Length") && area->child("Width")) {
          const double len = number(*area->child("Length")), wid = number(*area->child("Width"));
          const bool round = area->child("Circular") && boolean(*area->child("Circular"));
          opening_from_areas_ = round ? LuminousOpening{-wid, -len, 0} : LuminousOpening{wid, len, 0};
        }
      }
      if (c.name == "ColorTemperature" && lamp.color.empty())
        if (const Tm33Node* f = c.child("FixedCCT")) lamp.color = text(*f);
      if (c.name == "ColorRendering" && lamp.cri.empty()) {
        const Tm33Node* cri = c.child("CIE_CRI");
        const Tm33Node* ra = cri ? cri->child("Ra") : c.child("Ra");
        if (ra) lamp.cri = text(*ra);
      }
      keep(p, path, c);
    }
  }
  lamp.flux_lm = rated * std::max(1, lamp.count);
  p.lamp_sets.push_back(lamp);
}

void Tm33Parser::read_lm63_block(Photometry& p, const Tm33Node& c) {
  have_lm63_ = true;
  for (const auto& d : c.children) {
    if (d.name == "Keyword") {
      std::string name;
      for (const auto& [k, v] : d.attributes)
        if (k == "name") name = v;
      extra_kw_.push_back({name, d.text});
    } else if (d.name == "SecondFactor") p.ies_second_factor = number(d);
    else if (d.name == "InputWatts") input_watts_ = number(d);
    else if (d.name == "Units") p.units = text(d) == "feet" ? IesUnits::feet : IesUnits::metres;
    else if (d.name == "LuminousOpening")
      p.opening = {attribute_number(d, "width"), attribute_number(d, "length"), attribute_number(d, "height")};
    else if (d.name == "TiltLampGeometry" && p.tilt) p.tilt->lamp_geometry = static_cast<int>(integer(d, 1, 3));
    else if (d.name == "TiltSource" && p.tilt) p.tilt->source = d.text;
  }
}

void Tm33Parser::read_eulumdat_block(Photometry& p, const Tm33Node& c) {
  have_eulumdat_ = true;
  LdtHeader& h = p.ldt;
  for (const auto& d : c.children) {
    const std::string& n = d.name;
    if (n == "Company") h.company = d.text;
    else if (n == "HeaderFromFields") header_from_fields_ = d.text;
    else if (n == "Ityp") h.ityp = static_cast<int>(integer(d, 0, 3));
    else if (n == "ReportNumber") h.report_number = d.text;
    else if (n == "LuminaireName") h.luminaire_name = d.text;
    else if (n == "LuminaireNumber") h.luminaire_number = d.text;
    else if (n == "FileName") h.file_name = d.text;
    else if (n == "DateUser") h.date_user = d.text;
    else if (n == "LuminaireLength") h.luminaire_length_mm = number(d);
    else if (n == "LuminaireWidth") h.luminaire_width_mm = number(d);
    else if (n == "LuminaireHeight") h.luminaire_height_mm = number(d);
    else if (n == "AreaLength") h.area_length_mm = number(d);
    else if (n == "AreaWidth") h.area_width_mm = number(d);
    else if (n == "AreaHeightC0") h.area_height_mm[0] = number(d);
    else if (n == "AreaHeightC90") h.area_height_mm[1] = number(d);
    else if (n == "AreaHeightC180") h.area_height_mm[2] = number(d);
    else if (n == "AreaHeightC270") h.area_height_mm[3] = number(d);
    else if (n == "DFF") h.dff_percent = number(d);
    else if (n == "LOR") h.lor_percent = number(d);
    else if (n == "ConversionFactor") h.conversion_factor = number(d);
    else if (n == "Tilt") h.tilt_deg = number(d);
    else if (n == "DirectRatios") {
      h.direct_ratios.clear();
      const std::string t = d.text;
      std::size_t i = 0;
      while (i < t.size() && h.direct_ratios.size() < 10) {
        while (i < t.size() && t[i] == ' ') ++i;
        std::size_t j = i;
        while (j < t.size() && t[j] != ' ') ++j;
        if (j > i) {
          double v = 0;
          if (!detail::parse_number(std::string_view(t).substr(i, j - i), v)) fail(d, n, "not a list of numbers");
          h.direct_ratios.push_back(v);
        }
        i = j;
      }
    } else if (n == "LampSet") {
      long idx = -1;
      for (const auto& [k, v] : d.attributes)
        if (k == "index") {
          double x = 0;
          if (detail::parse_number(v, x) && x >= 0 && x < 1e6 && x == std::floor(x)) idx = static_cast<long>(x);
        }
      if (idx < 0 || static_cast<std::size_t>(idx) >= p.lamp_sets.size())
        fail(d, "LampSet@index", "does not name one of the " + std::to_string(p.lamp_sets.size()) + " emitters");
      LampSet& ls = p.lamp_sets[static_cast<std::size_t>(idx)];
      if (const Tm33Node* x = d.child("Color")) ls.color = x->text;
      if (const Tm33Node* x = d.child("CRI")) ls.cri = x->text;
      if (const Tm33Node* x = d.child("Count")) ls.count = static_cast<int>(integer(*x, -1000000, 1000000));
      if (const Tm33Node* x = d.child("Flux")) ls.flux_lm = number(*x);
    }
  }
}

Photometry Tm33Parser::parse(const Tm33Node& root) {
  if (root.name != "IESTM33" && root.name != "IESTM33-22" && root.name != "LuminaireOpticalData")
    fail(root, "root", "'" + detail::excerpt(root.name) +
                           "' is not a TM-33 root element (IESTM33, IESTM33-22 or LuminaireOpticalData)");
  Photometry p;
  p.source.file = file_;
  p.source.format = "TM-33";
  p.tm33.root = root.name;
  for (const auto& [k, v] : root.attributes)
    if (k == "version") p.tm33.version = v;
  if (const Tm33Node* v = root.child("Version")) p.tm33.version = text(*v);
  p.source.version = (root.name == "IESTM33-22" || p.tm33.version == "1.1") ? file_format::kTm33_23 : file_format::kTm33_18;

  // Equipment first: the goniometer type decides the photometric type of the table.
  if (const Tm33Node* eq = root.child("Equipment")) {
    const Tm33Node* g = eq->child("Gonioradiometer");
    if (!g) g = eq->child("Goniometer");
    const Tm33Node* t = g ? g->child("Type") : nullptr;
    if (t) {
      std::string s;
      for (char c : text(*t))
        if (c != ' ') s += c;
      p.tm33.goniometer_type = s;
      const char last = s.empty() ? 'C' : s.back();
      if (s == "CUSTOM") fail(*t, "Type", "CUSTOM goniometer geometry has no LM-63 photometric type");
      if (last == 'A') p.type = PhotometricType::A;
      else if (last == 'B') p.type = PhotometricType::B;
      else if (last == 'C') p.type = PhotometricType::C;
      else fail(*t, "Type", "'" + detail::excerpt(s) + "' is not one of CIE_A, CIE_B, CIE_C, IES_A, IES_B, IES_C");
    }
  }

  std::size_t emitters = 0;
  const Tm33Node* num_emitter = nullptr;
  std::vector<const Tm33Node*> custom;
  for (const auto& c : root.children) {
    if (c.name == "Version") continue;
    if (c.name == "Header") read_header(p, c);
    else if (c.name == "Luminaire") {
      read_luminaire(p, c);
      num_emitter = c.child("NumEmitter");
    } else if (c.name == "Emitter") {
      if (emitters >= opt_.limits.max_lamp_sets)
        fail(c, "Emitter", "more emitters than ReadLimits::max_lamp_sets (" + std::to_string(opt_.limits.max_lamp_sets) + ")");
      read_emitter(p, c, emitters++);
    } else if (c.name == "CustomData") {
      const Tm33Node* id = c.child("UniqueIdentifier");
      const std::string uid = id ? text(*id) : std::string();
      if (uid == tm33::kLm63Block || uid == tm33::kEulumdatBlock) custom.push_back(&c);
      else keep(p, "", c);
    } else if (c.name == "Equipment" && c.children.size() == 1 && c.children[0].children.size() == 1 &&
               c.children[0].children[0].name == "Type") {
      continue;  // only the goniometer type, which the model holds and a writer states again
    } else {
      keep(p, "", c);
    }
  }
  if (emitters == 0) fail(root, "Emitter", "no Emitter element");
  if (!have_table_) fail(root, "LuminousData", "no Emitter has LuminousData/LuminousIntensity (luminous intensity table)");
  if (num_emitter && static_cast<std::size_t>(integer(*num_emitter, 0, 1000000)) != emitters)
    warn(*num_emitter, "NumEmitter", "states " + text(*num_emitter) + " emitters; the file has " + std::to_string(emitters));
  for (const Tm33Node* c : custom) {
    const std::string uid = text(*c->child("UniqueIdentifier"));
    if (uid == tm33::kLm63Block) read_lm63_block(p, *c);
    else read_eulumdat_block(p, *c);
  }

  // Keywords: mapped header fields in LM-63 order, comments, then the LM-63 keywords kept as custom data.
  // Header fields a writer filled from EULUMDAT fields (listed in the EULUMDAT block) are not keywords.
  const std::string derived = " " + header_from_fields_ + " ";
  for (const char* k : {"TEST", "TESTLAB", "ISSUEDATE", "MANUFAC", "LUMCAT", "LUMINAIRE"})
    for (const auto& kw : header_kw_)
      if (kw.name == k && derived.find(" " + kw.name + " ") == std::string::npos) p.keywords.push_back(kw);
  for (auto& kw : extra_kw_) p.keywords.push_back(std::move(kw));
  for (auto& kw : comments_) p.keywords.push_back(std::move(kw));

  double watts = 0;
  for (const auto& l : p.lamp_sets) watts += l.watts;
  p.input_watts = input_watts_ ? *input_watts_ : watts;
  if (!have_lm63_ && opening_from_areas_) p.opening = *opening_from_areas_;
  // With an LM-63 block but no EULUMDAT block, a lumx writer derived Dimensions from the opening.
  if (!have_eulumdat_ && !have_lm63_ && have_dims_) {
    p.ldt.luminaire_length_mm = dims_m_[0] * 1000.0;
    p.ldt.luminaire_width_mm = dims_m_[1] * 1000.0;
    p.ldt.luminaire_height_mm = dims_m_[2] * 1000.0;
  }
  return p;
}

Photometry read_tree(const detail::Tm33Node& root, const std::string& name, const ReadOptions& options, bool json) {
  return Tm33Parser(name, options, json).parse(root);
}

}  // namespace

Photometry read_tm33_xml(std::string_view text, const std::string& name, const ReadOptions& options) {
  if (text.size() > options.limits.max_file_bytes)
    throw_at_field(name, "file", std::to_string(text.size()) + " bytes, above ReadLimits::max_file_bytes (" + std::to_string(options.limits.max_file_bytes) + ")");
  return read_tree(detail::parse_tm33_xml_tree(text, name), name, options, false);
}

Photometry read_tm33_json(std::string_view text, const std::string& name, const ReadOptions& options) {
  if (text.size() > options.limits.max_file_bytes)
    throw_at_field(name, "file", std::to_string(text.size()) + " bytes, above ReadLimits::max_file_bytes (" + std::to_string(options.limits.max_file_bytes) + ")");
  return read_tree(detail::parse_tm33_json_tree(text, name), name, options, true);
}

LUMX_NAMESPACE_END
