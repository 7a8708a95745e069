// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Internal: what the rayset readers and the TM-25 writer share — a read-only file read through pread with
// located errors, little-endian decoding, length units, per-ray validation, the end-of-pass checks (flux
// total against the header, normalised directions), a bounded line reader for the text formats, UTF-32
// text, and a streaming atomic file writer.
#pragma once

// The Neumaier sums below (and the exact comparisons of the readers) need IEEE arithmetic: -ffast-math lets
// the compiler reassociate (a + b) − a to b, which removes the compensation (hard-cases.md §6 item 39).
#if defined(__FAST_MATH__)
#error "lumx's compensated flux sums need IEEE arithmetic: build lumx without -ffast-math"
#endif

#include <lumx/core/diagnostic.h>
#include <lumx/io/rayset_io.h>
#include <lumx/rays/rayset.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace detail {

Diagnostic warning_at_offset(const std::string& file, std::int64_t offset, std::string field, std::string message);
Diagnostic warning_at_line(const std::string& file, int line, std::string field, std::string message);

/// A regular file opened read-only; reads go through pread, so nothing is mapped or cached here.
class RayFile {
 public:
  explicit RayFile(const std::string& path);
  ~RayFile();
  RayFile(const RayFile&) = delete;
  RayFile& operator=(const RayFile&) = delete;

  const std::string& path() const { return path_; }
  std::uint64_t size() const { return size_; }
  /// Reads exactly `n` bytes at `offset`. If the file ends first: lumx::Error at the offset where the
  /// bytes are missing, naming `field`.
  void read_exact(std::uint64_t offset, void* out, std::size_t n, const std::string& field) const;
  /// Reads up to `n` bytes at `offset`; returns how many (fewer only at the end of the file).
  std::size_t read_some(std::uint64_t offset, void* out, std::size_t n) const;

 private:
  std::string path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

inline std::uint32_t le_u32(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}
inline std::int32_t le_i32(const unsigned char* p) {
  const std::uint32_t u = le_u32(p);
  std::int32_t v;
  std::memcpy(&v, &u, 4);
  return v;
}
inline std::uint64_t le_u64(const unsigned char* p) {
  return std::uint64_t(le_u32(p)) | std::uint64_t(le_u32(p + 4)) << 32;
}
inline float le_f32(const unsigned char* p) {
  const std::uint32_t u = le_u32(p);
  float v;
  std::memcpy(&v, &u, 4);
  return v;
}
inline void put_u32(unsigned char* p, std::uint32_t u) {
  p[0] = static_cast<unsigned char>(u), p[1] = static_cast<unsigned char>(u >> 8);
  p[2] = static_cast<unsigned char>(u >> 16), p[3] = static_cast<unsigned char>(u >> 24);
}
inline void put_i32(unsigned char* p, std::int32_t v) {
  std::uint32_t u;
  std::memcpy(&u, &v, 4);
  put_u32(p, u);
}
inline void put_f32(unsigned char* p, float v) {
  std::uint32_t u;
  std::memcpy(&u, &v, 4);
  put_u32(p, u);
}
inline void put_u64(unsigned char* p, std::uint64_t v) {
  put_u32(p, static_cast<std::uint32_t>(v));
  put_u32(p + 4, static_cast<std::uint32_t>(v >> 32));
}

/// A length unit: metres = value * mul / div (division by an exact power of ten keeps mm → m correctly
/// rounded).
struct LengthUnit {
  std::string name;  ///< "mm", "m", "in", ...
  double mul = 1, div = 1;
  float to_metres(float v) const { return static_cast<float>(static_cast<double>(v) * mul / div); }
};
/// Units by the names the plain-text header and LightTools text use ("mm", "millimeters", ...).
std::optional<LengthUnit> length_unit_named(std::string_view name);
/// A format's numeric unit code: `names[code]` for 0 ≤ code < names.size() (an empty name means the
/// code has no unit, e.g. LightTools' 0 = "system units"), else nullopt.
inline std::optional<LengthUnit> length_unit_coded(std::int64_t code, std::initializer_list<const char*> names) {
  if (code < 0 || code >= static_cast<std::int64_t>(names.size())) return std::nullopt;
  const char* name = names.begin()[code];
  return *name ? length_unit_named(name) : std::nullopt;
}
/// Numbers in ray-reader messages: the project's one format (text_scanner.h), 9 significant digits.
std::string format_number_9(double v);
/// TM-25 positions are mm: metres → mm such that reading gives back exactly `m` when any float in mm
/// does (tm25_writer.cpp; docs/rays.md).
float metres_to_tm25_mm(float m);
inline float tm25_mm_to_metres(float mm) {
  return static_cast<float>(static_cast<double>(mm) / 1000.0);
}

/// Where a ray came from, for its diagnostics: its record's byte offset (binary; the field's offset within
/// the record is added) or its line (text).
struct RayLocation {
  std::int64_t byte_offset = -1;
  int line = 0;
  int flux_delta = 24;        ///< byte offset of the flux within the record
  int wavelength_delta = 28;  ///< byte offset of the wavelength within the record
};

/// Field names a format uses in its diagnostics.
struct RayFieldNames {
  std::string position = "position";
  std::string direction = "direction";
  std::string flux = "flux";
  std::string wavelength = "wavelength";

  /// The names the vendor binary formats (LightTools, Zemax) use in diagnostics.
  static RayFieldNames binary_records() { return {"ray position", "ray direction", "ray flux", "ray wavelength"}; }
};

/// Validates one ray and appends it (normalising a direction that is not unit length).
class RayAppender {
 public:
  RayAppender(std::string file, RayFieldNames names) : file_(std::move(file)), names_(std::move(names)) {}
  void append(RayChunk& out, float x, float y, float z, float dx, float dy, float dz, float flux, std::uint64_t index,
              const RayLocation& where);
  /// Checks and appends a wavelength (nm) for the ray just appended.
  void append_wavelength(RayChunk& out, float nm, std::uint64_t index, const RayLocation& where);
  /// Counts since the last reset().
  std::uint64_t normalised = 0;
  double worst_length_error = 0;
  double flux_sum = 0, flux_comp = 0;  ///< Neumaier sum of the fluxes
  std::uint64_t rays = 0;
  void reset() { normalised = 0, worst_length_error = 0, flux_sum = 0, flux_comp = 0, rays = 0; }
  double total() const { return flux_sum + flux_comp; }

 private:
  [[noreturn]] void fail(const RayLocation& where, int delta, const std::string& field,
                         const std::string& message) const;
  std::string file_;
  RayFieldNames names_;
};

/// The part every reader shares: info, warnings, the end-of-pass checks. A reader implements read() and
/// restart().
class RaySourceBase : public RaySource {
 public:
  RaySourceBase(RaysetInfo info, const RaysetReadOptions& options, RayFieldNames names);
  const RaysetInfo& info() const override { return info_; }
  bool next(RayChunk& out, std::size_t max_rays) final;
  void rewind() final;

 protected:
  /// Appends up to `max_rays` rays to `out` (empty on entry); the appender validates them.
  virtual void read(RayChunk& out, std::size_t max_rays) = 0;
  virtual void restart() = 0;
  void warn(const Diagnostic& d) const {
    if (warnings_) warnings_(d);
  }
  /// Where the header states its total flux (for the end-of-pass warning).
  void set_header_flux_location(std::int64_t byte_offset, int line, std::string field) {
    flux_offset_ = byte_offset, flux_line_ = line, flux_field_ = std::move(field);
  }

  RaysetInfo info_;
  RayAppender appender_;
  std::uint64_t delivered_ = 0;  ///< rays handed out since the last rewind

 private:
  void end_of_pass();
  DiagnosticSink warnings_;
  double tolerance_;
  bool pass_clean_ = true;  ///< this pass started at the first ray and nothing was skipped
  bool checked_ = false;    ///< the end-of-pass checks ran once already
  bool at_end_ = false;
  std::int64_t flux_offset_ = -1;
  int flux_line_ = 0;
  std::string flux_field_ = "total flux";
};

/// Lines of a text file read through a bounded buffer (pread). Lines end at LF, CRLF or a lone CR; a UTF-8
/// BOM at the start is skipped; a line longer than the limit is an error at its line.
class LineReader {
 public:
  LineReader(const RayFile& file, std::size_t max_line_bytes);
  /// The next line (valid until the next call), or false at the end.
  bool next(std::string_view& line);
  int line_number() const { return line_; }         ///< number of the line last returned
  std::uint64_t offset() const { return offset_; }  ///< byte offset just after the line last returned
  /// Continue at `offset`, where line `line_number` + 1 starts.
  void seek(std::uint64_t offset, int line_number);

 private:
  bool fill();
  const RayFile& file_;
  std::size_t max_line_;
  std::vector<char> buf_;
  std::size_t begin_ = 0, end_ = 0;  ///< unread bytes in buf_
  std::uint64_t file_pos_ = 0;       ///< file offset of buf_[end_]
  std::uint64_t offset_ = 0;
  int line_ = 0;
  bool eof_ = false;
};

/// Splits a line into numbers (blanks, tabs or commas between them). False if a token is not a finite
/// decimal number (its text in `bad`) or there are more than out_capacity tokens (count still returned).
bool split_floats(std::string_view line, float* out, std::size_t out_capacity, std::size_t& count,
                  std::string_view& bad);
std::string_view trim_blanks(std::string_view s);

/// UTF-32LE text of `n` code units (stops at the first NUL) as UTF-8. Invalid code points become U+FFFD
/// and set `bad`.
std::string utf32le_to_utf8(const unsigned char* p, std::size_t n, bool& bad);
/// UTF-8 text as UTF-32LE code units. False if `s` is not valid UTF-8.
bool utf8_to_utf32(std::string_view s, std::u32string& out);

/// A file written by streaming into a temporary file beside `path`, then (commit) fsync, close, rename
/// over `path` and fsync of the folder. Destroyed without commit: the temporary file is removed.
class AtomicStreamFile {
 public:
  explicit AtomicStreamFile(const std::string& path);
  ~AtomicStreamFile();
  AtomicStreamFile(const AtomicStreamFile&) = delete;
  AtomicStreamFile& operator=(const AtomicStreamFile&) = delete;
  void write(const void* data, std::size_t n);                            ///< appends (buffered)
  void pwrite_at(std::uint64_t offset, const void* data, std::size_t n);  ///< rewrites bytes already written
  std::uint64_t size() const { return written_ + buf_.size(); }
  void commit();

 private:
  void flush();
  [[noreturn]] void fail(const std::string& step, int err);
  std::string path_, tmp_;
  int fd_ = -1;
  std::vector<unsigned char> buf_;
  std::uint64_t written_ = 0;
};

/// Relative-difference text for the flux warning (" (10000 times the header)", " (+3.2 %)").
std::string ratio_text(double header, double sum);

/// Binary formats whose rays are fixed-size records of little-endian float32 (TM-25, LightTools, Zemax).
struct FloatRecordLayout {
  std::uint64_t data_offset = 0;  ///< byte offset of the first ray
  std::uint64_t rays = 0;         ///< checked against the file size by the caller
  unsigned columns = 7;           ///< floats per ray; x y z kx ky kz come first
  int flux_column = 6;
  int wavelength_column = -1;   ///< −1: none
  double wavelength_to_nm = 1;  ///< 1000 for µm
  LengthUnit unit{"mm", 1, 1000};
  std::vector<int> unit_range_columns;  ///< values that must lie in [−1, 1] (TM-25 Stokes S1..S3)
  std::string unit_range_field;
  int index_column = -1;  ///< a 1-based index that must lie in [1, index_max] (TM-25 spectrum index)
  std::int64_t index_max = 0;
  std::string index_field;
  std::int64_t flux_offset = -1;  ///< where the header states the total flux
  std::string flux_field = "total flux";
};
std::unique_ptr<RaySource> make_float_record_source(std::shared_ptr<const RayFile> file, RaysetInfo info,
                                                    const RaysetReadOptions& options, RayFieldNames names,
                                                    FloatRecordLayout layout);

/// Text formats with one ray per line (LightTools text, Zemax text, plain text).
struct TextRayLayout {
  std::uint64_t data_offset = 0;  ///< byte offset of the line after the header
  int header_lines = 0;           ///< lines before data_offset
  std::size_t columns = 7;        ///< numbers per ray line
  std::string column_names = "x y z kx ky kz flux";
  int flux_column = 6;  ///< −1: every ray carries constant_flux
  float constant_flux = 1;
  int wavelength_column = -1;
  double wavelength_to_nm = 1;
  LengthUnit unit{"mm", 1, 1000};
  std::string end_marker;      ///< a line that ends the data ("lt_endofdata"), or empty (end of file)
  bool hash_comments = false;  ///< lines starting with '#' are comments
  std::size_t max_line_bytes = 64u << 10;
  std::uint64_t max_rays = ~std::uint64_t(0);  ///< RaysetLimits::max_rays
  int flux_line = 0;  ///< where the header states the total flux
  std::string flux_field = "total flux";
};
/// Counts the ray lines after the header (no number is parsed); warns about text after the end marker
/// and fails if the end marker is missing.
std::uint64_t count_text_rays(const RayFile& file, const TextRayLayout& layout, const DiagnosticSink& warnings);
std::unique_ptr<RaySource> make_text_ray_source(std::shared_ptr<const RayFile> file, RaysetInfo info,
                                                const RaysetReadOptions& options, RayFieldNames names,
                                                TextRayLayout layout);

/// Format-specific openers (tm25_reader.cpp, lighttools_reader.cpp, zemax_reader.cpp, plain_rays_reader.cpp).
std::unique_ptr<RaySource> open_tm25(std::shared_ptr<const RayFile> file, const RaysetReadOptions& options);
std::unique_ptr<RaySource> open_lighttools_binary(std::shared_ptr<const RayFile> file,
                                                  const RaysetReadOptions& options);
std::unique_ptr<RaySource> open_lighttools_text(std::shared_ptr<const RayFile> file, const RaysetReadOptions& options);
std::unique_ptr<RaySource> open_zemax_binary(std::shared_ptr<const RayFile> file, const RaysetReadOptions& options);
std::unique_ptr<RaySource> open_zemax_text(std::shared_ptr<const RayFile> file, const RaysetReadOptions& options);
std::unique_ptr<RaySource> open_plain_rays(std::shared_ptr<const RayFile> file, const RaysetReadOptions& options);

}  // namespace detail
LUMX_NAMESPACE_END
