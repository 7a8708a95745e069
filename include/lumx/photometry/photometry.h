// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/photometry.h — the far-field photometry data model (no I/O).
//
// One Photometry holds what an IES LM-63 or EULUMDAT file describes: a table of luminous intensity (cd)
// over a grid of horizontal and vertical angles, the symmetry that lets the file store only part of the
// sphere, lamp data, the luminous opening and the descriptive text. Readers and writers for the file
// formats live in lumx/io/; queries (intensity at a direction, flux, beam angles) in lumx/photometry/intensity_table.h
// and lumx/photometry/metrics.h.
//
// Conventions (photometric frame of the luminaire, right-handed, metres):
//   +X = C0 plane (the luminaire's length axis in IES terms), +Y = C90, -Z = nadir (gamma 0), +Z = zenith.
//   Type C: d = (sin g cos C, sin g sin C, -cos g)              C in [0,360), gamma g in [0,180]
//   Type B: polar axis +Y (width):  d = (cos V sin H, sin V, -cos V cos H)   H in [-180,180], V in [-90,90]
//   Type A: polar axis +X (length): d = (sin V, cos V sin H, -cos V cos H)
// Types A and B share their photometric zero (H0 V0) with Type C's nadir, so tan H = cos C tan g and
// sin V = sin C sin g relate Type B to Type C (formats.md §1.3). Angles in the model are degrees, as in
// the files; intensities are absolute candela (the file's candela multiplier, or EULUMDAT's cd/klm scale,
// already applied). The ballast factor and TILT multipliers are kept beside the table, not folded in.
#pragma once

#include <lumx/version.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// LM-63 photometric type (the file stores 1 = C, 2 = B, 3 = A).
enum class PhotometricType { C = 1, B = 2, A = 3 };

/// Which part of the sphere the stored planes cover; the rest follows by mirroring.
/// The first five apply to Type C (IES horizontal range / EULUMDAT Isym); `lateral` to Types A and B.
enum class Symmetry {
  none,            ///< all planes stored (IES 0..360, Isym 0)
  rotational,      ///< one plane, same in every C (IES 0, Isym 1)
  plane_c0_c180,   ///< mirror about the C0-C180 plane: I(C) = I(360-C) (IES 0..180, Isym 2)
  plane_c90_c270,  ///< mirror about the C90-C270 plane: I(C) = I(180-C) (IES 90..270, Isym 3)
  quadrant,        ///< both mirrors (IES 0..90, Isym 4)
  lateral,         ///< Types A/B: I(H) = I(-H), horizontal angles stored 0..90 (or 0..180)
};

const char* to_string(Symmetry s);
const char* to_string(PhotometricType t);

/// Units the luminous-opening dimensions are written in by an IES file (field "units type").
enum class IesUnits { feet = 1, metres = 2 };

inline constexpr double kMetresPerFoot = 0.3048;

/// LM-63-2019 §5.11 Table 1: the luminous opening's shape, encoded by the signs of width/length/height.
enum class LuminousShape {
  point,
  rectangle,
  rectangle_with_luminous_sides,
  circle,
  ellipse,
  vertical_cylinder,
  vertical_elliptical_cylinder,
  sphere,
  ellipsoid,
  horizontal_cylinder_along_length,  ///< axis along the photometric horizontal (C0)
  horizontal_elliptical_cylinder_along_length,
  horizontal_cylinder_along_width,   ///< axis perpendicular to it (C90)
  horizontal_elliptical_cylinder_along_width,
  vertical_circle,                   ///< facing the photometric horizontal
  vertical_ellipse,
  unknown,                           ///< a sign pattern the table does not list
};

const char* to_string(LuminousShape s);

/// The luminous opening as IES states it: signed dimensions in metres (negative = curved, see shape()).
struct LuminousOpening {
  double width_m = 0;   ///< along C90 (Y)
  double length_m = 0;  ///< along C0 (X)
  double height_m = 0;  ///< along Z
  /// Classifies the sign pattern per LM-63-2019 §5.11 Table 1.
  LuminousShape shape() const;
  /// Largest extent in metres (diameter for curved shapes) — the "D" of the 5·D far-field rule.
  double max_dimension_m() const;
};

/// One lamp set (EULUMDAT stores up to 20; IES one). `flux_lm` is the set's total rated flux.
struct LampSet {
  int count = 1;          ///< number of lamps; EULUMDAT writes it negative for absolute photometry
  std::string type;       ///< lamp type / designation
  double flux_lm = 0;     ///< total luminous flux of the set, lm (0 when unknown or absolute)
  std::string color;      ///< colour appearance / CCT text
  std::string cri;        ///< colour rendering group / index text
  double watts = 0;       ///< wattage including ballast, W
};

/// An IES keyword line ("[TEST] 1234"); order and [MORE] continuations are kept.
struct Keyword {
  std::string name;   ///< without brackets, e.g. "TEST", "_USERKEY"
  std::string value;  ///< text after the keyword; [MORE] lines are joined with '\n'
};

/// LM-63 TILT data: lamp output multipliers against the luminaire's tilt angle.
struct TiltTable {
  std::string source = "INCLUDE";  ///< "INCLUDE" or the external file name
  int lamp_geometry = 1;           ///< 1 vertical base up/down, 2 horizontal (stays), 3 horizontal (tilts)
  std::vector<double> angles_deg;  ///< increasing
  std::vector<double> multipliers; ///< same count, >= 0
  /// Multiplier at a tilt angle: piecewise linear, held constant beyond the first and last angle.
  double multiplier_at(double tilt_deg) const;
};

/// EULUMDAT fields with no IES counterpart, kept so LDT -> model -> LDT round-trips.
struct LdtHeader {
  std::string company;              ///< line 1
  int ityp = 1;                     ///< 0 point no symmetry, 1 point rotational, 2 linear, 3 point other
  std::string report_number;        ///< line 8
  std::string luminaire_name;       ///< line 9
  std::string luminaire_number;     ///< line 10
  std::string file_name;            ///< line 11
  std::string date_user;            ///< line 12
  double luminaire_length_mm = 0;   ///< line 13 (diameter if width is 0)
  double luminaire_width_mm = 0;    ///< line 14
  double luminaire_height_mm = 0;   ///< line 15
  double area_length_mm = 0;        ///< line 16 luminous area length / diameter
  double area_width_mm = 0;         ///< line 17 (0 = circular)
  double area_height_mm[4] = {0, 0, 0, 0};  ///< lines 18-21, heights in C0, C90, C180, C270
  double dff_percent = 0;           ///< line 22 as stated by the file
  double lor_percent = 0;           ///< line 23 as stated by the file
  double conversion_factor = 1;     ///< line 24
  double tilt_deg = 0;              ///< line 25, tilt during measurement
  std::vector<double> direct_ratios;  ///< line 27, 10 values for k = 0.6 ... 5 (empty if unknown)
};

/// An element of a structured file (XML, or its JSON form) kept as data because the model has no field
/// for it: TM-33 spectral and colour blocks, equipment, custom data. Name, attributes and text as read,
/// children in file order. A writer of the same format puts it back where it was.
struct DataElement {
  std::string name;
  std::vector<std::pair<std::string, std::string>> attributes;
  std::string text;
  std::vector<DataElement> children;
};

/// An element kept as data, with the path of the element it belonged to ("Header", "Luminaire",
/// "Equipment", "Emitter[0]", "Emitter[0]/LuminousData", "" for the root).
struct KeptElement {
  std::string parent;
  DataElement element;
};

/// IES TM-33 / ATLA S001 fields with no IES or EULUMDAT counterpart, kept so that TM-33 -> model -> TM-33
/// round-trips (docs/tm33.md).
struct Tm33Header {
  std::string version;          ///< "Version" as read: "1.0" (TM-33-18 / S001) or "1.1" (TM-33-23)
  std::string root;             ///< root element read: "IESTM33", "IESTM33-22" or "LuminaireOpticalData"
  std::string goniometer_type;  ///< Equipment/Gonioradiometer/Type as read ("CIE_C", "IES_B", ...)
  double luminous_flux_lm = 0;  ///< LuminousData/LuminousFlux as stated by the file, lm (0 = absent)
  std::vector<KeptElement> kept;  ///< elements with no place in the model, in file order
};

/// Where the data came from; line numbers locate validation findings in the source.
struct SourceInfo {
  std::string file;                 ///< path or name given to the reader
  std::string format;               ///< "IES", "EULUMDAT" or "TM-33"
  std::string version;              ///< e.g. "LM-63-2002"
  std::vector<std::uint32_t> horizontal_lines;  ///< line of each stored horizontal angle (may be empty)
  std::vector<std::uint32_t> vertical_lines;    ///< line of each stored vertical angle
  std::vector<std::uint32_t> candela_lines;     ///< line of each stored candela value
};

/// Far-field photometry: the stored subset of the intensity table plus everything needed to rebuild the
/// full sphere and to write it back out.
struct Photometry {
  PhotometricType type = PhotometricType::C;
  Symmetry symmetry = Symmetry::none;
  std::vector<double> horizontal_deg;  ///< stored horizontal angles (C for Type C, H for A/B), increasing
  std::vector<double> vertical_deg;    ///< stored vertical angles (gamma for C, V for A/B), increasing
  std::vector<double> candela;         ///< cd, horizontal-major: candela[ih * vertical.size() + iv]

  bool absolute = false;               ///< absolute photometry: no rated lamp flux (IES -1, LDT count < 0)
  std::vector<LampSet> lamp_sets;      ///< rated lamps (relative photometry scales to their flux)
  double ballast_factor = 1.0;         ///< reported, not applied to candela
  /// IES line-2 middle field: ballast-lamp factor (<=2002) or file generation type (2019). Never used as
  /// a multiplier (formats.md §0.3).
  double ies_second_factor = 1.0;
  double input_watts = 0;              ///< luminaire input power, W
  double candela_multiplier = 1.0;     ///< the file's multiplier, already applied to `candela`
  IesUnits units = IesUnits::metres;   ///< how an IES writer states the opening
  LuminousOpening opening;
  std::vector<Keyword> keywords;       ///< IES keywords in file order
  std::optional<TiltTable> tilt;       ///< TILT data, if the file had any
  LdtHeader ldt;                       ///< EULUMDAT-only fields
  Tm33Header tm33;                     ///< TM-33-only fields and kept blocks
  SourceInfo source;

  std::size_t num_horizontal() const { return horizontal_deg.size(); }
  std::size_t num_vertical() const { return vertical_deg.size(); }
  double& at(std::size_t ih, std::size_t iv) { return candela[ih * vertical_deg.size() + iv]; }
  double at(std::size_t ih, std::size_t iv) const { return candela[ih * vertical_deg.size() + iv]; }

  /// Sum of the lamp sets' rated flux, lm (0 for absolute photometry).
  double rated_lamp_flux_lm() const;
  /// Total number of lamps (absolute value of the counts).
  int lamp_count() const;
  /// First keyword with this name, or nullptr.
  const Keyword* find_keyword(const std::string& name) const;
};

/// True for the values of LM-63-2019 Table 2 (file generation type): 1.00001 undefined, 1.00010
/// simulation, 1.00000 unaccredited lab, +0.00100 lumen-scaled, +0.01000 interpolated, 1.10000 accredited.
bool is_lm63_2019_file_generation_type(double v);

/// A copy of `p` with every candela value multiplied by the TILT multiplier at `tilt_deg` (the
/// luminaire's installed tilt). Returns `p` unchanged if it has no TILT data.
Photometry apply_tilt(const Photometry& p, double tilt_deg);

LUMX_NAMESPACE_END

#include <lumx/photometry/detail/photometry_impl.h>
