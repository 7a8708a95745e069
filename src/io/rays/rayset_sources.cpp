// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The two RaySource shapes every reader reduces to: fixed-size float32 records (TM-25, LightTools binary,
// Zemax binary) read through a 4 MiB pread window, and one ray per text line (LightTools text, Zemax
// text, plain text) read through a bounded line buffer.
#include "io/rays/rayset_common.h"
#include "io/text_scanner.h"

#include <algorithm>

LUMX_NAMESPACE_BEGIN
namespace detail {
namespace {

constexpr std::size_t kWindowBytes = 4u << 20;

class FloatRecordSource final : public RaySourceBase {
 public:
  FloatRecordSource(std::shared_ptr<const RayFile> file, RaysetInfo info, const RaysetReadOptions& options,
                    RayFieldNames names, FloatRecordLayout layout)
      : RaySourceBase(std::move(info), options, std::move(names)),
        file_(std::move(file)),
        l_(std::move(layout)),
        rec_(4u * l_.columns),
        block_rays_(std::max<std::size_t>(1, kWindowBytes / rec_)) {
    set_header_flux_location(l_.flux_offset, 0, l_.flux_field);
  }

 protected:
  void read(RayChunk& out, std::size_t max_rays) override {
    const std::uint64_t left = l_.rays - next_;
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(max_rays, left));
    if (n == 0) return;
    out.reserve(n);
    if (l_.wavelength_column >= 0) out.wavelength_nm.reserve(n);
    std::size_t done = 0;
    while (done < n) {
      const std::size_t m = std::min(n - done, block_rays_);
      buf_.resize(m * rec_);
      const std::uint64_t off = l_.data_offset + next_ * rec_;
      file_->read_exact(off, buf_.data(), m * rec_, "ray data");
      for (std::size_t i = 0; i < m; ++i) decode(out, buf_.data() + i * rec_, next_ + i, off + i * rec_);
      next_ += m;
      done += m;
    }
  }
  void restart() override { next_ = 0; }

 private:
  void decode(RayChunk& out, const unsigned char* p, std::uint64_t index, std::uint64_t offset) {
    const LengthUnit& u = l_.unit;
    RayLocation where;
    where.byte_offset = static_cast<std::int64_t>(offset);
    where.flux_delta = 4 * l_.flux_column;
    where.wavelength_delta = 4 * l_.wavelength_column;
    appender_.append(out, u.to_metres(le_f32(p)), u.to_metres(le_f32(p + 4)), u.to_metres(le_f32(p + 8)),
                     le_f32(p + 12), le_f32(p + 16), le_f32(p + 20), le_f32(p + 4 * l_.flux_column), index, where);
    if (l_.wavelength_column >= 0)
      appender_.append_wavelength(
          out, static_cast<float>(static_cast<double>(le_f32(p + 4 * l_.wavelength_column)) * l_.wavelength_to_nm),
          index, where);
    for (int c : l_.unit_range_columns) {
      const float v = le_f32(p + 4 * c);
      if (!(v >= -1.0f && v <= 1.0f))
        throw_at_offset(info_.file, static_cast<std::int64_t>(offset) + 4 * c, l_.unit_range_field,
                        "ray " + std::to_string(index + 1) + ": value " + std::to_string(v) + " is outside [-1, 1]");
    }
    if (l_.index_column >= 0) {
      const float v = le_f32(p + 4 * l_.index_column);
      if (!(v >= 1.0f && v <= static_cast<float>(l_.index_max) && v == std::floor(v)))
        throw_at_offset(info_.file, static_cast<std::int64_t>(offset) + 4 * l_.index_column, l_.index_field,
                        "ray " + std::to_string(index + 1) + ": spectrum index " + std::to_string(v) +
                            " is not a table number 1.." + std::to_string(l_.index_max));
    }
  }

  std::shared_ptr<const RayFile> file_;
  FloatRecordLayout l_;
  std::size_t rec_;
  std::size_t block_rays_;
  std::uint64_t next_ = 0;
  std::vector<unsigned char> buf_;
};

bool is_comment_or_blank(std::string_view t, bool hash_comments) {
  return t.empty() || (hash_comments && t.front() == '#');
}

class TextRaySource final : public RaySourceBase {
 public:
  TextRaySource(std::shared_ptr<const RayFile> file, RaysetInfo info, const RaysetReadOptions& options,
                RayFieldNames names, TextRayLayout layout)
      : RaySourceBase(std::move(info), options, std::move(names)),
        file_(std::move(file)),
        l_(std::move(layout)),
        lines_(*file_, l_.max_line_bytes) {
    set_header_flux_location(-1, l_.flux_line, l_.flux_field);
    restart();
  }

 protected:
  void read(RayChunk& out, std::size_t max_rays) override {
    float v[9];
    while (out.size() < max_rays && !done_) {
      std::string_view line;
      if (!lines_.next(line)) {
        done_ = true;
        break;
      }
      const std::string_view t = trim_blanks(line);
      if (is_comment_or_blank(t, l_.hash_comments)) continue;
      if (!l_.end_marker.empty() && t == l_.end_marker) {
        done_ = true;
        break;
      }
      const int ln = lines_.line_number();
      std::size_t count = 0;
      std::string_view bad;
      const bool ok = split_floats(t, v, 9, count, bad);
      if (!ok && count <= 9) throw_at_line(info_.file, ln, "ray", "'" + excerpt(bad) + "' is not a finite number");
      if (count != l_.columns)
        throw_at_line(info_.file, ln, "ray",
                      "expected " + std::to_string(l_.columns) + " numbers (" + l_.column_names + "), found " +
                          std::to_string(count));
      const LengthUnit& u = l_.unit;
      RayLocation where;
      where.line = ln;
      const float flux = l_.flux_column >= 0 ? v[l_.flux_column] : l_.constant_flux;
      appender_.append(out, u.to_metres(v[0]), u.to_metres(v[1]), u.to_metres(v[2]), v[3], v[4], v[5], flux, index_,
                       where);
      if (l_.wavelength_column >= 0)
        appender_.append_wavelength(
            out, static_cast<float>(static_cast<double>(v[l_.wavelength_column]) * l_.wavelength_to_nm), index_, where);
      ++index_;
    }
  }
  void restart() override {
    lines_.seek(l_.data_offset, l_.header_lines);
    index_ = 0;
    done_ = false;
  }

 private:
  std::shared_ptr<const RayFile> file_;
  TextRayLayout l_;
  LineReader lines_;
  std::uint64_t index_ = 0;
  bool done_ = false;
};

}  // namespace

std::unique_ptr<RaySource> make_float_record_source(std::shared_ptr<const RayFile> file, RaysetInfo info,
                                                    const RaysetReadOptions& options, RayFieldNames names,
                                                    FloatRecordLayout layout) {
  return std::make_unique<FloatRecordSource>(std::move(file), std::move(info), options, std::move(names),
                                             std::move(layout));
}

std::unique_ptr<RaySource> make_text_ray_source(std::shared_ptr<const RayFile> file, RaysetInfo info,
                                                const RaysetReadOptions& options, RayFieldNames names,
                                                TextRayLayout layout) {
  return std::make_unique<TextRaySource>(std::move(file), std::move(info), options, std::move(names),
                                         std::move(layout));
}

std::uint64_t count_text_rays(const RayFile& file, const TextRayLayout& layout, const DiagnosticSink& warnings) {
  LineReader lines(file, layout.max_line_bytes);
  lines.seek(layout.data_offset, layout.header_lines);
  std::uint64_t n = 0;
  bool ended = false;
  std::string_view line;
  while (lines.next(line)) {
    const std::string_view t = trim_blanks(line);
    if (ended) {
      if (!t.empty()) {
        if (warnings)
          warnings(warning_at_line(file.path(), lines.line_number(), "end of data",
                                   "text after '" + layout.end_marker + "' is ignored"));
        break;
      }
      continue;
    }
    if (is_comment_or_blank(t, layout.hash_comments)) continue;
    if (!layout.end_marker.empty() && t == layout.end_marker) {
      ended = true;
      continue;
    }
    if (++n > layout.max_rays)
      throw_at_line(file.path(), lines.line_number(), "ray data",
                    "more rays than RaysetLimits::max_rays (" + std::to_string(layout.max_rays) + ")");
  }
  if (!layout.end_marker.empty() && !ended)
    throw_at_line(file.path(), std::max(1, lines.line_number()), "end of data",
                  "the file ends without the '" + layout.end_marker + "' line (truncated?)");
  return n;
}

}  // namespace detail
LUMX_NAMESPACE_END
