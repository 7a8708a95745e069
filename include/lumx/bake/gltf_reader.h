// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/gltf_reader.h — luminaires from glTF 2.0 files (.gltf with buffers, .glb, data URIs; Draco).
#pragma once

#include <lumx/bake/luminaire.h>

#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace bake {

struct GltfReadOptions {
  DiagnosticSink warnings;  ///< what is ignored (textures, extensionsUsed only, ...); may be empty
};

/// Reads a luminaire. Throws lumx::Error with a located diagnostic (file, byte offset or JSON pointer).
LuminaireScene read_gltf_luminaire(const std::string& path, const GltfReadOptions& options = {});

}  // namespace bake
LUMX_NAMESPACE_END
