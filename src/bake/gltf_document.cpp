// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The container layer of the glTF reader (src/bake/gltf_document.h): GLB chunks, JSON, buffers, buffer
// views, accessors and Draco primitives, validated before they are read.
#include "bake/gltf_document.h"
#include "io/json_depth.h"
#include "io/json_members.h"

#include <draco/compression/decode.h>
#include <draco/core/decoder_buffer.h>
#include <draco/mesh/mesh.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>

LUMX_NAMESPACE_BEGIN
namespace bake {
namespace gltf {
namespace {

constexpr std::uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr std::uint32_t kChunkJson = 0x4E4F534A;     // "JSON"
constexpr std::uint32_t kChunkBin = 0x004E4942;      // "BIN\0"

std::uint32_t le32(const std::uint8_t* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

const char* json_type_name(const Json& v) { return v.type_name(); }

int component_bytes(int component_type) {
  switch (component_type) {
    case 5120: case 5121: return 1;  // BYTE, UNSIGNED_BYTE
    case 5122: case 5123: return 2;  // SHORT, UNSIGNED_SHORT
    case 5125: case 5126: return 4;  // UNSIGNED_INT, FLOAT
    default: return 0;
  }
}

int type_components(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  if (type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  if (type == "MAT4") return 16;
  return 0;
}

/// One component as a float: floats as stored; integers normalised (KHR_mesh_quantization) or as is.
float component_value(const std::uint8_t* p, int component_type, bool normalized) {
  switch (component_type) {
    case 5126: { float f; std::memcpy(&f, p, 4); return f; }
    case 5120: { std::int8_t v; std::memcpy(&v, p, 1); return normalized ? std::max(v / 127.0f, -1.0f) : float(v); }
    case 5121: { std::uint8_t v = *p; return normalized ? v / 255.0f : float(v); }
    case 5122: { std::int16_t v; std::memcpy(&v, p, 2); return normalized ? std::max(v / 32767.0f, -1.0f) : float(v); }
    case 5123: { std::uint16_t v; std::memcpy(&v, p, 2); return normalized ? v / 65535.0f : float(v); }
    default: return std::numeric_limits<float>::quiet_NaN();
  }
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

/// Base64 (RFC 4648, with or without padding); false on any other character.
bool decode_base64(const char* s, std::size_t n, std::vector<std::uint8_t>& out) {
  out.clear();
  out.reserve(n / 4 * 3 + 3);
  std::uint32_t acc = 0;
  int bits = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const char c = s[i];
    int v;
    if (c >= 'A' && c <= 'Z') v = c - 'A';
    else if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
    else if (c >= '0' && c <= '9') v = c - '0' + 52;
    else if (c == '+' || c == '-') v = 62;
    else if (c == '/' || c == '_') v = 63;
    else if (c == '=') break;
    else return false;
    acc = (acc << 6) | std::uint32_t(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<std::uint8_t>((acc >> bits) & 0xFF));
    }
  }
  return true;
}

std::vector<std::uint8_t> read_file_bytes(const std::string& path, std::uint64_t max_bytes, std::uint64_t want,
                                          const std::string& error_file, const std::string& pointer) {
  std::error_code ec;
  const std::filesystem::path p(path);
  if (!std::filesystem::is_regular_file(p, ec))
    throw_at_field(error_file, pointer, "cannot open '" + path + "': not a readable file");
  const std::uint64_t size = std::filesystem::file_size(p, ec);
  if (ec) throw_at_field(error_file, pointer, "cannot read the size of '" + path + "'");
  if (size > max_bytes)
    throw_at_field(error_file, pointer, "'" + path + "' has " + std::to_string(size) +
                                            " bytes, more than GltfReadOptions::max_file_bytes (" +
                                            std::to_string(max_bytes) + ")");
  const std::uint64_t n = std::min(size, want);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(n));
  std::ifstream f(p, std::ios::binary);
  if (!f || !f.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(n)))
    throw_at_field(error_file, pointer, "cannot read '" + path + "'");
  return bytes;
}

}  // namespace

std::string pointer_token(const std::string& key) {
  std::string s;
  for (char c : key) {
    if (c == '~') s += "~0";
    else if (c == '/') s += "~1";
    else s += c;
  }
  return s;
}

// ---- JsonRef -------------------------------------------------------------------------------------------------

void JsonRef::fail(const std::string& message) const { doc->fail(pointer, message); }

bool JsonRef::has(const char* key) const { return value->is_object() && value->contains(key); }

JsonRef JsonRef::member(const char* key) const {
  if (!value->is_object()) fail(std::string("must be an object, not ") + json_type_name(*value));
  auto it = value->find(key);
  if (it == value->end()) doc->fail(pointer + "/" + pointer_token(key), "is required");
  return JsonRef{doc, &*it, pointer + "/" + pointer_token(key)};
}

JsonRef JsonRef::element(std::size_t i) const {
  if (!value->is_array()) fail(std::string("must be an array, not ") + json_type_name(*value));
  if (i >= value->size()) fail("has no element " + std::to_string(i));
  return JsonRef{doc, &(*value)[i], pointer + "/" + std::to_string(i)};
}

std::size_t JsonRef::array_size() const {
  if (!value->is_array()) fail(std::string("must be an array, not ") + json_type_name(*value));
  return value->size();
}

void JsonRef::require_object() const {
  if (!value->is_object()) fail(std::string("must be an object, not ") + json_type_name(*value));
}

double JsonRef::number(const char* key, double fallback, double lo, double hi) const {
  if (!has(key)) {
    require_object();
    return fallback;
  }
  const JsonRef m = member(key);
  if (!m.value->is_number()) m.fail(std::string("must be a number, not ") + json_type_name(*m.value));
  const double v = m.value->get<double>();
  if (!std::isfinite(v)) m.fail("must be finite");
  if (v < lo || v > hi) m.fail("is " + Json(v).dump() + ", outside [" + Json(lo).dump() + ", " + Json(hi).dump() + "]");
  return v;
}

std::uint64_t JsonRef::integer(const char* key, std::optional<std::uint64_t> fallback, std::uint64_t lo,
                               std::uint64_t hi) const {
  if (!has(key)) {
    require_object();
    if (!fallback) member(key);  // fails: "is required"
    return *fallback;
  }
  const JsonRef m = member(key);
  std::uint64_t v = 0;
  if (m.value->is_number_unsigned()) {
    v = m.value->get<std::uint64_t>();
  } else if (m.value->is_number_integer()) {
    m.fail("is " + m.value->dump() + ", must not be negative");
  } else if (m.value->is_number_float()) {
    const double d = m.value->get<double>();
    if (!(d >= 0.0 && d < 1.8e19 && std::floor(d) == d)) m.fail("is " + m.value->dump() + ", must be an integer ≥ 0");
    v = static_cast<std::uint64_t>(d);
  } else {
    m.fail(std::string("must be an integer, not ") + json_type_name(*m.value));
  }
  if (v < lo || v > hi)
    m.fail("is " + std::to_string(v) + ", outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

std::uint32_t JsonRef::index(const char* key, std::size_t count, const char* what) const {
  const std::uint64_t v = integer(key, std::nullopt, 0, std::numeric_limits<std::uint64_t>::max());
  if (v >= count)
    doc->fail(pointer + "/" + pointer_token(key), "is " + std::to_string(v) + ", but there " +
                                                      (count == 1 ? "is 1 " : "are " + std::to_string(count) + " ") + what);
  return static_cast<std::uint32_t>(v);
}

std::string JsonRef::string(const char* key, const std::string& fallback) const {
  if (!has(key)) {
    require_object();
    return fallback;
  }
  const JsonRef m = member(key);
  if (!m.value->is_string()) m.fail(std::string("must be a string, not ") + json_type_name(*m.value));
  return m.value->get<std::string>();
}

bool JsonRef::boolean(const char* key, bool fallback) const {
  if (!has(key)) {
    require_object();
    return fallback;
  }
  const JsonRef m = member(key);
  if (!m.value->is_boolean()) m.fail(std::string("must be true or false, not ") + json_type_name(*m.value));
  return m.value->get<bool>();
}

std::vector<double> JsonRef::numbers(const char* key, std::size_t n, const std::vector<double>& fallback, double lo,
                                     double hi) const {
  if (!has(key)) {
    require_object();
    return fallback;
  }
  const JsonRef m = member(key);
  if (m.array_size() != n) m.fail("must have " + std::to_string(n) + " numbers, not " + std::to_string(m.array_size()));
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const JsonRef e = m.element(i);
    if (!e.value->is_number()) e.fail(std::string("must be a number, not ") + json_type_name(*e.value));
    out[i] = e.value->get<double>();
    if (!std::isfinite(out[i])) e.fail("must be finite");
    if (out[i] < lo || out[i] > hi)
      e.fail("is " + Json(out[i]).dump() + ", outside [" + Json(lo).dump() + ", " + Json(hi).dump() + "]");
  }
  return out;
}

// ---- Document ------------------------------------------------------------------------------------------------

Document::Document(const std::string& path, const GltfReadOptions& options)
    : path_(path), base_dir_(std::filesystem::path(path).parent_path()), options_(options) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw_at_field(path, "", "cannot open: not a readable file");
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) throw_at_field(path, "", "cannot read the file size");
  if (size > options.max_file_bytes)
    throw_at_offset(path, 0, "file size", std::to_string(size) + " bytes, more than GltfReadOptions::max_file_bytes (" +
                                              std::to_string(options.max_file_bytes) + ")");
  file_.resize(static_cast<std::size_t>(size));
  {
    std::ifstream f(path, std::ios::binary);
    if (!f || !f.read(reinterpret_cast<char*>(file_.data()), static_cast<std::streamsize>(size)))
      throw_at_field(path, "", "cannot read the file");
  }
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool magic = file_.size() >= 4 && le32(file_.data()) == kGlbMagic;
  const std::uint8_t* json_begin = file_.data();
  std::size_t json_size = file_.size();
  std::int64_t json_offset = 0;
  if (magic || ext == ".glb") {
    is_glb_ = true;
    if (file_.size() < 12) throw_at_offset(path, 0, "GLB header", "truncated: " + std::to_string(file_.size()) +
                                                                     " bytes, the header has 12");
    if (!magic) throw_at_offset(path, 0, "GLB magic", "not a binary glTF file (the first bytes are not \"glTF\")");
    const std::uint32_t version = le32(&file_[4]);
    if (version != 2) throw_at_offset(path, 4, "GLB version", "is " + std::to_string(version) + ", lumx reads 2");
    const std::uint32_t length = le32(&file_[8]);
    if (length > file_.size())
      throw_at_offset(path, 8, "GLB length", "the header states " + std::to_string(length) + " bytes, but the file has " +
                                                 std::to_string(file_.size()) + " (truncated)");
    if (length < file_.size())
      warn("", "GLB length: the header states " + std::to_string(length) + " bytes, the file has " +
                   std::to_string(file_.size()) + "; the bytes after the stated length are ignored");
    std::size_t off = 12;
    bool have_json = false;
    while (off < length) {
      if (length - off < 8)
        throw_at_offset(path, std::int64_t(off), "GLB chunk header",
                        "truncated: " + std::to_string(length - off) + " bytes left, a chunk header has 8");
      const std::uint32_t chunk_length = le32(&file_[off]);
      const std::uint32_t chunk_type = le32(&file_[off + 4]);
      if (std::uint64_t(chunk_length) > std::uint64_t(length - off - 8))
        throw_at_offset(path, std::int64_t(off), "GLB chunk length",
                        "chunk of " + std::to_string(chunk_length) + " bytes runs past the end of the file (" +
                            std::to_string(length - off - 8) + " bytes left)");
      // glTF 2.0, GLB format, chunks: every chunk starts and ends on a 4-byte boundary (padded with spaces or
      // zeros), so a length that is not a multiple of 4 is a broken or hand-made container.
      if (chunk_length % 4 != 0)
        throw_at_offset(path, std::int64_t(off), "GLB chunk length",
                        "is " + std::to_string(chunk_length) + ", not a multiple of 4 (chunks are 4-byte aligned)");
      if (!have_json) {
        if (chunk_type != kChunkJson)
          throw_at_offset(path, std::int64_t(off + 4), "GLB chunk type", "the first chunk must be JSON");
        if (chunk_length == 0) throw_at_offset(path, std::int64_t(off), "GLB chunk length", "the JSON chunk is empty");
        json_begin = &file_[off + 8];
        json_size = chunk_length;
        json_offset = std::int64_t(off + 8);
        have_json = true;
      } else if (chunk_type == kChunkBin && bin_chunk_.data == nullptr) {
        bin_chunk_ = Bytes{&file_[off + 8], chunk_length};
      }
      off += 8 + std::size_t(chunk_length);
    }
    if (!have_json) throw_at_offset(path, 12, "GLB chunk", "the file has no JSON chunk");
  }
  if (const std::size_t at = lumx::detail::json_too_deep_at(std::string_view(reinterpret_cast<const char*>(json_begin), json_size));
      at != std::string_view::npos)
    throw_at_offset(path, json_offset + std::int64_t(at), "JSON",
                    "nested more than " + std::to_string(lumx::detail::kMaxJsonDepth) + " levels deep");
  lumx::detail::RepeatedMemberWatch<Json> members;
  try {
    json_ = Json::parse(json_begin, json_begin + json_size, members.callback());
  } catch (const Json::parse_error& e) {
    std::string msg = e.what();
    const auto colon = msg.find("] ");
    if (colon != std::string::npos) msg = msg.substr(colon + 2);
    std::string printable;  // the parser quotes what it read last, which may be any bytes
    for (unsigned char c : msg) {
      if (c >= 0x20 && c < 0x7F) {
        printable += static_cast<char>(c);
      } else {
        char hex[8];
        std::snprintf(hex, sizeof hex, "\\x%02X", c);
        printable += hex;
      }
    }
    msg = printable;
    throw_at_offset(path, json_offset + std::int64_t(e.byte > 0 ? e.byte - 1 : 0), "JSON", msg);
  } catch (const Json::exception& e) {  // a number beyond double's range (out_of_range 406) has no position
    const std::string_view text(reinterpret_cast<const char*>(json_begin), json_size);
    const std::size_t at = e.id == 406 ? lumx::detail::json_overflow_at(text, e.what()) : std::string_view::npos;
    if (at == std::string_view::npos) throw_at_field(path, "JSON", e.what());
    throw_at_offset(path, json_offset + std::int64_t(at), "JSON", "a number beyond the range of a double");
  }
  if (!members.repeated().empty()) fail(members.repeated(), "this name appears twice in its object; readers disagree on which value counts");
  if (!json_.is_object()) throw_at_field(path, "", "the glTF JSON must be an object");
  buffers_.resize(count("buffers"));
}

std::size_t Document::count(const char* top) const {
  const JsonRef r = root();
  if (!r.has(top)) return 0;
  return r.member(top).array_size();
}

void Document::fail(const std::string& pointer, const std::string& message) const {
  throw_at_field(path_, pointer, message);
}

void Document::warn(const std::string& pointer, const std::string& message) {
  Diagnostic d;
  d.severity = Severity::warning;
  d.file = path_;
  d.field = pointer;
  d.message = message;
  warnings_.push_back(d);
  if (options_.warnings) options_.warnings(d);
}

std::filesystem::path Document::resolve_uri(const std::string& uri, const std::string& pointer) const {
  if (uri.find("://") != std::string::npos) fail(pointer, "'" + uri + "': only relative file paths and data URIs are read");
  std::string decoded;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && hex_digit(uri[i + 1]) >= 0 && hex_digit(uri[i + 2]) >= 0) {
      decoded += static_cast<char>(hex_digit(uri[i + 1]) * 16 + hex_digit(uri[i + 2]));
      i += 2;
    } else {
      decoded += uri[i];
    }
  }
  if (decoded.empty()) fail(pointer, "is empty");
  namespace fs = std::filesystem;
  const fs::path p(decoded);
  if (options_.allow_files_outside_folder) return p.is_absolute() ? p : base_dir_ / p;
  // A file from a download names files beside it; an absolute path, '..' or a symbolic link out of the
  // glTF file's folder is refused, so that a luminaire cannot make an application read what it holds.
  // The name is never given to a shell: '$(...)' or backticks are only characters of a file name.
  const char* option = " (GltfReadOptions::allow_files_outside_folder)";
  if (p.is_absolute()) fail(pointer, "'" + uri + "' is an absolute path; only files in the glTF file's folder are read" + option);
  const fs::path folder = base_dir_.empty() ? fs::path(".") : base_dir_;
  std::error_code ec_folder, ec_file;
  const fs::path real_folder = fs::weakly_canonical(folder, ec_folder);
  const fs::path real_file = fs::weakly_canonical(folder / p, ec_file);
  const fs::path inside = real_file.lexically_relative(real_folder);
  if (ec_folder || ec_file || inside.empty() || *inside.begin() == "..")
    fail(pointer, "'" + uri + "' leads out of the glTF file's folder" + option);
  for (const char c : decoded)
    if (static_cast<unsigned char>(c) < 0x20) fail(pointer, "'" + uri + "' holds a control character");
  // The resolved path, so that a later open (ray files are opened again when the tracer is built) reaches
  // the file that was checked, whatever the working folder is then.
  return real_file;
}

std::vector<std::uint8_t> Document::uri_bytes(const std::string& uri, const std::string& pointer,
                                              std::uint64_t max_bytes) {
  if (uri.rfind("data:", 0) == 0) {
    const auto comma = uri.find(',');
    if (comma == std::string::npos || uri.rfind(";base64", comma) == std::string::npos ||
        uri.rfind(";base64", comma) + 7 != comma)
      fail(pointer, "a data URI must be base64 (\"data:...;base64,...\")");
    std::vector<std::uint8_t> out;
    if (!decode_base64(uri.data() + comma + 1, uri.size() - comma - 1, out))
      fail(pointer, "the data URI's base64 text has a character outside the base64 alphabet");
    return out;
  }
  return read_file_bytes(resolve_uri(uri, pointer).string(), max_bytes, max_bytes, path_, pointer);
}

Bytes Document::buffer(std::uint32_t index) {
  Buffer& b = buffers_.at(index);
  if (b.loaded) return b.bytes;
  const std::string ptr = "/buffers/" + std::to_string(index);
  const JsonRef j = root().member("buffers").element(index);
  const std::uint64_t length = j.integer("byteLength", std::nullopt, 1, std::numeric_limits<std::uint64_t>::max());
  if (buffer_bytes_loaded_ + length > options_.max_buffer_bytes)
    fail(ptr + "/byteLength", std::to_string(length) + " bytes would bring the buffers loaded above "
                              "GltfReadOptions::max_buffer_bytes (" + std::to_string(options_.max_buffer_bytes) + ")");
  if (!j.has("uri")) {
    if (!is_glb_ || index != 0) fail(ptr, "has no uri (only buffer 0 of a .glb file may use the BIN chunk)");
    if (bin_chunk_.data == nullptr) fail(ptr, "refers to the GLB BIN chunk, but the file has none");
    if (length > bin_chunk_.size)
      fail(ptr + "/byteLength", "is " + std::to_string(length) + ", but the GLB BIN chunk has " +
                                    std::to_string(bin_chunk_.size) + " bytes");
    b.bytes = Bytes{bin_chunk_.data, static_cast<std::size_t>(length)};
  } else {
    const std::string uri = j.string("uri", "");
    if (uri.rfind("data:", 0) == 0) {
      b.owned = uri_bytes(uri, ptr + "/uri", length);
    } else {
      b.owned = read_file_bytes(resolve_uri(uri, ptr + "/uri").string(), options_.max_file_bytes, length, path_,
                                ptr + "/uri");
    }
    if (b.owned.size() < length)
      fail(ptr + "/byteLength", "is " + std::to_string(length) + ", but '" + (uri.size() > 64 ? uri.substr(0, 64) + "..." : uri) +
                                    "' holds " + std::to_string(b.owned.size()) + " bytes");
    b.bytes = Bytes{b.owned.data(), static_cast<std::size_t>(length)};
  }
  buffer_bytes_loaded_ += length;
  b.loaded = true;
  return b.bytes;
}

Bytes Document::buffer_view(std::uint32_t index) {
  const std::string ptr = "/bufferViews/" + std::to_string(index);
  const JsonRef v = root().member("bufferViews").element(index);
  const std::uint32_t buf = v.index("buffer", count("buffers"), "buffers");
  const std::uint64_t offset = v.integer("byteOffset", 0, 0, std::numeric_limits<std::uint64_t>::max());
  const std::uint64_t length = v.integer("byteLength", std::nullopt, 1, std::numeric_limits<std::uint64_t>::max());
  const std::uint64_t declared =
      root().member("buffers").element(buf).integer("byteLength", std::nullopt, 1, std::numeric_limits<std::uint64_t>::max());
  if (offset >= declared)
    fail(ptr + "/byteOffset", "is " + std::to_string(offset) + ", past the end of buffer " + std::to_string(buf) + " (" +
                                  std::to_string(declared) + " bytes)");
  if (length > declared - offset)
    fail(ptr + "/byteLength", "byteOffset " + std::to_string(offset) + " + byteLength " + std::to_string(length) +
                                  " runs past the end of buffer " + std::to_string(buf) + " (" + std::to_string(declared) +
                                  " bytes)");
  const Bytes b = buffer(buf);
  return Bytes{b.data + offset, static_cast<std::size_t>(length)};
}

std::uint64_t Document::accessor_count(std::uint32_t index) const {
  const JsonRef a = root().member("accessors").element(index);
  a.require_object();
  return a.integer("count", std::nullopt, 1, std::numeric_limits<std::uint64_t>::max());
}

Document::AccessorView Document::accessor(std::uint32_t index, const char* type, std::uint64_t max_count) {
  const std::string ptr = "/accessors/" + std::to_string(index);
  const JsonRef a = root().member("accessors").element(index);
  a.require_object();
  if (a.has("sparse")) fail(ptr + "/sparse", "sparse accessors are not supported");
  const int ctype = static_cast<int>(a.integer("componentType", std::nullopt, 0, 1u << 20));
  const int csize = component_bytes(ctype);
  if (csize == 0) fail(ptr + "/componentType", "is " + std::to_string(ctype) + ", not a glTF component type");
  const std::string t = a.string("type", "");
  if (!a.has("type")) a.member("type");
  if (type_components(t) == 0) fail(ptr + "/type", "is \"" + t + "\", not a glTF accessor type");
  if (t != type) fail(ptr + "/type", "is \"" + t + "\", but " + type + " is needed here");
  const std::uint64_t n = a.integer("count", std::nullopt, 1, std::numeric_limits<std::uint64_t>::max());
  if (n > max_count)
    fail(ptr + "/count", "is " + std::to_string(n) + ", more than " +
                             (t == "SCALAR" ? "3 x GltfReadOptions::max_triangles + 2 (" : "GltfReadOptions::max_vertices (") +
                             std::to_string(max_count) + ")");
  const bool normalized = a.boolean("normalized", false);
  const std::uint64_t offset = a.integer("byteOffset", 0, 0, std::numeric_limits<std::uint64_t>::max());
  if (!a.has("bufferView")) fail(ptr + "/bufferView", "is required here (an accessor of zeros is no geometry)");
  const std::uint32_t view_index = a.index("bufferView", count("bufferViews"), "bufferViews");
  const Bytes view = buffer_view(view_index);
  const JsonRef vj = root().member("bufferViews").element(view_index);
  const std::uint64_t element = std::uint64_t(type_components(t)) * std::uint64_t(csize);
  std::uint64_t stride = element;
  if (vj.has("byteStride")) {
    stride = vj.integer("byteStride", std::nullopt, 4, 252);
    if (stride < element)
      fail("/bufferViews/" + std::to_string(view_index) + "/byteStride",
           "is " + std::to_string(stride) + ", less than the " + std::to_string(element) + "-byte elements of accessor " +
               std::to_string(index));
  }
  if (offset >= view.size)
    fail(ptr + "/byteOffset", "is " + std::to_string(offset) + ", past the end of bufferView " +
                                  std::to_string(view_index) + " (" + std::to_string(view.size) + " bytes)");
  // count ≤ view.size keeps the product below 2^64 (stride ≤ 252).
  if (n > view.size || offset + stride * (n - 1) + element > view.size)
    fail(ptr + "/count", "is " + std::to_string(n) + ": " + std::to_string(n) + " elements of " +
                             std::to_string(element) + " bytes every " + std::to_string(stride) + " from byteOffset " +
                             std::to_string(offset) + " run past the end of bufferView " + std::to_string(view_index) +
                             " (" + std::to_string(view.size) + " bytes)");
  AccessorView out;
  out.first = view.data + offset;
  out.stride = static_cast<std::size_t>(stride);
  out.count = static_cast<std::size_t>(n);
  out.component_type = ctype;
  out.normalized = normalized;
  return out;
}

std::vector<glm::vec3> Document::read_vec3(std::uint32_t index, std::uint64_t max_count) {
  const AccessorView a = accessor(index, "VEC3", max_count);
  const std::string ptr = "/accessors/" + std::to_string(index);
  if (a.component_type == 5125) fail(ptr + "/componentType", "UNSIGNED_INT is not a vertex attribute type");
  const int csize = component_bytes(a.component_type);
  std::vector<glm::vec3> out(a.count);
  for (std::size_t i = 0; i < a.count; ++i) {
    const std::uint8_t* p = a.first + i * a.stride;
    for (int k = 0; k < 3; ++k) out[i][k] = component_value(p + k * csize, a.component_type, a.normalized);
    if (!std::isfinite(out[i].x) || !std::isfinite(out[i].y) || !std::isfinite(out[i].z))
      fail(ptr, "element " + std::to_string(i) + " is not finite (NaN or infinite)");
  }
  return out;
}

std::vector<std::uint32_t> Document::read_indices(std::uint32_t index, std::uint64_t max_count) {
  const AccessorView a = accessor(index, "SCALAR", max_count);
  const std::string ptr = "/accessors/" + std::to_string(index);
  if (a.component_type != 5121 && a.component_type != 5123 && a.component_type != 5125)
    fail(ptr + "/componentType", "indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
  if (a.normalized) fail(ptr + "/normalized", "indices must not be normalized");
  std::vector<std::uint32_t> out(a.count);
  for (std::size_t i = 0; i < a.count; ++i) {
    const std::uint8_t* p = a.first + i * a.stride;
    if (a.component_type == 5121) {
      out[i] = *p;
    } else if (a.component_type == 5123) {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      out[i] = v;
    } else {
      std::memcpy(&out[i], p, 4);
    }
  }
  return out;
}

LocalPrimitive Document::decode_draco(const JsonRef& ext, std::uint64_t max_vertices, std::uint64_t max_triangles) {
  const std::uint32_t view_index = ext.index("bufferView", count("bufferViews"), "bufferViews");
  const JsonRef attributes = ext.member("attributes");
  attributes.require_object();
  const Bytes view = buffer_view(view_index);
  const std::string where = ext.pointer + "/bufferView";

  draco::DecoderBuffer in;
  in.Init(reinterpret_cast<const char*>(view.data), view.size);
  auto type = draco::Decoder::GetEncodedGeometryType(&in);
  if (!type.ok()) fail(where, "the Draco payload does not decode: " + type.status().error_msg_string());
  if (type.value() != draco::TRIANGULAR_MESH) fail(where, "the Draco payload is not a triangle mesh");
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&in);
  if (!decoded.ok()) fail(where, "the Draco payload does not decode: " + decoded.status().error_msg_string());
  const std::unique_ptr<draco::Mesh>& mesh = decoded.value();
  if (!mesh) fail(where, "the Draco payload does not decode");
  const std::uint64_t points = mesh->num_points();
  const std::uint64_t faces = mesh->num_faces();
  if (points > max_vertices)
    fail(where, "the Draco mesh has " + std::to_string(points) + " vertices, more than GltfReadOptions::max_vertices (" +
                    std::to_string(max_vertices) + ")");
  if (faces > max_triangles)
    fail(where, "the Draco mesh has " + std::to_string(faces) + " triangles, more than GltfReadOptions::max_triangles (" +
                    std::to_string(max_triangles) + ")");

  auto read_attribute = [&](const char* name, std::vector<glm::vec3>& out) {
    const JsonRef id_ref = attributes.member(name);
    const std::uint64_t id = attributes.integer(name, std::nullopt, 0, std::numeric_limits<std::uint32_t>::max());
    const draco::PointAttribute* att = mesh->GetAttributeByUniqueId(static_cast<std::uint32_t>(id));
    if (att == nullptr) id_ref.fail("the Draco payload has no attribute with id " + std::to_string(id));
    if (att->num_components() < 3)
      id_ref.fail("the Draco attribute has " + std::to_string(int(att->num_components())) + " components, 3 needed");
    out.resize(static_cast<std::size_t>(points));
    for (std::uint32_t i = 0; i < points; ++i) {
      float v[3];
      if (!att->ConvertValue<float>(att->mapped_index(draco::PointIndex(i)), 3, v))
        id_ref.fail("the Draco attribute's value " + std::to_string(i) + " cannot be read");
      if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
        id_ref.fail("the Draco attribute's value " + std::to_string(i) + " is not finite (NaN or infinite)");
      out[i] = glm::vec3(v[0], v[1], v[2]);
    }
  };
  LocalPrimitive p;
  read_attribute("POSITION", p.positions);
  if (attributes.has("NORMAL")) read_attribute("NORMAL", p.normals);
  p.indices.resize(static_cast<std::size_t>(faces) * 3);
  for (std::uint32_t f = 0; f < faces; ++f) {
    const draco::Mesh::Face& face = mesh->face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = face[k].value();
      if (v >= points)
        fail(where, "the Draco mesh's triangle " + std::to_string(f) + " has vertex " + std::to_string(v) +
                        ", out of range (" + std::to_string(points) + " vertices)");
      p.indices[std::size_t(f) * 3 + k] = v;
    }
  }
  return p;
}

}  // namespace gltf
}  // namespace bake
LUMX_NAMESPACE_END
