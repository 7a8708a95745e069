// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/rays/rayset.h — raysets: measured or simulated near-field rays leaving a light source.
//
// A rayset is a list of rays, each a start point on (or near) the source, a direction and a flux; IES
// TM-25 and vendor formats (LightTools, Zemax, plain text) store them (formats.md §3; seed 001). Files
// hold up to tens of millions of rays (280 MB for 10 M), so rays are handed out in chunks by a RaySource
// and never need to be in memory all at once.
//
// Conventions after reading, whatever the file said: positions in metres, directions unit vectors in
// the file's frame, flux per ray in lm (photometric) or W (radiometric), as RaysetInfo::quantity says.
#pragma once

#include <lumx/core/units.h>
#include <lumx/math/bounding_sphere.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// Rays in structure-of-arrays form (a chunk of a rayset, or a whole small one).
struct RayChunk {
  std::vector<float> x, y, z;     ///< start point, m
  std::vector<float> dx, dy, dz;  ///< unit direction
  std::vector<float> flux;        ///< lm or W per ray (≥ 0)
  std::vector<float> wavelength_nm;  ///< per-ray wavelength when the file has one, else empty

  std::size_t size() const { return x.size(); }
  bool empty() const { return x.empty(); }
  void clear() {
    for (auto* v : {&x, &y, &z, &dx, &dy, &dz, &flux, &wavelength_nm}) v->clear();
  }
  void reserve(std::size_t n) {
    for (auto* v : {&x, &y, &z, &dx, &dy, &dz, &flux}) v->reserve(n);
  }
  void push_back(const glm::vec3& p, const glm::vec3& d, float f) {
    x.push_back(p.x), y.push_back(p.y), z.push_back(p.z);
    dx.push_back(d.x), dy.push_back(d.y), dz.push_back(d.z);
    flux.push_back(f);
  }
  glm::vec3 position(std::size_t i) const { return {x[i], y[i], z[i]}; }
  glm::vec3 direction(std::size_t i) const { return {dx[i], dy[i], dz[i]}; }
};

/// One spectral table (TM-25 §4.7.2): wavelengths (nm) and relative weights.
struct SpectralTable {
  std::vector<float> wavelength_nm, weight;
};

/// What a rayset file says about itself.
struct RaysetInfo {
  std::string file;                      ///< path or name given to the reader
  std::string format;                    ///< "TM-25", "LightTools binary", "LightTools text", "Zemax binary",
                                         ///< "Zemax text", "plain text"
  std::string version;                   ///< e.g. "2013" for TM-25
  std::uint64_t ray_count = 0;           ///< rays in the file
  PhotometricQuantity quantity = PhotometricQuantity::photometric;  ///< unit of each ray's flux
  double header_flux = NAN;              ///< total flux the header states (lm or W), NaN when absent
  std::string source_length_unit;        ///< the file's length unit before conversion to metres
  std::optional<double> wavelength_nm;   ///< single wavelength, when the file states one
  std::vector<SpectralTable> spectra;    ///< TM-25 spectral tables
  std::map<std::string, std::string> text;  ///< named text fields (TM-25 §4.7.3, LightTools header keys)
  /// Other numeric header fields by name, as the file states them (TM-25: "luminous flux lm", "radiant
  /// flux W", "creation method", "ray start position", "wavelength min nm", ...; Zemax: "source flux", ...).
  /// `lumx info` lists them; the TM-25 writer reuses the TM-25 ones so write-then-read keeps the header.
  std::map<std::string, double> values;
  bool simulated = false;                ///< creation method, when stated (TM-25: 0 simulation)
};

/// Summary of the rays themselves (computed by streaming them once; see summarize_rays in rayset_io.h).
struct RaysetSummary {
  std::uint64_t rays = 0;
  double flux_sum = 0;                  ///< Σ ray flux (double), lm or W
  glm::dvec3 lo{INFINITY}, hi{-INFINITY};  ///< bounding box of start points, m
  BoundingSphere bounds;                ///< centre of the box, radius to the farthest start point
  std::uint64_t zero_flux_rays = 0;
};

/// A stream of rays: readers of ray files implement it (io/rayset_io.h), and so does MemoryRaySource.
/// Algorithms that need several passes (clustering, then assignment) call rewind() between them.
class RaySource {
 public:
  virtual ~RaySource() = default;
  virtual const RaysetInfo& info() const = 0;
  /// Clears `out` and fills it with up to `max_rays` next rays; false when no ray was left.
  virtual bool next(RayChunk& out, std::size_t max_rays) = 0;
  /// Starts again from the first ray.
  virtual void rewind() = 0;
};

/// Rays held in memory, served in chunks (tests, synthetic raysets, small files).
class MemoryRaySource : public RaySource {
 public:
  MemoryRaySource(RayChunk rays, RaysetInfo info) : rays_(std::move(rays)), info_(std::move(info)) {
    info_.ray_count = rays_.size();
  }
  const RaysetInfo& info() const override { return info_; }
  bool next(RayChunk& out, std::size_t max_rays) override {
    out.clear();
    const std::size_t end = std::min(rays_.size(), position_ + std::max<std::size_t>(1, max_rays));
    if (position_ >= end) return false;
    auto take = [&](const std::vector<float>& from, std::vector<float>& to) {
      if (!from.empty()) to.assign(from.begin() + std::ptrdiff_t(position_), from.begin() + std::ptrdiff_t(end));
    };
    take(rays_.x, out.x), take(rays_.y, out.y), take(rays_.z, out.z);
    take(rays_.dx, out.dx), take(rays_.dy, out.dy), take(rays_.dz, out.dz);
    take(rays_.flux, out.flux), take(rays_.wavelength_nm, out.wavelength_nm);
    position_ = end;
    return true;
  }
  void rewind() override { position_ = 0; }

 private:
  RayChunk rays_;
  RaysetInfo info_;
  std::size_t position_ = 0;
};

LUMX_NAMESPACE_END
