// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/bake/luminaire.h — a luminaire as the tracer sees it: world-space triangles grouped in parts, each part
// with one material, and the emitters, all in metres and photometric units. No I/O here: lumx/bake/gltf_reader.h
// fills one from glTF 2.0, and tests and generators build them in code.
#pragma once

#include <lumx/bake/material.h>
#include <lumx/core/diagnostic.h>
#include <lumx/photometry/photometry.h>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace bake {

/// One mesh primitive placed by one node: a run of the scene's triangles sharing a material.
struct Part {
  std::string name;                  ///< node name (or mesh name, or "part N")
  std::string source;                ///< where it came from, as a JSON pointer: "/meshes/1/primitives/0"
  std::uint32_t material = 0;        ///< index into LuminaireScene::materials
  std::uint32_t first_triangle = 0;  ///< triangles [first_triangle, first_triangle + triangle_count)
  std::uint32_t triangle_count = 0;
  std::int32_t node = -1;       ///< glTF node index that placed it (-1: not from glTF)
  std::int32_t mesh = -1;       ///< glTF mesh index (-1: not from glTF)
  std::int32_t primitive = -1;  ///< primitive index within the mesh (-1: not from glTF)
  /// Every edge is shared by exactly two of the part's triangles once equal positions are welded (a closed
  /// surface, as a refracting volume needs). Set by the glTF reader with part_is_closed()
  /// (lumx/bake/luminaire_check.h); false for parts built in code unless they set it.
  bool closed = false;
};

enum class EmitterKind {
  surface,  ///< a part whose material is emissive: Lambertian, luminance from the material
  point,    ///< KHR_lights_punctual point: isotropic intensity
  spot,     ///< KHR_lights_punctual spot: along the node's −z, the extension's smooth cone falloff
  ies,      ///< EXT_lights_ies: an LM-63 profile placed by the node
  rayset,   ///< rays from a ray file (TM-25 or any lumx reads) placed by the node
};
const char* to_string(EmitterKind k);

struct Emitter {
  EmitterKind kind = EmitterKind::point;
  std::string name;
  std::string source;         ///< JSON pointer of its definition ("/materials/2", "/extensions/.../lights/0")
  std::uint32_t part = 0;     ///< surface: the emitting part (its material gives luminance and sides)
  /// Node-to-world transform (metres) for point, spot, ies and rayset emitters: position = column 3;
  /// a spot shines along −z of this frame; an IES profile's photometric frame is this frame as
  /// EXT_lights_ies defines it (see gltf_reader.h); rays are transformed by it.
  glm::dmat4 to_world{1.0};
  Rgb intensity_cd{0.0};      ///< point, spot: colour × intensity, cd per channel (at the axis for a spot)
  double inner_cone_rad = 0.0;   ///< spot: full intensity inside this half-angle
  double outer_cone_rad = 0.7853981633974483;  ///< spot: zero outside this half-angle
  Rgb color{1.0};             ///< ies, rayset: colour multiplier per channel
  double multiplier = 1.0;    ///< ies: EXT_lights_ies multiplier applied to the profile's candela
  std::shared_ptr<const Photometry> photometry;  ///< ies: the profile (absolute candela; TILT data not applied)
  std::string rayset_path;    ///< rayset: resolved path of the ray file
};

struct LuminaireScene {
  std::string name;                        ///< file name or generator name
  std::vector<glm::vec3> positions;        ///< world, m
  std::vector<glm::vec3> normals;          ///< per vertex shading normals, world; empty = flat shading
  std::vector<std::uint32_t> indices;      ///< 3 per triangle, counter-clockwise = front
  std::vector<std::uint32_t> triangle_part;  ///< part of each triangle
  std::vector<Part> parts;
  std::vector<Material> materials;
  std::vector<Emitter> emitters;           ///< every emissive part is one surface emitter here too
  std::vector<Diagnostic> warnings;        ///< what the reader ignored (textures, extensionsUsed, ...)

  std::size_t triangle_count() const { return indices.size() / 3; }
};

/// Area of triangle t, m².
double triangle_area(const LuminaireScene& scene, std::size_t t);

/// Flux an emitter emits, lm (luminance of each quantity): surface π L A (×2 when double-sided), point
/// 4π I, spot 2π ∫ I(θ) sin θ dθ of the cone falloff, ies the profile's flux × multiplier × Y(color),
/// rayset the file's total flux × Y(color). Per channel in emitter_flux_rgb().
double emitter_flux_lm(const LuminaireScene& scene, const Emitter& e);
Rgb emitter_flux_rgb(const LuminaireScene& scene, const Emitter& e);

/// KHR_lights_punctual's spot attenuation: smooth ramp in cos θ between the outer and inner cone, squared
/// as the extension's reference implementation does. θ is the angle from the spot axis.
double spot_falloff(double cos_theta, double inner_cone_rad, double outer_cone_rad);

}  // namespace bake
LUMX_NAMESPACE_END
