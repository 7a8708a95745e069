// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/far_field_grid.h — the Type C (C, γ) grid on which a far field is tabulated when lumx
// computes one (from an APL level in apl/far_field.h, from rays in rays/far_field.h) for IES/EULUMDAT export.
#pragma once

#include <lumx/version.h>

#include <cmath>
#include <stdexcept>
#include <string>

LUMX_NAMESPACE_BEGIN

/// A full-sphere Type C grid: C planes 0, c_step, ..., 360 and γ 0, gamma_step, ..., 180 (degrees).
struct FarFieldGrid {
  double c_step_deg = 2.5;      ///< C planes 0, step, ..., 360
  double gamma_step_deg = 1.0;  ///< γ 0, step, ..., 180
  /// lm per W to turn a radiometric set (W/sr) into cd; must be set (> 0) for radiometric sets, since
  /// the efficacy depends on the spectrum, which the set does not know.
  double luminous_efficacy_lm_per_w = 0;
};

namespace detail {
/// Steps of `step` degrees in `span` degrees: a whole number, at most 3600; throws naming `field`.
inline int far_field_steps(double step, double span, const std::string& field) {
  if (!(step > 0) || !std::isfinite(step) || std::abs(span / step - std::round(span / step)) > 1e-9 || span / step > 3600)
    throw std::invalid_argument(field + " must divide " + std::to_string(int(span)) + "° into at most 3600 steps");
  return int(std::round(span / step));
}
}  // namespace detail

LUMX_NAMESPACE_END
