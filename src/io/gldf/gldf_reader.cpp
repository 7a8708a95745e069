// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// GLDF containers: product.xml listed, references resolved, XSD validation (libxml2), photometry inside
// read and validated (gldf_io.h, docs/gldf.md).
#include <lumx/io/gldf_io.h>
#include <lumx/io/tm33_io.h>
#include <lumx/photometry/validate.h>

#include "io/gldf/zip_archive.h"
#include "io/photometry/tm33_tree.h"

#include <libxml/parser.h>
#include <libxml/xmlschemas.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <memory>

LUMX_NAMESPACE_BEGIN
namespace {

using detail::Tm33Node;

std::string attr(const Tm33Node& n, const char* name) {
  for (const auto& [k, v] : n.attributes)
    if (k == name) return v;
  return {};
}

void each_descendant(const Tm33Node& n, const char* name, const std::function<void(const Tm33Node&)>& f) {
  for (const auto& c : n.children) {
    if (c.name == name) f(c);
    each_descendant(c, name, f);
  }
}

const Tm33Node* descend(const Tm33Node& n, std::initializer_list<const char*> names) {
  const Tm33Node* p = &n;
  for (const char* s : names)
    if (!(p = p->child(s))) return nullptr;
  return p;
}

/// A Locale text of a localised element: English if there is one, else the first.
std::string localised(const Tm33Node* n) {
  if (!n) return {};
  std::string first;
  for (const auto& c : n->children) {
    if (c.name != "Locale") continue;
    if (attr(c, "language") == "en") return std::string(detail::trim_space(c.text));
    if (first.empty()) first = std::string(detail::trim_space(c.text));
  }
  return first;
}

/// The archive folder of a content type (GLDF container specification).
std::string folder_of(const std::string& content_type) {
  static const char* const kMap[][2] = {{"ldc/", "ldc/"},         {"geo/", "geo/"},       {"image/", "image/"},
                                        {"document/", "doc/"},    {"sensor/", "sensor/"}, {"spectrum/", "spectrum/"},
                                        {"symbol/", "symbol/"},   {"other", "other/"}};
  for (const auto& m : kMap)
    if (content_type.rfind(m[0], 0) == 0) return m[1];
  return {};
}

Diagnostic finding(Severity s, const std::string& file, int line, const std::string& field, const std::string& msg) {
  Diagnostic d;
  d.severity = s;
  d.file = file;
  d.line = line;
  d.field = field;
  d.message = msg;
  return d;
}

GldfContainer list_container(const std::string& path, const detail::ZipArchive& zip) {
  GldfContainer c;
  c.path = path;
  c.entries = zip.names();
  const std::string product = path + "!/product.xml";
  if (!zip.contains("product.xml")) throw_at_field(product, "product.xml", "missing: every GLDF container has one");
  const Tm33Node root = detail::parse_tm33_xml_tree(zip.read("product.xml"), product);
  if (root.name != "Root") throw_at_line(product, root.line, "Root", "the root element is '" + root.name + "', not Root");
  if (const Tm33Node* h = root.child("Header")) {
    if (const Tm33Node* m = h->child("Manufacturer")) c.manufacturer = std::string(detail::trim_space(m->text));
    if (const Tm33Node* v = h->child("FormatVersion")) {
      c.format_version = attr(*v, "major") + "." + attr(*v, "minor");
      if (!attr(*v, "pre-release").empty()) c.format_version += "-rc." + attr(*v, "pre-release");
    }
  }
  const Tm33Node* general = root.child("GeneralDefinitions");
  if (const Tm33Node* files = general ? general->child("Files") : nullptr) {
    for (const auto& f : files->children) {
      if (f.name != "File") continue;
      GldfFile g{attr(f, "id"), attr(f, "contentType"), attr(f, "type"), std::string(detail::trim_space(f.text)), {}, f.line};
      if (g.type == "localFileName") {
        const std::string folder = folder_of(g.content_type);
        if (!folder.empty() && zip.contains(folder + g.name)) {
          g.entry = folder + g.name;
        } else {
          for (const auto& e : c.entries)  // legacy folders ("geometry/"): the same file name elsewhere
            if (e.size() > g.name.size() && e.compare(e.size() - g.name.size(), g.name.size(), g.name) == 0 &&
                e[e.size() - g.name.size() - 1] == '/')
              g.entry = e;
          c.findings.push_back(g.entry.empty()
                                   ? finding(Severity::error, product, f.line, "File",
                                             "'" + g.name + "' (" + g.content_type + ") is not in the container")
                                   : finding(Severity::warning, product, f.line, "File",
                                             "'" + g.name + "' is at " + g.entry + ", not in " +
                                                 (folder.empty() ? "its content type's folder" : folder)));
        }
      }
      c.files.push_back(std::move(g));
    }
  }
  auto has_file = [&](const std::string& id) {
    return std::any_of(c.files.begin(), c.files.end(), [&](const GldfFile& f) { return f.id == id; });
  };
  if (const Tm33Node* ps = general ? general->child("Photometries") : nullptr)
    for (const auto& p : ps->children) {
      if (p.name != "Photometry") continue;
      GldfPhotometry g{attr(p, "id"), {}, p.line};
      if (const Tm33Node* r = p.child("PhotometryFileReference")) g.file_id = attr(*r, "fileId");
      if (!g.file_id.empty() && !has_file(g.file_id))
        c.findings.push_back(finding(Severity::error, product, p.line, "PhotometryFileReference",
                                     "fileId '" + g.file_id + "' names no File"));
      c.photometries.push_back(std::move(g));
    }
  if (const Tm33Node* es = general ? general->child("Emitters") : nullptr)
    for (const auto& e : es->children) {
      if (e.name != "Emitter") continue;
      GldfEmitter g{attr(e, "id"), {}, e.line};
      each_descendant(e, "PhotometryReference", [&](const Tm33Node& r) {
        const std::string id = attr(r, "photometryId");
        g.photometry_ids.push_back(id);
        if (std::none_of(c.photometries.begin(), c.photometries.end(), [&](const GldfPhotometry& p) { return p.id == id; }))
          c.findings.push_back(finding(Severity::error, product, r.line, "PhotometryReference",
                                       "photometryId '" + id + "' names no Photometry"));
      });
      c.emitters.push_back(std::move(g));
    }
  if (const Tm33Node* gs = general ? general->child("Geometries") : nullptr)
    for (const auto& g : gs->children) {
      GldfGeometry geo{attr(g, "id"), {}, g.line};
      each_descendant(g, "GeometryFileReference", [&](const Tm33Node& r) { geo.file_ids.push_back(attr(r, "fileId")); });
      c.geometries.push_back(std::move(geo));
    }
  const Tm33Node* meta = descend(root, {"ProductDefinitions", "ProductMetaData"});
  c.product_name = localised(meta ? meta->child("Name") : nullptr);
  c.product_number = localised(meta ? meta->child("ProductNumber") : nullptr);
  if (const Tm33Node* vs = descend(root, {"ProductDefinitions", "Variants"}))
    for (const auto& v : vs->children) {
      if (v.name != "Variant") continue;
      GldfVariant g{attr(v, "id"), localised(v.child("Name")), {}, {}, v.line};
      each_descendant(v, "EmitterReference", [&](const Tm33Node& r) {
        const std::string id = attr(r, "emitterId");
        g.emitter_ids.push_back(id);
        if (std::none_of(c.emitters.begin(), c.emitters.end(), [&](const GldfEmitter& e) { return e.id == id; }))
          c.findings.push_back(finding(Severity::error, product, r.line, "EmitterReference", "emitterId '" + id + "' names no Emitter"));
      });
      for (const char* ref : {"ModelGeometryReference", "SimpleGeometryReference"})
        each_descendant(v, ref, [&](const Tm33Node& r) { g.geometry_id = attr(r, "geometryId"); });
      c.variants.push_back(std::move(g));
    }
  return c;
}

/// XSD violations of product.xml, located by line.
std::vector<Diagnostic> validate_product_xml(const std::string& bytes, const std::string& location,
                                             const std::string& xsd_path) {
  std::vector<Diagnostic> out;
  struct Sink {
    std::vector<Diagnostic>* out;
    std::string file, field;
  };
  auto handler = [](void* ctx, xmlErrorPtr e) {
    auto* s = static_cast<Sink*>(ctx);
    std::string msg = e && e->message ? e->message : "schema error";
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
    s->out->push_back(finding(Severity::error, s->file, e ? e->line : 0, s->field, msg));
  };
  Sink schema_sink{&out, xsd_path, "XSD"};
  std::unique_ptr<xmlSchemaParserCtxt, void (*)(xmlSchemaParserCtxtPtr)> pctx(xmlSchemaNewParserCtxt(xsd_path.c_str()),
                                                                             xmlSchemaFreeParserCtxt);
  if (!pctx) return {finding(Severity::error, xsd_path, 0, "XSD", "cannot read the schema")};
  xmlSchemaSetParserStructuredErrors(pctx.get(), handler, &schema_sink);
  std::unique_ptr<xmlSchema, void (*)(xmlSchemaPtr)> schema(xmlSchemaParse(pctx.get()), xmlSchemaFree);
  if (!schema) {
    if (out.empty()) out.push_back(finding(Severity::error, xsd_path, 0, "XSD", "not a usable XML schema"));
    return out;
  }
  std::unique_ptr<xmlDoc, void (*)(xmlDocPtr)> doc(
      xmlReadMemory(bytes.data(), static_cast<int>(bytes.size()), location.c_str(), nullptr,
                    XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING | XML_PARSE_BIG_LINES),
      xmlFreeDoc);
  if (!doc) return out;  // malformed: read_gldf has reported it
  std::unique_ptr<xmlSchemaValidCtxt, void (*)(xmlSchemaValidCtxtPtr)> vctx(xmlSchemaNewValidCtxt(schema.get()),
                                                                           xmlSchemaFreeValidCtxt);
  Sink doc_sink{&out, location, "XSD"};
  xmlSchemaSetValidStructuredErrors(vctx.get(), handler, &doc_sink);
  xmlSchemaValidateDoc(vctx.get(), doc.get());
  return out;
}

}  // namespace

GldfContainer read_gldf(const std::string& path, const GldfReadOptions& options) {
  const detail::ZipArchive zip(path, options.limits);
  return list_container(path, zip);
}

std::string read_gldf_entry(const std::string& path, const std::string& entry, const GldfLimits& limits) {
  const detail::ZipArchive zip(path, limits);
  return zip.read(entry);
}

Photometry read_gldf_photometry(const GldfContainer& c, const GldfFile& f, const GldfReadOptions& options) {
  const std::string name = c.path + "!/" + (f.entry.empty() ? f.name : f.entry);
  if (f.entry.empty()) throw_at_field(name, "File", "not a file inside the container");
  const std::string bytes = read_gldf_entry(c.path, f.entry, options.limits);
  if (f.content_type == "ldc/eulumdat") return read_ldt(bytes, name, options.photometry);
  if (f.content_type == "ldc/ies") return read_ies(bytes, name, options.photometry);
  if (f.content_type == "ldc/iesxml") return read_tm33_xml(bytes, name, options.photometry);
  throw_at_field(name, "contentType", "'" + f.content_type + "' is not a photometry format lumx reads");
}

std::vector<Diagnostic> check_gldf(const std::string& path, const std::string& xsd_path, const GldfReadOptions& options) {
  std::vector<Diagnostic> out;
  try {
    const detail::ZipArchive zip(path, options.limits);
    const GldfContainer c = list_container(path, zip);
    if (!xsd_path.empty())
      for (auto& d : validate_product_xml(zip.read("product.xml"), path + "!/product.xml", xsd_path)) out.push_back(d);
    for (const auto& d : c.findings) out.push_back(d);
    for (const auto& f : c.files) {
      if (f.content_type.rfind("ldc/", 0) != 0 || f.entry.empty()) continue;
      GldfReadOptions o = options;
      o.photometry.warnings = [&out](const Diagnostic& d) { out.push_back(d); };
      try {
        const Photometry p = read_gldf_photometry(c, f, o);
        for (auto& d : validate(p)) out.push_back(d);
      } catch (const Error& e) {
        out.push_back(e.diagnostic());
      }
    }
  } catch (const Error& e) {
    out.push_back(e.diagnostic());
  }
  return out;
}

LUMX_NAMESPACE_END
