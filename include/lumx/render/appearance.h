// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/render/appearance.h — the luminaire as a camera sees it (dissertation 000 §4.5, Figure 4.6): eye rays
// traced through its glass and metal up to n_b scattering events ("sparkles"), then the radiance volume's
// low-frequency "glow"; and a path-traced reference of the same view.
//
// Quantity and units. Every image is luminance per channel in cd/m² (linear Rec. 709 RGB whose
// bake::luminance() is cd/m²), the unit of glTF's emissive × strength (lumx/bake/material.h), of the
// radiance volume (flux in lm per particle, lengths in m: lm/(m² sr) = cd/m²) and of the background.
//
// Transport. Radiance is gathered backwards along the eye ray with the tracer's BSDFs (lumx/bake/bsdf.h) in
// TransportMode::radiance: the throughput is multiplied by the sample weight f(wo, wi) |wi·ns| / pdf with
// the shading normal's cosine and no adjoint correction (Veach 1997 §5.3: the shading-normal factor
// |wo·ns||wi·ng| / (|wo·ng||wi·ns|) belongs to particle transport only). The radiance carried is the true
// radiance of the medium the ray is in: crossing into glass of index η scales it by 1/η² and leaving
// glass by η² (Veach 1997 §5.2, carried by the BSDF's radiance mode), so an emitter seen through a slab
// keeps its luminance up to the two Fresnel transmittances. Inside a closed solid (Material::volume)
// Beer–Lambert absorption exp(−σ t) is applied per segment. The eye is assumed to be outside every solid.
//
// What a path sees, with n = the scattering events so far:
//   - a miss: background(origin, direction), the room around the luminaire (cd/m²);
//   - an emissive surface (its front, or either side when double-sided): its emitted luminance. Surface
//     emitters are also sampled directly at every non-specular vertex (next-event estimation, an area
//     sample ∝ luminance × area and a shadow ray), combined with the hits by the power heuristic (Veach
//     1997 §9.2). Shadow rays stop at any surface, glass included: light reaching a vertex only through
//     specular glass is found by BSDF sampling alone;
//   - punctual, spot and IES emitters have no area: no eye ray hits them (they are invisible themselves);
//     they light every non-specular vertex in sight through next-event estimation (E = I(ω)/r²), in both
//     the depth-limited images and the reference, and reach the glow through the bake's particles. Their
//     light that reaches a surface only through another one (a point light inside a glass bulb) is found by
//     neither strategy: the reference misses it, the depth-limited images have it through the glow only.
//     Rayset emitters are neither hit nor sampled: they appear through the glow only;
//   - depth-limited rendering (AppearanceOptions::depth = n_b ≥ 0): at the vertex reached after n_b
//     scattering events the path ends; a non-emissive surface returns the glow, the radiance volume's
//     radiance along the direction toward the eye (propagation direction −d, lumx/volume/radiance_volume.h),
//     looked up at the hit point moved back along the last segment by min(half of it, one voxel) when that
//     segment started on the luminaire (radiance is constant along it; the volume holds no exits, so voxels
//     straddling an outer wall are part empty); an emissive surface returns its emission only. n_b = 0
//     therefore shows the emitters and the glow at the first hit; no volume = black glow;
//   - the reference (depth = kReferenceDepth): Russian roulette from `roulette_depth` events on
//     (survival = max channel of the throughput, capped at 1, survivors divided by it), a hard cap at
//     `reference_max_depth` (counted), no glow.
// The expected depth-limited image converges to the reference's as n_b grows: both sum the same paths,
// the depth-limited one replacing those longer than n_b by the glow.
//
// Determinism. Sample s of pixel p draws from a PCG32 stream chosen by (seed, p, s) alone (bake/random.h);
// pixels are independent; the image is bit-identical for any thread count and any split into passes.
// Even and odd samples are also accumulated apart (first_half, second_half): two independent estimates
// whose difference measures the image's Monte Carlo noise.
#pragma once

#include <lumx/bake/luminaire.h>
#include <lumx/math/aabb.h>
#include <lumx/render/camera.h>
#include <lumx/render/image.h>
#include <lumx/volume/radiance_volume.h>

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <memory>

LUMX_NAMESPACE_BEGIN
namespace render {

/// Luminance (cd/m² per channel) seen along a ray that leaves the luminaire at `origin` in unit `direction`.
using BackgroundLuminance = std::function<glm::dvec3(const glm::dvec3& origin, const glm::dvec3& direction)>;

/// AppearanceOptions::depth of the path-traced reference.
constexpr int kReferenceDepth = -1;

struct AppearanceOptions {
  int depth = 4;                  ///< n_b ≥ 0: scattering events before the glow; kReferenceDepth: reference
  int samples_per_pixel = 16;     ///< ≥ 1
  std::uint64_t seed = 1;
  int threads = 0;                ///< 0 = every hardware thread; the image does not depend on it
  bool glow = true;               ///< look the radiance volume up at n_b (when the renderer has one)
  int roulette_depth = 5;         ///< reference: Russian roulette from this many scattering events on
  int reference_max_depth = 256;  ///< reference: paths still alive here are dropped (counted)
  /// Stop after the pass (of `pass_samples` samples per pixel) that crosses this many seconds (0 = none);
  /// the image then holds fewer samples (AppearanceImage::samples_per_pixel), each pass complete.
  double time_limit_seconds = 0;
  int pass_samples = 4;
  /// Called after every pass with the fraction of samples done (from the calling thread).
  std::function<void(double fraction)> progress;
};

struct AppearanceImage {
  Image image;        ///< mean of every sample, channels R G B, cd/m²
  Image first_half;   ///< mean of the even samples (independent of second_half)
  Image second_half;  ///< mean of the odd samples
  int samples_per_pixel = 0;
  double seconds = 0;                 ///< wall-clock rendering time
  std::uint64_t rays = 0;             ///< rays cast (eye, scattered and shadow rays)
  std::uint64_t depth_capped = 0;     ///< reference paths dropped at reference_max_depth
};

class AppearanceRenderer {
 public:
  /// Builds an Embree scene over `scene` (kept by reference: it must outlive the renderer). `volume` may be
  /// null (black glow); it is kept by reference too. An empty `background` is black. Throws lumx::Error
  /// when the scene has no triangles.
  AppearanceRenderer(const bake::LuminaireScene& scene, const RadianceVolume* volume, BackgroundLuminance background);
  ~AppearanceRenderer();
  AppearanceRenderer(const AppearanceRenderer&) = delete;
  AppearanceRenderer& operator=(const AppearanceRenderer&) = delete;

  /// Renders the view of `camera`. Throws lumx::Error for an invalid camera or options.
  AppearanceImage render(const PinholeCamera& camera, const AppearanceOptions& options) const;

  /// One channel "mask": 1 where the eye ray through the pixel centre hits the luminaire, else 0.
  Image luminaire_mask(const PinholeCamera& camera) const;

  /// The luminaire's triangles' bounding box, m.
  Aabb bounds() const;
  bool has_volume() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace render
LUMX_NAMESPACE_END
