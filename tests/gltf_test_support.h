// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Writing small glTF 2.0 luminaires from tests: a JSON document with one binary buffer, saved as .gltf with
// a base64 data URI, as .gltf with an external .bin, or as .glb; and simple shapes (unit quad, unit cube,
// disk) to put in it.
#pragma once

#include <nlohmann/json.hpp>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace lumx_gltf_test {

using Json = nlohmann::json;

struct Shape {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<std::uint32_t> indices;
};

/// The unit square [0,1]² at z = 0, facing +z (counter-clockwise seen from +z): area 1 m².
inline Shape unit_quad() {
  Shape s;
  s.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  s.normals.assign(4, glm::vec3(0, 0, 1));
  s.indices = {0, 1, 2, 0, 2, 3};
  return s;
}

/// The closed unit cube [0,1]³, outward faces, 4 vertices per face (normals per face): area 6 m².
inline Shape unit_cube() {
  Shape s;
  const glm::vec3 n[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const glm::vec3& normal : n) {
    // Two axes spanning the face, with u × v = normal.
    glm::vec3 u = std::abs(normal.x) > 0 ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    glm::vec3 v(normal.y * u.z - normal.z * u.y, normal.z * u.x - normal.x * u.z, normal.x * u.y - normal.y * u.x);
    const glm::vec3 centre = glm::vec3(0.5f) + 0.5f * normal;
    const auto base = static_cast<std::uint32_t>(s.positions.size());
    for (const auto& c : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
      s.positions.push_back(centre + 0.5f * c.x * u + 0.5f * c.y * v);
      s.normals.push_back(normal);
    }
    s.indices.insert(s.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  return s;
}

/// A disk of radius r at z = 0 facing +z, as a fan of `segments` triangles around the centre.
inline Shape disk(int segments, float r) {
  Shape s;
  s.positions.push_back({0, 0, 0});
  for (int i = 0; i < segments; ++i) {
    const double a = 2 * 3.14159265358979323846 * i / segments;
    s.positions.push_back({float(r * std::cos(a)), float(r * std::sin(a)), 0.0f});
  }
  s.normals.assign(s.positions.size(), glm::vec3(0, 0, 1));
  for (int i = 0; i < segments; ++i)
    s.indices.insert(s.indices.end(), {0u, std::uint32_t(1 + i), std::uint32_t(1 + (i + 1) % segments)});
  return s;
}

inline std::string base64(const std::vector<std::uint8_t>& b) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string s;
  for (std::size_t i = 0; i < b.size(); i += 3) {
    const std::uint32_t v = std::uint32_t(b[i]) << 16 | (i + 1 < b.size() ? std::uint32_t(b[i + 1]) << 8 : 0) |
                            (i + 2 < b.size() ? b[i + 2] : 0);
    s += k[v >> 18 & 63];
    s += k[v >> 12 & 63];
    s += i + 1 < b.size() ? k[v >> 6 & 63] : '=';
    s += i + 2 < b.size() ? k[v & 63] : '=';
  }
  return s;
}

/// A glTF document under construction with one binary buffer (index 0).
struct GltfBuilder {
  Json doc = {{"asset", {{"version", "2.0"}, {"generator", "lumx tests"}}}};
  std::vector<std::uint8_t> bin;

  int push(const char* array, Json value) {
    doc[array].push_back(std::move(value));
    return static_cast<int>(doc[array].size() - 1);
  }
  int add_view(const void* data, std::size_t bytes) {
    while (bin.size() % 4) bin.push_back(0);
    const std::size_t offset = bin.size();
    bin.resize(offset + bytes);
    std::memcpy(bin.data() + offset, data, bytes);
    return push("bufferViews", {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
  }
  int add_vec3(const std::vector<glm::vec3>& v, bool with_bounds = true) {
    const int view = add_view(v.data(), v.size() * sizeof(glm::vec3));
    Json a = {{"bufferView", view}, {"componentType", 5126}, {"count", v.size()}, {"type", "VEC3"}};
    if (with_bounds && !v.empty()) {
      glm::vec3 lo = v[0], hi = v[0];
      for (const auto& p : v)
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
      a["min"] = {lo.x, lo.y, lo.z};
      a["max"] = {hi.x, hi.y, hi.z};
    }
    return push("accessors", a);
  }
  int add_indices(const std::vector<std::uint32_t>& idx) {
    const int view = add_view(idx.data(), idx.size() * 4);
    return push("accessors", {{"bufferView", view}, {"componentType", 5125}, {"count", idx.size()}, {"type", "SCALAR"}});
  }
  /// A one-primitive mesh; material < 0: none.
  int add_mesh(const Shape& s, int material, bool normals = true, const std::string& name = "") {
    Json prim = {{"attributes", {{"POSITION", add_vec3(s.positions)}}}, {"indices", add_indices(s.indices)}};
    if (normals && !s.normals.empty()) prim["attributes"]["NORMAL"] = add_vec3(s.normals, false);
    if (material >= 0) prim["material"] = material;
    Json mesh = {{"primitives", Json::array({prim})}};
    if (!name.empty()) mesh["name"] = name;
    return push("meshes", mesh);
  }
  int add_material(Json m) { return push("materials", std::move(m)); }
  int add_node(Json n) { return push("nodes", std::move(n)); }
  /// Puts `nodes` in scene 0 (the default scene).
  void set_scene(const std::vector<int>& nodes) {
    doc["scenes"] = Json::array({{{"nodes", nodes}}});
    doc["scene"] = 0;
  }
  void use_extension(const std::string& name, bool required = false) {
    doc["extensionsUsed"].push_back(name);
    if (required) doc["extensionsRequired"].push_back(name);
  }

  Json with_buffer(const Json& uri) const {
    Json d = doc;
    if (!bin.empty()) {
      d["buffers"] = Json::array({{{"byteLength", bin.size()}}});
      if (!uri.is_null()) d["buffers"][0]["uri"] = uri;
    }
    return d;
  }
  /// .gltf with the buffer as a base64 data URI.
  void write_gltf(const std::filesystem::path& path) const {
    std::ofstream(path, std::ios::binary) << with_buffer("data:application/octet-stream;base64," + base64(bin)).dump(1);
  }
  /// .gltf with the buffer in `bin_name` beside it.
  void write_gltf_external(const std::filesystem::path& path, const std::string& bin_name) const {
    std::ofstream(path, std::ios::binary) << with_buffer(bin_name).dump(1);
    std::ofstream(path.parent_path() / bin_name, std::ios::binary)
        .write(reinterpret_cast<const char*>(bin.data()), static_cast<std::streamsize>(bin.size()));
  }
  /// .glb: header, JSON chunk (space padded), BIN chunk (zero padded).
  std::vector<std::uint8_t> glb_bytes() const {
    std::string json = with_buffer(nullptr).dump();
    while (json.size() % 4) json += ' ';
    std::vector<std::uint8_t> b = bin;
    while (b.size() % 4) b.push_back(0);
    std::vector<std::uint8_t> out;
    auto u32 = [&out](std::uint32_t v) {
      for (int k = 0; k < 4; ++k) out.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
    };
    const std::size_t total = 12 + 8 + json.size() + (b.empty() ? 0 : 8 + b.size());
    u32(0x46546C67);
    u32(2);
    u32(static_cast<std::uint32_t>(total));
    u32(static_cast<std::uint32_t>(json.size()));
    u32(0x4E4F534A);
    out.insert(out.end(), json.begin(), json.end());
    if (!b.empty()) {
      u32(static_cast<std::uint32_t>(b.size()));
      u32(0x004E4942);
      out.insert(out.end(), b.begin(), b.end());
    }
    return out;
  }
  void write_glb(const std::filesystem::path& path) const {
    const auto bytes = glb_bytes();
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
};

inline void write_bytes(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}
inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

/// A fresh, empty folder for one test's files, removed with everything in it when the test ends.
struct ScratchDir {
  std::filesystem::path path;
  explicit ScratchDir(const std::string& name)
      : path(std::filesystem::temp_directory_path() / ("lumx_gltf_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  template <class T>
  std::filesystem::path operator/(const T& name) const {
    return path / name;
  }
};

inline ScratchDir scratch_dir(const std::string& name) { return ScratchDir(name); }

}  // namespace lumx_gltf_test
