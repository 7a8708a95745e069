// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// glTF 2.0 writing of luminaires (see lumx/bake/gltf_writer.h): JSON by nlohmann-json, one binary buffer.
#include <lumx/bake/gltf_writer.h>

#include <lumx/io/atomic_file.h>
#include <lumx/io/photometry_io.h>

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstring>
#include <limits>
#include <unordered_map>

LUMX_NAMESPACE_BEGIN
namespace bake {
namespace {

using nlohmann::json;

constexpr int kFloat = 5126, kUnsignedInt = 5125, kArrayBuffer = 34962, kElementArrayBuffer = 34963;

/// The binary buffer and the bufferViews/accessors into it.
struct BufferBuilder {
  std::string bytes;
  json views = json::array(), accessors = json::array();

  int view(const void* data, std::size_t size, int target) {
    while (bytes.size() % 4) bytes.push_back('\0');
    json v = {{"buffer", 0}, {"byteOffset", bytes.size()}, {"byteLength", size}};
    if (target) v["target"] = target;
    bytes.append(static_cast<const char*>(data), size);
    views.push_back(v);
    return int(views.size()) - 1;
  }
  int vec3_accessor(const std::vector<float>& xyz, bool with_bounds) {
    json a = {{"bufferView", view(xyz.data(), xyz.size() * sizeof(float), kArrayBuffer)},
              {"componentType", kFloat},
              {"count", xyz.size() / 3},
              {"type", "VEC3"}};
    if (with_bounds) {  // POSITION accessors must state min and max
      std::vector<float> lo(3, std::numeric_limits<float>::infinity()), hi(3, -std::numeric_limits<float>::infinity());
      for (std::size_t i = 0; i < xyz.size(); ++i) {
        lo[i % 3] = std::min(lo[i % 3], xyz[i]);
        hi[i % 3] = std::max(hi[i % 3], xyz[i]);
      }
      a["min"] = lo;
      a["max"] = hi;
    }
    accessors.push_back(a);
    return int(accessors.size()) - 1;
  }
  int index_accessor(const std::vector<std::uint32_t>& indices) {
    accessors.push_back({{"bufferView", view(indices.data(), indices.size() * 4, kElementArrayBuffer)},
                         {"componentType", kUnsignedInt},
                         {"count", indices.size()},
                         {"type", "SCALAR"}});
    return int(accessors.size()) - 1;
  }
};

/// One mesh as a KHR_draco_mesh_compression primitive: the compressed bytes in a bufferView, and accessors
/// that state what decoding gives (counts, and the POSITION box) without data of their own.
json draco_primitive(BufferBuilder& buffer, const std::vector<float>& positions, const std::vector<float>& normals,
                     const std::vector<std::uint32_t>& indices, const GltfWriteOptions& o, const std::string& path,
                     const std::string& where) {
  draco::Mesh mesh;
  const std::size_t points = positions.size() / 3;
  mesh.set_num_points(std::uint32_t(points));
  auto add = [&](draco::GeometryAttribute::Type type, const std::vector<float>& values) {
    draco::GeometryAttribute a;
    a.Init(type, nullptr, 3, draco::DT_FLOAT32, false, sizeof(float) * 3, 0);
    const int id = mesh.AddAttribute(a, true, std::uint32_t(points));
    for (std::size_t i = 0; i < points; ++i)
      mesh.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(std::uint32_t(i)), &values[3 * i]);
    return int(mesh.attribute(id)->unique_id());
  };
  const int position_id = add(draco::GeometryAttribute::POSITION, positions);
  const int normal_id = normals.empty() ? -1 : add(draco::GeometryAttribute::NORMAL, normals);
  for (std::size_t t = 0; t < indices.size() / 3; ++t) {
    draco::Mesh::Face f;
    for (int k = 0; k < 3; ++k) f[k] = draco::PointIndex(indices[3 * t + k]);
    mesh.AddFace(f);
  }
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, o.draco_position_bits);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, o.draco_normal_bits);
  draco::EncoderBuffer encoded;
  const draco::Status status = encoder.EncodeMeshToBuffer(mesh, &encoded);
  if (!status.ok()) throw_at_field(path, where, std::string("Draco encoding failed: ") + status.error_msg());
  // The accessors describe the decoded mesh (its point count and quantised box), so decode once.
  draco::DecoderBuffer in;
  in.Init(encoded.data(), encoded.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&in);
  if (!decoded.ok()) throw_at_field(path, where, "Draco data written cannot be decoded");
  const draco::Mesh& back = *decoded.value();
  const draco::PointAttribute* pa = back.GetAttributeByUniqueId(std::uint32_t(position_id));
  std::vector<float> lo(3, std::numeric_limits<float>::infinity()), hi(3, -std::numeric_limits<float>::infinity());
  for (std::uint32_t i = 0; i < back.num_points(); ++i) {
    float v[3];
    pa->GetMappedValue(draco::PointIndex(i), v);
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
  }
  const int view = buffer.view(encoded.data(), encoded.size(), 0);
  auto accessor = [&](json a) {
    buffer.accessors.push_back(std::move(a));
    return int(buffer.accessors.size()) - 1;
  };
  json attributes = {{"POSITION", accessor({{"componentType", kFloat}, {"count", back.num_points()}, {"type", "VEC3"},
                                            {"min", lo}, {"max", hi}})}};
  json draco_attributes = {{"POSITION", position_id}};
  if (normal_id >= 0) {
    attributes["NORMAL"] = accessor({{"componentType", kFloat}, {"count", back.num_points()}, {"type", "VEC3"}});
    draco_attributes["NORMAL"] = normal_id;
  }
  const int index_accessor =
      accessor({{"componentType", kUnsignedInt}, {"count", 3 * back.num_faces()}, {"type", "SCALAR"}});
  return {{"attributes", attributes},
          {"indices", index_accessor},
          {"mode", 4},
          {"extensions", {{"KHR_draco_mesh_compression", {{"bufferView", view}, {"attributes", draco_attributes}}}}}};
}

std::string base64(const std::string& in) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < in.size(); i += 3) {
    const std::uint32_t b0 = std::uint8_t(in[i]), b1 = i + 1 < in.size() ? std::uint8_t(in[i + 1]) : 0,
                        b2 = i + 2 < in.size() ? std::uint8_t(in[i + 2]) : 0;
    const std::uint32_t v = (b0 << 16) | (b1 << 8) | b2;
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < in.size() ? table[(v >> 6) & 63] : '=';
    out += i + 2 < in.size() ? table[v & 63] : '=';
  }
  return out;
}

json rgb(const Rgb& c) { return json::array({c.x, c.y, c.z}); }

json material_json(const Material& m, std::vector<std::string>& used) {
  json j = {{"name", m.name.empty() ? "material" : m.name},
            {"pbrMetallicRoughness",
             {{"baseColorFactor", {m.base_color.x, m.base_color.y, m.base_color.z, 1.0}},
              {"metallicFactor", m.metallic},
              {"roughnessFactor", m.roughness}}}};
  if (m.double_sided) j["doubleSided"] = true;
  json ext = json::object();
  auto use = [&](const char* name, json value) {
    ext[name] = std::move(value);
    if (std::find(used.begin(), used.end(), name) == used.end()) used.push_back(name);
  };
  // emissiveFactor is limited to [0, 1]: the largest component moves into the strength.
  const double peak = std::max({m.emissive.x, m.emissive.y, m.emissive.z});
  if (peak > 0.0) {
    j["emissiveFactor"] = rgb(m.emissive / std::max(peak, 1.0));
    const double strength = m.emissive_strength * std::max(peak, 1.0);
    if (strength != 1.0) use("KHR_materials_emissive_strength", {{"emissiveStrength", strength}});
  }
  if (m.ior != 1.5) use("KHR_materials_ior", {{"ior", m.ior}});
  if (m.specular != 1.0 || m.specular_color != Rgb{1.0})
    use("KHR_materials_specular", {{"specularFactor", m.specular}, {"specularColorFactor", rgb(m.specular_color)}});
  if (m.transmission > 0.0) use("KHR_materials_transmission", {{"transmissionFactor", m.transmission}});
  if (m.diffuse_transmission > 0.0)
    use("KHR_materials_diffuse_transmission", {{"diffuseTransmissionFactor", m.diffuse_transmission},
                                               {"diffuseTransmissionColorFactor", rgb(m.diffuse_transmission_color)}});
  if (m.volume) {
    json v = {{"thicknessFactor", m.thickness_m > 0.0 ? m.thickness_m : 1e-3},
              {"attenuationColor", rgb(m.attenuation_color)}};
    if (std::isfinite(m.attenuation_distance_m)) v["attenuationDistance"] = m.attenuation_distance_m;
    use("KHR_materials_volume", v);
  }
  if (!ext.empty()) j["extensions"] = ext;
  return j;
}

json matrix_json(const glm::dmat4& m) {
  json a = json::array();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) a.push_back(m[c][r]);  // glTF matrices are column-major, as glm's
  return a;
}

}  // namespace

void write_gltf_luminaire(const LuminaireScene& scene, const std::string& path, const GltfWriteOptions& options) {
  BufferBuilder buffer;
  std::vector<std::string> used;
  json doc;
  doc["asset"] = {{"version", "2.0"}, {"generator", options.generator}};
  json materials = json::array(), meshes = json::array(), nodes = json::array(), scene_nodes = json::array();
  for (const Material& m : scene.materials) materials.push_back(material_json(m, used));

  for (std::size_t p = 0; p < scene.parts.size(); ++p) {
    const Part& part = scene.parts[p];
    if (part.material >= scene.materials.size())
      throw_at_field(path, "parts[" + std::to_string(p) + "].material", "material index out of range");
    std::unordered_map<std::uint32_t, std::uint32_t> remap;
    std::vector<float> positions, normals;
    std::vector<std::uint32_t> indices;
    for (std::uint32_t t = part.first_triangle; t < part.first_triangle + part.triangle_count; ++t)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = scene.indices.at(3 * std::size_t(t) + k);
        auto [it, inserted] = remap.emplace(v, std::uint32_t(remap.size()));
        if (inserted) {
          const glm::vec3 q = scene.positions.at(v);
          positions.insert(positions.end(), {q.x, q.y, q.z});
          if (!scene.normals.empty()) {
            const glm::vec3 n = scene.normals.at(v);
            normals.insert(normals.end(), {n.x, n.y, n.z});
          }
        }
        indices.push_back(it->second);
      }
    if (indices.empty()) continue;
    json primitive;
    if (options.draco) {
      primitive = draco_primitive(buffer, positions, normals, indices, options, path, "/meshes/" + std::to_string(meshes.size()));
    } else {
      json attributes = {{"POSITION", buffer.vec3_accessor(positions, true)}};
      if (!normals.empty()) attributes["NORMAL"] = buffer.vec3_accessor(normals, false);
      primitive = {{"attributes", attributes}, {"indices", buffer.index_accessor(indices)}, {"mode", 4}};
    }
    primitive["material"] = part.material;
    meshes.push_back({{"name", part.name}, {"primitives", json::array({primitive})}});
    nodes.push_back({{"name", part.name}, {"mesh", meshes.size() - 1}});
    scene_nodes.push_back(nodes.size() - 1);
  }

  json punctual = json::array(), ies_profiles = json::array();
  for (std::size_t e = 0; e < scene.emitters.size(); ++e) {
    const Emitter& em = scene.emitters[e];
    const std::string where = "emitters[" + std::to_string(e) + "] (" + em.name + ")";
    json node = {{"name", em.name.empty() ? std::string(to_string(em.kind)) : em.name}};
    if (em.to_world != glm::dmat4(1.0)) node["matrix"] = matrix_json(em.to_world);
    switch (em.kind) {
      case EmitterKind::surface: continue;  // the part's emissive material says it all
      case EmitterKind::point:
      case EmitterKind::spot: {
        const double peak = std::max({em.intensity_cd.x, em.intensity_cd.y, em.intensity_cd.z});
        json light = {{"type", em.kind == EmitterKind::point ? "point" : "spot"},
                      {"intensity", peak},
                      {"color", rgb(peak > 0 ? em.intensity_cd / peak : Rgb{1.0})}};
        if (em.kind == EmitterKind::spot)
          light["spot"] = {{"innerConeAngle", em.inner_cone_rad}, {"outerConeAngle", em.outer_cone_rad}};
        punctual.push_back(light);
        node["extensions"] = {{"KHR_lights_punctual", {{"light", punctual.size() - 1}}}};
        if (std::find(used.begin(), used.end(), "KHR_lights_punctual") == used.end())
          used.push_back("KHR_lights_punctual");
        break;
      }
      case EmitterKind::ies: {
        if (!em.photometry) throw_at_field(path, where, "IES emitter without a profile");
        const std::string text = format_ies(*em.photometry);
        ies_profiles.push_back({{"bufferView", buffer.view(text.data(), text.size(), 0)},
                                {"mimeType", "application/x-ies-lm-63"}});
        node["extensions"] = {{"EXT_lights_ies", {{"light", ies_profiles.size() - 1},
                                                  {"multiplier", em.multiplier},
                                                  {"color", rgb(em.color)}}}};
        if (std::find(used.begin(), used.end(), "EXT_lights_ies") == used.end()) used.push_back("EXT_lights_ies");
        break;
      }
      case EmitterKind::rayset:
        throw_at_field(path, where, "rayset emitters reference a ray file; glTF writing does not embed them");
    }
    nodes.push_back(node);
    scene_nodes.push_back(nodes.size() - 1);
  }

  if (!materials.empty()) doc["materials"] = materials;
  if (!meshes.empty()) doc["meshes"] = meshes;
  doc["nodes"] = nodes;
  doc["scenes"] = json::array({{{"nodes", scene_nodes}}});
  doc["scene"] = 0;
  json extensions = json::object();
  if (!punctual.empty()) extensions["KHR_lights_punctual"] = {{"lights", punctual}};
  if (!ies_profiles.empty()) extensions["EXT_lights_ies"] = {{"lights", ies_profiles}};
  if (!extensions.empty()) doc["extensions"] = extensions;
  if (options.draco && !meshes.empty()) {
    used.push_back("KHR_draco_mesh_compression");
    doc["extensionsRequired"] = json::array({"KHR_draco_mesh_compression"});
  }
  if (!used.empty()) doc["extensionsUsed"] = used;
  if (!buffer.bytes.empty()) {
    while (buffer.bytes.size() % 4) buffer.bytes.push_back('\0');
    json b = {{"byteLength", buffer.bytes.size()}};
    if (!options.binary) b["uri"] = "data:application/octet-stream;base64," + base64(buffer.bytes);
    doc["buffers"] = json::array({b});
    doc["bufferViews"] = buffer.views;
    doc["accessors"] = buffer.accessors;
  }

  std::string json_text = doc.dump();
  if (!options.binary) {
    write_file_atomically(path, json_text);
    return;
  }
  // GLB: 12-byte header, a JSON chunk padded with spaces, a BIN chunk padded with zeros (glTF 2.0 §4.4).
  while (json_text.size() % 4) json_text.push_back(' ');
  auto u32 = [](std::string& out, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) out.push_back(char((v >> (8 * k)) & 0xFF));
  };
  std::string glb;
  const std::size_t total = 12 + 8 + json_text.size() + (buffer.bytes.empty() ? 0 : 8 + buffer.bytes.size());
  if (total > std::numeric_limits<std::uint32_t>::max())
    throw_at_field(path, "", "the luminaire needs more than 4 GiB, beyond what a GLB file can hold");
  glb.reserve(total);
  u32(glb, 0x46546C67u);  // "glTF"
  u32(glb, 2);
  u32(glb, std::uint32_t(total));
  u32(glb, std::uint32_t(json_text.size()));
  u32(glb, 0x4E4F534Au);  // "JSON"
  glb += json_text;
  if (!buffer.bytes.empty()) {
    u32(glb, std::uint32_t(buffer.bytes.size()));
    u32(glb, 0x004E4942u);  // "BIN\0"
    glb += buffer.bytes;
  }
  write_file_atomically(path, glb);
}

}  // namespace bake
LUMX_NAMESPACE_END
