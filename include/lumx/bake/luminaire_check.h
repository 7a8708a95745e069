// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/luminaire_check.h — what is wrong or doubtful in a luminaire scene before it is traced: bad
// triangles, open meshes used as refracting volumes, emitters that emit nothing. Findings are located by the
// JSON pointer of the part, material or light they concern (Diagnostic::field), as the glTF reader set them.
#pragma once

#include <lumx/bake/luminaire.h>

#include <cstddef>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace bake {

/// Edge statistics of one part after welding exactly equal positions.
struct PartTopology {
  std::size_t edges = 0;               ///< distinct welded edges
  std::size_t boundary_edges = 0;      ///< used by one triangle
  std::size_t non_manifold_edges = 0;  ///< used by three or more triangles
  std::size_t degenerate_triangles = 0;  ///< two corners weld together (skipped from the edge count)
  /// Every edge is used by exactly two triangles (and the part has triangles).
  bool closed() const { return edges > 0 && boundary_edges == 0 && non_manifold_edges == 0; }
};

PartTopology part_topology(const LuminaireScene& scene, const Part& part);
inline bool part_is_closed(const LuminaireScene& scene, const Part& part) {
  return part_topology(scene, part).closed();
}

/// Findings, each with severity, `file` = scene.name and a JSON pointer in `field`:
///   error   — triangles with a non-finite corner; a volume material (KHR_materials_volume) on a part that
///             is not closed; an emitter whose flux is zero or cannot be computed; no emitter at all;
///             an index out of range or a part outside the triangle list (scenes built in code).
///   warning — zero-area triangles (count and the first few indices); a double-sided emissive part that is
///             closed (half of its flux goes inside); a part without triangles.
///   note    — a single-sided emissive part that is open (it emits from its front faces only).
std::vector<Diagnostic> check_luminaire(const LuminaireScene& scene);

}  // namespace bake
LUMX_NAMESPACE_END
