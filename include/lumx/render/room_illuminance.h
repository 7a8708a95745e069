// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/render/room_illuminance.h — direct illuminance (lx) on the room's surfaces from a luminaire, by each
// representation `lumx render room` compares (000 §5.2; part of lumx::bake):
//
//  * an APL level (000 §4.5): E(x, n) = Σ_i I_i(ω_i) max(0, −n·ω_i) / r_i² · V_i(x), the visibility V_i an
//    Embree shadow ray from APL i to x against the room's occluders (lumx/apl/evaluation.h);
//  * level of detail: per point, the level the distance rule of 000 §6.1 (eq. 6.2, lumx/apl/lod.h) picks
//    at x's relative distance, the stochastic choice drawn from (seed, point key) so it is the same for
//    any thread count;
//  * the far field: one point at the bundle's frame origin with the bundle's far-field IES attachment
//    (apl_set_from_photometry), shadowed the same way — what legacy tools do;
//  * the reference: particles traced from the real emitters through the luminaire's geometry
//    (bake::Tracer), each exit continued in a straight line to the first room surface or occluder it hits,
//    its flux deposited there at (u, v); per surface, illuminance is the deposits' flux per area
//    reconstructed by adaptive-kernel density estimation (lumx/render/adaptive_kernel_density.h).
//
// Direct light only: no inter-reflection between room surfaces, as the dissertation's comparison.
#pragma once

#include <lumx/apl/apl_set.h>
#include <lumx/bake/luminaire.h>
#include <lumx/bake/tracer.h>
#include <lumx/model/light_model.h>
#include <lumx/render/adaptive_kernel_density.h>
#include <lumx/render/room_scene.h>

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN
class BundleReader;
namespace render {

/// Illuminance at a point of one of the room's surfaces.
class RoomIlluminance {
 public:
  virtual ~RoomIlluminance() = default;
  /// E (lx) at the point (u, v) of surface `surface` (world point x, the surface's normal n). `key`
  /// identifies the query (texel or pixel) for methods that draw random numbers.
  virtual double at(int surface, const glm::dvec3& x, const glm::dvec3& n, double u, double v,
                    std::uint64_t key) const = 0;
};

/// Direct illuminance from the APLs of a set placed at `offset` (the bundle's frame origin in the room).
class AplRoomIlluminance : public RoomIlluminance {
 public:
  /// level ≥ 0: that level of `set`; kLevelOfDetail: per point by distance (000 eq. 6.2). `shadows`:
  /// shadow rays against the scene (the room's walls never occlude: it is convex and the luminaire inside).
  static constexpr int kLevelOfDetail = -1;
  AplRoomIlluminance(const AplSet& set, int level, const glm::dvec3& offset, const RoomScene& scene,
                     std::uint64_t seed = 1, bool shadows = true);
  double at(int surface, const glm::dvec3& x, const glm::dvec3& n, double u, double v,
            std::uint64_t key) const override;

 private:
  const AplSet& set_;
  int level_;
  glm::dvec3 offset_;
  const RoomScene& scene_;
  std::uint64_t seed_;
  bool shadows_;
  bool any_occluder_;
};

/// Direct illuminance from any representation (model/light_model.h) placed at `offset`: its
/// irradiance(), with the room's shadow rays as its Visibility when `shadows`.
class ModelRoomIlluminance : public RoomIlluminance {
 public:
  /// Throws std::invalid_argument for a radiometric model (illuminance needs cd).
  ModelRoomIlluminance(const LightModel& model, const glm::dvec3& offset, const RoomScene& scene, bool shadows = true);
  double at(int surface, const glm::dvec3& x, const glm::dvec3& n, double u, double v,
            std::uint64_t key) const override;

 private:
  const LightModel& model_;
  glm::dvec3 offset_;
  const RoomScene& scene_;
  bool shadows_;
};

/// The one-APL far-field set of a bundle: its IES attachment (far_field.ies, or any *.ies) through
/// apl_set_from_photometry, else the far field of its finest level. Throws lumx::Error naming the bundle.
AplSet far_field_set_of_bundle(const BundleReader& bundle, int map_resolution = 128);

/// The luminaire geometry a bundle ships (attachments luminaire.glb / luminaire.gltf, as lumx bake stores
/// it), read through a file in `scratch_dir`. Throws lumx::Error when the bundle has none.
bake::LuminaireScene luminaire_of_bundle(const BundleReader& bundle, const std::string& scratch_dir);

struct ReferenceOptions {
  std::uint64_t particles = 1000000;  ///< emitted particles (each Φ/N lm)
  std::uint64_t seed = 1;
  int threads = 0;                    ///< 0 = all cores; the deposits do not depend on it
  double time_limit_s = 0.0;          ///< stop after the pass that exceeds it (0: none); fluxes rescaled
  std::function<void(double fraction)> progress;  ///< fraction of the particles traced
  AdaptiveKernelOptions kernel;       ///< the reconstruction (threads taken from `threads`)
};

/// Particles' deposits on the room's surfaces, split by particle parity into two independent halves.
struct RoomDeposits {
  std::vector<std::vector<Deposit2D>> even, odd;  ///< per surface; flux as part of the full estimate (lm)
  std::uint64_t particles = 0;   ///< traced
  double emitted_lm = 0.0;       ///< the luminaire's flux
  double exited_lm = 0.0;        ///< left the luminaire
  double deposited_lm = 0.0;     ///< landed on the front of a room surface
  double seconds = 0.0;
};

/// Traces particles from `tracer`'s luminaire placed at `offset` into the room and deposits their flux.
/// Deterministic for a seed at any thread count (unless the time limit cuts the trace short).
RoomDeposits trace_room_particles(const bake::Tracer& tracer, const RoomScene& scene, const glm::dvec3& offset,
                                  const ReferenceOptions& options);

/// The reference: adaptive-kernel illuminance maps of the deposits, per surface, for all particles and for
/// each half (the halves give the reference's own noise: σ(E) ≈ |E_even − E_odd| / 2, since each half has
/// twice the variance of the whole and they are independent).
class ReferenceRoomIlluminance : public RoomIlluminance {
 public:
  ReferenceRoomIlluminance(const RoomScene& scene, const RoomDeposits& deposits, const AdaptiveKernelOptions& kernel);
  ~ReferenceRoomIlluminance() override;
  double at(int surface, const glm::dvec3& x, const glm::dvec3& n, double u, double v,
            std::uint64_t key) const override;
  /// Texel maps ([surface][iv · texels_u + iu], lx) of all particles, of the even and of the odd half.
  const std::vector<std::vector<double>>& texel_maps() const { return full_; }
  const std::vector<std::vector<double>>& even_half_maps() const { return even_; }
  const std::vector<std::vector<double>>& odd_half_maps() const { return odd_; }

 private:
  std::vector<std::unique_ptr<AdaptiveKernelDensity2D>> kde_;
  std::vector<std::vector<double>> full_, even_, odd_;
};

}  // namespace render
LUMX_NAMESPACE_END
