// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/io/photometry_io.h — reading and writing IES LM-63, EULUMDAT and IES TM-33 files.
//
// The format layer on top of the model in lumx/photometry/photometry.h. Each format has a reader and a writer
// (src/io/photometry/ies_reader.cpp, ies_writer.cpp, ldt_reader.cpp, ldt_writer.cpp; TM-33 in lumx/io/tm33_io.h
// and tm33_reader.cpp, tm33_writer.cpp); read_photometry() picks one by
// file extension and falls back to sniffing the content. Readers are permissive about what real files do
// (formats.md §1.6, §2.4) and report it as warnings; they throw lumx::Error, located by file, line and
// field, for anything that would make the data wrong. Untrusted counts are checked against the values
// actually present before anything is allocated from them.
#pragma once

#include <lumx/core/diagnostic.h>
#include <lumx/photometry/photometry.h>

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

LUMX_NAMESPACE_BEGIN

/// File formats of far-field photometry. TM-33 (= ATLA S001 = UNI 11733) is XML, or its JSON form.
enum class PhotometryFormat { ies, ldt, tm33_xml, tm33_json };

/// Limits that protect readers from absurd or hostile files. A file exceeding one is rejected.
struct ReadLimits {
  std::size_t max_file_bytes = 16u << 20;  ///< 16 MiB: the largest real files are ~2 MB
  std::size_t max_angles = 3601;           ///< per axis (0.05 degree steps over 180 degrees)
  std::size_t max_lamp_sets = 20;          ///< EULUMDAT allows at most 20 lamp sets
};

struct ReadOptions {
  DiagnosticSink warnings;  ///< receives warnings and notes; may be empty
  ReadLimits limits;
  /// Folder in which an IES `TILT=<file>` is looked up. read_photometry(path) sets it to the file's
  /// folder; reading from memory without it makes an external TILT file an error.
  std::string base_dir;
};

/// Parses IES LM-63 text (1986, 1991, 1995, 2002, 2019). `name` is used in diagnostics.
Photometry read_ies(std::string_view text, const std::string& name, const ReadOptions& options = {});
/// Parses EULUMDAT text. `name` is used in diagnostics.
Photometry read_ldt(std::string_view text, const std::string& name, const ReadOptions& options = {});

/// Format named by a file name's extension (.ies, .ldt, .xml and .json for TM-33; case-insensitive), if any.
std::optional<PhotometryFormat> format_from_extension(const std::string& path);

/// Format from a file name's extension (see format_from_extension), else by sniffing `head` (the
/// file's first bytes): '<' or '{' first means TM-33 XML or JSON, an IES version line or a TILT= line
/// means IES, otherwise EULUMDAT if the first lines have its numeric layout. Throws lumx::Error if none
/// fits.
PhotometryFormat detect_format(const std::string& path, std::string_view head);

/// Reads a file of either format. Throws lumx::Error (file missing, too large, or malformed).
Photometry read_photometry(const std::string& path, const ReadOptions& options = {});

/// LM-63 editions the IES writer can produce.
enum class IesVersion { lm63_2002, lm63_2019 };

struct IesWriteOptions {
  IesVersion version = IesVersion::lm63_2019;
  int significant_digits = 7;  ///< candela and angle precision
  /// C90-C270 symmetry is legal as the horizontal range 90..270 (LM-63-1995 on), and written so by
  /// default (write-then-read gives back the same model). Common readers mishandle it, though (Blender
  /// shifts it by 90 degrees, others require the last angle to be 0, 90, 180 or 360; formats.md §1.4):
  /// set this to write such data expanded to 0..360 instead, which changes no intensity. The `lumx
  /// convert` tool does so unless asked not to.
  bool expand_c90_c270 = false;
};

struct LdtWriteOptions {
  int significant_digits = 7;
};

/// IES text for `p` (Type A, B or C). The stored subset is written with the range that states its
/// symmetry (C90-C270: see IesWriteOptions); candela are written as absolute cd with multiplier 1.
/// Throws lumx::Error if `p` cannot be expressed (inconsistent table sizes, non-finite values, angles
/// not increasing, or a stored range that contradicts the symmetry).
std::string format_ies(const Photometry& p, const IesWriteOptions& options = {});
/// EULUMDAT text for `p`. Type C only (convert A/B with to_type_c first); intensities written in cd/klm.
std::string format_ldt(const Photometry& p, const LdtWriteOptions& options = {});

/// Editions of IES TM-33 the TM-33 writer can produce (docs/tm33.md).
enum class Tm33Version {
  tm33_23,  ///< root "IESTM33-22", Version 1.1: adds Symm and Multiplier (default)
  tm33_18,  ///< root "IESTM33", Version 1.0: TM-33-18, ATLA S001, UNI 11733
};

struct Tm33WriteOptions {
  Tm33Version version = Tm33Version::tm33_23;
  /// Significant digits of numbers; 0 writes the shortest text that reads back to the same double, so
  /// TM-33 -> model -> TM-33 keeps every value exactly.
  int significant_digits = 0;
};

struct WriteOptions {
  IesWriteOptions ies;
  LdtWriteOptions ldt;
  Tm33WriteOptions tm33;
};

/// Writes `p` in the format named by `path`'s extension, atomically (temporary file in the same folder,
/// fsync, rename): on any failure the previous file, if any, is left untouched.
void write_photometry(const Photometry& p, const std::string& path, const WriteOptions& options = {});

LUMX_NAMESPACE_END
