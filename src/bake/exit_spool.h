// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/bake/exit_spool.h — a bake's exiting particles on disk, so that they are never all in memory.
//
// A bake traces in passes and does not know its particle count N until it stops, so the spool keeps each
// exit's flux as if N were 1 (the particle's Φ_total · throughput) and its reader divides by N: any prefix
// of the spool is then a rayset of the first n particles, read as often as the builders need (rewind()).
// Records are 7 native floats (x, y, z m; dx, dy, dz; flux). The file is scratch: a temporary sibling of
// the bundle (io/atomic_file.h), removed when the bake ends, or by the next bake if a killed one left it.
#pragma once

#include <lumx/bake/tracer.h>
#include <lumx/rays/rayset.h>

#include <cstdint>
#include <cstdio>
#include <string>

LUMX_NAMESPACE_BEGIN
namespace bake {

class ExitSpool : public ParticleSink {
 public:
  /// Creates (truncates) `path`. Throws lumx::Error naming it.
  explicit ExitSpool(std::string path);
  ~ExitSpool() override;  // closes and removes the file
  ExitSpool(const ExitSpool&) = delete;
  ExitSpool& operator=(const ExitSpool&) = delete;

  /// Appends the chunk's exits (fluxes normalised to one particle, TraceOptions::normalization_particles 1).
  void consume(const ParticleChunk& chunk) override;
  /// Pushes appended records to the file, so readers see them. Throws lumx::Error on a write failure.
  void flush();

  std::uint64_t exits() const { return exits_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  std::uint64_t exits_ = 0;
};

/// The first `exits` records of a spool as rays of a trace of `particles` particles (flux / particles, lm).
class SpoolRaySource : public RaySource {
 public:
  /// Throws lumx::Error when the file cannot be opened.
  SpoolRaySource(const std::string& path, std::uint64_t exits, std::uint64_t particles, RaysetInfo info);
  ~SpoolRaySource() override;
  SpoolRaySource(const SpoolRaySource&) = delete;
  SpoolRaySource& operator=(const SpoolRaySource&) = delete;

  const RaysetInfo& info() const override { return info_; }
  bool next(RayChunk& out, std::size_t max_rays) override;
  void rewind() override;

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  std::uint64_t exits_, read_ = 0;
  double scale_;
  RaysetInfo info_;
  std::vector<float> buffer_;
};

}  // namespace bake
LUMX_NAMESPACE_END
