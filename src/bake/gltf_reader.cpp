// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// glTF 2.0 → LuminaireScene (lumx/bake/gltf_reader.h): the scene walk, node transforms, materials and lights.
// The file, its buffers, accessors and Draco payloads are read and checked by gltf_document.cpp.
#include <lumx/bake/gltf_reader.h>

#include "bake/gltf_document.h"

#include <lumx/bake/luminaire_check.h>
#include <lumx/io/photometry_io.h>
#include <lumx/io/rayset_io.h>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <string_view>
#include <utility>

LUMX_NAMESPACE_BEGIN
namespace bake {
namespace {

using gltf::Document;
using gltf::JsonRef;
using gltf::LocalPrimitive;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kHalfPi = 1.5707963267948966;

const std::set<std::string>& implemented_extensions() {
  static const std::set<std::string> names = {
      "KHR_draco_mesh_compression",   "KHR_mesh_quantization",         "KHR_lights_punctual",
      "EXT_lights_ies",               "LUMX_lights_rayset",            "KHR_materials_ior",
      "KHR_materials_specular",       "KHR_materials_transmission",    "KHR_materials_diffuse_transmission",
      "KHR_materials_volume",         "KHR_materials_emissive_strength", "KHR_texture_transform"};
  return names;
}

Rgb rgb(const std::vector<double>& v) { return Rgb{v[0], v[1], v[2]}; }

bool finite(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

/// A node placed in the world by the scene walk.
struct Placement {
  std::uint32_t node = 0;
  glm::dmat4 to_world{1.0};
};

class SceneBuilder {
 public:
  SceneBuilder(const std::string& path, const GltfReadOptions& options) : doc_(path, options), options_(options) {}

  LuminaireScene build() {
    scene_.name = doc_.path();
    check_asset();
    check_extensions();
    read_materials();
    read_punctual_lights();
    const std::vector<Placement> placements = walk_scene();
    decode_placed_primitives(placements);
    for (const Placement& p : placements) place_node(p);
    add_surface_emitters();
    scene_.warnings = doc_.warnings();
    return std::move(scene_);
  }

 private:
  // ---- asset and extensions ----------------------------------------------------------------------------------

  void check_asset() {
    const JsonRef asset = doc_.root().member("asset");
    const std::string version = asset.string("version", "");
    if (!asset.has("version")) asset.member("version");
    if (version.rfind("2.", 0) != 0) doc_.fail("/asset/version", "is \"" + version + "\", lumx reads glTF 2.x");
    if (asset.has("minVersion")) {
      const std::string min = asset.string("minVersion", "");
      if (min != "2.0") doc_.fail("/asset/minVersion", "is \"" + min + "\", lumx reads glTF 2.0");
    }
  }

  void check_extensions() {
    const JsonRef root = doc_.root();
    std::set<std::string> required;
    if (root.has("extensionsRequired")) {
      const JsonRef list = root.member("extensionsRequired");
      for (std::size_t i = 0; i < list.array_size(); ++i) {
        const JsonRef e = list.element(i);
        if (!e.value->is_string()) e.fail("must be a string");
        const std::string name = e.value->get<std::string>();
        if (!implemented_extensions().count(name))
          e.fail("the file requires " + name + ", which lumx does not implement");
        required.insert(name);
      }
    }
    if (root.has("extensionsUsed")) {
      const JsonRef list = root.member("extensionsUsed");
      for (std::size_t i = 0; i < list.array_size(); ++i) {
        const JsonRef e = list.element(i);
        if (!e.value->is_string()) e.fail("must be a string");
        const std::string name = e.value->get<std::string>();
        if (!implemented_extensions().count(name))
          doc_.warn(e.pointer, name + " is not implemented by lumx; what it adds is ignored");
      }
    }
  }

  // ---- materials ---------------------------------------------------------------------------------------------

  /// Warns about every texture reference in a material (members named "...Texture" holding an object).
  void warn_textures(const JsonRef& j, int depth) {
    if (depth > 6 || !j.value->is_object()) return;
    for (auto it = j.value->begin(); it != j.value->end(); ++it) {
      const std::string& key = it.key();
      const std::string ptr = j.pointer + "/" + gltf::pointer_token(key);
      const bool texture = key.size() >= 7 && key.compare(key.size() - 7, 7, "Texture") == 0 && it->is_object();
      if (texture)
        doc_.warn(ptr, "texture ignored: lumx uses the material's factors alone");
      else if (it->is_object())
        warn_textures(JsonRef{&doc_, &*it, ptr}, depth + 1);
    }
  }

  Material read_material(const JsonRef& j) {
    j.require_object();
    Material m;
    m.name = j.string("name", "");
    if (j.has("pbrMetallicRoughness")) {
      const JsonRef pbr = j.member("pbrMetallicRoughness");
      const auto base = pbr.numbers("baseColorFactor", 4, {1, 1, 1, 1}, 0.0, 1.0);
      m.base_color = Rgb{base[0], base[1], base[2]};
      m.metallic = pbr.number("metallicFactor", 1.0, 0.0, 1.0);
      m.roughness = pbr.number("roughnessFactor", 1.0, 0.0, 1.0);
    }
    m.emissive = rgb(j.numbers("emissiveFactor", 3, {0, 0, 0}, 0.0, 1.0));
    m.double_sided = j.boolean("doubleSided", false);
    const std::string alpha = j.string("alphaMode", "OPAQUE");
    if (alpha != "OPAQUE")
      doc_.warn(j.pointer + "/alphaMode", "\"" + alpha + "\" ignored: lumx treats every surface as opaque "
                                          "(transmission comes from KHR_materials_transmission)");
    if (j.has("extensions")) {
      const JsonRef ext = j.member("extensions");
      ext.require_object();
      for (auto it = ext.value->begin(); it != ext.value->end(); ++it) {
        const std::string& name = it.key();
        const JsonRef e{&doc_, &*it, ext.pointer + "/" + gltf::pointer_token(name)};
        if (name == "KHR_materials_ior") {
          m.ior = e.number("ior", 1.5, 0.0, 1e3);
          if (m.ior > 0.0 && m.ior < 1.0) e.member("ior").fail("must be 0 or at least 1 (KHR_materials_ior)");
        } else if (name == "KHR_materials_specular") {
          m.specular = e.number("specularFactor", 1.0, 0.0, 1.0);
          m.specular_color = rgb(e.numbers("specularColorFactor", 3, {1, 1, 1}, 0.0, kInf));
        } else if (name == "KHR_materials_transmission") {
          m.transmission = e.number("transmissionFactor", 0.0, 0.0, 1.0);
        } else if (name == "KHR_materials_diffuse_transmission") {
          m.diffuse_transmission = e.number("diffuseTransmissionFactor", 0.0, 0.0, 1.0);
          m.diffuse_transmission_color = rgb(e.numbers("diffuseTransmissionColorFactor", 3, {1, 1, 1}, 0.0, 1.0));
        } else if (name == "KHR_materials_volume") {
          m.thickness_m = e.number("thicknessFactor", 0.0, 0.0, kInf);
          m.volume = m.thickness_m > 0.0;
          m.attenuation_distance_m = kInf;
          if (e.has("attenuationDistance")) {
            m.attenuation_distance_m = e.number("attenuationDistance", kInf, 0.0, kInf);
            if (!(m.attenuation_distance_m > 0.0)) e.member("attenuationDistance").fail("must be greater than 0");
          }
          m.attenuation_color = rgb(e.numbers("attenuationColor", 3, {1, 1, 1}, 0.0, 1.0));
        } else if (name == "KHR_materials_emissive_strength") {
          m.emissive_strength = e.number("emissiveStrength", 1.0, 0.0, kInf);
        } else {
          doc_.warn(e.pointer, name + " is not implemented by lumx; ignored");
        }
      }
    }
    warn_textures(j, 0);
    return m;
  }

  void read_materials() {
    const std::size_t n = doc_.count("materials");
    for (std::size_t i = 0; i < n; ++i)
      scene_.materials.push_back(read_material(doc_.root().member("materials").element(i)));
  }

  std::uint32_t default_material() {
    if (default_material_ < 0) {
      Material m;
      m.name = "glTF default";
      default_material_ = static_cast<std::int64_t>(scene_.materials.size());
      scene_.materials.push_back(m);
    }
    return static_cast<std::uint32_t>(default_material_);
  }

  // ---- lights ------------------------------------------------------------------------------------------------

  struct PunctualLight {
    std::string type, name;
    Rgb intensity_cd{0.0};
    double inner = 0.0, outer = 0.7853981633974483;
  };

  void read_punctual_lights() {
    const JsonRef root = doc_.root();
    if (!root.has("extensions") || !root.member("extensions").has("KHR_lights_punctual")) return;
    const JsonRef ext = root.member("extensions").member("KHR_lights_punctual");
    const JsonRef lights = ext.member("lights");
    for (std::size_t i = 0; i < lights.array_size(); ++i) {
      const JsonRef l = lights.element(i);
      l.require_object();
      PunctualLight p;
      if (!l.has("type")) l.member("type");
      p.type = l.string("type", "");
      p.name = l.string("name", "");
      const Rgb color = rgb(l.numbers("color", 3, {1, 1, 1}, 0.0, 1.0));
      p.intensity_cd = color * l.number("intensity", 1.0, 0.0, kInf);
      if (p.type == "spot") {
        const JsonRef spot = l.member("spot");
        p.inner = spot.number("innerConeAngle", 0.0, 0.0, kHalfPi);
        p.outer = spot.number("outerConeAngle", 0.7853981633974483, 0.0, kHalfPi);
        if (!(p.inner < p.outer))
          spot.member(spot.has("innerConeAngle") ? "innerConeAngle" : "outerConeAngle")
              .fail("innerConeAngle must be less than outerConeAngle");
        if (!(p.outer > 0.0)) spot.member("outerConeAngle").fail("must be greater than 0");
      } else if (p.type != "point" && p.type != "directional") {
        l.member("type").fail("is \"" + p.type + "\", not point, spot or directional");
      }
      punctual_.push_back(p);
    }
  }

  std::shared_ptr<const Photometry> ies_profile(std::uint32_t index) {
    auto found = ies_profiles_.find(index);
    if (found != ies_profiles_.end()) return found->second;
    const JsonRef l = doc_.root().member("extensions").member("EXT_lights_ies").member("lights").element(index);
    l.require_object();
    std::vector<std::uint8_t> bytes;
    std::string name;
    ReadOptions ro;
    ro.base_dir = doc_.base_dir().string();
    ro.warnings = [this](const Diagnostic& d) {
      doc_.warnings().push_back(d);
      if (options_.warnings) options_.warnings(d);
    };
    if (l.has("uri") == l.has("bufferView")) l.fail("a light profile needs either uri or bufferView");
    if (l.has("uri")) {
      const std::string uri = l.string("uri", "");
      bytes = doc_.uri_bytes(uri, l.pointer + "/uri", ro.limits.max_file_bytes);
      name = uri.rfind("data:", 0) == 0 ? doc_.path() + "#" + l.pointer : doc_.resolve_uri(uri, l.pointer + "/uri").string();
    } else {
      const std::uint32_t view = l.index("bufferView", doc_.count("bufferViews"), "bufferViews");
      const std::string mime = l.string("mimeType", "");
      if (mime != "application/x-ies-lm-63")
        doc_.warn(l.pointer + "/mimeType", "should be \"application/x-ies-lm-63\" with a bufferView");
      const gltf::Bytes b = doc_.buffer_view(view);
      bytes.assign(b.data, b.data + b.size);
      name = doc_.path() + "#" + l.pointer;
    }
    if (bytes.size() > ro.limits.max_file_bytes)
      l.fail("the profile has " + std::to_string(bytes.size()) + " bytes, more than ReadLimits::max_file_bytes (" +
             std::to_string(ro.limits.max_file_bytes) + ")");
    const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    auto profile = std::make_shared<const Photometry>(read_ies(text, name, ro));
    ies_profiles_[index] = profile;
    return profile;
  }

  void place_lights(const Placement& p, const JsonRef& node, const std::string& node_name) {
    if (!node.has("extensions")) return;
    const JsonRef ext = node.member("extensions");
    ext.require_object();
    if (ext.has("KHR_lights_punctual")) {
      const JsonRef e = ext.member("KHR_lights_punctual");
      const std::uint32_t i = e.index("light", punctual_.size(), "KHR_lights_punctual lights");
      const PunctualLight& l = punctual_[i];
      const std::string source = "/extensions/KHR_lights_punctual/lights/" + std::to_string(i);
      if (l.type == "directional") {
        doc_.warn(e.pointer + "/light", "directional light ignored: a luminaire has no light from infinity");
      } else {
        Emitter em;
        em.kind = l.type == "spot" ? EmitterKind::spot : EmitterKind::point;
        em.name = !l.name.empty() ? l.name : node_name;
        em.source = source;
        em.to_world = p.to_world;
        em.intensity_cd = l.intensity_cd;
        em.inner_cone_rad = l.inner;
        em.outer_cone_rad = l.outer;
        scene_.emitters.push_back(em);
      }
    }
    if (ext.has("EXT_lights_ies")) {
      const JsonRef e = ext.member("EXT_lights_ies");
      std::size_t profiles = 0;
      const JsonRef root = doc_.root();
      if (root.has("extensions") && root.member("extensions").has("EXT_lights_ies"))
        profiles = root.member("extensions").member("EXT_lights_ies").member("lights").array_size();
      const std::uint32_t i = e.index("light", profiles, "EXT_lights_ies light profiles");
      Emitter em;
      em.kind = EmitterKind::ies;
      em.source = "/extensions/EXT_lights_ies/lights/" + std::to_string(i);
      em.name = doc_.root().member("extensions").member("EXT_lights_ies").member("lights").element(i).string("name", "");
      if (em.name.empty()) em.name = node_name;
      em.to_world = p.to_world;
      em.multiplier = e.number("multiplier", 1.0, 0.0, kInf);
      em.color = rgb(e.numbers("color", 3, {1, 1, 1}, -kInf, kInf));
      for (int c = 0; c < 3; ++c) em.color[c] = std::clamp(em.color[c], 0.0, 1.0);  // the extension clamps
      em.photometry = ies_profile(i);
      scene_.emitters.push_back(em);
    }
    if (ext.has("LUMX_lights_rayset")) {
      const JsonRef e = ext.member("LUMX_lights_rayset");
      e.require_object();
      if (!e.has("uri")) e.member("uri");
      const std::string uri = e.string("uri", "");
      if (uri.rfind("data:", 0) == 0) e.member("uri").fail("a ray file must be a file path, not a data URI");
      const std::filesystem::path file = doc_.resolve_uri(uri, e.pointer + "/uri");
      std::error_code ec;
      if (!std::filesystem::is_regular_file(file, ec))
        e.member("uri").fail("the ray file '" + file.string() + "' does not exist or is not a file");
      RaysetReadOptions ro;
      ro.warnings = [this](const Diagnostic& d) {
        doc_.warnings().push_back(d);
        if (options_.warnings) options_.warnings(d);
      };
      open_rayset(file.string(), ro);  // reads and checks the header now; the tracer streams the rays
      Emitter em;
      em.kind = EmitterKind::rayset;
      em.name = node_name;
      em.source = e.pointer;
      em.to_world = p.to_world;
      em.color = rgb(e.numbers("color", 3, {1, 1, 1}, 0.0, kInf));
      em.rayset_path = file.string();
      scene_.emitters.push_back(em);
    }
  }

  // ---- the scene walk ----------------------------------------------------------------------------------------

  glm::dmat4 local_matrix(const JsonRef& node) {
    const bool trs = node.has("translation") || node.has("rotation") || node.has("scale");
    if (node.has("matrix")) {
      if (trs) node.member("matrix").fail("a node has either matrix or translation/rotation/scale, not both");
      const auto m = node.numbers("matrix", 16, {}, -kInf, kInf);
      glm::dmat4 out;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) out[c][r] = m[std::size_t(c) * 4 + r];  // column-major, as glTF stores it
      return out;
    }
    const auto t = node.numbers("translation", 3, {0, 0, 0}, -kInf, kInf);
    const auto q = node.numbers("rotation", 4, {0, 0, 0, 1}, -1.0 - 1e-6, 1.0 + 1e-6);
    const auto s = node.numbers("scale", 3, {1, 1, 1}, -kInf, kInf);
    glm::dquat rot(q[3], q[0], q[1], q[2]);  // glTF stores x, y, z, w
    const double len = glm::length(rot);
    if (!(len > 0.0)) node.member("rotation").fail("is not a rotation (zero quaternion)");
    if (std::abs(len - 1.0) > 1e-3)
      doc_.warn(node.pointer + "/rotation", "quaternion of length " + std::to_string(len) + " normalised");
    rot = rot / len;
    glm::dmat4 out = glm::mat4_cast(rot);
    for (int c = 0; c < 3; ++c) out[c] *= s[std::size_t(c)];
    out[3] = glm::dvec4(t[0], t[1], t[2], 1.0);
    return out;
  }

  std::vector<std::uint32_t> scene_roots() {
    const JsonRef root = doc_.root();
    const std::size_t nodes = doc_.count("nodes");
    const std::size_t scenes = doc_.count("scenes");
    std::vector<std::uint32_t> roots;
    if (scenes > 0) {
      const std::uint32_t s = root.has("scene") ? root.index("scene", scenes, "scenes") : 0;
      const JsonRef sj = root.member("scenes").element(s);
      sj.require_object();
      if (sj.has("nodes")) {
        const JsonRef list = sj.member("nodes");
        std::vector<bool> listed(nodes, false);
        for (std::size_t i = 0; i < list.array_size(); ++i) {
          const std::uint32_t n = child_index(list, i, nodes);
          if (listed[n]) list.element(i).fail("node " + std::to_string(n) + " is listed twice in the scene");
          listed[n] = true;
          roots.push_back(n);
        }
      }
      return roots;
    }
    if (root.has("scene")) root.index("scene", 0, "scenes");  // fails: a scene index without scenes
    std::vector<bool> is_child(nodes, false);
    for (std::size_t n = 0; n < nodes; ++n) {
      const JsonRef node = root.member("nodes").element(n);
      if (!node.has("children")) continue;
      const JsonRef children = node.member("children");
      for (std::size_t c = 0; c < children.array_size(); ++c) is_child[child_index(children, c, nodes)] = true;
    }
    for (std::size_t n = 0; n < nodes; ++n)
      if (!is_child[n]) roots.push_back(static_cast<std::uint32_t>(n));
    return roots;
  }

  std::uint32_t child_index(const JsonRef& list, std::size_t i, std::size_t nodes) {
    const JsonRef e = list.element(i);
    if (!e.value->is_number_unsigned() || e.value->get<std::uint64_t>() >= nodes)
      e.fail("must be a node index below " + std::to_string(nodes));
    return static_cast<std::uint32_t>(e.value->get<std::uint64_t>());
  }

  std::vector<Placement> walk_scene() {
    const std::size_t nodes = doc_.count("nodes");
    const std::vector<std::uint32_t> roots = scene_roots();
    std::vector<Placement> out;
    std::vector<std::int64_t> reached_from(nodes, -2);  // -2: not reached; -1: a root; else the parent
    std::vector<Placement> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back(Placement{*it, glm::dmat4(1.0)});
    for (std::uint32_t r : roots) {
      reached_from[r] = -1;
    }
    std::uint64_t visits = 0;
    while (!stack.empty()) {
      Placement p = stack.back();
      stack.pop_back();
      if (++visits > options_.max_nodes_placed)
        doc_.fail("/nodes", "the scene places more nodes than GltfReadOptions::max_nodes_placed (" +
                                std::to_string(options_.max_nodes_placed) + ")");
      const JsonRef node = doc_.root().member("nodes").element(p.node);
      node.require_object();
      p.to_world = p.to_world * local_matrix(node);
      if (!finite(p.to_world)) node.fail("the node's world transform is not finite");
      out.push_back(p);
      if (!node.has("children")) continue;
      const JsonRef children = node.member("children");
      const std::size_t n = children.array_size();
      for (std::size_t k = n; k-- > 0;) {
        const std::uint32_t c = child_index(children, k, nodes);
        if (reached_from[c] != -2)
          children.element(k).fail("node " + std::to_string(c) + " is reached twice (a cycle, or a second parent)");
        reached_from[c] = p.node;
        stack.push_back(Placement{c, p.to_world});
      }
    }
    return out;
  }

  // ---- meshes ------------------------------------------------------------------------------------------------

  std::string primitive_pointer(std::uint32_t mesh, std::uint32_t prim) const {
    return "/meshes/" + std::to_string(mesh) + "/primitives/" + std::to_string(prim);
  }

  LocalPrimitive decode_primitive(std::uint32_t mesh, std::uint32_t prim) {
    const JsonRef p = doc_.root().member("meshes").element(mesh).member("primitives").element(prim);
    p.require_object();
    const std::uint64_t mode = p.integer("mode", 4, 0, std::numeric_limits<std::uint64_t>::max());
    if (mode <= 3)
      p.member("mode").fail("is " + std::to_string(mode) + " (" +
                            (mode == 0 ? "POINTS" : mode == 1 ? "LINES" : mode == 2 ? "LINE_LOOP" : "LINE_STRIP") +
                            "): a luminaire part must be made of triangles");
    if (mode > 6) p.member("mode").fail("is " + std::to_string(mode) + ", not a glTF primitive mode");
    const JsonRef attributes = p.member("attributes");
    attributes.require_object();
    const std::size_t accessors = doc_.count("accessors");
    const std::uint64_t max_v = options_.max_vertices;
    const std::uint64_t max_i = options_.max_triangles * 3 + 2;
    LocalPrimitive out;
    const bool draco = p.has("extensions") && p.member("extensions").has("KHR_draco_mesh_compression");
    if (draco) {
      // A Draco primitive's accessors still state its counts: they are checked against the limits before
      // Draco decodes (and allocates), and the decoded mesh must then have exactly those counts.
      const std::uint32_t position = attributes.index("POSITION", accessors, "accessors");
      const std::uint64_t declared_vertices = doc_.accessor_count(position);
      const std::string position_count = "/accessors/" + std::to_string(position) + "/count";
      if (declared_vertices > max_v)
        doc_.fail(position_count, "is " + std::to_string(declared_vertices) + ", more than GltfReadOptions::max_vertices (" +
                                      std::to_string(max_v) + "); the Draco payload is not decoded");
      std::optional<std::uint64_t> declared_indices;
      std::string indices_count;
      if (p.has("indices")) {
        const std::uint32_t ia = p.index("indices", accessors, "accessors");
        declared_indices = doc_.accessor_count(ia);
        indices_count = "/accessors/" + std::to_string(ia) + "/count";
        if (*declared_indices > max_i)
          doc_.fail(indices_count, "is " + std::to_string(*declared_indices) +
                                       ", more than 3 x GltfReadOptions::max_triangles + 2 (" + std::to_string(max_i) +
                                       "); the Draco payload is not decoded");
      }
      const JsonRef ext = p.member("extensions").member("KHR_draco_mesh_compression");
      out = doc_.decode_draco(ext, max_v, options_.max_triangles);
      if (out.positions.size() != declared_vertices)
        doc_.fail(position_count, "is " + std::to_string(declared_vertices) + ", but the Draco mesh has " +
                                      std::to_string(out.positions.size()) + " vertices");
      if (declared_indices && out.indices.size() != *declared_indices)
        doc_.fail(indices_count, "is " + std::to_string(*declared_indices) + ", but the Draco mesh has " +
                                     std::to_string(out.indices.size()) + " indices");
      if (mode != 4) p.member("mode").fail("a Draco-compressed primitive must be TRIANGLES");
    } else {
      out.positions = doc_.read_vec3(attributes.index("POSITION", accessors, "accessors"), max_v);
      if (attributes.has("NORMAL")) {
        out.normals = doc_.read_vec3(attributes.index("NORMAL", accessors, "accessors"), max_v);
        if (out.normals.size() != out.positions.size())
          attributes.member("NORMAL").fail("has " + std::to_string(out.normals.size()) + " normals for " +
                                           std::to_string(out.positions.size()) + " positions");
      }
      std::vector<std::uint32_t> list;
      if (p.has("indices")) {
        list = doc_.read_indices(p.index("indices", accessors, "accessors"), max_i);
        for (std::size_t i = 0; i < list.size(); ++i)
          if (list[i] >= out.positions.size())
            p.member("indices").fail("index " + std::to_string(i) + " is " + std::to_string(list[i]) +
                                     ", out of range: the primitive has " + std::to_string(out.positions.size()) +
                                     " vertices");
      } else {
        if (out.positions.size() > max_i) attributes.member("POSITION").fail("too many vertices");
        list.resize(out.positions.size());
        for (std::size_t i = 0; i < list.size(); ++i) list[i] = static_cast<std::uint32_t>(i);
      }
      const std::string count_pointer = p.has("indices") ? p.pointer + "/indices" : attributes.pointer + "/POSITION";
      if (mode == 4) {
        if (list.size() % 3 != 0)
          doc_.fail(count_pointer, std::to_string(list.size()) + " vertices do not make whole triangles");
        out.indices = std::move(list);
      } else {
        // TRIANGLE_STRIP (5) and TRIANGLE_FAN (6), as glTF 2.0 §3.7.2.1 orders their corners; triangles that
        // repeat a vertex (strip joints) are dropped.
        for (std::size_t i = 0; i + 2 < list.size(); ++i) {
          std::uint32_t a, b, c;
          if (mode == 5) {
            a = list[i], b = list[i + 1 + i % 2], c = list[i + 2 - i % 2];
          } else {
            a = list[i + 1], b = list[i + 2], c = list[0];
          }
          if (a == b || b == c || a == c) continue;
          out.indices.insert(out.indices.end(), {a, b, c});
        }
      }
    }
    return out;
  }

  void decode_placed_primitives(const std::vector<Placement>& placements) {
    const std::size_t meshes = doc_.count("meshes");
    std::set<std::uint32_t> decoded;
    std::uint64_t parts = 0, decoded_vertices = 0, decoded_triangles = 0;
    for (const Placement& pl : placements) {
      const JsonRef node = doc_.root().member("nodes").element(pl.node);
      if (!node.has("mesh")) continue;
      const std::uint32_t m = node.index("mesh", meshes, "meshes");
      const JsonRef prims = doc_.root().member("meshes").element(m).member("primitives");
      parts += prims.array_size();
      if (parts > options_.max_parts)
        node.member("mesh").fail("the scene would have more parts than GltfReadOptions::max_parts (" +
                                 std::to_string(options_.max_parts) + ")");
      if (!decoded.insert(m).second) continue;
      for (std::uint32_t k = 0; k < prims.array_size(); ++k) {
        LocalPrimitive lp = decode_primitive(m, k);
        // Decoded data counts against the scene's limits too: primitives may share one large accessor, so
        // memory would otherwise grow with the number of primitives rather than with the file.
        decoded_vertices += lp.positions.size();
        decoded_triangles += lp.indices.size() / 3;
        if (decoded_vertices > options_.max_vertices)
          prims.element(k).fail("decoding the meshes would hold more vertices than GltfReadOptions::max_vertices (" +
                                std::to_string(options_.max_vertices) + ")");
        if (decoded_triangles > options_.max_triangles)
          prims.element(k).fail("decoding the meshes would hold more triangles than GltfReadOptions::max_triangles (" +
                                std::to_string(options_.max_triangles) + ")");
        any_normals_ = any_normals_ || !lp.normals.empty();
        primitives_.emplace(std::make_pair(m, k), std::move(lp));
      }
    }
  }

  void place_node(const Placement& pl) {
    const JsonRef node = doc_.root().member("nodes").element(pl.node);
    const std::string node_name = node.string("name", "");
    if (node.has("mesh")) {
      const std::uint32_t m = node.index("mesh", doc_.count("meshes"), "meshes");
      const JsonRef mesh = doc_.root().member("meshes").element(m);
      const std::string mesh_name = mesh.string("name", "");
      const std::size_t prims = mesh.member("primitives").array_size();
      for (std::uint32_t k = 0; k < prims; ++k) {
        std::string name = !node_name.empty() ? node_name : !mesh_name.empty() ? mesh_name
                                                                               : "part " + std::to_string(scene_.parts.size());
        if (prims > 1) name += "[" + std::to_string(k) + "]";
        place_primitive(pl, m, k, name);
      }
    }
    place_lights(pl, node, !node_name.empty() ? node_name : "node " + std::to_string(pl.node));
  }

  void place_primitive(const Placement& pl, std::uint32_t mesh, std::uint32_t prim, const std::string& name) {
    const LocalPrimitive& lp = primitives_.at({mesh, prim});
    const JsonRef pj = doc_.root().member("meshes").element(mesh).member("primitives").element(prim);
    const std::string where = "/nodes/" + std::to_string(pl.node);
    const bool flat = any_normals_ && lp.normals.empty();
    const std::uint64_t new_vertices = flat ? lp.indices.size() : lp.positions.size();
    if (scene_.positions.size() + new_vertices > options_.max_vertices)
      doc_.fail(where, "the scene would have more vertices than GltfReadOptions::max_vertices (" +
                           std::to_string(options_.max_vertices) + ")");
    if (scene_.triangle_count() + lp.indices.size() / 3 > options_.max_triangles)
      doc_.fail(where, "the scene would have more triangles than GltfReadOptions::max_triangles (" +
                           std::to_string(options_.max_triangles) + ")");

    Part part;
    part.name = name;
    part.source = primitive_pointer(mesh, prim);
    part.material = pj.has("material") ? pj.index("material", doc_.count("materials"), "materials") : default_material();
    part.first_triangle = static_cast<std::uint32_t>(scene_.triangle_count());
    part.triangle_count = static_cast<std::uint32_t>(lp.indices.size() / 3);
    part.node = static_cast<std::int32_t>(pl.node);
    part.mesh = static_cast<std::int32_t>(mesh);
    part.primitive = static_cast<std::int32_t>(prim);

    const glm::dmat3 linear(pl.to_world);
    const double det = glm::determinant(linear);
    const glm::dmat3 normal_matrix = det != 0.0 ? glm::transpose(glm::inverse(linear)) : glm::dmat3(0.0);
    const bool flip = det < 0.0;
    auto world_position = [&](const glm::vec3& p) {
      const glm::dvec4 w = pl.to_world * glm::dvec4(glm::dvec3(p), 1.0);
      const glm::vec3 out(w);
      if (!std::isfinite(out.x) || !std::isfinite(out.y) || !std::isfinite(out.z))
        doc_.fail(where, "a vertex of " + part.source + " is not finite in world space");
      return out;
    };
    auto unit = [](const glm::dvec3& n) {
      const double len = glm::length(n);
      return len > 0.0 && std::isfinite(len) ? glm::vec3(n / len) : glm::vec3(0.0f);
    };
    const std::uint32_t base = static_cast<std::uint32_t>(scene_.positions.size());
    const std::uint32_t part_index = static_cast<std::uint32_t>(scene_.parts.size());
    if (!flat) {
      for (const glm::vec3& p : lp.positions) scene_.positions.push_back(world_position(p));
      if (any_normals_)
        for (const glm::vec3& n : lp.normals) scene_.normals.push_back(unit(normal_matrix * glm::dvec3(n)));
      for (std::size_t t = 0; t < lp.indices.size(); t += 3) {
        scene_.indices.push_back(base + lp.indices[t]);
        scene_.indices.push_back(base + lp.indices[t + (flip ? 2 : 1)]);
        scene_.indices.push_back(base + lp.indices[t + (flip ? 1 : 2)]);
        scene_.triangle_part.push_back(part_index);
      }
    } else {
      // No normals in a scene that has them: flat normals, one vertex per corner (glTF 2.0 §3.7.2.1).
      for (std::size_t t = 0; t < lp.indices.size(); t += 3) {
        const glm::vec3 a = world_position(lp.positions[lp.indices[t]]);
        const glm::vec3 b = world_position(lp.positions[lp.indices[t + (flip ? 2 : 1)]]);
        const glm::vec3 c = world_position(lp.positions[lp.indices[t + (flip ? 1 : 2)]]);
        const glm::vec3 n = unit(glm::cross(glm::dvec3(b) - glm::dvec3(a), glm::dvec3(c) - glm::dvec3(a)));
        const std::uint32_t v = static_cast<std::uint32_t>(scene_.positions.size());
        scene_.positions.insert(scene_.positions.end(), {a, b, c});
        scene_.normals.insert(scene_.normals.end(), {n, n, n});
        scene_.indices.insert(scene_.indices.end(), {v, v + 1, v + 2});
        scene_.triangle_part.push_back(part_index);
      }
    }
    scene_.parts.push_back(part);
    scene_.parts.back().closed = part_is_closed(scene_, scene_.parts.back());
  }

  void add_surface_emitters() {
    for (std::uint32_t i = 0; i < scene_.parts.size(); ++i) {
      const Part& part = scene_.parts[i];
      const Material& m = scene_.materials[part.material];
      if (!m.emissive_any()) continue;
      Emitter e;
      e.kind = EmitterKind::surface;
      e.name = part.name;
      e.source = std::int64_t(part.material) == default_material_ ? part.source
                                                                   : "/materials/" + std::to_string(part.material);
      e.part = i;
      scene_.emitters.push_back(e);
    }
  }

  Document doc_;
  const GltfReadOptions& options_;
  LuminaireScene scene_;
  std::int64_t default_material_ = -1;
  std::vector<PunctualLight> punctual_;
  std::map<std::uint32_t, std::shared_ptr<const Photometry>> ies_profiles_;
  std::map<std::pair<std::uint32_t, std::uint32_t>, LocalPrimitive> primitives_;
  bool any_normals_ = false;
};

}  // namespace

LuminaireScene read_gltf_luminaire(const std::string& path, const GltfReadOptions& options) {
  return SceneBuilder(path, options).build();
}

}  // namespace bake
LUMX_NAMESPACE_END
