// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// What the rayset readers and the TM-25 writer share (see rayset_common.h).
#include "io/rays/rayset_common.h"
#include "io/text_scanner.h"

#include <lumx/io/atomic_file.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <limits>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

LUMX_NAMESPACE_BEGIN
namespace detail {

std::string format_number_9(double v) { return format_number(v, 9); }

/// A warning located by byte offset (offset ≥ 0) or by line (line > 0).
static Diagnostic warning_at(const std::string& file, std::int64_t offset, int line, std::string field,
                             std::string message) {
  Diagnostic d;
  d.severity = Severity::warning;
  d.file = file;
  d.byte_offset = offset;
  d.line = line;
  d.field = std::move(field);
  d.message = std::move(message);
  return d;
}

Diagnostic warning_at_offset(const std::string& file, std::int64_t offset, std::string field, std::string message) {
  return warning_at(file, offset, 0, std::move(field), std::move(message));
}

Diagnostic warning_at_line(const std::string& file, int line, std::string field, std::string message) {
  return warning_at(file, -1, line, std::move(field), std::move(message));
}

// ---- RayFile ----

RayFile::RayFile(const std::string& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) throw_at_field(path, "file", std::string("cannot open: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd_, &st) != 0) {
    const int err = errno;
    ::close(fd_);
    throw_at_field(path, "file", std::string("cannot stat: ") + std::strerror(err));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd_);
    throw_at_field(path, "file", "not a regular file");
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
}

RayFile::~RayFile() {
  if (fd_ >= 0) ::close(fd_);
}

std::size_t RayFile::read_some(std::uint64_t offset, void* out, std::size_t n) const {
  auto* p = static_cast<unsigned char*>(out);
  std::size_t got = 0;
  while (got < n) {
    const ssize_t r = ::pread(fd_, p + got, n - got, static_cast<off_t>(offset + got));
    if (r < 0) {
      if (errno == EINTR) continue;
      throw_at_offset(path_, static_cast<std::int64_t>(offset + got), "file",
                      std::string("read failed: ") + std::strerror(errno));
    }
    if (r == 0) break;
    got += static_cast<std::size_t>(r);
  }
  return got;
}

void RayFile::read_exact(std::uint64_t offset, void* out, std::size_t n, const std::string& field) const {
  if (offset > size_ || n > size_ - offset)
    throw_at_offset(path_, static_cast<std::int64_t>(std::min(offset, size_)), field,
                    "file ends at byte " + std::to_string(size_) + ", inside this field (bytes " +
                        std::to_string(offset) + ".." + std::to_string(offset + n) + ")");
  if (read_some(offset, out, n) != n)
    throw_at_offset(path_, static_cast<std::int64_t>(offset), field, "file shrank while being read");
}

// ---- units ----

std::optional<LengthUnit> length_unit_named(std::string_view name) {
  std::string s(name);
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (s == "mm" || s == "millimeter" || s == "millimeters" || s == "millimetre" || s == "millimetres")
    return LengthUnit{"mm", 1, 1000};
  if (s == "cm" || s == "centimeter" || s == "centimeters" || s == "centimetre" || s == "centimetres")
    return LengthUnit{"cm", 1, 100};
  if (s == "m" || s == "meter" || s == "meters" || s == "metre" || s == "metres") return LengthUnit{"m", 1, 1};
  if (s == "um" || s == "micron" || s == "microns" || s == "micrometer" || s == "micrometers" || s == "micrometre" ||
      s == "micrometres")
    return LengthUnit{"um", 1, 1e6};
  if (s == "nm" || s == "nanometer" || s == "nanometers" || s == "nanometre" || s == "nanometres")
    return LengthUnit{"nm", 1, 1e9};
  if (s == "in" || s == "inch" || s == "inches") return LengthUnit{"in", 0.0254, 1};
  if (s == "ft" || s == "foot" || s == "feet") return LengthUnit{"ft", 0.3048, 1};
  return std::nullopt;
}

float metres_to_tm25_mm(float m) {
  // mm → m (the reader) is not onto the floats, so m → mm picks, among the float nearest to m·1000 and
  // its two neighbours, one that reads back as exactly m. Every float a reader produced has one.
  const float y = static_cast<float>(static_cast<double>(m) * 1000.0);
  if (!std::isfinite(y) || tm25_mm_to_metres(y) == m) return y;
  const float up = std::nextafter(y, std::numeric_limits<float>::infinity());
  if (tm25_mm_to_metres(up) == m) return up;
  const float down = std::nextafter(y, -std::numeric_limits<float>::infinity());
  if (tm25_mm_to_metres(down) == m) return down;
  return y;
}

// ---- ray validation ----

void RayAppender::fail(const RayLocation& where, int delta, const std::string& field,
                       const std::string& message) const {
  Diagnostic d;
  d.file = file_;
  d.line = where.line;
  d.byte_offset = where.line > 0 || where.byte_offset < 0 ? -1 : where.byte_offset + delta;
  d.field = field;
  d.message = message;
  throw Error(std::move(d));
}

namespace {
std::string fnum(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}
}  // namespace

void RayAppender::append(RayChunk& out, float x, float y, float z, float dx, float dy, float dz, float flux,
                         std::uint64_t index, const RayLocation& where) {
  const auto ray = [index] { return "ray " + std::to_string(index + 1) + ": "; };  // only on failure
  if (!(std::isfinite(x) && std::isfinite(y) && std::isfinite(z)))
    fail(where, 0, names_.position,
         ray() + "start point (" + fnum(x) + ", " + fnum(y) + ", " + fnum(z) + ") m is not finite");
  if (!(std::isfinite(dx) && std::isfinite(dy) && std::isfinite(dz)))
    fail(where, 12, names_.direction,
         ray() + "direction (" + fnum(dx) + ", " + fnum(dy) + ", " + fnum(dz) + ") is not finite");
  const double ddx = dx, ddy = dy, ddz = dz;
  const double len2 = ddx * ddx + ddy * ddy + ddz * ddz;
  if (!(len2 > 0)) fail(where, 12, names_.direction, ray() + "direction is the zero vector");
  const double len = std::sqrt(len2);
  const double err = std::abs(len - 1.0);
  if (err > 1e-6) {
    dx = static_cast<float>(ddx / len), dy = static_cast<float>(ddy / len), dz = static_cast<float>(ddz / len);
    ++normalised;
    worst_length_error = std::max(worst_length_error, err);
  }
  if (!std::isfinite(flux)) fail(where, where.flux_delta, names_.flux, ray() + "flux " + fnum(flux) + " is not finite");
  if (flux < 0) fail(where, where.flux_delta, names_.flux, ray() + "flux " + fnum(flux) + " is negative");
  out.x.push_back(x), out.y.push_back(y), out.z.push_back(z);
  out.dx.push_back(dx), out.dy.push_back(dy), out.dz.push_back(dz);
  out.flux.push_back(flux);
  // Neumaier's compensated sum: the flux check against the header must not drift with 10^7 rays.
  const double f = flux;
  const double t = flux_sum + f;
  flux_comp += std::abs(flux_sum) >= std::abs(f) ? (flux_sum - t) + f : (f - t) + flux_sum;
  flux_sum = t;
  ++rays;
}

void RayAppender::append_wavelength(RayChunk& out, float nm, std::uint64_t index, const RayLocation& where) {
  if (!(std::isfinite(nm) && nm > 0))
    fail(where, where.wavelength_delta, names_.wavelength,
         "ray " + std::to_string(index + 1) + ": wavelength " + fnum(nm) + " nm is not a positive number");
  out.wavelength_nm.push_back(nm);
}

// ---- RaySourceBase ----

RaySourceBase::RaySourceBase(RaysetInfo info, const RaysetReadOptions& options, RayFieldNames names)
    : info_(std::move(info)),
      appender_(info_.file, std::move(names)),
      warnings_(options.warnings),
      tolerance_(options.flux_tolerance) {}

bool RaySourceBase::next(RayChunk& out, std::size_t max_rays) {
  out.clear();
  if (at_end_) return false;
  try {
    read(out, std::max<std::size_t>(max_rays, 1));
  } catch (...) {
    pass_clean_ = false;  // the caller may go on after an error; its totals are not the file's
    out.clear();
    throw;
  }
  delivered_ += out.size();
  if (out.empty()) {
    at_end_ = true;
    if (pass_clean_ && !checked_) end_of_pass();
    return false;
  }
  return true;
}

void RaySourceBase::rewind() {
  restart();
  appender_.reset();
  delivered_ = 0;
  at_end_ = false;
  pass_clean_ = true;
}

std::string ratio_text(double header, double sum) {
  if (header == 0 || sum == 0) return "";
  const double r = sum / header;
  char buf[64];
  if (r > 2 || r < 0.5)
    std::snprintf(buf, sizeof buf, " (%.6g times the header)", r);
  else
    std::snprintf(buf, sizeof buf, " (%+.4g %%)", 100 * (r - 1));
  return buf;
}

void RaySourceBase::end_of_pass() {
  checked_ = true;
  const char* unit = flux_unit(info_.quantity);
  if (appender_.normalised > 0) {
    Diagnostic d = warning_at_offset(info_.file, -1, appender_.normalised == 1 ? "direction" : "directions",
                                     std::to_string(appender_.normalised) + " of " + std::to_string(appender_.rays) +
                                         " directions were not unit vectors (largest | |k| - 1 | = " +
                                         fnum(appender_.worst_length_error) + "); they were normalised");
    warn(d);
  }
  if (std::isnan(info_.header_flux)) return;
  const double sum = appender_.total();
  const double h = info_.header_flux;
  if (std::abs(sum - h) > tolerance_ * std::max(std::abs(h), std::abs(sum))) {
    Diagnostic d;
    d.severity = Severity::warning;
    d.file = info_.file;
    d.line = flux_line_;
    d.byte_offset = flux_line_ > 0 ? -1 : flux_offset_;
    d.field = flux_field_;
    d.message = "the header states " + fnum(h) + " " + unit + ", the " + std::to_string(appender_.rays) +
                " rays sum to " + fnum(sum) + " " + unit + ratio_text(h, sum) +
                "; the rays are kept as they are and the header value is reported as is";
    warn(d);
  }
}

// ---- LineReader ----

LineReader::LineReader(const RayFile& file, std::size_t max_line_bytes)
    : file_(file), max_line_(max_line_bytes), buf_(std::max<std::size_t>(1u << 20, 2 * max_line_bytes + 16)) {}

void LineReader::seek(std::uint64_t offset, int line_number) {
  begin_ = end_ = 0;
  file_pos_ = offset;
  offset_ = offset;
  line_ = line_number;
  eof_ = false;
}

bool LineReader::fill() {
  if (eof_) return false;
  if (begin_ > 0) {
    std::memmove(buf_.data(), buf_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  if (end_ == buf_.size()) return false;
  const std::size_t got = file_.read_some(file_pos_, buf_.data() + end_, buf_.size() - end_);
  if (got == 0) eof_ = true;
  end_ += got;
  file_pos_ += got;
  return got > 0;
}

bool LineReader::next(std::string_view& line) {
  for (;;) {
    const char* b = buf_.data() + begin_;
    const std::size_t n = end_ - begin_;
    std::size_t k = 0;
    while (k < n && b[k] != '\n' && b[k] != '\r') ++k;
    if (k > max_line_)
      throw_at_line(file_.path(), line_ + 1, "line",
                    "line is longer than RaysetLimits::max_line_bytes (" + std::to_string(max_line_) + ")");
    bool have = false;
    std::size_t term = 0;
    if (k < n) {
      if (b[k] == '\n') {
        have = true, term = 1;
      } else if (k + 1 < n) {
        have = true, term = b[k + 1] == '\n' ? 2 : 1;
      } else if (eof_) {
        have = true, term = 1;
      }
    } else if (eof_) {
      if (n == 0) return false;
      have = true, term = 0;
    }
    if (!have) {
      fill();
      continue;
    }
    line = std::string_view(b, k);
    if (line_ == 0 && offset_ == 0 && line.size() >= 3 && static_cast<unsigned char>(line[0]) == 0xEF &&
        static_cast<unsigned char>(line[1]) == 0xBB && static_cast<unsigned char>(line[2]) == 0xBF)
      line.remove_prefix(3);
    begin_ += k + term;
    offset_ += k + term;
    ++line_;
    return true;
  }
}

// ---- text numbers ----

std::string_view trim_blanks(std::string_view s) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\f' || c == '\v' || c == '\0'; };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

bool split_floats(std::string_view line, float* out, std::size_t out_capacity, std::size_t& count,
                  std::string_view& bad) {
  count = 0;
  std::size_t i = 0;
  const auto sep = [](char c) { return c == ' ' || c == '\t' || c == ',' || c == '\f' || c == '\v' || c == '\0'; };
  bool ok = true;
  while (i < line.size()) {
    while (i < line.size() && sep(line[i])) ++i;
    if (i >= line.size()) break;
    std::size_t j = i;
    while (j < line.size() && !sep(line[j])) ++j;
    std::string_view tok = line.substr(i, j - i);
    i = j;
    if (count >= out_capacity) {
      ++count;
      ok = false;
      continue;
    }
    std::string_view t = tok;
    if (!t.empty() && t.front() == '+') t.remove_prefix(1);
    const char c0 = t.empty() ? 'x' : t.front();
    float v = 0;
    bool good = c0 == '-' || c0 == '.' || (c0 >= '0' && c0 <= '9');
    if (good) {
      const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
      if (r.ptr != t.data() + t.size()) {
        good = false;
      } else if (r.ec == std::errc::result_out_of_range) {
        double dv = 0;  // underflow becomes 0 or a subnormal; overflow is refused
        const auto r2 = std::from_chars(t.data(), t.data() + t.size(), dv);
        good = r2.ec == std::errc() && std::abs(dv) < 1.0;
        v = static_cast<float>(dv);
      } else if (r.ec != std::errc()) {
        good = false;
      }
      good = good && std::isfinite(v);
    }
    if (!good) {
      if (ok) bad = tok;
      ok = false;
    }
    out[count++] = v;
  }
  return ok;
}

// ---- UTF-32 ----

namespace {
void put_utf8(std::string& s, char32_t c) {
  if (c < 0x80) {
    s += static_cast<char>(c);
  } else if (c < 0x800) {
    s += static_cast<char>(0xC0 | (c >> 6));
    s += static_cast<char>(0x80 | (c & 0x3F));
  } else if (c < 0x10000) {
    s += static_cast<char>(0xE0 | (c >> 12));
    s += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    s += static_cast<char>(0x80 | (c & 0x3F));
  } else {
    s += static_cast<char>(0xF0 | (c >> 18));
    s += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
    s += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    s += static_cast<char>(0x80 | (c & 0x3F));
  }
}
}  // namespace

std::string utf32le_to_utf8(const unsigned char* p, std::size_t n, bool& bad) {
  std::string s;
  for (std::size_t i = 0; i < n; ++i) {
    char32_t c = le_u32(p + 4 * i);
    if (c == 0) break;
    if (c > 0x10FFFF || (c >= 0xD800 && c <= 0xDFFF)) {
      c = 0xFFFD;
      bad = true;
    }
    put_utf8(s, c);
  }
  return s;
}

bool utf8_to_utf32(std::string_view s, std::u32string& out) {
  out.clear();
  std::size_t i = 0;
  while (i < s.size()) {
    const auto b0 = static_cast<unsigned char>(s[i]);
    std::size_t len = 0;
    char32_t c = 0;
    if (b0 < 0x80) {
      len = 1, c = b0;
    } else if ((b0 & 0xE0) == 0xC0) {
      len = 2, c = b0 & 0x1F;
    } else if ((b0 & 0xF0) == 0xE0) {
      len = 3, c = b0 & 0x0F;
    } else if ((b0 & 0xF8) == 0xF0) {
      len = 4, c = b0 & 0x07;
    } else {
      return false;
    }
    if (i + len > s.size()) return false;
    for (std::size_t k = 1; k < len; ++k) {
      const auto b = static_cast<unsigned char>(s[i + k]);
      if ((b & 0xC0) != 0x80) return false;
      c = (c << 6) | (b & 0x3F);
    }
    const char32_t min_for_len[] = {0, 0, 0x80, 0x800, 0x10000};
    if (c < min_for_len[len] || c > 0x10FFFF || (c >= 0xD800 && c <= 0xDFFF)) return false;
    out.push_back(c);
    i += len;
  }
  return true;
}

// ---- AtomicStreamFile ----

AtomicStreamFile::AtomicStreamFile(const std::string& path) : path_(path) {
  remove_stale_temporaries(path);
  tmp_ = temporary_sibling_name(path);
  fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    const int err = errno;
    throw_at_field(path_, "file", std::string("create temporary file: ") + std::strerror(err));
  }
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) ::fchmod(fd_, st.st_mode & 07777);
  buf_.reserve(4u << 20);
}

AtomicStreamFile::~AtomicStreamFile() {
  if (fd_ >= 0) {
    ::close(fd_);
    ::unlink(tmp_.c_str());
  }
}

void AtomicStreamFile::fail(const std::string& step, int err) {
  if (fd_ >= 0) {
    ::close(fd_);
    ::unlink(tmp_.c_str());
    fd_ = -1;
  }
  throw_at_field(path_, "file", step + ": " + std::strerror(err));
}

void AtomicStreamFile::flush() {
  const unsigned char* p = buf_.data();
  std::size_t left = buf_.size();
  while (left > 0) {
    const ssize_t n = ::write(fd_, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("write", errno);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  written_ += buf_.size();
  buf_.clear();
}

void AtomicStreamFile::write(const void* data, std::size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  while (n > 0) {
    const std::size_t room = buf_.capacity() - buf_.size();
    const std::size_t k = std::min(room, n);
    buf_.insert(buf_.end(), p, p + k);
    p += k;
    n -= k;
    if (buf_.size() == buf_.capacity()) flush();
  }
}

void AtomicStreamFile::pwrite_at(std::uint64_t offset, const void* data, std::size_t n) {
  flush();
  const auto* p = static_cast<const unsigned char*>(data);
  std::size_t done = 0;
  while (done < n) {
    const ssize_t r = ::pwrite(fd_, p + done, n - done, static_cast<off_t>(offset + done));
    if (r < 0) {
      if (errno == EINTR) continue;
      fail("write", errno);
    }
    done += static_cast<std::size_t>(r);
  }
}

void AtomicStreamFile::commit() {
  flush();
  if (::fsync(fd_) != 0) fail("fsync", errno);
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp_.c_str());
    throw_at_field(path_, "file", std::string("close: ") + std::strerror(err));
  }
  if (::rename(tmp_.c_str(), path_.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp_.c_str());
    throw_at_field(path_, "file", std::string("rename: ") + std::strerror(err));
  }
  const std::filesystem::path target(path_);
  sync_folder(target.has_parent_path() ? target.parent_path().string() : std::string("."), path_, true);
}

}  // namespace detail
LUMX_NAMESPACE_END
