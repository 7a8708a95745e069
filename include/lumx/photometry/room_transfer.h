// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/room_transfer.h — inter-reflection in an empty rectangular room of three diffuse
// surfaces (floor cavity, walls, ceiling cavity): exact form factors and the flux transfer factors of
// CIE 190:2010 §4.2 (its Table 5), used for the background luminance of UGR tables.
#pragma once

#include <lumx/version.h>

LUMX_NAMESPACE_BEGIN

/// Diffuse reflectances (0..1) of the ceiling cavity, the walls and the floor cavity (reference plane).
struct Reflectances {
  double ceiling = 0.7;
  double walls = 0.5;
  double floor = 0.2;
};

/// Form factor between two equal, parallel, directly opposed rectangles a × b at distance c (metres, any
/// consistent unit): the fraction of the diffuse flux leaving one that reaches the other. Closed form
/// (Hamilton & Morgan 1952; Howell's catalogue of configuration factors, C-11). 0 if any size is not > 0.
double form_factor_parallel_rectangles(double a, double b, double c);

/// Flux received by the walls after all inter-reflections, per unit of flux first received by one surface
/// (CIE 190:2010 eq. 8b, symbols F_T,FW, F_T,WW-1, F_T,CW). The room is X × Y (plan) × H (between the
/// reference plane and the luminaire plane); the three surfaces exchange flux by their exact form
/// factors. `walls_to_walls_minus_one` excludes the first, direct reception (the "-1").
struct WallTransferFactors {
  double floor_to_walls = 0;
  double walls_to_walls_minus_one = 0;
  double ceiling_to_walls = 0;
};

/// Transfer factors for a room of x_m × y_m × h_m (metres). Throws std::invalid_argument for sizes that
/// are not > 0 or reflectances outside [0, 1).
WallTransferFactors wall_transfer_factors(double x_m, double y_m, double h_m, const Reflectances& r);

LUMX_NAMESPACE_END
