// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Helpers shared by the rayset tests: the real files in ../shared/data/raysets, the independent Python
// reference (tests/tools/rayset_reference.py), a byte-level TM-25 builder for hostile files, scratch
// folders, and a RaySource that computes rays on the fly (no storage) for the memory tests.
#pragma once

#include "test_support.h"

#include <lumx/io/rayset_io.h>
#include <lumx/rays/rayset.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

namespace lumx_rays {

namespace fs = std::filesystem;

/// ../shared/data/raysets, or empty if absent.
inline fs::path rayset_dir() {
  const fs::path shared = lumx_test::shared_dir();
  if (shared.empty() || !fs::exists(shared / "data" / "raysets")) return {};
  return shared / "data" / "raysets";
}

/// Every ray file there (everything but the PDF and the notes), sorted.
inline std::vector<fs::path> real_ray_files() {
  std::vector<fs::path> out;
  const fs::path root = rayset_dir();
  if (root.empty()) return out;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (!e.is_regular_file()) continue;
    const std::string ext = e.path().extension().string();
    if (ext == ".pdf" || ext == ".md") continue;
    out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

inline fs::path real_file(const std::string& name) {
  for (const auto& p : real_ray_files())
    if (p.filename() == name) return p;
  return {};
}

/// Output of `/usr/bin/python3 tests/tools/rayset_reference.py FILE`, parsed; nullopt (with a test failure)
/// if it could not be run.
inline std::optional<nlohmann::json> python_reference(const fs::path& file) {
  const std::string script = std::string(LUMX_SOURCE_DIR) + "/tests/tools/rayset_reference.py";
  if (access("/usr/bin/python3", X_OK) != 0) {
    ADD_FAILURE() << "/usr/bin/python3 is missing (scripts/deps.sh installs it)";
    return std::nullopt;
  }
  const std::string cmd = "/usr/bin/python3 \"" + script + "\" \"" + file.string() + "\"";
  FILE* f = popen(cmd.c_str(), "r");
  if (!f) return std::nullopt;
  std::string out;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = fread(buf.data(), 1, buf.size(), f)) > 0) out.append(buf.data(), n);
  const int st = pclose(f);
  if (st != 0) {
    ADD_FAILURE() << cmd << " failed: " << out;
    return std::nullopt;
  }
  return nlohmann::json::parse(out);
}

/// A fresh folder per test and process.
inline fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("lumx_rays_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

inline void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

inline std::string read_bytes(const fs::path& p) {
  return lumx_test::read_text(p);
}

// ---- little-endian byte building ----

inline void put32(std::string& s, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) s[at + i] = static_cast<char>((v >> (8 * i)) & 0xFF);
}
inline void puti(std::string& s, std::size_t at, std::int32_t v) {
  std::uint32_t u;
  std::memcpy(&u, &v, 4);
  put32(s, at, u);
}
inline void putf(std::string& s, std::size_t at, float v) {
  std::uint32_t u;
  std::memcpy(&u, &v, 4);
  put32(s, at, u);
}
inline void put64(std::string& s, std::size_t at, std::uint64_t v) {
  put32(s, at, static_cast<std::uint32_t>(v));
  put32(s, at + 4, static_cast<std::uint32_t>(v >> 32));
}
inline void appendf(std::string& s, float v) {
  s.resize(s.size() + 4);
  putf(s, s.size() - 4, v);
}
inline void appendi(std::string& s, std::int32_t v) {
  s.resize(s.size() + 4);
  puti(s, s.size() - 4, v);
}

/// A TM-25 file byte by byte, with every field settable (also to wrong values).
struct Tm25Spec {
  char magic[5] = "TM25";
  std::int32_t version = 2013;
  std::int32_t method = 0;
  float phi_v = NAN, phi_e = 1;
  std::optional<std::uint64_t> rays_field;  ///< default: the number of rows
  std::int32_t spectral = 0;
  float lambda = 0, lambda_min = 0, lambda_max = 0;
  std::vector<std::vector<std::pair<float, float>>> tables;
  std::optional<std::int32_t> tables_field;
  std::vector<std::string> column_names;  ///< additional items (ASCII)
  std::optional<std::int32_t> additional_field;
  std::string additional_text;  ///< ASCII; padded to 32 bytes
  std::optional<std::int32_t> text_size_field;
  std::array<std::int32_t, 8> flags{1, 1, 1, 0, 0, 0, 0, 0};
  std::string name = "synthetic source";
  std::vector<std::vector<float>> rows;  ///< full records, mm
};

inline std::string build_tm25(const Tm25Spec& s) {
  std::string b(36288, '\0');
  std::memcpy(&b[0], s.magic, 4);
  puti(b, 4, s.version);
  puti(b, 8, s.method);
  putf(b, 12, s.phi_v);
  putf(b, 16, s.phi_e);
  put64(b, 20, s.rays_field ? *s.rays_field : s.rows.size());
  std::memcpy(&b[28], "2026-01-02T03:04:05Z", 20);
  puti(b, 56, 0);
  puti(b, 60, s.spectral);
  putf(b, 64, s.lambda);
  putf(b, 68, s.lambda_min);
  putf(b, 72, s.lambda_max);
  puti(b, 76, s.tables_field ? *s.tables_field : static_cast<std::int32_t>(s.tables.size()));
  puti(b, 80, s.additional_field ? *s.additional_field : static_cast<std::int32_t>(s.column_names.size()));
  const std::size_t text_bytes = (4 * s.additional_text.size() + 31) / 32 * 32;
  puti(b, 84, s.text_size_field ? *s.text_size_field : static_cast<std::int32_t>(text_bytes));
  for (int i = 0; i < 8; ++i) puti(b, 256 + 4 * i, s.flags[i]);
  for (std::size_t i = 0; i < s.name.size() && i < 1000; ++i)
    put32(b, 288 + 4 * i, static_cast<unsigned char>(s.name[i]));
  std::string tables;
  for (const auto& t : s.tables) {
    appendi(tables, static_cast<std::int32_t>(t.size()));
    for (const auto& [lam, w] : t) appendf(tables, lam), appendf(tables, w);
  }
  tables.resize((tables.size() + 31) / 32 * 32, '\0');
  b += tables;
  for (const auto& n : s.column_names) {
    std::string c(512, '\0');
    for (std::size_t i = 0; i < n.size() && i < 128; ++i) put32(c, 4 * i, static_cast<unsigned char>(n[i]));
    b += c;
  }
  std::string text(text_bytes, '\0');
  for (std::size_t i = 0; i < s.additional_text.size(); ++i)
    put32(text, 4 * i, static_cast<unsigned char>(s.additional_text[i]));
  b += text;
  for (const auto& r : s.rows)
    for (float v : r) appendf(b, v);
  return b;
}

/// Three plain rays, x y z kx ky kz Φe, in mm.
inline std::vector<std::vector<float>> three_rows() {
  return {{1, 2, 3, 0, 0, 1, 0.5f}, {-1, 0, 0.25f, 0.6f, 0, 0.8f, 0.25f}, {0, -4, 2, 0, -1, 0, 1}};
}

/// Rays computed from their index: a deterministic synthetic rayset of any size held nowhere.
class GeneratedRays : public lumx::RaySource {
 public:
  explicit GeneratedRays(std::uint64_t n) {
    info_.file = "generated";
    info_.format = "generated";
    info_.ray_count = n;
    info_.quantity = lumx::PhotometricQuantity::photometric;
    info_.header_flux = NAN;
  }
  const lumx::RaysetInfo& info() const override { return info_; }
  bool next(lumx::RayChunk& out, std::size_t max_rays) override {
    out.clear();
    const std::uint64_t end = std::min<std::uint64_t>(info_.ray_count, pos_ + std::max<std::size_t>(max_rays, 1));
    if (pos_ >= end) return false;
    out.reserve(static_cast<std::size_t>(end - pos_));
    for (; pos_ < end; ++pos_) {
      const double t = static_cast<double>(pos_);
      const glm::vec3 p(static_cast<float>(0.01 * std::sin(t * 0.37)), static_cast<float>(0.01 * std::cos(t * 0.11)),
                        static_cast<float>(0.002 * std::sin(t * 0.05)));
      const glm::vec3 d =
          glm::normalize(glm::vec3(static_cast<float>(std::sin(t)), static_cast<float>(std::cos(t * 1.3)),
                                   1.5f + static_cast<float>(std::sin(t * 0.7))));
      out.push_back(p, d, 0.001f * static_cast<float>(1 + pos_ % 7));
    }
    return true;
  }
  void rewind() override { pos_ = 0; }

 private:
  lumx::RaysetInfo info_;
  std::uint64_t pos_ = 0;
};

/// Bit-exact equality of two chunks.
inline bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), 4 * a.size()) == 0);
}
inline bool same_rays(const lumx::RayChunk& a, const lumx::RayChunk& b) {
  return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z) && same_bits(a.dx, b.dx) &&
         same_bits(a.dy, b.dy) && same_bits(a.dz, b.dz) && same_bits(a.flux, b.flux) &&
         same_bits(a.wavelength_nm, b.wavelength_nm);
}

/// Opens `path`, collecting warnings.
inline std::unique_ptr<lumx::RaySource> open_collect(const fs::path& path, std::vector<lumx::Diagnostic>& warnings,
                                                     lumx::RaysetReadOptions o = {}) {
  o.warnings = [&warnings](const lumx::Diagnostic& d) { warnings.push_back(d); };
  return lumx::open_rayset(path.string(), o);
}

}  // namespace lumx_rays
