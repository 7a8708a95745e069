// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Writes IES TM-25-13 ray files: the preamble from RaysetInfo, the rays streamed from a RaySource into a
// temporary file, the header completed (ray count, wavelength range) once the rays are known, then the
// temporary file renamed over the target (AtomicStreamFile: fsync, rename, fsync of the folder).
#include "io/rays/rayset_common.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <limits>

LUMX_NAMESPACE_BEGIN
namespace detail {
namespace {

constexpr std::size_t kPreamble = 36288;
const char* const kTextFields[9] = {"name",          "manufacturer", "model creator",       "ray file creator",
                                    "equipment",     "camera",       "operating condition", "additional information",
                                    "data reference"};

double value_or(const RaysetInfo& info, const char* key, double fallback) {
  const auto it = info.values.find(key);
  return it == info.values.end() ? fallback : it->second;
}

std::int32_t int_value_or(const RaysetInfo& info, const char* key, std::int32_t fallback) {
  const double v = value_or(info, key, fallback);
  if (!(v >= std::numeric_limits<std::int32_t>::min() && v <= std::numeric_limits<std::int32_t>::max()))
    throw_at_field(info.file, key, "value " + std::to_string(v) + " does not fit a TM-25 integer field");
  return static_cast<std::int32_t>(v);
}

void put_utf32(unsigned char* p, const std::u32string& s) {
  for (std::size_t i = 0; i < s.size(); ++i) put_u32(p + 4 * i, static_cast<std::uint32_t>(s[i]));
}

std::string g(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace
}  // namespace detail

void write_tm25(const std::string& path, const RaysetInfo& info, RaySource& rays, const Tm25WriteOptions& options) {
  using namespace detail;
  const auto fail = [&](const std::string& field, const std::string& message) { throw_at_field(path, field, message); };
  // ---- everything of the preamble that does not depend on the rays ----
  std::vector<unsigned char> pre(kPreamble, 0);
  std::memcpy(pre.data(), "TM25", 4);
  put_i32(pre.data() + 4, 2013);
  const bool radiometric = info.quantity == PhotometricQuantity::radiometric;
  if (!(std::isnan(info.header_flux) || (info.header_flux >= 0 && std::isfinite(info.header_flux))))
    fail("header flux", "must be non-negative or NaN, is " + g(info.header_flux));
  const double phi_v = radiometric ? value_or(info, "luminous flux lm", NAN) : info.header_flux;
  const double phi_e = radiometric ? info.header_flux : value_or(info, "radiant flux W", NAN);
  for (double v : {phi_v, phi_e})
    if (!(std::isnan(v) || (v >= 0 && v <= std::numeric_limits<float>::max())))
      fail("header flux", "total flux " + g(v) + " cannot be written (non-negative float or NaN)");
  put_i32(pre.data() + 8, int_value_or(info, "creation method", info.simulated ? 0 : 1));
  put_f32(pre.data() + 12, static_cast<float>(phi_v));
  put_f32(pre.data() + 16, static_cast<float>(phi_e));
  if (const auto it = info.text.find("creation date"); it != info.text.end()) {
    const std::string& d = it->second;
    if (d.size() > 28) fail("creation date", "longer than the 28 bytes TM-25 holds");
    for (char c : d)
      if (static_cast<unsigned char>(c) >= 0x80 || c == 0) fail("creation date", "must be ASCII text");
    std::memcpy(pre.data() + 28, d.data(), d.size());
  }
  put_i32(pre.data() + 56, int_value_or(info, "ray start position", 0));
  for (std::size_t i = 0; i < info.spectra.size(); ++i) {
    const SpectralTable& t = info.spectra[i];
    const std::string field = "spectral table " + std::to_string(i + 1);
    if (t.wavelength_nm.empty() || t.wavelength_nm.size() != t.weight.size())
      fail(field, "needs as many weights as wavelengths, and at least one");
    if (t.wavelength_nm.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max() / 8))
      fail(field, "too many points");
    for (std::size_t k = 0; k < t.weight.size(); ++k)
      if (!(t.wavelength_nm[k] > 0 && std::isfinite(t.wavelength_nm[k]) && t.weight[k] >= 0 &&
            std::isfinite(t.weight[k])))
        fail(field, "point " + std::to_string(k + 1) + ": wavelengths must be positive, weights non-negative");
  }
  if (info.spectra.size() > 1)
    fail("spectral tables",
         "several tables need a spectrum index per ray (spectral identifier 4), which RayChunk does not carry");
  put_i32(pre.data() + 76, static_cast<std::int32_t>(info.spectra.size()));
  // Text fields (4.7.3): 1000 UTF-32 code units each.
  for (int i = 0; i < 9; ++i) {
    const auto it = info.text.find(kTextFields[i]);
    if (it == info.text.end()) continue;
    std::u32string s;
    if (!utf8_to_utf32(it->second, s)) fail(kTextFields[i], "is not valid UTF-8");
    if (s.size() > 1000) fail(kTextFields[i], "is longer than the 1000 characters TM-25 holds");
    put_utf32(pre.data() + 288 + 4000 * i, s);
  }
  // Additional columns ("additional column N" in info.text) are not carried by RayChunk: not written.
  // Spectral tables (4.7.4), padded to 32 bytes, and the additional text (4.7.6).
  std::vector<unsigned char> tables;
  for (const SpectralTable& t : info.spectra) {
    const std::size_t at = tables.size();
    tables.resize(at + 4 + 8 * t.weight.size());
    put_i32(tables.data() + at, static_cast<std::int32_t>(t.weight.size()));
    for (std::size_t k = 0; k < t.weight.size(); ++k) {
      put_f32(tables.data() + at + 4 + 8 * k, t.wavelength_nm[k]);
      put_f32(tables.data() + at + 8 + 8 * k, t.weight[k]);
    }
  }
  tables.resize((tables.size() + 31) / 32 * 32, 0);
  std::vector<unsigned char> text;
  if (const auto it = info.text.find("additional text"); it != info.text.end()) {
    std::u32string s;
    if (!utf8_to_utf32(it->second, s)) fail("additional text", "is not valid UTF-8");
    text.resize((4 * s.size() + 31) / 32 * 32, 0);
    if (text.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
      fail("additional text", "too long");
    put_utf32(text.data(), s);
  }
  put_i32(pre.data() + 84, static_cast<std::int32_t>(text.size()));
  put_i32(pre.data() + 256, 1);  // position
  put_i32(pre.data() + 260, 1);  // direction

  AtomicStreamFile out(path);
  out.write(pre.data(), pre.size());
  out.write(tables.data(), tables.size());
  out.write(text.data(), text.size());

  // ---- the rays ----
  RayChunk c;
  std::vector<unsigned char> buf;
  std::uint64_t n = 0;
  double flux_sum = 0.0;
  int with_wavelength = -1;  // decided by the first chunk
  float lam_min = INFINITY, lam_max = -INFINITY;
  const std::size_t chunk = std::max<std::size_t>(options.chunk_rays, 1);
  rays.rewind();
  while (rays.next(c, chunk)) {
    const bool wl = !c.wavelength_nm.empty();
    if (with_wavelength < 0) {
      with_wavelength = wl;
      if (wl && !radiometric)
        fail("wavelength", "TM-25 stores a wavelength per ray only with radiant flux (spectral identifier 2)");
    }
    if (wl != (with_wavelength == 1) || (wl && c.wavelength_nm.size() != c.size()))
      fail("wavelength", "some rays carry a wavelength and others do not");
    const std::size_t cols = with_wavelength == 1 ? 8 : 7;
    buf.resize(c.size() * 4 * cols);
    for (std::size_t i = 0; i < c.size(); ++i) {
      const auto ray = [&] { return "ray " + std::to_string(n + i + 1) + ": "; };
      const float v[7] = {metres_to_tm25_mm(c.x[i]),
                          metres_to_tm25_mm(c.y[i]),
                          metres_to_tm25_mm(c.z[i]),
                          c.dx[i],
                          c.dy[i],
                          c.dz[i],
                          c.flux[i]};
      if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])))
        fail("ray position", ray() + "start point is not finite in mm");
      if (!(std::isfinite(v[3]) && std::isfinite(v[4]) && std::isfinite(v[5])) || (v[3] == 0 && v[4] == 0 && v[5] == 0))
        fail("ray direction", ray() + "direction is zero or not finite");
      if (!(v[6] >= 0 && std::isfinite(v[6])))
        fail("ray flux", ray() + "flux " + g(v[6]) + " is negative or not finite");
      unsigned char* p = buf.data() + i * 4 * cols;
      for (int k = 0; k < 7; ++k) put_f32(p + 4 * k, v[k]);
      flux_sum += double(v[6]);
      if (cols == 8) {
        const float lam = c.wavelength_nm[i];
        if (!(lam > 0 && std::isfinite(lam)))
          fail("ray wavelength", ray() + "wavelength " + g(lam) + " is not positive");
        lam_min = std::min(lam_min, lam);
        lam_max = std::max(lam_max, lam);
        put_f32(p + 28, lam);
      }
    }
    out.write(buf.data(), buf.size());
    n += c.size();
  }

  // ---- the header fields that depend on the rays ----
  unsigned char h[288 - 20];
  std::memcpy(h, pre.data() + 20, sizeof h);
  const auto at = [&](std::size_t off) { return h + (off - 20); };
  put_u64(at(20), n);
  std::int32_t spectral = 0;
  if (with_wavelength == 1) {
    spectral = 2;
  } else if (info.spectra.size() == 1) {
    spectral = 3;
  } else if (info.wavelength_nm) {
    if (!(*info.wavelength_nm > 0 && std::isfinite(*info.wavelength_nm)))
      fail("wavelength", "single wavelength " + g(*info.wavelength_nm) + " is not positive");
    spectral = 1;
  }
  put_i32(at(60), spectral);
  put_f32(at(64), spectral == 1 ? static_cast<float>(*info.wavelength_nm)
                                : static_cast<float>(value_or(info, "single wavelength nm", NAN)));
  float table_min = INFINITY, table_max = -INFINITY;
  for (const SpectralTable& t : info.spectra)
    for (float lam : t.wavelength_nm) table_min = std::min(table_min, lam), table_max = std::max(table_max, lam);
  const float wl_min = spectral == 2 && n > 0 ? lam_min
                       : info.values.count("wavelength min nm")
                           ? static_cast<float>(info.values.at("wavelength min nm"))
                       : spectral == 3 ? table_min
                                       : NAN;
  const float wl_max = spectral == 2 && n > 0 ? lam_max
                       : info.values.count("wavelength max nm")
                           ? static_cast<float>(info.values.at("wavelength max nm"))
                       : spectral == 3 ? table_max
                                       : NAN;
  put_f32(at(68), wl_min);
  put_f32(at(72), wl_max);
  put_i32(at(264), radiometric ? 1 : 0);           // radiant flux
  put_i32(at(268), with_wavelength == 1 ? 1 : 0);  // wavelength
  put_i32(at(272), radiometric ? 0 : 1);           // luminous flux
  out.pwrite_at(20, h, sizeof h);
  if (options.header_flux_from_rays) {
    if (!(flux_sum <= std::numeric_limits<float>::max())) fail("header flux", "the rays' total flux exceeds a float");
    unsigned char f[4];
    put_f32(f, static_cast<float>(flux_sum));
    out.pwrite_at(radiometric ? 16 : 12, f, sizeof f);
  }
  out.commit();
}

LUMX_NAMESPACE_END
