// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/gltf_writer.h — a LuminaireScene written as glTF 2.0 (.glb, or .gltf with the buffer as a data URI),
// so luminaires generated in code (samples, tests) are files every glTF tool opens and read_gltf_luminaire reads
// back: one mesh and node per part (positions already in world space, metres; normals when the scene has them),
// materials with the KHR_materials_{ior,specular,transmission,diffuse_transmission,volume,emissive_strength}
// extensions where they differ from glTF's defaults, point and spot emitters as KHR_lights_punctual on nodes
// placed by their transform, IES emitters as EXT_lights_ies with the profile embedded (bufferView, LM-63-2019
// text). Rayset emitters are refused (their file lives outside the glTF). Meshes may be Draco-compressed.
// Written atomically.
#pragma once

#include <lumx/bake/luminaire.h>

#include <string>

LUMX_NAMESPACE_BEGIN
namespace bake {

struct GltfWriteOptions {
  bool binary = true;  ///< .glb (one BIN chunk); false: .gltf JSON with the buffer as a base64 data URI
  std::string generator = "lumx";  ///< asset.generator
  /// Compress every mesh with KHR_draco_mesh_compression (required by the file then): positions quantised
  /// to `draco_position_bits` over each mesh's box, normals to `draco_normal_bits` (glTF-Transform's
  /// defaults, 14 and 10: 0.06 mm steps over a 1 m box).
  bool draco = false;
  int draco_position_bits = 14;
  int draco_normal_bits = 10;
};

/// Throws lumx::Error (naming the path and the part or emitter) for what glTF cannot hold.
void write_gltf_luminaire(const LuminaireScene& scene, const std::string& path, const GltfWriteOptions& options = {});

}  // namespace bake
LUMX_NAMESPACE_END
