// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The lumx command-line tool's subcommands. Each returns the process exit status; none calls exit().
#pragma once

#include <lumx/core/diagnostic.h>

#include <string>
#include <vector>

namespace lumx_cli {

struct InfoArgs {
  std::string file;
  bool json = false;
};
struct CheckArgs {
  std::vector<std::string> files;
  bool json = false;
  bool strict = false;  ///< warnings count as failures
  std::string xsd;      ///< GLDF: validate product.xml against this schema (gldf.xsd)
};
struct ConvertArgs {
  std::string in, out;
  int map_resolution = 64;           ///< photometry → bundle: the one APL's map resolution R
  int level = -1;                    ///< bundle → photometry: level index (-1: the first, one APL)
  double c_step_deg = 2.5;           ///< bundle → photometry: C-plane step
  double gamma_step_deg = 1.0;       ///< bundle → photometry: gamma step
  double efficacy_lm_per_w = 0;      ///< bundle → photometry: lm/W for radiometric bundles
  std::string ies_version = "2019";  ///< "2002" or "2019"
  double rotate_c_deg = 0;           ///< C-plane rotation (see lumx::rotate_c_planes)
  int digits = 7;                    ///< significant digits written
  double tilt_deg = 0;               ///< installed tilt at which TILT multipliers are applied
  bool apply_tilt = false;
  bool keep_c90_c270 = false;        ///< write IES C90-C270 symmetry as 90..270 instead of 0..360
  std::string tm33_version = "23";   ///< TM-33 edition written for .xml/.json: "23" (TM-33-23) or "18"
  bool bundle = false;               ///< write a bundle folder whatever the output's extension
};
struct PlotArgs {
  std::string file, out, title;
  int level = -1;  ///< bundles: level index (-1: the finest level)
  int apl = -1;    ///< bundles: draw this APL's map (-1: draw the level's APL positions)
  int size_px = 800;
  bool force_cd = false;
  std::string kind = "polar";        ///< polar, isolux, isocandela, cone, ugr (photometry files)
  double mounting_height_m = 3.0;    ///< isolux: luminaire above the plane
  double tilt_deg = 0;               ///< isolux: aiming tilt about the C0-C180 axis
  double spacing_to_height = 0.25;   ///< ugr: S/H of the luminaire grid
  std::vector<double> distances_m;   ///< cone: distances (empty: 1 … 5 m)
};

int run_info(const InfoArgs& a);
int run_check(const CheckArgs& a);
int run_convert(const ConvertArgs& a);
int run_plot(const PlotArgs& a);
/// True when `path` names a lumx bundle folder rather than a photometry file.
bool is_bundle_path(const std::string& path);
/// Bundle variants of the subcommands (bundle_commands.cpp).
int run_bundle_info(const InfoArgs& a);
int run_convert_to_bundle(const ConvertArgs& a);
int run_convert_from_bundle(const ConvertArgs& a);
int run_bundle_plot(const PlotArgs& a);

/// True when `path` is a rayset (TM-25, LightTools, Zemax, plain text): by extension (.tm25ray, .ray) or
/// content; .ies/.ldt files and folders never are (ray_commands.cpp).
bool is_rayset_path(const std::string& path);
/// Rayset variants: info (rays, flux header and summed, bounding box and sphere, spectrum, text fields) and
/// the findings of reading every ray (warnings, or the located error).
int run_rayset_info(const InfoArgs& a);
std::vector<lumx::Diagnostic> check_rayset(const std::string& path);

/// True when `path` names a glTF 2.0 luminaire (.gltf or .glb, by extension; luminaire_commands.cpp).
bool is_luminaire_path(const std::string& path);
/// Luminaire variants: info (parts, material models, emitters with flux, bounding box, warnings) and the
/// findings of reading and checking the scene (lumx::bake::check_luminaire).
int run_luminaire_info(const InfoArgs& a);
std::vector<lumx::Diagnostic> check_luminaire_file(const std::string& path);

/// True when `path` names a GLDF container (.gldf, by extension; gldf_commands.cpp).
bool is_gldf_path(const std::string& path);
/// GLDF variants: info (products, variants, emitters, photometry and geometry files), the findings of
/// check_gldf (archive, XSD, references, photometry inside), and extraction of the photometry files.
int run_gldf_info(const InfoArgs& a);
std::vector<lumx::Diagnostic> check_gldf_file(const std::string& path, const std::string& xsd);
int run_gldf_extract(const ConvertArgs& a);

/// Prints the library, ABI and file-format versions.
void print_version();

}  // namespace lumx_cli
