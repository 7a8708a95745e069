// The lumx command-line tool's subcommands. Each returns the process exit status; none calls exit().
#pragma once

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
};
struct ConvertArgs {
  std::string in, out;
  std::string ies_version = "2019";  ///< "2002" or "2019"
  double rotate_c_deg = 0;           ///< C-plane rotation (see lumx::rotate_c_planes)
  int digits = 7;                    ///< significant digits written
  double tilt_deg = 0;               ///< installed tilt at which TILT multipliers are applied
  bool apply_tilt = false;
  bool keep_c90_c270 = false;        ///< write IES C90-C270 symmetry as 90..270 instead of 0..360
};
struct PlotArgs {
  std::string file, out, title;
  int size_px = 800;
  bool force_cd = false;
};

int run_info(const InfoArgs& a);
int run_check(const CheckArgs& a);
int run_convert(const ConvertArgs& a);
int run_plot(const PlotArgs& a);
/// Prints the library, ABI and file-format versions.
void print_version();

}  // namespace lumx_cli
