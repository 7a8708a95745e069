// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/ugr.h — the Unified Glare Rating table of a luminaire by the tabular method of
// CIE 117:1995 and CIE 190:2010 (docs/metrics.md): UGR = 8 log10(0.25 / Lb · Σ L² ω / p²) for an
// observer at the middle of a wall looking horizontally along the room, in rooms of X × Y (multiples of
// H) lit by a regular array of the luminaire, for five ceiling/wall/floor reflectance combinations,
// with the luminaires crosswise and endwise to the line of sight.
//
// Geometry (metres): H is the height of the luminaire plane above the eye (1.2 m above the floor); X is
// the room's width across the line of sight, Y its depth along it. The luminaires sit on a square grid
// of spacing S = spacing_to_height · H, centred across the room, the first row S/2 from the observer's
// wall. Crosswise: the photometric C0 axis lies along the line of sight (C = atan(T/R), CIE 117
// eq. 4.5), so a luminaire whose length runs along C90 is seen across; endwise: the C90 axis does
// (C = 90° - atan(T/R), eq. 4.6).
#pragma once

#include <lumx/photometry/photometry.h>
#include <lumx/photometry/room_transfer.h>

#include <cstddef>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// A room in multiples of H: X across the line of sight, Y along it.
struct UgrRoom {
  double x_h = 4;
  double y_h = 8;
};

/// The 19 rooms of the standard table, in its row order: X = 2H (Y = 2H, 3H, 4H, 6H, 8H, 12H), X = 4H
/// (Y = 2H … 12H), X = 8H (Y = 4H, 6H, 8H, 12H), X = 12H (Y = 4H, 6H, 8H).
std::vector<UgrRoom> standard_ugr_rooms();

/// The five reflectance combinations of the standard table (ceiling/walls/floor): 0.7/0.5/0.2,
/// 0.7/0.3/0.2, 0.5/0.5/0.2, 0.5/0.3/0.2, 0.3/0.3/0.2.
std::vector<Reflectances> standard_ugr_reflectances();

enum class UgrView { crosswise, endwise };

struct UgrTableOptions {
  /// S/H of the luminaire grid. 0.25 is the convention of catalogue tables (DIALux, Relux: "SHR 0.25");
  /// CIE 190's own example table is computed at 1.0.
  double spacing_to_height = 0.25;
  double height_m = 2.0;  ///< H: luminaire plane above the eye (CIE 190 §4.2)
  std::vector<UgrRoom> rooms = standard_ugr_rooms();
  std::vector<Reflectances> reflectances = standard_ugr_reflectances();
};

/// What one room and one view contribute before the reflectances are applied.
struct UgrRoomTerms {
  std::size_t luminaires = 0;  ///< N in the room
  std::size_t in_view = 0;     ///< luminaires inside the field of view of Table 4.1 (the others count 0)
  double glare_sum = 0;        ///< Σ L² ω / p² over the luminaires in view, cd²/m⁴·sr
  double floor_lm = 0;         ///< flux of one luminaire reaching the floor (reference plane) directly
  double walls_lm = 0;         ///< … the walls directly (the rest of its downward flux)
  double ceiling_lm = 0;       ///< … the ceiling (its upward flux)
};

struct UgrTable {
  UgrTableOptions options;
  double luminaire_flux_lm = 0;        ///< flux of one luminaire, lm
  std::vector<UgrRoomTerms> terms[2];  ///< per room, [crosswise, endwise]
  /// UGR per room and reflectance: values[view][room * reflectances.size() + k]. NaN where no luminaire
  /// is in view (nothing to rate).
  std::vector<double> values[2];

  double at(std::size_t room, std::size_t reflectance, UgrView view) const {
    return values[view == UgrView::crosswise ? 0 : 1][room * options.reflectances.size() + reflectance];
  }
  /// Background luminance (cd/m²) of a room, reflectance and view: Lb = E_WID / π (CIE 190 eq. 7).
  double background_cd_m2(std::size_t room, std::size_t reflectance, UgrView view) const;
};

/// The UGR table of `p` (absolute candela as the model holds them: the luminaire's own flux).
/// Throws lumx::Error located at the file (field "luminous area") when the file gives no luminous area —
/// a point source has no luminance — or ("flux") when the luminaire emits nothing, and
/// std::invalid_argument for options out of range (sizes not > 0, reflectances outside [0, 1)).
UgrTable ugr_table(const Photometry& p, const UgrTableOptions& options = {});

LUMX_NAMESPACE_END
