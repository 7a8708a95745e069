// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/io/rayset_io.h — reading raysets (IES TM-25, LightTools, Zemax, plain text) and writing TM-25.
//
// The format layer on top of lumx/rays/rayset.h. A rayset is opened as a RaySource, which reads the file's
// header at once (checking every count against the file size before anything is allocated from it) and
// then hands out rays in chunks: the file is read through a bounded window (pread), never whole, so a
// 10 M-ray file is processed in a few MiB of memory. Implementations are in src/io/rays/tm25_reader.cpp,
// tm25_writer.cpp, lighttools_reader.cpp, zemax_reader.cpp, plain_rays_reader.cpp and
// rayset_registry.cpp (format choice); docs/rays.md describes the formats, units and policies.
//
// After reading, whatever the file said: positions in metres, unit directions, flux per ray in lm or W
// (RaysetInfo::quantity), wavelengths in nm. Every problem is a lumx::Error whose Diagnostic names the
// file, the byte offset (binary formats) or line (text formats) and the field; warnings go to
// RaysetReadOptions::warnings.
//
// Normalisation policy: rays are kept as they are. The header's total flux is reported
// (RaysetInfo::header_flux) and never applied; when it disagrees with the sum of the rays' fluxes, a
// warning says so at the end of the first complete pass. Directions whose length differs from 1 by more
// than 1e-6 are normalised (one warning per pass with the count); zero, NaN or infinite directions, and
// NaN, infinite or negative fluxes, are errors.
#pragma once

#include <lumx/core/diagnostic.h>
#include <lumx/rays/rayset.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

LUMX_NAMESPACE_BEGIN

enum class RaysetFormat { tm25, lighttools_binary, lighttools_text, zemax_binary, zemax_text, plain_text };

/// "TM-25", "LightTools binary", ... (the RaysetInfo::format strings).
const char* to_string(RaysetFormat f);

/// Which flux column a TM-25 file with both a radiant and a luminous column is read by.
enum class FluxPreference { automatic, luminous, radiant };

/// Limits that protect the readers from absurd or hostile headers. A file exceeding one is rejected.
struct RaysetLimits {
  std::uint64_t max_rays = std::uint64_t(1) << 34;  ///< 17 G rays (the count must also fit the file)
  std::size_t max_spectral_tables = 4096;           ///< TM-25 §4.7.4 tables
  std::size_t max_spectral_points = 1u << 20;       ///< pairs in all spectral tables together
  std::size_t max_additional_items = 1024;          ///< TM-25 §4.7.5 additional columns
  std::size_t max_text_bytes = 16u << 20;           ///< TM-25 §4.7.6 additional text block
  std::size_t max_line_bytes = 64u << 10;           ///< one line of a text format
  std::size_t max_header_lines = 10000;             ///< header lines of a text format
};

struct RaysetReadOptions {
  DiagnosticSink warnings;         ///< receives warnings and notes; may be empty
  std::size_t chunk_rays = 65536;  ///< rays per chunk where a caller reads for you (lumx info/check)
  RaysetLimits limits;
  std::optional<RaysetFormat> format;  ///< read as this format instead of choosing by extension and content
  /// TM-25 files with both flux columns: automatic reads the luminous one (lm).
  FluxPreference flux = FluxPreference::automatic;
  /// Relative difference between the header's total flux and the rays' sum above which a warning is given.
  double flux_tolerance = 1e-4;
  /// Length unit assumed when a file does not state one (LightTools "system units"): a warning says so.
  std::string default_length_unit = "mm";
  /// Quantity assumed for Zemax text files, which do not state one (docs/rays.md).
  PhotometricQuantity zemax_text_quantity = PhotometricQuantity::radiometric;
};

// RaySource (the stream every reader returns) and MemoryRaySource (rays in memory) are in lumx/rays/rayset.h.
// The readers' next() throws lumx::Error, located at the ray's byte offset or line, for a ray that is not
// valid; after an error, rewind() before reading again.

/// Opens a rayset: the format from `options.format`, else by extension (.tm25ray is TM-25) and by content
/// (magic "TM25", "LTRF", a Zemax id 1010 header, a LightTools text header, a "# lumx-rays" header, a
/// Zemax text count line). Reads and checks the header only. Throws lumx::Error.
std::unique_ptr<RaySource> open_rayset(const std::string& path, const RaysetReadOptions& options = {});

/// The format `path` would be read as, or nullopt if it is not a rayset lumx recognises (or cannot be
/// read). Never throws.
std::optional<RaysetFormat> detect_rayset_format(const std::string& path);

/// Streams every ray (from the first, rewinding first) and summarises them; two passes (the bounding
/// sphere's radius needs the box's centre). Leaves the source at its end.
RaysetSummary summarize_rays(RaySource& rays, std::size_t chunk_rays = 65536);

/// Every ray in one chunk (rewinding first). Throws lumx::Error if the source holds more than `max_rays`
/// rays, so that a caller states how much memory it accepts.
RayChunk read_all_rays(RaySource& rays, std::uint64_t max_rays);

struct Tm25WriteOptions {
  std::size_t chunk_rays = 65536;
  /// The header's total flux (for info.quantity) is the sum of the rays written, not info.header_flux: for
  /// rays whose total is known only once they are all streamed (a trace's exits).
  bool header_flux_from_rays = false;
};

/// Writes `rays` (rewound first) as an IES TM-25-13 file, atomically: streamed into a temporary file in
/// the same folder, the header completed, fsync, rename over `path`, fsync of the folder. On any failure
/// `path` is untouched and the temporary file removed. The header comes from `info`: header_flux is
/// written for info.quantity, the other quantity's total from info.values ("luminous flux lm" / "radiant
/// flux W", else NaN), text fields by their RaysetInfo::text names, spectral tables, single wavelength;
/// a wavelength column is written when the chunks carry wavelengths. Positions are converted to mm so
/// that reading the file gives back exactly the floats written, for every position that came from a file
/// in mm (other metre floats: within 1 ulp; docs/rays.md "Exactness"). Throws lumx::Error for a ray or
/// header value TM-25 cannot hold (non-finite, negative flux, text over 1000 characters or not UTF-8,
/// several spectral tables).
void write_tm25(const std::string& path, const RaysetInfo& info, RaySource& rays, const Tm25WriteOptions& options = {});

LUMX_NAMESPACE_END
