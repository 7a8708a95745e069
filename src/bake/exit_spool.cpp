// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// A bake's exiting particles on disk (exit_spool.h).
#include "exit_spool.h"

#include <lumx/core/diagnostic.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

LUMX_NAMESPACE_BEGIN
namespace bake {
namespace {

constexpr std::size_t kFloatsPerExit = 7;

[[noreturn]] void fail(const std::string& path, const char* step) {
  throw_at_field(path, "exit spool", std::string(step) + ": " + std::strerror(errno));
}

}  // namespace

ExitSpool::ExitSpool(std::string path) : path_(std::move(path)) {
  file_ = std::fopen(path_.c_str(), "w+b");
  if (!file_) fail(path_, "cannot create the scratch file of exiting particles");
}

ExitSpool::~ExitSpool() {
  if (file_) std::fclose(file_);
  std::error_code ignored;
  std::filesystem::remove(path_, ignored);
}

void ExitSpool::consume(const ParticleChunk& chunk) {
  std::vector<float> records;
  records.reserve(chunk.exits.size() * kFloatsPerExit);
  for (const ExitParticle& e : chunk.exits) {
    const float flux = float(luminance(glm::dvec3(e.flux_lm)));
    records.insert(records.end(), {e.position.x, e.position.y, e.position.z, e.direction.x, e.direction.y,
                                   e.direction.z, flux});
  }
  if (!records.empty() && std::fwrite(records.data(), sizeof(float), records.size(), file_) != records.size())
    fail(path_, "cannot append exiting particles");
  exits_ += chunk.exits.size();
}

void ExitSpool::flush() {
  if (std::fflush(file_) != 0) fail(path_, "cannot flush exiting particles");
}

SpoolRaySource::SpoolRaySource(const std::string& path, std::uint64_t exits, std::uint64_t particles,
                               RaysetInfo info)
    : path_(path), exits_(exits), scale_(1.0 / double(std::max<std::uint64_t>(1, particles))), info_(std::move(info)) {
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_) fail(path_, "cannot read the scratch file of exiting particles");
  info_.ray_count = exits;
}

SpoolRaySource::~SpoolRaySource() {
  if (file_) std::fclose(file_);
}

bool SpoolRaySource::next(RayChunk& out, std::size_t max_rays) {
  out.clear();
  const std::uint64_t n = std::min<std::uint64_t>(exits_ - read_, std::max<std::size_t>(1, max_rays));
  if (n == 0) return false;
  buffer_.resize(std::size_t(n) * kFloatsPerExit);
  if (std::fread(buffer_.data(), sizeof(float), buffer_.size(), file_) != buffer_.size())
    throw_at_offset(path_, std::int64_t(read_ * kFloatsPerExit * sizeof(float)), "exit spool",
                    "the scratch file of exiting particles is shorter than the exits written to it");
  out.reserve(std::size_t(n));
  for (std::size_t i = 0; i < std::size_t(n); ++i) {
    const float* r = buffer_.data() + i * kFloatsPerExit;
    out.push_back({r[0], r[1], r[2]}, {r[3], r[4], r[5]}, float(double(r[6]) * scale_));
  }
  read_ += n;
  return true;
}

void SpoolRaySource::rewind() {
  read_ = 0;
  if (std::fseek(file_, 0, SEEK_SET) != 0) fail(path_, "cannot rewind the scratch file of exiting particles");
}

}  // namespace bake
LUMX_NAMESPACE_END
