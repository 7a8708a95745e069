// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The TM-33 element tree: XML via libxml2, the JSON form via nlohmann-json, both located (tm33_tree.h).
#include "io/photometry/tm33_tree.h"
#include "io/json_depth.h"
#include "io/json_members.h"

#include "io/text_scanner.h"

#include <libxml/parser.h>
#include <libxml/tree.h>
#include <libxml/xmlerror.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <climits>
#include <cstring>
#include <memory>
#include <mutex>

LUMX_NAMESPACE_BEGIN
namespace detail {
namespace {

using ojson = nlohmann::ordered_json;

// ---------------------------------------------------------------- XML in

struct DocFree {
  void operator()(xmlDoc* d) const { xmlFreeDoc(d); }
};
struct CtxtFree {
  void operator()(xmlParserCtxt* c) const { xmlFreeParserCtxt(c); }
};

std::string xml_string(const xmlChar* s) { return s ? std::string(reinterpret_cast<const char*>(s)) : std::string(); }

std::string trim_message(std::string m) {
  while (!m.empty() && (m.back() == '\n' || m.back() == ' ')) m.pop_back();
  return m;
}

Tm33Node convert_xml(const xmlNode* e, const std::string& file, int depth) {
  Tm33Node n;
  n.name = xml_string(e->name);
  n.line = static_cast<int>(xmlGetLineNo(e));
  if (depth > kTm33MaxDepth)
    throw_at_line(file, n.line, n.name, "elements nest deeper than " + std::to_string(kTm33MaxDepth) + " levels");
  for (const xmlAttr* a = e->properties; a; a = a->next) {
    xmlChar* v = xmlNodeListGetString(e->doc, a->children, 1);
    n.attributes.emplace_back(xml_string(a->name), xml_string(v));
    xmlFree(v);
  }
  for (const xmlNode* c = e->children; c; c = c->next) {
    switch (c->type) {
      case XML_ELEMENT_NODE: n.children.push_back(convert_xml(c, file, depth + 1)); break;
      case XML_TEXT_NODE:
      case XML_CDATA_SECTION_NODE: n.text += xml_string(c->content); break;
      default: break;  // comments, processing instructions
    }
  }
  if (!n.children.empty() && trim_space(n.text).empty()) n.text.clear();  // indentation between child elements
  return n;
}

// ---------------------------------------------------------------- JSON in

std::string pointer_token(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

bool valid_xml_name(const std::string& s) {
  if (s.empty()) return false;
  auto start_ok = [](unsigned char c) { return std::isalpha(c) || c == '_' || c == ':' || c >= 0x80; };
  if (!start_ok(static_cast<unsigned char>(s[0]))) return false;
  for (unsigned char c : s)
    if (!(start_ok(c) || std::isdigit(c) || c == '-' || c == '.')) return false;
  return true;
}

std::string json_scalar_text(const ojson& v, const std::string& file, const std::string& pointer) {
  switch (v.type()) {
    case ojson::value_t::string: return v.get<std::string>();
    case ojson::value_t::boolean: return v.get<bool>() ? "true" : "false";
    case ojson::value_t::number_integer:
    case ojson::value_t::number_unsigned:
    case ojson::value_t::number_float: return v.dump();
    case ojson::value_t::null: return std::string();
    default: throw_at_field(file, pointer, "expected a string, number, boolean or null here");
  }
}

void convert_json_into(Tm33Node& n, const ojson& v, const std::string& file, int depth);

Tm33Node convert_json(const std::string& name, const ojson& v, const std::string& pointer, const std::string& file,
                      int depth) {
  if (!valid_xml_name(name)) throw_at_field(file, pointer, "'" + excerpt(name) + "' is not a valid element name");
  if (depth > kTm33MaxDepth)
    throw_at_field(file, pointer, "values nest deeper than " + std::to_string(kTm33MaxDepth) + " levels");
  Tm33Node n;
  n.name = name;
  n.pointer = pointer;
  if (v.is_object()) {
    convert_json_into(n, v, file, depth);
  } else if (v.is_array()) {
    throw_at_field(file, pointer, "an array inside an array; repeated elements are one array of values");
  } else {
    n.text = json_scalar_text(v, file, pointer);
  }
  return n;
}

void convert_json_into(Tm33Node& n, const ojson& v, const std::string& file, int depth) {
  for (auto it = v.begin(); it != v.end(); ++it) {
    const std::string& key = it.key();
    const std::string p = n.pointer + "/" + pointer_token(key);
    if (key == "#text") {
      n.text = json_scalar_text(it.value(), file, p);
    } else if (!key.empty() && key[0] == '@') {
      const std::string attr = key.substr(1);
      if (!valid_xml_name(attr)) throw_at_field(file, p, "'" + excerpt(attr) + "' is not a valid attribute name");
      n.attributes.emplace_back(attr, json_scalar_text(it.value(), file, p));
    } else if (it.value().is_array()) {
      std::size_t i = 0;
      for (const auto& item : it.value()) {
        n.children.push_back(convert_json(key, item, p + "/" + std::to_string(i), file, depth + 1));
        ++i;
      }
    } else {
      n.children.push_back(convert_json(key, it.value(), p, file, depth + 1));
    }
  }
}

// ---------------------------------------------------------------- out

void escape_into(std::string& out, std::string_view s, bool attribute) {
  for (char ch : s) {
    const unsigned char c = static_cast<unsigned char>(ch);
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += attribute ? "&quot;" : "\""; break;
      case '\r': out += "&#13;"; break;
      case '\n': out += attribute ? "&#10;" : "\n"; break;
      case '\t': out += attribute ? "&#9;" : "\t"; break;
      default:
        out += c < 0x20 ? ' ' : ch;  // XML 1.0 has no other control characters
    }
  }
}

bool blank(std::string_view s) { return trim_space(s).empty(); }

void xml_into(std::string& out, const Tm33Node& n, int depth) {
  out.append(static_cast<std::size_t>(2 * depth), ' ');
  out += '<';
  out += n.name;
  for (const auto& [k, v] : n.attributes) {
    out += ' ';
    out += k;
    out += "=\"";
    escape_into(out, v, true);
    out += '"';
  }
  if (n.children.empty()) {
    if (n.text.empty()) {
      out += "/>\n";
    } else {
      out += '>';
      escape_into(out, n.text, false);
      out += "</" + n.name + ">\n";
    }
    return;
  }
  out += ">\n";
  if (!blank(n.text)) {
    out.append(static_cast<std::size_t>(2 * depth + 2), ' ');
    escape_into(out, trim_space(n.text), false);
    out += '\n';
  }
  for (const auto& c : n.children) xml_into(out, c, depth + 1);
  out.append(static_cast<std::size_t>(2 * depth), ' ');
  out += "</" + n.name + ">\n";
}

/// Elements the JSON form always writes as arrays, because TM-33 lets them repeat.
bool always_array(const std::string& name) {
  static const char* const kNames[] = {"Emitter",   "IntData",  "Comment",  "Reference", "Tilt",
                                       "PwrData",   "CustomData", "EmitterSpectral", "ChannelMult",
                                       "Illum",     "Irrad",    "PFD",      "SIrrad",    "TopArea",
                                       "BottomArea", "C0Area",  "C90Area",  "C180Area",  "C270Area",
                                       "MeasurementEquipment", "Keyword", "LampSet"};
  for (const char* k : kNames)
    if (name == k) return true;
  return false;
}

/// A text as the JSON value that reads back to the same text: booleans and numbers whose JSON spelling
/// is exactly the text, else a string ("00123" and "0.10" stay strings).
ojson json_scalar(const std::string& t) {
  if (t == "true") return true;
  if (t == "false") return false;
  double d = 0;
  if (!t.empty() && parse_number(t, d)) {
    const bool integral = t.find_first_of(".eE") == std::string::npos;
    if (integral && t.size() <= 18) {
      try {
        const long long i = std::stoll(t);
        if (std::to_string(i) == t) return i;
      } catch (const std::exception&) {
      }
    } else if (!integral) {
      const ojson j = d;
      if (j.dump() == t) return j;
    }
  }
  return t;
}

ojson json_value(const Tm33Node& n) {
  if (n.attributes.empty() && n.children.empty()) return json_scalar(n.text);
  ojson o = ojson::object();
  for (const auto& [k, v] : n.attributes) o["@" + k] = json_scalar(v);
  if (n.children.empty() ? !n.text.empty() : !blank(n.text)) o["#text"] = json_scalar(n.children.empty() ? n.text : std::string(trim_space(n.text)));
  for (const auto& c : n.children) {
    auto it = o.find(c.name);
    if (it == o.end()) {
      std::size_t count = 0;
      for (const auto& d : n.children) count += d.name == c.name ? 1 : 0;
      if (count > 1 || always_array(c.name)) {
        o[c.name] = ojson::array();
        o[c.name].push_back(json_value(c));
      } else {
        o[c.name] = json_value(c);
      }
    } else {
      it->push_back(json_value(c));
    }
  }
  return o;
}

}  // namespace

Tm33Node parse_tm33_xml_tree(std::string_view text, const std::string& file) {
  if (text.size() > static_cast<std::size_t>(INT_MAX)) throw_at_field(file, "file", "too large");
  // TM-33 needs no DTD; refusing one rules out entity expansion (billion laughs, external entities).
  const std::size_t dtd = text.find("<!DOCTYPE");
  if (dtd != std::string_view::npos)
    throw_at_line(file, 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(dtd), '\n')),
                  "DOCTYPE", "a document type declaration is not allowed in TM-33 (no entities are expanded)");
  static std::once_flag init;
  std::call_once(init, [] { xmlInitParser(); });
  std::unique_ptr<xmlParserCtxt, CtxtFree> ctxt(xmlNewParserCtxt());
  if (!ctxt) throw_at_field(file, "file", "cannot create an XML parser");
  const int options = XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING | XML_PARSE_BIG_LINES;
  std::unique_ptr<xmlDoc, DocFree> doc(
      xmlCtxtReadMemory(ctxt.get(), text.data(), static_cast<int>(text.size()), file.c_str(), nullptr, options));
  if (!doc || !ctxt->wellFormed) {
    const xmlError* e = xmlCtxtGetLastError(ctxt.get());
    const int line = e ? e->line : 0;
    const std::string msg = e && e->message ? trim_message(e->message) : "malformed XML";
    throw_at_line(file, line > 0 ? line : 1, "XML", msg);
  }
  const xmlNode* root = xmlDocGetRootElement(doc.get());
  if (!root) throw_at_line(file, 1, "XML", "no root element");
  return convert_xml(root, file, 0);
}

Tm33Node parse_tm33_json_tree(std::string_view text, const std::string& file) {
  ojson j;
  if (const std::size_t at = detail::json_too_deep_at(text); at != std::string_view::npos)
    throw_at_line(file, 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n')), "JSON",
                  "nested more than " + std::to_string(detail::kMaxJsonDepth) + " levels deep");
  detail::RepeatedMemberWatch<ojson> members;
  try {
    j = ojson::parse(text.begin(), text.end(), members.callback());
  } catch (const ojson::parse_error& e) {
    const std::size_t at = std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
    std::string msg = e.what();
    const std::size_t colon = msg.find("parse error");
    if (colon != std::string::npos) msg = msg.substr(colon);
    throw_at_line(file, line, "JSON", msg);
  } catch (const ojson::exception& e) {  // a number too large for a double: nlohmann gives no position
    const std::size_t at = e.id == 406 ? detail::json_overflow_at(text, e.what()) : std::string_view::npos;
    if (at == std::string_view::npos) throw_at_field(file, "JSON", e.what());
    throw_at_line(file, 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n')), "JSON",
                  "a number beyond the range of a double");
  }
  if (!members.repeated().empty()) throw_at_field(file, members.repeated(), "this name appears twice in its object; readers disagree on which value counts");
  if (!j.is_object() || j.size() != 1)
    throw_at_field(file, "/", "a TM-33 JSON document is an object with one member, the root element");
  const auto it = j.begin();
  return convert_json(it.key(), it.value(), "/" + pointer_token(it.key()), file, 0);
}

std::string tm33_tree_to_xml(const Tm33Node& root) {
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  xml_into(out, root, 0);
  return out;
}

std::string tm33_tree_to_json(const Tm33Node& root) {
  ojson doc = ojson::object();
  doc[root.name] = json_value(root);
  return doc.dump(1, ' ', false, ojson::error_handler_t::replace) + "\n";
}

DataElement to_data_element(const Tm33Node& n) {
  DataElement e{n.name, n.attributes, n.text, {}};
  e.children.reserve(n.children.size());
  for (const auto& c : n.children) e.children.push_back(to_data_element(c));
  return e;
}

Tm33Node to_tm33_node(const DataElement& e) {
  Tm33Node n;
  n.name = e.name;
  n.attributes = e.attributes;
  n.text = e.text;
  for (const auto& c : e.children) n.children.push_back(to_tm33_node(c));
  return n;
}

}  // namespace detail
LUMX_NAMESPACE_END
