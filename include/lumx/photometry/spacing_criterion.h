// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/spacing_criterion.h — the IES spacing criterion (SC): the largest spacing-to-mounting-
// height ratio S/MH at which the horizontal illuminance midway between two adjacent luminaires (from the
// two of them) still equals the illuminance directly below one (from it alone), as defined in the IES
// Lighting Handbook (10th ed., "spacing criterion") and printed on IES photometric reports.
//
// With both luminaires at height MH over the plane, the point midway is seen from each at gamma with
// tan gamma = S / (2 MH); the condition E_mid = E_nadir reads
//     [I(C, gamma) + I(C + 180°, gamma)] cos³ gamma = I(nadir),
// solved for the first gamma (from nadir outwards) at which the left side falls to the right one;
// SC = 2 tan gamma. Closed forms: an isotropic source gives 2 cos³ gamma = 1, SC = 1.533; a cosine
// (Lambertian) one 2 cos⁴ gamma = 1, SC = 1.287.
#pragma once

#include <lumx/photometry/intensity_table.h>

#include <optional>

LUMX_NAMESPACE_BEGIN

struct SpacingCriterion {
  std::optional<double> c0_c180;   ///< luminaires in a row along C0-C180
  std::optional<double> c90_c270;  ///< … along C90-C270
  std::optional<double> diagonal;  ///< … along C45-C225 (IES reports' "diagonal")
};

/// SC in the plane through C = `c_deg` and C + 180°: none when the nadir intensity is zero or the
/// midpoint illuminance stays above the nadir one out to gamma = 85°.
std::optional<double> spacing_criterion(const IntensityTable& t, double c_deg);

SpacingCriterion spacing_criteria(const IntensityTable& t);

LUMX_NAMESPACE_END
