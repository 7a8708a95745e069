// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// ZIP reading with libzip; the archive checks that make extraction safe (zip_archive.h).
#include "io/gldf/zip_archive.h"

#include <set>

#include <zip.h>

#include <filesystem>
#include <system_error>

LUMX_NAMESPACE_BEGIN
namespace detail {
namespace {

zip_t* as_zip(void* z) { return static_cast<zip_t*>(z); }

/// Why an entry name is unsafe to extract, or empty if it is safe.
std::string unsafe_name(const std::string& n) {
  if (n.empty()) return "an empty entry name";
  if (n.front() == '/') return "an absolute path";
  if (n.find('\\') != std::string::npos) return "a backslash (a Windows path separator)";
  if (n.size() >= 2 && n[1] == ':') return "a drive letter";
  for (unsigned char c : n)
    if (c < 0x20 || c == 0x7f) return "a control character";
  std::size_t start = 0;
  while (start <= n.size()) {
    const std::size_t slash = n.find('/', start);
    const std::string seg = n.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    if (seg == "..") return "a '..' segment (path traversal)";
    if (slash == std::string::npos) break;
    start = slash + 1;
  }
  return {};
}

}  // namespace

ZipArchive::ZipArchive(const std::string& path, const GldfLimits& limits) : path_(path) {
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  if (ec) throw_at_field(path, "file", "cannot read: " + ec.message());
  if (bytes > limits.max_archive_bytes)
    throw_at_field(path, "file", std::to_string(bytes) + " bytes exceed GldfLimits::max_archive_bytes (" +
                                     std::to_string(limits.max_archive_bytes) + ")");
  int err = 0;
  zip_t* z = zip_open(path.c_str(), ZIP_RDONLY | ZIP_CHECKCONS, &err);
  if (!z) {
    zip_error_t ze;
    zip_error_init_with_code(&ze, err);
    const std::string msg = zip_error_strerror(&ze);
    zip_error_fini(&ze);
    // libzip refuses an archive whose directory names one entry twice with ZIP_ER_EXISTS.
    throw_at_field(path, "ZIP", err == ZIP_ER_EXISTS ? "two entries have the same name (" + msg + ")"
                                                     : "not a readable ZIP archive: " + msg);
  }
  zip_ = z;
  try {
    const zip_int64_t n = zip_get_num_entries(z, 0);
    if (n < 0) throw_at_field(path, "ZIP", "cannot count the entries");
    if (static_cast<std::uint64_t>(n) > limits.max_entries)
      throw_at_field(path, "ZIP", std::to_string(n) + " entries exceed GldfLimits::max_entries (" + std::to_string(limits.max_entries) + ")");
    std::uint64_t total = 0;
    std::set<std::string> seen;
    for (zip_uint64_t i = 0; i < static_cast<zip_uint64_t>(n); ++i) {
      zip_stat_t st;
      zip_stat_init(&st);
      if (zip_stat_index(z, i, 0, &st) != 0 || !(st.valid & ZIP_STAT_NAME))
        throw_at_field(path, "ZIP", "entry " + std::to_string(i) + " has no readable header");
      const std::string name = st.name;
      const std::string where = path + "!/" + name;
      if (const std::string why = unsafe_name(name); !why.empty())
        throw_at_field(where, "entry name", "refused: the name has " + why);
      // Readers that take the first of two equal names and readers that take the last would see different
      // products: an archive that is ambiguous is refused.
      if (!seen.insert(name).second)
        throw_at_field(where, "entry name", "refused: the archive holds two entries of this name (named twice)");
      if ((st.valid & ZIP_STAT_ENCRYPTION_METHOD) && st.encryption_method != ZIP_EM_NONE)
        throw_at_field(where, "entry", "refused: encrypted");
      if (!(st.valid & ZIP_STAT_SIZE)) throw_at_field(where, "entry size", "unknown");
      if (st.size > limits.max_entry_bytes)
        throw_at_field(where, "entry size", "refused: " + std::to_string(st.size) + " bytes exceed GldfLimits::max_entry_bytes (" +
                                                std::to_string(limits.max_entry_bytes) + ")");
      total += st.size;
      if (total > limits.max_total_bytes)
        throw_at_field(where, "entry size", "refused: the entries add up to more than GldfLimits::max_total_bytes (" +
                                                std::to_string(limits.max_total_bytes) + ")");
      if (st.size > (1u << 20) && (st.valid & ZIP_STAT_COMP_SIZE) &&
          static_cast<double>(st.size) > limits.max_compression_ratio * static_cast<double>(std::max<zip_uint64_t>(st.comp_size, 1)))
        throw_at_field(where, "compression ratio",
                       "refused: " + std::to_string(st.size) + " bytes from " + std::to_string(st.comp_size) +
                           " compressed, a ratio above GldfLimits::max_compression_ratio (a zip bomb?)");
      if (name.back() == '/') continue;  // a folder
      entries_.push_back({name, i, st.size});
      names_.push_back(name);
    }
  } catch (...) {
    zip_discard(z);
    zip_ = nullptr;
    throw;
  }
}

ZipArchive::~ZipArchive() {
  if (zip_) zip_discard(as_zip(zip_));
}

bool ZipArchive::contains(const std::string& name) const {
  for (const auto& e : entries_)
    if (e.name == name) return true;
  return false;
}

std::string ZipArchive::read(const std::string& name) const {
  const Entry* e = nullptr;
  for (const auto& x : entries_)
    if (x.name == name) e = &x;
  const std::string where = path_ + "!/" + name;
  if (!e) throw_at_field(where, "entry", "not in the archive");
  zip_file_t* f = zip_fopen_index(as_zip(zip_), e->index, 0);
  if (!f) throw_at_field(where, "entry", std::string("cannot open: ") + zip_strerror(as_zip(zip_)));
  std::string out(static_cast<std::size_t>(e->size), '\0');  // bounded by GldfLimits::max_entry_bytes
  std::uint64_t got = 0;
  char extra = 0;
  zip_int64_t r = 0;
  while (got < e->size && (r = zip_fread(f, out.data() + got, e->size - got)) > 0) got += static_cast<std::uint64_t>(r);
  const zip_int64_t beyond = r >= 0 ? zip_fread(f, &extra, 1) : -1;
  const std::string err = (r < 0 || beyond < 0) ? zip_file_strerror(f) : std::string();
  zip_fclose(f);
  if (!err.empty()) throw_at_field(where, "entry", "cannot decompress: " + err);
  if (got != e->size || beyond != 0)
    throw_at_field(where, "entry size", "the data does not have the size its header states (" + std::to_string(e->size) + " bytes)");
  return out;
}

}  // namespace detail
LUMX_NAMESPACE_END
