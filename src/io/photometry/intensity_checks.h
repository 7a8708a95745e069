// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Internal: the negative-intensity policy shared by the readers (hard-cases.md §6 #4).
//
// A goniophotometer's dark-signal subtraction leaves small negative values in real files; up to
// kNegativeNoiseFraction of the table's peak they are measurement noise, kept with a warning. Anything
// larger cannot be an intensity and is an error.
#pragma once

#include <lumx/version.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace detail {

inline constexpr double kNegativeNoiseFraction = 1e-3;

struct NegativeIntensities {
  double peak = 0;             ///< largest value
  std::size_t count = 0;       ///< negative values within the noise limit
  int first_line = 0;          ///< earliest line holding one of them
  std::size_t bad = SIZE_MAX;  ///< index of the first (in file order) value beyond the limit, if any
};

/// Scans `cd` (with the source line of each value) for negative values.
inline NegativeIntensities find_negative_intensities(const std::vector<double>& cd,
                                                     const std::vector<std::uint32_t>& lines) {
  NegativeIntensities r;
  for (double c : cd) r.peak = std::max(r.peak, c);
  auto line_of = [&](std::size_t i) { return i < lines.size() ? static_cast<int>(lines[i]) : 0; };
  for (std::size_t i = 0; i < cd.size(); ++i) {
    if (cd[i] >= 0) continue;
    const int ln = line_of(i);
    if (-cd[i] > kNegativeNoiseFraction * r.peak) {
      if (r.bad == SIZE_MAX || ln < line_of(r.bad)) r.bad = i;
    } else if (r.count++ == 0 || ln < r.first_line) {
      r.first_line = ln;
    }
  }
  return r;
}

}  // namespace detail
LUMX_NAMESPACE_END
