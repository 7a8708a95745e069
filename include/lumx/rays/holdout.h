// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/rays/holdout.h — half of a rayset, for grading a representation on rays it was not built from.
//
// A rayset is a Monte-Carlo sample of the luminaire's emission. A representation built from it and judged
// against the same rays shares their noise, which cancels in the comparison and flatters it. Split by ray
// index, the even and odd rays are two independent samples (for files written in any order: the split
// does not depend on where a ray is stored), and each, with its flux doubled, is an unbiased estimate of
// the whole luminaire: build from one half, measure the reference from the other (apl/error.h).
#pragma once

#include <lumx/rays/rayset.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>

LUMX_NAMESPACE_BEGIN

/// The rays of `base` whose index (from 0, in stream order) has parity `part` (0: even, 1: odd), each with
/// its flux multiplied by 2. `base` must outlive it; rewinding it rewinds `base`.
class RayHalf : public RaySource {
 public:
  RayHalf(RaySource& base, int part) : base_(base), part_(part) {
    if (part != 0 && part != 1) throw std::invalid_argument("RayHalf: part must be 0 (even rays) or 1 (odd rays)");
    info_ = base.info();
    // Rays 0..n−1: ⌈n/2⌉ even ones, ⌊n/2⌋ odd ones.
    info_.ray_count = part == 0 ? (info_.ray_count + 1) / 2 : info_.ray_count / 2;
    info_.file += part == 0 ? " (even rays, flux x2)" : " (odd rays, flux x2)";
  }
  const RaysetInfo& info() const override { return info_; }
  void rewind() override {
    base_.rewind();
    buffer_.clear();
    pos_ = 0;
    index_ = 0;
  }
  bool next(RayChunk& out, std::size_t max_rays) override {
    out.clear();
    max_rays = std::max<std::size_t>(1, max_rays);
    while (out.size() < max_rays) {
      if (pos_ >= buffer_.size()) {
        if (!base_.next(buffer_, 2 * max_rays)) break;
        pos_ = 0;
      }
      for (; pos_ < buffer_.size() && out.size() < max_rays; ++pos_, ++index_) {
        if (int(index_ % 2) != part_) continue;
        out.push_back(buffer_.position(pos_), buffer_.direction(pos_), 2.0f * buffer_.flux[pos_]);
        if (!buffer_.wavelength_nm.empty()) out.wavelength_nm.push_back(buffer_.wavelength_nm[pos_]);
      }
    }
    return !out.empty();
  }

 private:
  RaySource& base_;
  int part_;
  RaysetInfo info_;
  RayChunk buffer_;
  std::size_t pos_ = 0;
  std::uint64_t index_ = 0;
};

LUMX_NAMESPACE_END
