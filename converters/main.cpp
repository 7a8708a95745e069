// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx — command-line tool for luminaire data: info, check, convert, plot.
//
// Subcommands and their one-line help come from one table (kCommands); CLI11 renders `lumx --help`,
// `lumx <cmd> --help` and usage errors (to stderr, exit status 2 or CLI11's code) from it.
#include "bake_command.h"
#include "build_command.h"
#include "commands.h"
#include "eval_commands.h"
#include "render_room_command.h"
#include "render_appearance_command.h"

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
lumx_cli::BuildArgs g_build;
lumx_cli::BakeArgs g_bake;
lumx_cli::EvalArgs g_eval;
lumx_cli::RenderRoomArgs g_render_room;

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
    {"info", "Summarise a photometry file (IES or EULUMDAT: grid, flux, peak, beam/field angles), a bundle "
             "(levels, APLs, map resolutions, flux and bytes per level, volume grid) or a rayset (TM-25, "
             "LightTools, Zemax, plain text: rays, flux in the header and summed, bounding box and sphere, "
             "spectrum, text fields) or a glTF luminaire (.gltf, .glb: parts, material models, emitters and "
             "their flux, bounding box)",
     [](CLI::App& c, int& st) {
       c.add_option("file", g_info.file, "IES (.ies) or EULUMDAT (.ldt) file, a bundle folder, a rayset, or a glTF luminaire")
           ->required();
       c.add_flag("--json", g_info.json, "print the facts as JSON");
       c.callback([&st] { st = lumx_cli::run_info(g_info); });
     }},
    {"check", "Validate files or bundles strictly: 'FILE: OK' or located findings; exit status 1 on errors. "
              "Bundles: manifest rules, every payload's size and SHA-256, maps finite and non-negative, "
              "flux equal across levels within 0.1 %. Raysets: every ray read and checked (header, counts, "
              "directions, fluxes); the header total against the rays' sum is a warning. glTF luminaires: "
              "the reader's checks, bad triangles, open volumes, emitters without flux",
     [](CLI::App& c, int& st) {
       c.add_option("files", g_check.files, "files or bundle folders to check")->required();
       c.add_flag("--json", g_check.json, "print findings as JSON");
       c.add_flag("--strict", g_check.strict, "treat warnings as failures");
       c.add_option("--xsd", g_check.xsd, "GLDF: validate product.xml against this schema file (gldf.xsd)");
       c.callback([&st] { st = lumx_cli::run_check(g_check); });
     }},
    {"convert", "Convert between IES, EULUMDAT and TM-33 (the output's extension names its format: .ies, .ldt, "
                ".xml or .json for TM-33); photometry to a one-APL bundle (.lumx or --bundle); a bundle level's "
                "far field to any of the photometry formats",
     [](CLI::App& c, int& st) {
       c.add_option("input", g_convert.in, "input file or bundle folder")->required();
       c.add_option("output", g_convert.out, "output file (.ies, .ldt, .xml, .json) or bundle folder (.lumx)")
           ->required();
       c.add_flag("--bundle", g_convert.bundle, "photometry -> bundle folder whatever the output's extension");
       c.add_option("--tm33-version", g_convert.tm33_version,
                    "TM-33 edition written to .xml/.json: 23 (TM-33-23, default) or 18 (TM-33-18 / ATLA S001)")
           ->check(CLI::IsMember({"18", "23"}));
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
    {"plot", "Draw the polar intensity diagram (C0-C180 and C90-C270), or with --kind the isolux, isocandela or cone "
             "diagram or the UGR table, as SVG or PNG; for a bundle, one APL's "
             "map (--apl I) or a level's APL positions in three orthographic views",
     [](CLI::App& c, int& st) {
       c.add_option("file", g_plot.file, "IES or EULUMDAT file, or a bundle folder")->required();
       c.add_option("--level", g_plot.level, "bundles: level index (default: the finest)")->check(CLI::NonNegativeNumber);
       c.add_option("--apl", g_plot.apl, "bundles: draw this APL's directional map")->check(CLI::NonNegativeNumber);
       c.add_option("-o,--output", g_plot.out, "output .svg or .png")->required();
       c.add_option("--title", g_plot.title, "title (default: luminaire name or file name)");
       c.add_option("--size", g_plot.size_px, "image size in pixels (default 800)")->check(CLI::Range(200, 8000));
       c.add_flag("--cd", g_plot.force_cd, "plot absolute cd even for relative photometry (default cd/klm)");
       c.add_option("--kind", g_plot.kind, "photometry: polar (default), isolux, isocandela, cone or ugr")
           ->check(CLI::IsMember({"polar", "isolux", "isocandela", "cone", "ugr"}));
       c.add_option("--height", g_plot.mounting_height_m, "isolux: mounting height above the plane, m (default 3)")
           ->check(CLI::Range(0.01, 1000.0));
       c.add_option("--tilt", g_plot.tilt_deg, "isolux: aiming tilt about the C0-C180 axis, degrees (default 0)")
           ->check(CLI::Range(0.0, 85.0));
       c.add_option("--distances", g_plot.distances_m, "cone: distances along the axis, m (default 1 2 3 4 5)")
           ->check(CLI::Range(0.001, 10000.0));
       c.add_option("--spacing", g_plot.spacing_to_height, "ugr: luminaire spacing over H (default 0.25)")
           ->check(CLI::Range(0.05, 4.0));
       c.callback([&st] { st = lumx_cli::run_plot(g_plot); });
     }},
    {"build", "Build a bundle from a rayset (TM-25, LightTools, Zemax, plain text): APL levels by agglomerative "
              "clustering, each level's error against the rays (stored as error tables), the far field as IES and "
              "EULUMDAT attachments; prints the speed-against-error table",
     [](CLI::App& c, int& st) {
       c.add_option("rays", g_build.rays, "rayset file")->required();
       c.add_option("output", g_build.out, "bundle folder to write")->required();
       c.add_option("--levels", g_build.levels, "APLs per level, increasing (default 1 8 64 256 512)");
       c.add_option("--seeds", g_build.seed_rays, "rays the cluster tree is built from (default 250000)")
           ->check(CLI::Range(std::size_t(1), std::size_t(1) << 30));
       c.add_option("--map-resolution", g_build.map_resolution,
                    "map resolution R for every level (default: by the rays-per-texel rule)")
           ->check(CLI::Range(0, 4096));
       c.add_option("--rays-per-texel", g_build.rays_per_texel, "the resolution rule's target (default 8)")
           ->check(CLI::PositiveNumber);
       c.add_option("--max-resolution", g_build.max_resolution,
                    "the finest map resolution R the rule may give, and so the finest the held-out fit tries "
                    "(default 128; smaller bundles and a faster fit)")
           ->check(CLI::Range(1, 4096));
       c.add_option("--patches", g_build.patch_resolution, "error evaluation: N = 2R^2 patches per sphere (default 16)")
           ->check(CLI::Range(1, 1024));
       c.add_flag("--no-eval", g_build.no_eval, "skip the error evaluation (no error tables)");
       c.add_option("--efficacy", g_build.efficacy_lm_per_w,
                    "lm/W for the far field of rays in W (default: the header's luminous / radiant flux)")
           ->check(finite);
       c.add_flag("--progress", g_build.progress, "show the progress bar even when stderr is not a terminal");
       c.add_flag("--converge,!--no-converge", g_build.converge,
                  "treat rays as lines: cluster them by where they come from and place each APL where its rays' "
                  "lines converge (least squares), when inside the luminaire (default); --no-converge: cluster "
                  "start points and place APLs at their box centres (the dissertation's rule)");
       c.add_flag("--point-sources,!--no-point-sources", g_build.point_sources,
                  "with --converge: where every ray's line passes through one of a few points, one masked APL per "
                  "point source, its beam borders as geometry (default); --no-point-sources: keep the clustered "
                  "set (docs/apl_sets.md, \"Point sources behind apertures\")");
       c.add_option("--representations", g_build.representations,
                    "representations to store, comma-separated, by registered name (default apl; e.g. "
                    "apl,far-field): each besides apl is built from every ray, stored as a model and graded on "
                    "held-out rays (docs/architecture.md, \"The representation seam\")")
           ->delimiter(',');
       c.add_option("--cluster-by", g_build.cluster_by,
                    "with --converge: cluster rays by start point or by where their lines pass (default auto: "
                    "by line when the lines meet; see docs/apl_sets.md)")
           ->check(CLI::IsMember({"auto", "start", "line"}));
       c.add_option("--smooth", g_build.smooth_rays,
                    "flux-exact pull-push smoothing of sparse maps: a block of 2x2, 4x4, ... texels with fewer than 4T "
                    "rays shares its light among its quarters like the parent APL's map (default 0: off)")
           ->check(CLI::Range(0.0, 1e6));
       c.add_option("--resolution-exponent", g_build.apl_exponent,
                    "the resolution rule's n^e, 2R^2 <= N/(rays-per-texel * n^e): 0 = the level's rays (default), "
                    "1 = one APL's")
           ->check(CLI::Range(0.0, 1.0));
       c.add_option("--threads", g_build.threads, "threads for the ray assignment (default: every core; the bundle "
                                                  "is the same for any count)")
           ->check(CLI::Range(0u, 256u));
       c.callback([&st] { st = lumx_cli::run_build(g_build); });
     }},
    {"bake", "Bake a glTF 2.0 luminaire (.glb/.gltf, Draco allowed) into a bundle: trace light particles from its "
             "emitters through its geometry, then build APL levels and error tables from the exits (as lumx build), "
             "the radiance volume from the internal segments, the far field as IES/EULUMDAT, and ship the luminaire",
     [](CLI::App& c, int& st) {
       c.add_option("luminaire", g_bake.luminaire, "glTF 2.0 luminaire (.glb or .gltf)")->required();
       c.add_option("output", g_bake.out, "bundle folder to write")->required();
       c.add_option("--particles", g_bake.particles, "particle budget: at most this many are traced (default 1000000)")
           ->check(CLI::Range(std::uint64_t(1), std::uint64_t(1) << 40));
       c.add_option("--target-error", g_bake.target_error,
                    "stop once the finest level's relative RMSE of irradiance at single points, at --target-distance, "
                    "graded on held-out particles, is known to be below this fraction (default 0.05; 0: trace the "
                    "whole budget)")
           ->check(CLI::Range(0.0, 10.0));
       c.add_option("--target-distance", g_bake.target_distance,
                    "relative distance d (luminaire diameters) of --target-error (default 1)")
           ->check(CLI::Range(0.01, 1000.0));
       c.add_option("--time-limit", g_bake.time_limit, "seconds: no pass starts that would end after it (default: none)")
           ->check(CLI::Range(0.0, 1e7));
       c.add_option("--pass-particles", g_bake.pass_particles,
                    "particles per pass (default: 262144, then sized by the target error, or doubling)")
           ->check(CLI::Range(std::uint64_t(1), std::uint64_t(1) << 40));
       c.add_option("--seed", g_bake.seed, "seed of the particles' random streams (default 1)");
       c.add_option("--volume-voxels", g_bake.volume_voxels,
                    "radiance volume voxels, about (default 32768 = 32^3; 0: no volume)")
           ->check(CLI::Range(0, 1 << 24));
       c.add_option("--max-depth", g_bake.max_depth, "scattering events before a particle is dropped (default 256)")
           ->check(CLI::Range(1, 100000));
       c.add_option("--rays-out", g_bake.rays_out, "also keep the exits as an IES TM-25 rayset (a virtual near-field "
                                                   "goniophotometer)");
       c.add_option("--preview", g_bake.preview,
                    "folder for a preview after every pass: the intensity distribution filtered by pull-push, its "
                    "histogram, its polar diagram, and a table of errors against passes");
       c.add_option("--preview-resolution", g_bake.preview_resolution,
                    "--preview: sphere-map resolution R, a power of two (default 64: 128 x 64 texels)")
           ->check(CLI::IsMember({1, 2, 4, 8, 16, 32, 64, 128, 256, 512}));
       c.add_option("--levels", g_bake.build.levels, "APLs per level, increasing (default 1 8 64 256 512)");
       c.add_option("--max-resolution", g_bake.build.max_resolution,
                    "the finest map resolution R the rule may give, and so the finest the held-out fit tries "
                    "(default 128; smaller bundles and a faster fit and grading)")
           ->check(CLI::Range(1, 4096));
       c.add_flag("--no-eval", g_bake.build.no_eval, "skip the error evaluation (no error tables, no --target-error)");
       c.add_flag("--progress", g_bake.build.progress, "show the progress bar even when stderr is not a terminal");
       c.add_option("--threads", g_bake.build.threads, "threads (default: every core; the bundle is the same for "
                                                       "any count)")
           ->check(CLI::Range(0u, 256u));
       c.callback([&st] { st = lumx_cli::run_bake(g_bake); });
     }},
    {"eval", "Irradiance of a bundle at given points (--points: 'x y z nx ny nz' per line, one value per line "
             "out, lx or W/m^2), or its error against a rayset (--rays: relative RMSE, eq. 5.1, per level and the "
             "far field on spheres at relative distances d, the rays' noise floor, ns per evaluation, bytes; "
             "Hellinger and l2 distances; --plots for error against distance, time and bytes)",
     [](CLI::App& c, int& st) {
       c.add_option("bundle", g_eval.bundle, "bundle folder")->required();
       c.add_option("--points", g_eval.points, "text file of points 'x y z nx ny nz' (m), '#' comments");
       c.add_option("--level", g_eval.level, "--points: level index (default: the finest)")
           ->check(CLI::NonNegativeNumber);
       c.add_flag("--lod", g_eval.lod, "--points: level per point by relative distance (eq. 6.2), stochastic");
       c.add_option("--seed", g_eval.seed, "--lod: seed of the per-line random choice (default 1)");
       c.add_option("-o,--output", g_eval.out, "--points: output file (default: standard output)");
       c.add_option("--rays", g_eval.rays, "rayset to evaluate the bundle against (TM-25, LightTools, Zemax, text)");
       c.add_option("--patches", g_eval.patch_resolution,
                    "--rays: patch resolution R, 2R^2 equal-area patches per sphere (default 16: 512)")
           ->check(CLI::Range(1, 1024));
       c.add_option("--subsamples", g_eval.subsamples,
                    "--rays: 1 = one point per patch, its centre, as a renderer queries (default); k > 1: the mean "
                    "of k x k points, a patch average that hides texel noise (0: k per level)")
           ->check(CLI::Range(0, 16));
       c.add_option("--distances", g_eval.distances,
                    "--rays: relative distances d, comma-separated (default 0.5,0.75,1,2,5,10)")
           ->delimiter(',')
           ->check(CLI::PositiveNumber);
       c.add_option("--plots", g_eval.plots_dir, "--rays: write error_vs_distance/time/bytes plots into DIR");
       c.add_option("--plot-format", g_eval.plot_format, "--plots: png (default) or svg")
           ->check(CLI::IsMember({"png", "svg"}));
       c.add_flag("--json", g_eval.json, "--rays: print the report as JSON");
       c.add_flag("--independent", g_eval.independent,
                  "--rays: grade the bundle itself even when RAYS are the rays it was built from (by default they "
                  "are split: levels rebuilt from the even rays, graded on the odd ones)");
       c.add_flag("--store-errors", g_eval.store_errors,
                  "--rays: store each level's relative RMSE table in the bundle (read by the LOD error target)");
       c.callback([&st] { st = lumx_cli::run_eval(g_eval); });
     }},
    {"render", "Render pictures of a bundle's luminaire: 'room' = the luminaire lighting an empty room, by a "
               "particle-traced reference, each APL level, level of detail and the far field, compared (docs/render.md); 'appearance' = the luminaire as a camera sees it, depth-limited tracing with the glow against a path-traced reference (docs/appearance.md)",
     [](CLI::App& c, int& st) {
       c.require_subcommand(1, 1);
       lumx_cli::add_render_appearance_command(c, st);
       CLI::App* room = c.add_subcommand(
           "room", "Direct illuminance of an empty room (default 3 x 3 x 2 m, the luminaire 10 cm from the right wall): "
                   "EXR and PNG pictures with log-spaced iso-lines per method, difference images against the "
                   "reference, and a table of relative RMSE, time and speed-up");
       auto& r = g_render_room;
       room->add_option("bundle", r.bundle, "bundle folder (lumx bake's: it ships the luminaire's glTF for the reference)")
           ->required();
       room->add_option("-o,--output", r.out, "folder for the pictures, images and table")->required();
       room->add_option("--room", r.room, "room size W D H, m (default 3 3 2)")->expected(3);
       room->add_option("--luminaire-at", r.luminaire_at,
                        "where the bundle's frame origin hangs, X Y Z in m (default: bounding sphere 10 cm from the "
                        "wall x = W and below the ceiling, at mid-depth)")
           ->expected(3);
       room->add_option("--occluder", r.occluders, "a box x0 y0 z0 x1 y1 z1 (m) that casts shadows; repeatable")
           ->expected(6)
           ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
       room->add_option("--albedo", r.albedo, "diffuse reflectance of every surface (default 0.5)")->check(CLI::Range(0.0, 1.0));
       room->add_option("--eye", r.eye, "camera position X Y Z, m")->expected(3);
       room->add_option("--look-at", r.look_at, "point the camera looks at, X Y Z, m")->expected(3);
       room->add_option("--fov", r.fov, "vertical field of view, degrees (default 75)")->check(CLI::Range(1.0, 170.0));
       room->add_option("--size", r.size, "picture size W H, pixels (default 480 320)")->expected(2);
       room->add_option("--particles", r.particles, "the reference's particles (default 1000000)")
           ->check(CLI::Range(std::uint64_t(1000), std::uint64_t(1) << 40));
       room->add_option("--levels", r.levels, "APL counts of the stored levels to render (default: all)");
       room->add_option("--seed", r.seed, "seed of the particles and of level-of-detail choices (default 1)");
       room->add_option("--threads", r.threads, "threads (default: every core; the results are the same for any count)")
           ->check(CLI::Range(0u, 256u));
       room->add_option("--time-limit", r.time_limit, "seconds: the reference stops tracing after the pass that passes "
                                                      "it, its fluxes rescaled (default: none)")
           ->check(CLI::Range(0.0, 1e9));
       room->add_option("--difference-range", r.difference_range,
                        "relative difference at the ends of the difference images' colour bar (default 0.5 = 50 %)")
           ->check(CLI::Range(0.001, 100.0));
       room->add_flag("--progress", r.progress, "show the progress bar even when stderr is not a terminal");
       room->add_flag("--json", r.json, "print the table as JSON");
       room->callback([&st] { st = lumx_cli::run_render_room(g_render_room); });
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
