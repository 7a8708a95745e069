// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/bug_rating.h — the Backlight-Uplight-Glare rating of outdoor luminaires: lumens in the
// ten secondary solid angles of the Luminaire Classification System (IES TM-15-11) rated against the
// lumen limits of TM-15-11 Addendum A (the tables the IES/IDA Model Lighting Ordinance reprints).
//
// Zones (gamma from nadir, Type C frame of the luminaire as mounted): low 0-30°, mid 30-60°, high 60-80°,
// very high 80-90° in front (F) and behind (B); uplight low 90-100° (UL) and high 100-180° (UH) all round.
// "Front" is the half of the sphere around the C angle `forward_c_deg` (default C90, the street side of
// IES roadway photometry, TM-15's 270°-0°-90° half when its 0° points at the street).
#pragma once

#include <lumx/photometry/photometry.h>

#include <optional>
#include <string>

LUMX_NAMESPACE_BEGIN

struct BugZones {  ///< lm
  double fl = 0, fm = 0, fh = 0, fvh = 0;
  double bl = 0, bm = 0, bh = 0, bvh = 0;
  double ul = 0, uh = 0;
};

struct BugOptions {
  double forward_c_deg = 90;  ///< C angle (degrees) the front half is centred on
  /// Type V / VS (quadrilateral-symmetric) distributions are rated for glare with the FH limits on BH
  /// too (Addendum A, Table A-3's second part). Unset: decided from the data (rotational symmetry, or
  /// I(C + 90°, gamma) within 2 % of the peak of I(C, gamma) everywhere).
  std::optional<bool> quadrilateral_symmetric;
};

struct BugRating {
  BugZones zones;
  int b = 0, u = 0, g = 0;  ///< 0 … 5
  bool quadrilateral_symmetric = false;
  std::string str() const;  ///< "B1 U0 G1"
};

/// Rates `p` (absolute lumens of the luminaire as the model holds them: relative photometry is already
/// scaled to its rated lamps).
BugRating bug_rating(const Photometry& p, const BugOptions& options = {});

/// Rates given zone lumens (the limits of Addendum A; a zone at a limit still passes).
BugRating bug_rating(const BugZones& zones, bool quadrilateral_symmetric);

LUMX_NAMESPACE_END
