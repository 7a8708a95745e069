// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// IES TM-33 / ATLA S001 writer: the photometry model as a TM-33 element tree, then XML or JSON text.
//
// The tree follows the TM-33-23 element order (TM-33-18 drops Symm and Multiplier). Elements kept from
// a TM-33 source go back under the element they came from; LM-63 and EULUMDAT fields TM-33 has no
// element for go into two CustomData blocks (docs/tm33.md), so IES -> TM-33 -> IES and LDT -> TM-33 ->
// LDT lose nothing the model holds.
#include <lumx/io/tm33_io.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/version.h>

#include "io/photometry/tm33_fields.h"
#include "io/photometry/tm33_tree.h"
#include "io/text_scanner.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>

LUMX_NAMESPACE_BEGIN
namespace {

using detail::Tm33Node;

[[noreturn]] void fail(const Photometry& p, const std::string& field, const std::string& msg) {
  Diagnostic d;
  d.file = p.source.file;
  d.field = field;
  d.message = msg;
  throw Error(std::move(d));
}

class TreeBuilder {
 public:
  TreeBuilder(const Photometry& p, const Tm33WriteOptions& o) : p_(p), o_(o) {}
  Tm33Node build();

 private:
  /// Number text: shortest round-trip decimal (significant_digits 0), else that many digits.
  std::string num(double v) const {
    if (o_.significant_digits > 0) return detail::format_number(v, o_.significant_digits);
    if (v == 0) return "0";
    char buf[128];
    const double a = std::abs(v);
    const auto r = (a >= 1e-5 && a < 1e15) ? std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed)
                                           : std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
  }
  bool v23() const { return o_.version == Tm33Version::tm33_23; }
  const DataElement* kept(const std::string& parent, const std::string& name) const {
    for (const auto& k : p_.tm33.kept)
      if (k.parent == parent && k.element.name == name) return &k.element;
    return nullptr;
  }

  void header(Tm33Node& root);
  void luminaire(Tm33Node& root);
  void equipment(Tm33Node& root);
  void emitter(Tm33Node& root, std::size_t i);
  void intensity(Tm33Node& emitter);
  void lm63_block(Tm33Node& root);
  void eulumdat_block(Tm33Node& root);
  void insert_kept(Tm33Node& root);

  const Photometry& p_;
  const Tm33WriteOptions& o_;
  std::vector<Keyword> extra_keywords_;
  std::string from_eulumdat_;  ///< header keywords written from EULUMDAT fields (the model had no keyword)
};

void TreeBuilder::header(Tm33Node& root) {
  Tm33Node& h = root.add("Header");
  std::set<std::string> mapped;
  std::vector<std::string> comments;
  std::vector<std::pair<std::string, std::string>> fields;  // element, value
  for (const auto& k : p_.keywords) {
    const char* element = tm33::header_element(k.name);
    if (k.name == "OTHER") comments.push_back(k.value);
    else if (element && mapped.insert(k.name).second) fields.emplace_back(element, k.value);
    else extra_keywords_.push_back(k);
  }
  auto fallback = [&](const char* keyword, const std::string& ldt_value) {
    if (!mapped.count(keyword) && !ldt_value.empty()) {
      fields.emplace_back(tm33::header_element(keyword), ldt_value);
      mapped.insert(keyword);
      from_eulumdat_ += (from_eulumdat_.empty() ? "" : " ") + std::string(keyword);
    }
  };
  fallback("MANUFAC", p_.ldt.company);
  fallback("LUMCAT", p_.ldt.luminaire_number);
  fallback("LUMINAIRE", p_.ldt.luminaire_name);
  fallback("TEST", p_.ldt.report_number);
  // TM-33-23 requires Description, Laboratory and ReportNumber (possibly empty strings).
  for (const char* k : {"LUMINAIRE", "TESTLAB", "TEST"})
    if (!mapped.count(k)) fields.emplace_back(tm33::header_element(k), std::string());
  for (auto& [e, v] : fields) h.add(e, v);
  for (auto& c : comments) h.add("Comment", c);
}

void TreeBuilder::luminaire(Tm33Node& root) {
  Tm33Node& l = root.add("Luminaire");
  Tm33Node& d = l.add("Dimensions");
  const LdtHeader& h = p_.ldt;
  double dims[3] = {h.luminaire_length_mm / 1000.0, h.luminaire_width_mm / 1000.0, h.luminaire_height_mm / 1000.0};
  if (dims[0] == 0 && dims[1] == 0 && dims[2] == 0) {
    dims[0] = std::abs(p_.opening.length_m);
    dims[1] = std::abs(p_.opening.width_m);
    dims[2] = std::abs(p_.opening.height_m);
  }
  d.add("Length", num(dims[0]));
  d.add("Width", num(dims[1]));
  d.add("Height", num(dims[2]));
  l.add("NumEmitter", std::to_string(std::max<std::size_t>(1, p_.lamp_sets.size())));
}

void TreeBuilder::equipment(Tm33Node& root) {
  const char letter = p_.type == PhotometricType::A ? 'A' : p_.type == PhotometricType::B ? 'B' : 'C';
  std::string type = p_.tm33.goniometer_type;
  if (type.empty() || type.back() != letter) type = std::string("CIE_") + letter;
  Tm33Node eq = kept("", "Equipment") ? detail::to_tm33_node(*kept("", "Equipment")) : Tm33Node{"Equipment", {}, {}, {}, 0, {}};
  Tm33Node* g = nullptr;
  for (auto& c : eq.children)
    if (c.name == "Gonioradiometer" || c.name == "Goniometer") g = &c;
  if (!g) {
    eq.children.insert(eq.children.begin(), Tm33Node{"Gonioradiometer", {}, {}, {}, 0, {}});
    g = &eq.children.front();
  }
  Tm33Node* t = nullptr;
  for (auto& c : g->children)
    if (c.name == "Type") t = &c;
  if (t) t->text = type;
  else g->children.insert(g->children.begin(), Tm33Node{"Type", {}, type, {}, 0, {}});
  root.children.push_back(std::move(eq));
}

void TreeBuilder::intensity(Tm33Node& e) {
  const std::size_t nh = p_.horizontal_deg.size(), nv = p_.vertical_deg.size();
  Tm33Node& ld = e.add("LuminousData");
  Tm33Node& li = ld.add("LuminousIntensity");
  li.add("AbsolutePhotometry", p_.absolute ? "true" : "false");
  if (v23()) {
    if (p_.type == PhotometricType::C) {
      const char* s = "Symm_None";
      switch (p_.symmetry) {
        case Symmetry::none: s = "Symm_None"; break;
        case Symmetry::rotational: s = "Symm_Full"; break;
        case Symmetry::plane_c0_c180: s = "Symm_Bi_0"; break;
        case Symmetry::plane_c90_c270: s = "Symm_Bi_90"; break;
        case Symmetry::quadrant: s = "Symm_Quad"; break;
        case Symmetry::lateral: s = "Symm_Arbitrary"; break;
      }
      li.add("Symm", s);
    }
    li.add("Multiplier", "1");
  }
  li.add("NumberMeasured", std::to_string(nh * nv));
  li.add("NumberHorz", std::to_string(nh));
  li.add("NumberVert", std::to_string(nv));
  li.children.reserve(li.children.size() + nh * nv);
  for (std::size_t ih = 0; ih < nh; ++ih) {
    const std::string h = num(p_.horizontal_deg[ih]);
    for (std::size_t iv = 0; iv < nv; ++iv) {
      Tm33Node& d = li.add("IntData", num(p_.at(ih, iv)));
      d.attributes = {{"h", h}, {"v", num(p_.vertical_deg[iv])}};
    }
  }
  double flux = p_.tm33.luminous_flux_lm;
  if (!(flux > 0) && nv >= 2) {
    try {
      flux = IntensityTable(p_).flux_lm();
    } catch (const std::exception&) {
      flux = 0;  // a table the intensity model refuses: no flux is stated
    }
  }
  if (flux > 0 && std::isfinite(flux)) ld.add("LuminousFlux", num(flux));
}

void TreeBuilder::emitter(Tm33Node& root, std::size_t i) {
  const std::string path = "Emitter[" + std::to_string(i) + "]";
  const LampSet lamp = i < p_.lamp_sets.size() ? p_.lamp_sets[i] : LampSet{};
  Tm33Node& e = root.add("Emitter");
  const int quantity = std::max(1, std::abs(lamp.count));
  e.add("Quantity", std::to_string(quantity));
  e.add("Description", lamp.type);
  if (lamp.flux_lm > 0) e.add("RatedLumens", num(lamp.flux_lm / quantity));
  e.add("InputWattage", num(lamp.watts));
  if (i == 0) {
    e.add("BallastFactor", num(p_.ballast_factor));
    if (p_.tilt) {
      Tm33Node& t = e.add("TiltAngles");
      t.add("NumberAngles", std::to_string(p_.tilt->angles_deg.size()));
      const std::size_t n = std::min(p_.tilt->angles_deg.size(), p_.tilt->multipliers.size());
      for (std::size_t k = 0; k < n; ++k) t.add("Tilt", num(p_.tilt->multipliers[k])).attributes = {{"angle", num(p_.tilt->angles_deg[k])}};
    }
  }
  double v = 0;
  if (!kept(path, "ColorTemperature") && detail::parse_number(detail::trim_space(lamp.color), v))
    e.add("ColorTemperature").add("FixedCCT", std::string(detail::trim_space(lamp.color)));
  if (!kept(path, "ColorRendering") && detail::parse_number(detail::trim_space(lamp.cri), v))
    e.add("ColorRendering").add("CIE_CRI").add("Ra", std::string(detail::trim_space(lamp.cri)));
  if (i == 0) intensity(e);
  if (i == 0 && !kept(path, "EmissionAreas")) {
    const LuminousOpening& op = p_.opening;
    const LuminousShape s = op.shape();
    if (s == LuminousShape::rectangle || s == LuminousShape::circle || s == LuminousShape::ellipse) {
      Tm33Node& a = e.add("EmissionAreas").add("BottomFace");
      a.add("NumberBottom", "1");
      Tm33Node& b = a.add("BottomArea");
      b.add("Length", num(std::abs(op.length_m)));
      b.add("Width", num(std::abs(op.width_m)));
      b.add("LengthOffset", "0");
      b.add("WidthOffset", "0");
      if (s != LuminousShape::rectangle) b.add("Circular", "true");
    }
  }
}

void TreeBuilder::lm63_block(Tm33Node& root) {
  double watts = 0;
  for (const auto& l : p_.lamp_sets) watts += l.watts;
  const bool tilt_extra = p_.tilt && (p_.tilt->lamp_geometry != 1 || p_.tilt->source != "INCLUDE");
  const bool opening = p_.opening.width_m != 0 || p_.opening.length_m != 0 || p_.opening.height_m != 0;
  if (extra_keywords_.empty() && p_.ies_second_factor == 1.0 && p_.units == IesUnits::metres && !opening &&
      p_.input_watts == watts && !tilt_extra)
    return;
  Tm33Node& c = root.add("CustomData");
  c.add("Name", "LM-63 fields without a TM-33 element");
  c.add("UniqueIdentifier", tm33::kLm63Block);
  for (const auto& k : extra_keywords_) c.add("Keyword", k.value).attributes = {{"name", k.name}};
  c.add("SecondFactor", num(p_.ies_second_factor));
  c.add("InputWatts", num(p_.input_watts));
  c.add("Units", p_.units == IesUnits::feet ? "feet" : "metres");
  c.add("LuminousOpening").attributes = {
      {"width", num(p_.opening.width_m)}, {"length", num(p_.opening.length_m)}, {"height", num(p_.opening.height_m)}};
  if (p_.tilt) {
    c.add("TiltLampGeometry", std::to_string(p_.tilt->lamp_geometry));
    c.add("TiltSource", p_.tilt->source);
  }
}

void TreeBuilder::eulumdat_block(Tm33Node& root) {
  const LdtHeader& h = p_.ldt;
  const LdtHeader d;
  bool lamps_extra = false;
  for (const auto& l : p_.lamp_sets) lamps_extra = lamps_extra || !l.color.empty() || !l.cri.empty() || l.count < 0;
  const bool header_extra =
      h.company != d.company || h.ityp != d.ityp || h.report_number != d.report_number ||
      h.luminaire_name != d.luminaire_name || h.luminaire_number != d.luminaire_number || h.file_name != d.file_name ||
      h.date_user != d.date_user || h.luminaire_length_mm != 0 || h.luminaire_width_mm != 0 ||
      h.luminaire_height_mm != 0 || h.area_length_mm != 0 || h.area_width_mm != 0 || h.area_height_mm[0] != 0 ||
      h.area_height_mm[1] != 0 || h.area_height_mm[2] != 0 || h.area_height_mm[3] != 0 || h.dff_percent != 0 ||
      h.lor_percent != 0 || h.conversion_factor != 1 || h.tilt_deg != 0 || !h.direct_ratios.empty();
  if (!header_extra && !lamps_extra) return;
  Tm33Node& c = root.add("CustomData");
  c.add("Name", "EULUMDAT fields without a TM-33 element");
  c.add("UniqueIdentifier", tm33::kEulumdatBlock);
  if (!from_eulumdat_.empty()) c.add("HeaderFromFields", from_eulumdat_);
  c.add("Company", h.company);
  c.add("Ityp", std::to_string(h.ityp));
  c.add("ReportNumber", h.report_number);
  c.add("LuminaireName", h.luminaire_name);
  c.add("LuminaireNumber", h.luminaire_number);
  c.add("FileName", h.file_name);
  c.add("DateUser", h.date_user);
  c.add("LuminaireLength", num(h.luminaire_length_mm));
  c.add("LuminaireWidth", num(h.luminaire_width_mm));
  c.add("LuminaireHeight", num(h.luminaire_height_mm));
  c.add("AreaLength", num(h.area_length_mm));
  c.add("AreaWidth", num(h.area_width_mm));
  c.add("AreaHeightC0", num(h.area_height_mm[0]));
  c.add("AreaHeightC90", num(h.area_height_mm[1]));
  c.add("AreaHeightC180", num(h.area_height_mm[2]));
  c.add("AreaHeightC270", num(h.area_height_mm[3]));
  c.add("DFF", num(h.dff_percent));
  c.add("LOR", num(h.lor_percent));
  c.add("ConversionFactor", num(h.conversion_factor));
  c.add("Tilt", num(h.tilt_deg));
  if (!h.direct_ratios.empty()) {
    std::string s;
    for (double r : h.direct_ratios) s += (s.empty() ? "" : " ") + num(r);
    c.add("DirectRatios", s);
  }
  for (std::size_t i = 0; i < p_.lamp_sets.size(); ++i) {
    const LampSet& l = p_.lamp_sets[i];
    Tm33Node& s = c.add("LampSet");
    s.attributes = {{"index", std::to_string(i)}};
    s.add("Count", std::to_string(l.count));
    s.add("Flux", num(l.flux_lm));
    s.add("Color", l.color);
    s.add("CRI", l.cri);
  }
}

/// The node a kept element's parent path names ("Emitter[1]/LuminousData"), created if missing.
Tm33Node& resolve(Tm33Node& root, const std::string& path) {
  Tm33Node* n = &root;
  std::size_t start = 0;
  while (start < path.size()) {
    const std::size_t slash = path.find('/', start);
    const std::string seg = path.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    start = slash == std::string::npos ? path.size() : slash + 1;
    std::string name = seg;
    std::size_t index = 0;
    const std::size_t br = seg.find('[');
    if (br != std::string::npos) {
      name = seg.substr(0, br);
      index = static_cast<std::size_t>(std::strtoul(seg.c_str() + br + 1, nullptr, 10));
    }
    Tm33Node* found = nullptr;
    std::size_t k = 0;
    for (auto& c : n->children)
      if (c.name == name && k++ == index) {
        found = &c;
        break;
      }
    n = found ? found : &n->add(name);
  }
  return *n;
}

void TreeBuilder::insert_kept(Tm33Node& root) {
  for (const auto& k : p_.tm33.kept) {
    if (k.parent.empty() && k.element.name == "Equipment") continue;  // merged by equipment()
    // A second luminous intensity table of the first emitter cannot coexist with the one written.
    resolve(root, k.parent).children.push_back(detail::to_tm33_node(k.element));
  }
}

void sort_by_schema(Tm33Node& n) {
  std::stable_sort(n.children.begin(), n.children.end(), [&](const Tm33Node& a, const Tm33Node& b) {
    return tm33::schema_rank(n.name, a.name) < tm33::schema_rank(n.name, b.name);
  });
  for (auto& c : n.children) sort_by_schema(c);
}

Tm33Node TreeBuilder::build() {
  const std::size_t nh = p_.horizontal_deg.size(), nv = p_.vertical_deg.size();
  if (nh == 0 || nv == 0 || p_.candela.size() != nh * nv)
    fail(p_, "candela", "table is " + std::to_string(p_.candela.size()) + " values for " + std::to_string(nh) + " x " +
                            std::to_string(nv) + " angles");
  for (double c : p_.candela)
    if (!std::isfinite(c)) fail(p_, "candela", "non-finite value");
  for (const auto* a : {&p_.horizontal_deg, &p_.vertical_deg})
    for (std::size_t i = 0; i < a->size(); ++i)
      if (!std::isfinite((*a)[i]) || (i > 0 && !((*a)[i] > (*a)[i - 1])))
        fail(p_, a == &p_.vertical_deg ? "vertical angle" : "horizontal angle", "angles must be finite and strictly increasing");
  Tm33Node root{v23() ? "IESTM33-22" : "IESTM33", {}, {}, {}, 0, {}};
  root.add("Version", v23() ? "1.1" : "1.0");
  header(root);
  luminaire(root);
  equipment(root);
  const std::size_t emitters = std::max<std::size_t>(1, p_.lamp_sets.size());
  for (std::size_t i = 0; i < emitters; ++i) emitter(root, i);
  insert_kept(root);
  lm63_block(root);
  eulumdat_block(root);
  sort_by_schema(root);
  return root;
}

}  // namespace

std::string format_tm33_xml(const Photometry& p, const Tm33WriteOptions& options) {
  return detail::tm33_tree_to_xml(TreeBuilder(p, options).build());
}

std::string format_tm33_json(const Photometry& p, const Tm33WriteOptions& options) {
  return detail::tm33_tree_to_json(TreeBuilder(p, options).build());
}

LUMX_NAMESPACE_END
