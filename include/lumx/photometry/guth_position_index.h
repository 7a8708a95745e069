// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/guth_position_index.h — Guth's position index p: how much less a glare source off the
// line of sight counts than one on it (the p of the UGR formula, CIE 117:1995 §4.3).
//
// Geometry (CIE 117 Figure 4.2): the observer looks horizontally; a source lies R ahead along the line
// of sight, T to the side (either side) and H above the eye (metres, any consistent unit).
#pragma once

#include <lumx/version.h>

LUMX_NAMESPACE_BEGIN

/// p from CIE 117:1995 Table 4.1 (T/R = 0 … 3 and H/R = 0 … 1.9 in steps of 0.1), bilinear between its
/// entries. Returns NaN where the table has no value — beyond T/R = 3 or H/R = 1.9, in its blank
/// corner near the top of the field of view, or next to it — that is, for sources the tabular UGR method
/// leaves out. Negative T/R is mirrored; H/R must be >= 0.
double guth_position_index(double t_over_r, double h_over_r);

/// p from the closed form that Table 4.1 was tabulated from (Luckiesh & Guth 1949; IES RP-1 / Guth 1963):
/// ln p = (35.2 - 0.31889 a - 1.22 e^(-2a/9)) 1e-3 b + (21 + 0.26667 a - 0.002963 a^2) 1e-5 b^2,
/// with a the angle (degrees) of the plane through the line of sight and the source from the vertical and
/// b the angle (degrees) between the line of sight and the source. Defined for every R > 0; the table and
/// this formula differ by up to 9.9 % (rounding and smoothing in the published table; at T/R 2.2, H/R 0.8).
double guth_position_index_formula(double t_over_r, double h_over_r);

LUMX_NAMESPACE_END
