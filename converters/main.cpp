// lumx — command-line tool for luminaire data: info, check, convert, plot.
//
// Subcommands and their one-line help come from one table (kCommands); CLI11 renders `lumx --help`,
// `lumx <cmd> --help` and usage errors (to stderr, exit status 2 or CLI11's code) from it.
#include "commands.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <functional>

namespace {

struct Command {
  const char* name;
  const char* summary;
  std::function<void(CLI::App&, int& status)> setup;  // adds options and the callback
};

int g_status = 0;
lumx_cli::InfoArgs g_info;
lumx_cli::CheckArgs g_check;
lumx_cli::ConvertArgs g_convert;
lumx_cli::PlotArgs g_plot;

/// Refuses nan/inf for angle options (CLI11's number parsing accepts them).
const CLI::Validator finite(
    [](std::string& v) {
      try {
        return std::isfinite(std::stod(v)) ? std::string() : "must be a finite number of degrees";
      } catch (const std::exception&) {
        return std::string("must be a number");
      }
    },
    "DEG");

const Command kCommands[] = {
    {"info", "Summarise a photometry file (IES or EULUMDAT: grid, flux, peak, beam/field angles) or a bundle "
             "(levels, APLs, map resolutions, flux and bytes per level, volume grid)",
     [](CLI::App& c, int& st) {
       c.add_option("file", g_info.file, "IES (.ies) or EULUMDAT (.ldt) file, or a bundle folder")->required();
       c.add_flag("--json", g_info.json, "print the facts as JSON");
       c.callback([&st] { st = lumx_cli::run_info(g_info); });
     }},
    {"check", "Validate files or bundles strictly: 'FILE: OK' or located findings; exit status 1 on errors. "
              "Bundles: manifest rules, every payload's size and SHA-256, maps finite and non-negative, "
              "flux equal across levels within 0.1 %",
     [](CLI::App& c, int& st) {
       c.add_option("files", g_check.files, "files or bundle folders to check")->required();
       c.add_flag("--json", g_check.json, "print findings as JSON");
       c.add_flag("--strict", g_check.strict, "treat warnings as failures");
       c.callback([&st] { st = lumx_cli::run_check(g_check); });
     }},
    {"convert", "Convert between IES and EULUMDAT (format from the extensions); photometry to a one-APL "
                "bundle (output without .ies/.ldt); a bundle level's far field to IES or EULUMDAT",
     [](CLI::App& c, int& st) {
       c.add_option("input", g_convert.in, "input file or bundle folder")->required();
       c.add_option("output", g_convert.out, "output file (.ies or .ldt) or bundle folder")->required();
       c.add_option("--map-resolution", g_convert.map_resolution,
                    "photometry -> bundle: map resolution R (image 2R x R, default 64)")
           ->check(CLI::Range(1, 4096));
       c.add_option("--level", g_convert.level, "bundle -> photometry: level index (default 0, one APL)")
           ->check(CLI::NonNegativeNumber);
       c.add_option("--c-step", g_convert.c_step_deg, "bundle -> photometry: C-plane step, degrees (default 2.5)")
           ->check(finite);
       c.add_option("--gamma-step", g_convert.gamma_step_deg, "bundle -> photometry: gamma step, degrees (default 1)")
           ->check(finite);
       c.add_option("--efficacy", g_convert.efficacy_lm_per_w,
                    "bundle -> photometry: lm/W for radiometric (W/sr) bundles")
           ->check(finite);
       c.add_option("--ies-version", g_convert.ies_version, "LM-63 edition to write: 2019 (default) or 2002")
           ->check(CLI::IsMember({"2002", "2019"}));
       c.add_option("--rotate-c", g_convert.rotate_c_deg,
                    "rotate C-planes by DEG (default 0; 90 or -90 switches between the 'C0 along' and "
                    "'C0 across the luminaire length' readings)")
           ->check(finite);
       c.add_option("--digits", g_convert.digits, "significant digits written (default 7)")->check(CLI::Range(3, 17));
       c.add_option("--apply-tilt", g_convert.tilt_deg,
                    "fold the TILT multiplier at this installed tilt (degrees) into the candela values")
           ->check(finite)
           ->each([](const std::string&) { g_convert.apply_tilt = true; });
       c.add_flag("--keep-c90-c270", g_convert.keep_c90_c270,
                  "write C90-C270 symmetric data as IES horizontal angles 90..270 (LM-63 allows it, but several "
                  "readers misplace it; by default it is written as 0..360)");
       c.callback([&st] { st = lumx_cli::run_convert(g_convert); });
     }},
    {"plot", "Draw the polar intensity diagram (C0-C180 and C90-C270) as SVG or PNG; for a bundle, one APL's "
             "map (--apl I) or a level's APL positions in three orthographic views",
     [](CLI::App& c, int& st) {
       c.add_option("file", g_plot.file, "IES or EULUMDAT file, or a bundle folder")->required();
       c.add_option("--level", g_plot.level, "bundles: level index (default: the finest)")->check(CLI::NonNegativeNumber);
       c.add_option("--apl", g_plot.apl, "bundles: draw this APL's directional map")->check(CLI::NonNegativeNumber);
       c.add_option("-o,--output", g_plot.out, "output .svg or .png")->required();
       c.add_option("--title", g_plot.title, "title (default: luminaire name or file name)");
       c.add_option("--size", g_plot.size_px, "image size in pixels (default 800)")->check(CLI::Range(200, 8000));
       c.add_flag("--cd", g_plot.force_cd, "plot absolute cd even for relative photometry (default cd/klm)");
       c.callback([&st] { st = lumx_cli::run_plot(g_plot); });
     }},
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"lumx — luminaire data interchange: read, check, convert and plot IES LM-63 and EULUMDAT files and lumx bundles", "lumx"};
  app.require_subcommand(0, 1);
  bool version = false;
  app.add_flag("--version", version, "print library and file-format versions");
  for (const Command& cmd : kCommands) {
    CLI::App* sub = app.add_subcommand(cmd.name, cmd.summary);
    cmd.setup(*sub, g_status);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);  // --help to stdout with 0; usage errors to stderr, non-zero
  }
  if (version) {
    lumx_cli::print_version();
    return 0;
  }
  if (app.get_subcommands().empty()) {
    std::fputs(app.help().c_str(), stderr);
    return 2;
  }
  return g_status;
}
