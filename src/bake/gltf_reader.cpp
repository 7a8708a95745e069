// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Placeholder: replaced by the tinygltf-based reader.
#include <lumx/bake/gltf_reader.h>

LUMX_NAMESPACE_BEGIN
namespace bake {

LuminaireScene read_gltf_luminaire(const std::string& path, const GltfReadOptions&) {
  throw_at_field(path, "", "glTF reading is not available in this build");
}

}  // namespace bake
LUMX_NAMESPACE_END
