// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// IES TM-25-13 ray files (formats.md §3.1): the 256-byte header, 32 bytes of flags, nine 4000-byte UTF-32
// text fields, spectral tables, additional column names and text, then a float32 matrix of rays. Every
// consistency rule of the reference implementation is checked, every count against the file size before
// anything is allocated from it; section numbers are cited in the field names ("... (4.7.1.6)").
#include "io/rays/rayset_common.h"
#include "io/text_scanner.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <limits>

LUMX_NAMESPACE_BEGIN
namespace detail {
namespace {

constexpr std::uint64_t kFlagsEnd = 288;  // the 256-byte numeric header, then eight 4-byte flags
constexpr std::uint64_t kTextBytes = 4000;                            // 1000 UTF-32 code units
constexpr std::uint64_t kPreambleBytes = kFlagsEnd + 9 * kTextBytes;  // 36288
constexpr std::uint64_t kColumnNameBytes = 512;

const char* const kTextFields[9] = {"name",          "manufacturer", "model creator",       "ray file creator",
                                    "equipment",     "camera",       "operating condition", "additional information",
                                    "data reference"};

std::string g(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

class Tm25Header {
 public:
  Tm25Header(const RayFile& f, const RaysetReadOptions& o) : f_(f), o_(o) {}

  std::unique_ptr<RaySource> open(std::shared_ptr<const RayFile> self) {
    const std::string& file = f_.path();
    // The fixed part: header, flags and text fields (36288 bytes), read once.
    const std::size_t fixed = static_cast<std::size_t>(std::min<std::uint64_t>(f_.size(), kPreambleBytes));
    buf_.resize(kPreambleBytes);
    if (fixed > 0) f_.read_exact(0, buf_.data(), fixed, "file type (4.7.1.1)");

    need(0, 4, "file type (4.7.1.1)");
    if (std::string_view(reinterpret_cast<const char*>(buf_.data()), 4) != "TM25")
      throw_at_offset(file, 0, "file type (4.7.1.1)",
                      "the file does not start with \"TM25\" (found \"" +
                          excerpt(std::string_view(reinterpret_cast<const char*>(buf_.data()), 4)) + "\")");
    const std::int32_t version = i32(4, "version (4.7.1.2)");
    if (version != 2013)
      throw_at_offset(file, 4, "version (4.7.1.2)",
                      "version " + std::to_string(version) +
                          " is not supported: lumx reads TM-25-13 files (version 2013); later editions change the "
                          "layout in ways not publicly documented");
    const std::int32_t method = i32(8, "creation method (4.7.1.3)");
    if (method != 0 && method != 1)
      warn(warning_at_offset(file, 8, "creation method (4.7.1.3)",
                             "should be 0 (simulation) or 1 (measurement), is " + std::to_string(method)));
    const float phi_v = f32(12, "total luminous flux (4.7.1.4)");
    const float phi_e = f32(16, "total radiant flux (4.7.1.5)");
    check_total(phi_v, 12, "total luminous flux (4.7.1.4)", "lm");
    check_total(phi_e, 16, "total radiant flux (4.7.1.5)", "W");
    need(20, 8, "number of rays (4.7.1.6)");
    const std::uint64_t rays = le_u64(buf_.data() + 20);
    if (rays == 0) warn(warning_at_offset(file, 20, "number of rays (4.7.1.6)", "the file holds no rays"));
    if (rays > o_.limits.max_rays)
      throw_at_offset(file, 20, "number of rays (4.7.1.6)",
                      std::to_string(rays) + " rays exceed RaysetLimits::max_rays (" + std::to_string(o_.limits.max_rays) + ")");
    need(28, 28, "creation date (4.7.1.7)");
    std::string date;
    for (int i = 0; i < 28 && buf_[28 + i] != 0; ++i) date += static_cast<char>(buf_[28 + i]);
    date = to_utf8(trim(date));
    const std::int32_t start = i32(56, "ray start position (4.7.1.8)");
    if (start < 0 || start > 7)
      warn(warning_at_offset(file, 56, "ray start position (4.7.1.8)", "should be 0..7, is " + std::to_string(start)));
    const std::int32_t spectral = i32(60, "spectral data identifier (4.7.1.9)");
    if (spectral < 0 || spectral > 4)
      throw_at_offset(file, 60, "spectral data identifier (4.7.1.9)",
                      "must be 0..4 (none, single wavelength, wavelength per ray, one spectral table, spectrum "
                      "index per ray), is " +
                          std::to_string(spectral));
    const float lambda = f32(64, "single wavelength (4.7.1.10)");
    if (spectral == 1 && !(lambda > 0 && std::isfinite(lambda)))
      throw_at_offset(file, 64, "single wavelength (4.7.1.10)",
                      "spectral identifier 1 (single wavelength) needs a positive wavelength, found " + g(lambda));
    const float lambda_min = f32(68, "minimum wavelength (4.7.1.11)");
    const float lambda_max = f32(72, "maximum wavelength (4.7.1.12)");
    if (spectral >= 2) {
      if (!(lambda_min > 0))
        warn(warning_at_offset(file, 68, "minimum wavelength (4.7.1.11)",
                               "should be positive with spectral data, is " + g(lambda_min)));
      if (!(lambda_max > 0))
        warn(warning_at_offset(file, 72, "maximum wavelength (4.7.1.12)",
                               "should be positive with spectral data, is " + g(lambda_max)));
      else if (!(lambda_max >= lambda_min))
        warn(warning_at_offset(file, 72, "maximum wavelength (4.7.1.12)",
                               "is below the minimum wavelength " + g(lambda_min)));
    }
    const std::int32_t n_spectra = i32(76, "number of spectral tables (4.7.1.13)");
    if (n_spectra < 0)
      throw_at_offset(file, 76, "number of spectral tables (4.7.1.13)",
                      "is negative (" + std::to_string(n_spectra) + ")");
    if ((spectral == 3 || spectral == 4) && n_spectra < 1)
      throw_at_offset(file, 76, "number of spectral tables (4.7.1.13)",
                      "spectral identifier " + std::to_string(spectral) + " needs a spectral table, the file has none");
    if (static_cast<std::size_t>(n_spectra) > o_.limits.max_spectral_tables)
      throw_at_offset(
          file, 76, "number of spectral tables (4.7.1.13)",
          std::to_string(n_spectra) + " tables exceed RaysetLimits::max_spectral_tables (" + std::to_string(o_.limits.max_spectral_tables) + ")");
    const std::int32_t n_additional = i32(80, "number of additional items (4.7.1.14)");
    if (n_additional < 0)
      throw_at_offset(file, 80, "number of additional items (4.7.1.14)",
                      "is negative (" + std::to_string(n_additional) + ")");
    if (static_cast<std::size_t>(n_additional) > o_.limits.max_additional_items)
      throw_at_offset(file, 80, "number of additional items (4.7.1.14)",
                      std::to_string(n_additional) + " columns exceed RaysetLimits::max_additional_items (" +
                          std::to_string(o_.limits.max_additional_items) + ")");
    const std::int32_t text_size = i32(84, "additional text size (4.7.1.15)");
    if (text_size < 0 || text_size % 32 != 0)
      throw_at_offset(file, 84, "additional text size (4.7.1.15)",
                      "must be a non-negative multiple of 32 bytes, is " + std::to_string(text_size));
    if (static_cast<std::size_t>(text_size) > o_.limits.max_text_bytes)
      throw_at_offset(
          file, 84, "additional text size (4.7.1.15)",
          std::to_string(text_size) + " bytes exceed RaysetLimits::max_text_bytes (" + std::to_string(o_.limits.max_text_bytes) + ")");
    need(88, 168, "reserved (4.7.1.16)");

    // 4.7.2 known data flags
    const std::int32_t pos_flag = i32(256, "position flag (4.7.2.1)");
    if (pos_flag != 1)
      throw_at_offset(file, 256, "position flag (4.7.2.1)", "must be 1, is " + std::to_string(pos_flag));
    const std::int32_t dir_flag = i32(260, "direction flag (4.7.2.2)");
    if (dir_flag != 1)
      throw_at_offset(file, 260, "direction flag (4.7.2.2)", "must be 1, is " + std::to_string(dir_flag));
    const bool rad = flag(264, "radiant flux flag (4.7.2.3)");
    const bool wl = flag(268, "wavelength flag (4.7.2.4)");
    const bool lum = flag(272, "luminous flux flag (4.7.2.5)");
    const bool stokes = flag(276, "Stokes flag (4.7.2.6)");
    const bool tri = flag(280, "tristimulus flag (4.7.2.7)");
    const bool index = flag(284, "spectrum index flag (4.7.2.8)");
    if (!rad && !lum)
      throw_at_offset(file, 272, "luminous flux flag (4.7.2.5)",
                      "neither the radiant nor the luminous flux flag is set: the rays carry no flux");
    if ((spectral == 2 || spectral == 4) && !(rad && !lum))
      throw_at_offset(file, lum ? 272 : 264, lum ? "luminous flux flag (4.7.2.5)" : "radiant flux flag (4.7.2.3)",
                      "spectral identifier " + std::to_string(spectral) +
                          " needs radiant flux per ray and no luminous flux column");
    if (spectral == 2 && !wl)
      throw_at_offset(file, 268, "wavelength flag (4.7.2.4)",
                      "spectral identifier 2 (wavelength per ray) needs the wavelength flag");
    if (index != (spectral == 4))
      throw_at_offset(file, 284, "spectrum index flag (4.7.2.8)",
                      std::string("must be set exactly when the spectral identifier is 4 (it is ") +
                          std::to_string(spectral) + ", the flag is " + (index ? "1" : "0") + ")");
    if (tri && !lum)
      throw_at_offset(file, 280, "tristimulus flag (4.7.2.7)", "tristimulus values need the luminous flux flag");
    if (tri && spectral != 0)
      throw_at_offset(file, 280, "tristimulus flag (4.7.2.7)",
                      "tristimulus values need spectral identifier 0, it is " + std::to_string(spectral));
    if (stokes && !rad)
      throw_at_offset(file, 276, "Stokes flag (4.7.2.6)", "Stokes parameters need the radiant flux flag");
    if (wl && spectral != 2)
      warn(warning_at_offset(file, 268, "wavelength flag (4.7.2.4)",
                             "a wavelength column with spectral identifier " + std::to_string(spectral) +
                                 " (expected 2); the wavelengths are read"));

    // 4.7.3 text fields
    RaysetInfo info;
    info.file = file;
    info.format = "TM-25";
    info.version = "2013";
    info.ray_count = rays;
    info.source_length_unit = "mm";
    info.simulated = method == 0;
    for (int i = 0; i < 9; ++i) {
      const std::uint64_t off = kFlagsEnd + i * kTextBytes;
      const std::string field = std::string(kTextFields[i]) + " (4.7.3." + std::to_string(i + 1) + ")";
      need(off, kTextBytes, field);
      bool bad = false;
      std::string s = utf32le_to_utf8(buf_.data() + off, kTextBytes / 4, bad);
      if (bad)
        warn(warning_at_offset(file, static_cast<std::int64_t>(off), field,
                               "invalid UTF-32 code points replaced by U+FFFD"));
      if (!s.empty()) info.text[kTextFields[i]] = std::move(s);
    }
    if (!date.empty()) info.text["creation date"] = date;

    // 4.7.4 spectral tables: i32 count, count × (f32 λ nm, f32 weight), the block padded to 32 bytes
    std::uint64_t off = kPreambleBytes;
    std::size_t points = 0;
    for (std::int32_t t = 0; t < n_spectra; ++t) {
      const std::string field = "spectral table " + std::to_string(t + 1) + " (4.7.4)";
      unsigned char nb[4];
      f_.read_exact(off, nb, 4, field);
      const std::int32_t np = le_i32(nb);
      if (np <= 0)
        throw_at_offset(file, static_cast<std::int64_t>(off), field,
                        "number of wavelength/weight pairs must be positive, is " + std::to_string(np));
      points += static_cast<std::size_t>(np);
      if (points > o_.limits.max_spectral_points)
        throw_at_offset(file, static_cast<std::int64_t>(off), field,
                        "more spectral points in all than RaysetLimits::max_spectral_points (" + std::to_string(o_.limits.max_spectral_points) + ")");
      const std::uint64_t bytes = 8 * static_cast<std::uint64_t>(np);
      if (off + 4 + bytes > f_.size())
        throw_at_offset(file, static_cast<std::int64_t>(off), field,
                        std::to_string(np) + " pairs need " + std::to_string(bytes) + " bytes after byte " +
                            std::to_string(off + 4) + ", the file ends at byte " + std::to_string(f_.size()));
      std::vector<unsigned char> tb(static_cast<std::size_t>(bytes));
      f_.read_exact(off + 4, tb.data(), tb.size(), field);
      SpectralTable st;
      st.wavelength_nm.reserve(static_cast<std::size_t>(np));
      st.weight.reserve(static_cast<std::size_t>(np));
      for (std::int32_t k = 0; k < np; ++k) {
        const float lam = le_f32(tb.data() + 8 * k), w = le_f32(tb.data() + 8 * k + 4);
        const auto at = static_cast<std::int64_t>(off + 4 + 8 * static_cast<std::uint64_t>(k));
        if (!(lam > 0 && std::isfinite(lam)))
          throw_at_offset(file, at, field, "wavelength " + std::to_string(k + 1) + " is " + g(lam) + ", not positive");
        if (!(w >= 0 && std::isfinite(w)))
          throw_at_offset(file, at + 4, field, "weight " + std::to_string(k + 1) + " is " + g(w) + ", not >= 0");
        st.wavelength_nm.push_back(lam);
        st.weight.push_back(w);
      }
      info.spectra.push_back(std::move(st));
      off += 4 + bytes;
    }
    const std::uint64_t spectral_bytes = off - kPreambleBytes;
    const std::uint64_t padding = (32 - spectral_bytes % 32) % 32;
    if (off + padding > f_.size()) need(off, padding, "spectral table padding (4.7.4)");
    off += padding;
    if (spectral == 3 && n_spectra > 1)
      warn(warning_at_offset(file, 76, "number of spectral tables (4.7.1.13)",
                             "spectral identifier 3 uses one table, the file has " + std::to_string(n_spectra)));

    // 4.7.5 additional column names, 4.7.6 additional text
    if (static_cast<std::uint64_t>(n_additional) * kColumnNameBytes > f_.size() - std::min(off, f_.size()))
      throw_at_offset(file, 80, "number of additional items (4.7.1.14)",
                      std::to_string(n_additional) + " column names need " +
                          std::to_string(n_additional * kColumnNameBytes) + " bytes after byte " + std::to_string(off) +
                          ", the file ends at byte " + std::to_string(f_.size()));
    for (std::int32_t c = 0; c < n_additional; ++c) {
      const std::string field = "additional column " + std::to_string(c + 1) + " name (4.7.5)";
      unsigned char nb[kColumnNameBytes];
      f_.read_exact(off, nb, sizeof nb, field);
      bool bad = false;
      std::string name = utf32le_to_utf8(nb, kColumnNameBytes / 4, bad);
      if (name.empty()) {
        warn(warning_at_offset(file, static_cast<std::int64_t>(off), field, "empty column name"));
        name = "(unnamed)";
      }
      info.text["additional column " + std::to_string(c + 1)] = name;
      off += kColumnNameBytes;
    }
    if (text_size > 0) {
      if (static_cast<std::uint64_t>(text_size) > f_.size() - std::min(off, f_.size()))
        throw_at_offset(file, 84, "additional text size (4.7.1.15)",
                        std::to_string(text_size) + " bytes of text after byte " + std::to_string(off) +
                            " run past the end of the file at byte " + std::to_string(f_.size()));
      std::vector<unsigned char> tb(static_cast<std::size_t>(text_size));
      f_.read_exact(off, tb.data(), tb.size(), "additional text (4.7.6)");
      bool bad = false;
      std::string s = utf32le_to_utf8(tb.data(), tb.size() / 4, bad);
      if (bad)
        warn(warning_at_offset(file, static_cast<std::int64_t>(off), "additional text (4.7.6)",
                               "invalid UTF-32 code points replaced by U+FFFD"));
      if (!s.empty()) info.text["additional text"] = std::move(s);
      off += static_cast<std::uint64_t>(text_size);
    }

    // Ray columns: x y z kx ky kz [Φe] [λ] [Φv] [S1 S2 S3 ex ey ez] [X Z] [spectrum index] [additional]
    FloatRecordLayout l;
    int col = 6;
    const int rad_col = rad ? col++ : -1;
    const int wl_col = wl ? col++ : -1;
    const int lum_col = lum ? col++ : -1;
    if (stokes) {
      l.unit_range_columns = {col, col + 1, col + 2};
      l.unit_range_field = "Stokes parameters (4.7.2.6)";
      col += 6;
    }
    if (tri) col += 2;
    if (index) {
      l.index_column = col++;
      l.index_max = n_spectra;
      l.index_field = "spectrum index (4.7.2.8)";
    }
    col += n_additional;
    l.columns = static_cast<unsigned>(col);
    if (o_.flux == FluxPreference::luminous && !lum)
      warn(warning_at_offset(file, 272, "luminous flux flag (4.7.2.5)",
                             "luminous flux was asked for, the file has radiant flux only; reading that"));
    if (o_.flux == FluxPreference::radiant && !rad)
      warn(warning_at_offset(file, 264, "radiant flux flag (4.7.2.3)",
                             "radiant flux was asked for, the file has luminous flux only; reading that"));
    // automatic and luminous: the luminous column when there is one; radiant: the radiant one when there is.
    const bool take_rad = o_.flux == FluxPreference::radiant ? rad : !lum;
    l.flux_column = take_rad ? rad_col : lum_col;
    info.quantity = take_rad ? PhotometricQuantity::radiometric : PhotometricQuantity::photometric;
    info.header_flux = take_rad ? phi_e : phi_v;
    l.flux_offset = take_rad ? 16 : 12;
    l.flux_field = take_rad ? "total radiant flux (4.7.1.5)" : "total luminous flux (4.7.1.4)";
    l.wavelength_column = wl_col;
    if (spectral == 1) info.wavelength_nm = lambda;

    info.values["creation method"] = method;
    info.values["luminous flux lm"] = phi_v;
    info.values["radiant flux W"] = phi_e;
    info.values["ray start position"] = start;
    info.values["spectral identifier"] = spectral;
    info.values["single wavelength nm"] = lambda;
    info.values["wavelength min nm"] = lambda_min;
    info.values["wavelength max nm"] = lambda_max;
    info.values["columns"] = col;
    info.values["additional items"] = n_additional;
    for (const auto& [name, flagged] : {std::pair<const char*, bool>{"radiant flux column", rad},
                                        {"wavelength column", wl},
                                        {"luminous flux column", lum},
                                        {"Stokes columns", stokes},
                                        {"tristimulus columns", tri},
                                        {"spectrum index column", index}})
      info.values[name] = flagged ? 1 : 0;

    // The rays fill the rest of the file exactly: ray_start + n · 4 · columns == file size.
    const std::uint64_t rec = 4 * static_cast<std::uint64_t>(col);
    std::uint64_t ray_start = off;
    const std::uint64_t have = f_.size() - std::min(ray_start, f_.size());
    const bool fits = rays <= have / rec;
    const std::uint64_t need_bytes = fits ? rays * rec : 0;
    if (!fits || need_bytes != have) {
      if (padding > 0 && n_additional == 0 && text_size == 0 && rays <= (have + padding) / rec &&
          rays * rec == have + padding) {
        // The spectral tables were not padded to 32 bytes (tm25ray reads the block so).
        ray_start -= padding;
        warn(warning_at_offset(file, static_cast<std::int64_t>(kPreambleBytes), "spectral tables (4.7.4)",
                               "the spectral table block is not padded to a multiple of 32 bytes"));
      } else if (!fits) {
        throw_at_offset(file, 20, "number of rays (4.7.1.6)",
                        std::to_string(rays) + " rays of " + std::to_string(col) + " columns need " +
                            (rays > std::numeric_limits<std::uint64_t>::max() / rec ? std::string("more than 2^64")
                                                                                    : std::to_string(rays * rec)) +
                            " bytes after byte " + std::to_string(ray_start) + ", the file has " +
                            std::to_string(have) + " (file size " + std::to_string(f_.size()) + ")");
      } else {
        warn(warning_at_offset(file, static_cast<std::int64_t>(ray_start + need_bytes), "ray data",
                               std::to_string(have - need_bytes) + " bytes after the last ray are ignored"));
      }
    }
    info.values["ray data offset"] = static_cast<double>(ray_start);
    l.data_offset = ray_start;
    l.rays = rays;
    l.unit = LengthUnit{"mm", 1, 1000};
    RayFieldNames names;
    names.position = "ray position x y z (4.7.2.1)";
    names.direction = "ray direction kx ky kz (4.7.2.2)";
    names.flux = take_rad ? "radiant flux (4.7.2.3)" : "luminous flux (4.7.2.5)";
    names.wavelength = "wavelength (4.7.2.4)";
    return make_float_record_source(std::move(self), std::move(info), o_, std::move(names), std::move(l));
  }

 private:
  void need(std::uint64_t off, std::uint64_t n, const std::string& field) const {
    if (off + n > f_.size())
      throw_at_offset(f_.path(), static_cast<std::int64_t>(std::min(off, f_.size())), field,
                      "file ends at byte " + std::to_string(f_.size()) + ", inside this field (bytes " +
                          std::to_string(off) + ".." + std::to_string(off + n) + ")");
  }
  std::int32_t i32(std::uint64_t off, const std::string& field) const {
    need(off, 4, field);
    return le_i32(buf_.data() + off);
  }
  float f32(std::uint64_t off, const std::string& field) const {
    need(off, 4, field);
    return le_f32(buf_.data() + off);
  }
  bool flag(std::uint64_t off, const std::string& field) const {
    const std::int32_t v = i32(off, field);
    if (v != 0 && v != 1)
      throw_at_offset(f_.path(), static_cast<std::int64_t>(off), field, "must be 0 or 1, is " + std::to_string(v));
    return v == 1;
  }
  void check_total(float v, std::uint64_t off, const std::string& field, const char* unit) const {
    if (std::isnan(v)) return;  // NaN: not stated (legal)
    if (!(v >= 0) || std::isinf(v))
      throw_at_offset(f_.path(), static_cast<std::int64_t>(off), field,
                      "must be non-negative or NaN, is " + g(v) + " " + unit);
  }
  void warn(const Diagnostic& d) const {
    if (o_.warnings) o_.warnings(d);
  }

  const RayFile& f_;
  const RaysetReadOptions& o_;
  std::vector<unsigned char> buf_;
};

}  // namespace

std::unique_ptr<RaySource> open_tm25(std::shared_ptr<const RayFile> file, const RaysetReadOptions& options) {
  Tm25Header h(*file, options);
  return h.open(file);
}

}  // namespace detail
LUMX_NAMESPACE_END
