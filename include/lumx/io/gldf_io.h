// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/io/gldf_io.h — reading GLDF containers (the ZIP product format of DIAL and Relux), read-only.
//
// A .gldf file is a ZIP archive with a mandatory product.xml (root "Root": Header, GeneralDefinitions,
// ProductDefinitions) and asset folders named by content type (ldc/ photometry, geo/ L3D geometry,
// image/, doc/, sensor/ ...). read_gldf() checks the archive before anything is extracted — entry count,
// entry names (no absolute paths, no "..", no backslashes), declared and actual sizes, compression ratio
// (zip bombs), encryption — then reads product.xml (no DTD) and lists products, variants, emitters,
// photometry and geometry files. check_gldf() also validates product.xml against the GLDF XSD (libxml2)
// and reads every photometry file inside with lumx's own readers and validation; findings are located
// as "container.gldf!/ldc/file.ldt:line". docs/gldf.md describes the checks.
#pragma once

#include <lumx/core/diagnostic.h>
#include <lumx/io/photometry_io.h>

#include <cstdint>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// Limits that protect the reader from hostile archives; an archive exceeding one is refused before
/// anything is extracted.
struct GldfLimits {
  std::uint64_t max_archive_bytes = 256ull << 20;  ///< the .gldf file itself
  std::uint64_t max_entries = 4096;
  std::uint64_t max_entry_bytes = 64ull << 20;     ///< uncompressed size of one entry
  std::uint64_t max_total_bytes = 512ull << 20;    ///< uncompressed size of all entries
  /// Largest uncompressed / compressed size ratio of an entry larger than 1 MiB (real photometry and
  /// geometry compress at most ~20:1; zip bombs reach 1000:1).
  double max_compression_ratio = 200;
};

/// GeneralDefinitions/Files/File.
struct GldfFile {
  std::string id;
  std::string content_type;  ///< "ldc/eulumdat", "ldc/ies", "ldc/iesxml", "geo/l3d", "image/png", ...
  std::string type;          ///< "localFileName" or "url"
  std::string name;          ///< file name (localFileName) or URL
  std::string entry;         ///< archive entry it resolves to ("ldc/x.ldt"), empty for URLs
  int line = 0;              ///< line in product.xml
};

/// GeneralDefinitions/Photometries/Photometry.
struct GldfPhotometry {
  std::string id, file_id;
  int line = 0;
};

/// GeneralDefinitions/Emitters/Emitter: the photometries its light emitters reference.
struct GldfEmitter {
  std::string id;
  std::vector<std::string> photometry_ids;
  int line = 0;
};

/// GeneralDefinitions/Geometries/ModelGeometry (L3D files) or SimpleGeometry.
struct GldfGeometry {
  std::string id;
  std::vector<std::string> file_ids;  ///< empty for a simple geometry
  int line = 0;
};

/// ProductDefinitions/Variants/Variant.
struct GldfVariant {
  std::string id, name;
  std::vector<std::string> emitter_ids;
  std::string geometry_id;
  int line = 0;
};

/// What a GLDF container holds, as listed by product.xml and the archive.
struct GldfContainer {
  std::string path;
  std::vector<std::string> entries;  ///< archive entry names (folders excluded)
  std::string manufacturer, format_version, product_name, product_number;
  std::vector<GldfFile> files;
  std::vector<GldfPhotometry> photometries;
  std::vector<GldfEmitter> emitters;
  std::vector<GldfGeometry> geometries;
  std::vector<GldfVariant> variants;
  std::vector<Diagnostic> findings;  ///< reference problems found while reading (missing files, ids)
};

struct GldfReadOptions {
  GldfLimits limits;
  ReadOptions photometry;  ///< for the photometry files inside
};

/// Opens and lists a container. Throws lumx::Error (located "path!/entry") if the archive is unsafe or
/// unreadable or product.xml is missing or malformed; reference problems go to GldfContainer::findings.
GldfContainer read_gldf(const std::string& path, const GldfReadOptions& options = {});

/// The bytes of one entry of a container, after the same archive checks read_gldf() makes.
std::string read_gldf_entry(const std::string& path, const std::string& entry, const GldfLimits& limits = {});

/// Every finding about a container: archive and product.xml errors, XSD violations of product.xml
/// (when `xsd_path` is not empty; located by product.xml line), reference problems, and the findings of
/// lumx's reader and validate() on every photometry file inside. Never throws for bad input.
std::vector<Diagnostic> check_gldf(const std::string& path, const std::string& xsd_path,
                                   const GldfReadOptions& options = {});

/// The photometry of one file of a container (a File whose content type starts with "ldc/").
Photometry read_gldf_photometry(const GldfContainer& c, const GldfFile& f, const GldfReadOptions& options = {});

LUMX_NAMESPACE_END
