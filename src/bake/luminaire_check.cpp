// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Findings about a luminaire scene (lumx/bake/luminaire_check.h): triangle validity, closedness of the parts
// used as volumes, and emitters.
#include <lumx/bake/luminaire_check.h>

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <unordered_map>

LUMX_NAMESPACE_BEGIN
namespace bake {
namespace {

/// Hash key of a position compared exactly (−0 and +0 are the same point).
struct PositionKey {
  float x, y, z;
  bool operator==(const PositionKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct PositionHash {
  std::size_t operator()(const PositionKey& k) const {
    auto bits = [](float f) {
      if (f == 0.0f) f = 0.0f;
      std::uint32_t u;
      std::memcpy(&u, &f, 4);
      return static_cast<std::size_t>(u);
    };
    std::size_t h = bits(k.x);
    h = h * 0x9E3779B97F4A7C15ull + bits(k.y);
    h = h * 0x9E3779B97F4A7C15ull + bits(k.z);
    return h ^ (h >> 29);
  }
};

bool finite(const glm::vec3& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

Diagnostic finding(const LuminaireScene& scene, Severity s, std::string field, std::string message) {
  Diagnostic d;
  d.severity = s;
  d.file = scene.name;
  d.field = std::move(field);
  d.message = std::move(message);
  return d;
}

/// "3 (0, 17, 42, ...)": a count and the first few triangle indices within the part.
std::string count_and_first(const std::vector<std::uint32_t>& list, std::size_t count) {
  std::string s = std::to_string(count) + " (triangle";
  s += count == 1 ? " " : "s ";
  for (std::size_t i = 0; i < list.size(); ++i) s += (i ? ", " : "") + std::to_string(list[i]);
  if (count > list.size()) s += ", ...";
  return s + " of the part)";
}

bool triangle_in_range(const LuminaireScene& scene, std::size_t t) {
  for (int k = 0; k < 3; ++k)
    if (scene.indices[3 * t + k] >= scene.positions.size()) return false;
  return true;
}

}  // namespace

PartTopology part_topology(const LuminaireScene& scene, const Part& part) {
  PartTopology topo;
  std::unordered_map<PositionKey, std::uint32_t, PositionHash> weld;
  std::unordered_map<std::uint64_t, std::uint32_t> edge_use;
  const std::size_t end = std::min<std::size_t>(std::size_t(part.first_triangle) + part.triangle_count,
                                                scene.triangle_count());
  weld.reserve(std::size_t(part.triangle_count) * 2);
  edge_use.reserve(std::size_t(part.triangle_count) * 2);
  for (std::size_t t = part.first_triangle; t < end; ++t) {
    if (!triangle_in_range(scene, t)) continue;
    std::uint32_t id[3];
    for (int k = 0; k < 3; ++k) {
      const glm::vec3& p = scene.positions[scene.indices[3 * t + k]];
      id[k] = weld.emplace(PositionKey{p.x, p.y, p.z}, static_cast<std::uint32_t>(weld.size())).first->second;
    }
    if (id[0] == id[1] || id[1] == id[2] || id[0] == id[2]) {
      ++topo.degenerate_triangles;
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = id[k], b = id[(k + 1) % 3];
      ++edge_use[a < b ? (a << 32 | b) : (b << 32 | a)];
    }
  }
  topo.edges = edge_use.size();
  for (const auto& [edge, uses] : edge_use) {
    if (uses == 1) ++topo.boundary_edges;
    if (uses >= 3) ++topo.non_manifold_edges;
  }
  return topo;
}

std::vector<Diagnostic> check_luminaire(const LuminaireScene& scene) {
  std::vector<Diagnostic> out;
  constexpr std::size_t kListed = 5;
  if (scene.indices.size() % 3 != 0 || scene.triangle_part.size() != scene.triangle_count())
    out.push_back(finding(scene, Severity::error, "", "the triangle list is inconsistent (indices not in threes, or "
                                                      "one part per triangle missing)"));

  for (std::size_t pi = 0; pi < scene.parts.size(); ++pi) {
    const Part& part = scene.parts[pi];
    const std::string where = part.source.empty() ? "part " + std::to_string(pi) : part.source;
    if (std::size_t(part.first_triangle) + part.triangle_count > scene.triangle_count()) {
      out.push_back(finding(scene, Severity::error, where, "part '" + part.name + "' lies outside the triangle list"));
      continue;
    }
    if (part.material >= scene.materials.size()) {
      out.push_back(finding(scene, Severity::error, where, "part '" + part.name + "' has no material " +
                                                               std::to_string(part.material)));
      continue;
    }
    if (part.triangle_count == 0) {
      out.push_back(finding(scene, Severity::warning, where, "part '" + part.name + "' has no triangles"));
      continue;
    }
    std::vector<std::uint32_t> bad_index, non_finite, zero_area;
    std::size_t n_bad_index = 0, n_non_finite = 0, n_zero_area = 0;
    for (std::uint32_t i = 0; i < part.triangle_count; ++i) {
      const std::size_t t = std::size_t(part.first_triangle) + i;
      if (!triangle_in_range(scene, t)) {
        if (n_bad_index++ < kListed) bad_index.push_back(i);
        continue;
      }
      bool ok = true;
      for (int k = 0; k < 3; ++k) ok = ok && finite(scene.positions[scene.indices[3 * t + k]]);
      if (!ok) {
        if (n_non_finite++ < kListed) non_finite.push_back(i);
        continue;
      }
      if (!(triangle_area(scene, t) > 0.0)) {
        if (n_zero_area++ < kListed) zero_area.push_back(i);
      }
    }
    if (n_bad_index)
      out.push_back(finding(scene, Severity::error, where, "part '" + part.name + "': vertex index out of range in " +
                                                               count_and_first(bad_index, n_bad_index)));
    if (n_non_finite)
      out.push_back(finding(scene, Severity::error, where, "part '" + part.name + "': non-finite (NaN or infinite) "
                                                               "corner in " + count_and_first(non_finite, n_non_finite)));
    if (n_zero_area)
      out.push_back(finding(scene, Severity::warning, where, "part '" + part.name + "': zero-area (degenerate) " +
                                                                 count_and_first(zero_area, n_zero_area)));

    const Material& m = scene.materials[part.material];
    const bool needs_topology = m.volume || m.emissive_any();
    if (!needs_topology) continue;
    const PartTopology topo = part_topology(scene, part);
    if (m.volume && !topo.closed())
      out.push_back(finding(scene, Severity::error, where,
                            "part '" + part.name + "' uses the volume material '" + m.name +
                                "' (KHR_materials_volume) but is not closed: " + std::to_string(topo.boundary_edges) +
                                " boundary edge(s), " + std::to_string(topo.non_manifold_edges) +
                                " edge(s) shared by more than two triangles after welding equal positions"));
    if (m.emissive_any() && m.double_sided && topo.closed())
      out.push_back(finding(scene, Severity::warning, where,
                            "emissive part '" + part.name + "' is double-sided and closed: half of its flux is "
                            "emitted into its inside"));
    if (m.emissive_any() && !m.double_sided && !topo.closed())
      out.push_back(finding(scene, Severity::note, where,
                            "emissive part '" + part.name + "' is open and single-sided: it emits from the front "
                            "(counter-clockwise) faces only"));
  }

  if (scene.emitters.empty())
    out.push_back(finding(scene, Severity::error, "", "no emitter: no emissive material, light or ray file"));
  for (std::size_t ei = 0; ei < scene.emitters.size(); ++ei) {
    const Emitter& e = scene.emitters[ei];
    const std::string where = e.source.empty() ? "emitter " + std::to_string(ei) : e.source;
    try {
      const double flux = emitter_flux_lm(scene, e);
      if (!std::isfinite(flux))
        out.push_back(finding(scene, Severity::error, where, std::string(to_string(e.kind)) + " emitter '" + e.name +
                                                                 "' has a non-finite flux"));
      else if (!(flux > 0.0))
        out.push_back(finding(scene, Severity::error, where,
                              std::string(to_string(e.kind)) + " emitter '" + e.name + "' emits no flux (0 lm)"));
    } catch (const Error& err) {
      out.push_back(finding(scene, Severity::error, where,
                            std::string(to_string(e.kind)) + " emitter '" + e.name + "': " + err.what()));
    }
    // Spots, IES profiles and ray files take their directions from the node's frame: it must have one.
    if (e.kind == EmitterKind::spot || e.kind == EmitterKind::ies || e.kind == EmitterKind::rayset) {
      const glm::dmat3 linear(e.to_world);
      const double scale = glm::length(linear[0]) * glm::length(linear[1]) * glm::length(linear[2]);
      const double det = glm::determinant(linear);
      if (!std::isfinite(det) || !(std::abs(det) > 1e-12 * scale) || !(scale > 0.0))
        out.push_back(finding(scene, Severity::error, where,
                              std::string(to_string(e.kind)) + " emitter '" + e.name +
                                  "': its node's transform is singular (a zero scale), so it has no direction"));
    }
  }
  return out;
}

}  // namespace bake
LUMX_NAMESPACE_END
