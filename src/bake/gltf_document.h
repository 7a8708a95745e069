// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/bake/gltf_document.h — the container layer of the glTF reader: the file (.gltf or .glb), its JSON, its
// buffers, buffer views and accessors, and Draco-compressed primitives, each checked against the others
// before anything is read. Every failure is a lumx::Error located by byte offset (container, JSON syntax)
// or by JSON pointer (Diagnostic::field). The scene (nodes, materials, lights) is built in gltf_reader.cpp.
#pragma once

#include <lumx/bake/gltf_reader.h>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace bake {
namespace gltf {

using Json = nlohmann::json;

/// A run of bytes owned by the Document (a buffer, or a part of one).
struct Bytes {
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
};

class Document;

/// A JSON value together with its JSON pointer, so that every check can name where it failed.
struct JsonRef {
  const Document* doc = nullptr;
  const Json* value = nullptr;
  std::string pointer;

  [[noreturn]] void fail(const std::string& message) const;
  bool has(const char* key) const;           ///< an object with this member
  JsonRef member(const char* key) const;     ///< the member (must exist: see has())
  JsonRef element(std::size_t i) const;      ///< the i-th element of an array
  std::size_t array_size() const;            ///< size of an array (fails if not an array)
  void require_object() const;

  /// A number member: `fallback` when absent; fails when not a finite number or outside [lo, hi].
  double number(const char* key, double fallback, double lo, double hi) const;
  /// A non-negative integer member in [lo, hi]; `fallback` when absent (nullopt: required).
  std::uint64_t integer(const char* key, std::optional<std::uint64_t> fallback, std::uint64_t lo,
                        std::uint64_t hi) const;
  /// An index into a top-level array of `count` elements named `what` ("accessors").
  std::uint32_t index(const char* key, std::size_t count, const char* what) const;
  std::string string(const char* key, const std::string& fallback) const;
  bool boolean(const char* key, bool fallback) const;
  /// An array of n finite numbers in [lo, hi]; `fallback` when absent.
  std::vector<double> numbers(const char* key, std::size_t n, const std::vector<double>& fallback, double lo,
                              double hi) const;
};

/// One JSON pointer reference token ("a/b" → "a~1b").
std::string pointer_token(const std::string& key);

/// A primitive's vertices and triangles in the mesh's own frame.
struct LocalPrimitive {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;  ///< empty when the primitive has none
  std::vector<std::uint32_t> indices;  ///< 3 per triangle (strips and fans already converted)
};

class Document {
 public:
  /// Reads the file (GLB container or JSON text) and parses the JSON. Buffers are loaded when first used.
  Document(const std::string& path, const GltfReadOptions& options);

  const std::string& path() const { return path_; }
  const std::filesystem::path& base_dir() const { return base_dir_; }
  const GltfReadOptions& options() const { return options_; }
  JsonRef root() const { return JsonRef{this, &json_, ""}; }
  /// Size of a top-level array ("nodes"); 0 when absent, error when not an array.
  std::size_t count(const char* top) const;

  [[noreturn]] void fail(const std::string& pointer, const std::string& message) const;
  void warn(const std::string& pointer, const std::string& message);
  std::vector<Diagnostic>& warnings() { return warnings_; }

  /// The bytes of buffer view `index`, checked against its buffer.
  Bytes buffer_view(std::uint32_t index);
  /// The bytes a URI names: a base64 data URI, or a file relative to the glTF file's folder (at most
  /// `max_bytes`). `pointer` locates the uri member in errors.
  std::vector<std::uint8_t> uri_bytes(const std::string& uri, const std::string& pointer, std::uint64_t max_bytes);
  /// A file path a relative URI names (percent-decoded, resolved against the glTF file's folder).
  std::filesystem::path resolve_uri(const std::string& uri, const std::string& pointer) const;

  /// VEC3 accessor as float (float, or KHR_mesh_quantization integer encodings); finite values only.
  std::vector<glm::vec3> read_vec3(std::uint32_t accessor, std::uint64_t max_count);
  /// SCALAR unsigned byte/short/int accessor.
  std::vector<std::uint32_t> read_indices(std::uint32_t accessor, std::uint64_t max_count);
  /// The `count` an accessor states (checked against the limits before Draco decodes a primitive).
  std::uint64_t accessor_count(std::uint32_t accessor) const;
  /// Decodes a KHR_draco_mesh_compression primitive (`ext` is the extension object).
  LocalPrimitive decode_draco(const JsonRef& ext, std::uint64_t max_vertices, std::uint64_t max_triangles);

 private:
  struct Buffer {
    bool loaded = false;
    std::vector<std::uint8_t> owned;
    Bytes bytes;
  };
  struct AccessorView {
    const std::uint8_t* first = nullptr;  ///< element 0
    std::size_t stride = 0;
    std::size_t count = 0;
    int component_type = 0;
    bool normalized = false;
  };
  Bytes buffer(std::uint32_t index);
  AccessorView accessor(std::uint32_t index, const char* type, std::uint64_t max_count);
  void read_glb(const std::vector<std::uint8_t>& file);

  std::string path_;
  std::filesystem::path base_dir_;
  GltfReadOptions options_;
  std::vector<std::uint8_t> file_;
  Bytes bin_chunk_;
  bool is_glb_ = false;
  Json json_;
  std::vector<Buffer> buffers_;
  std::uint64_t buffer_bytes_loaded_ = 0;
  std::vector<Diagnostic> warnings_;
};

}  // namespace gltf
}  // namespace bake
LUMX_NAMESPACE_END
