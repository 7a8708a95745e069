// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/render/room_render.h — what `lumx render room` computes from a RoomIlluminance: illuminance maps on
// the room's texels, a camera picture of luminance, and the error of one method against another (part of
// lumx::bake).
//
// Luminance of a diffuse surface of reflectance ρ under illuminance E is L = ρ E / π (cd/m², lx); a pixel
// shows the surface point its centre's eye ray hits first.
//
// Relative RMSE of a method's maps E against the reference's E_ref, over the texels t of every surface,
// weighted by texel area A_t (so every square metre of the room counts the same):
//   ε = sqrt( Σ_t A_t (E_t − E_ref,t)² / Σ_t A_t E_ref,t² ).
// The reference's own noise on the same scale, from its two independent halves (E_a, E_b; each of twice
// the variance of the whole): ε_ref = sqrt( Σ_t A_t (E_a,t − E_b,t)² / 4 / Σ_t A_t E_ref,t² ). A method whose
// ε is near ε_ref is as close to the truth as the reference can tell.
#pragma once

#include <lumx/render/camera.h>
#include <lumx/render/image.h>
#include <lumx/render/room_illuminance.h>

#include <vector>

LUMX_NAMESPACE_BEGIN
namespace render {

/// Per surface, texel values row-major ([iv · texels_u + iu]), lx.
using SurfaceMaps = std::vector<std::vector<double>>;

/// E at every texel centre of every surface (key = the texel's running index over all surfaces).
SurfaceMaps illuminance_maps(const RoomScene& scene, const RoomIlluminance& method, int threads = 0);

/// The camera's picture: channel "Y" = luminance ρE/π (cd/m²), "E" = illuminance (lx), "surface" = the
/// index of the surface seen (−1: none). One ray through each pixel's centre; key = the pixel index
/// offset past the texels (so keys never repeat between maps and pictures).
Image render_room_view(const RoomScene& scene, const PinholeCamera& camera, const RoomIlluminance& method,
                       int threads = 0);

/// ε above; 0 when the reference is zero everywhere. The maps must have the scene's texel counts.
double relative_rmse(const RoomScene& scene, const SurfaceMaps& maps, const SurfaceMaps& reference);
/// ε_ref above.
double half_noise(const RoomScene& scene, const SurfaceMaps& half_a, const SurfaceMaps& half_b,
                  const SurfaceMaps& reference);

}  // namespace render
LUMX_NAMESPACE_END
