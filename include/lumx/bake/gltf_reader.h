// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/gltf_reader.h — luminaires from glTF 2.0 files (.gltf with external buffers or data URIs, .glb;
// meshes compressed with KHR_draco_mesh_compression). docs/luminaires.md describes the whole mapping.
//
// What is read
//   * The default scene (`scene`), else scene 0, else every root node. Node matrices and TRS are composed
//     into world space; the scene keeps glTF's axes (+Y up) and units (metres). Normals are transformed by
//     the inverse transpose and renormalised; a node with a negative determinant flips the winding so that
//     counter-clockwise stays the front. A node may be reached once only (no cycles, one parent).
//   * Mesh primitives of mode TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN (strips and fans are converted to
//     triangles); POINTS and LINES are an error. POSITION is required; NORMAL is optional: when no primitive
//     has normals the scene has none (flat shading), otherwise a primitive without them gets flat normals
//     (its vertices are unshared), as glTF asks. Float attributes, and the integer encodings of
//     KHR_mesh_quantization (normalised or not), are accepted; sparse accessors are not.
//   * Materials exactly as glTF and KHR_materials_{ior,specular,transmission,diffuse_transmission,volume,
//     emissive_strength} define them, with their defaults. Textures are ignored (a warning names each one);
//     the factors are used alone. A primitive without a material gets glTF's default material, appended
//     after the file's materials under the name "glTF default".
//   * Emitters: every part whose material has emissive luminance > 0 (surface); KHR_lights_punctual point
//     and spot lights (intensity in cd × colour; directional lights are ignored with a warning);
//     EXT_lights_ies; and LUMX_lights_rayset (below).
//
// EXT_lights_ies orientation (the extension's "Coordinate System Mapping"): the profile's photometric zero
// (vertical and horizontal angle 0, Type C nadir) points along the node's −Z, the X/Z plane is the vertical
// photometric plane of horizontal angle 0 (C0) and the X/Y plane is the horizontal photometric plane. In
// lumx's photometric frame (lumx/photometry/photometry.h: +X = C0, +Y = C90, −Z = nadir) that is the
// identity: a direction d in the profile's frame is to_world × d in the world, with Emitter::to_world the
// node's world matrix (its scale does not change the intensity: use directions normalised). The profile is
// read with lumx::read_ies (uri relative to the glTF file, a data URI, or a bufferView); `multiplier`
// (≥ 0, default 1) and `color` (clamped to [0, 1], default white) come from the node.
//
// LUMX_lights_rayset (defined by lumx): a node extension placing a ray file, read later by the tracer with
// lumx::open_rayset, in the node's frame:
//     "nodes": [{ "extensions": { "LUMX_lights_rayset": { "uri": "led.tm25ray", "color": [1, 1, 1] } } }]
// `uri` (required) is a relative path resolved against the glTF file's folder (or an absolute path; data
// URIs are not accepted); the file must exist and its header must read. `color` (≥ 0 per channel, default
// white) multiplies each ray's flux. Ray positions and directions are transformed by Emitter::to_world.
//
// Extensions: one listed in `extensionsRequired` that lumx does not implement is an error; one only in
// `extensionsUsed` is a warning. Implemented: KHR_draco_mesh_compression, KHR_mesh_quantization,
// KHR_lights_punctual, EXT_lights_ies, LUMX_lights_rayset, the six KHR_materials_* above, and
// KHR_texture_transform (ignored with the textures).
//
// Errors: every problem is a lumx::Error naming the file and either a byte offset (GLB container, JSON
// syntax) or a JSON pointer in Diagnostic::field ("/accessors/3/count"). Accessors, buffer views and
// buffers are checked against each other and against the data actually present before anything is
// allocated or read; indices are checked against the vertex count; positions, normals and transforms must
// be finite. Sizes are bounded by GltfReadOptions.
#pragma once

#include <lumx/bake/luminaire.h>

#include <cstdint>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace bake {

struct GltfReadOptions {
  DiagnosticSink warnings;  ///< what is ignored (textures, extensionsUsed only, ...); may be empty
  /// Largest .gltf/.glb file and largest external buffer file, bytes (2 GiB).
  std::uint64_t max_file_bytes = std::uint64_t(2) << 30;
  /// Largest sum of all buffers loaded (decoded data URIs, external files, the GLB BIN chunk), bytes.
  std::uint64_t max_buffer_bytes = std::uint64_t(4) << 30;
  std::uint64_t max_triangles = 50'000'000;  ///< over the whole scene, after instancing by nodes
  std::uint64_t max_vertices = 100'000'000;  ///< over the whole scene, after instancing by nodes
  std::uint64_t max_nodes_placed = 1'000'000;  ///< node visits while walking the scene
  std::uint64_t max_parts = 1'000'000;         ///< primitives placed by nodes, over the whole scene
  /// Files a .gltf names (buffers, IES profiles, ray files) must lie in its folder or below: an absolute
  /// path, '..' or a symbolic link out of the folder is an error. True also follows those (trusted input).
  bool allow_files_outside_folder = false;
};

/// Reads a luminaire. Throws lumx::Error with a located diagnostic (file, byte offset or JSON pointer).
/// Warnings go to `options.warnings` and are also kept in LuminaireScene::warnings.
LuminaireScene read_gltf_luminaire(const std::string& path, const GltfReadOptions& options = {});

}  // namespace bake
LUMX_NAMESPACE_END
