// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// `lumx render appearance`: the bundle's luminaire (its glTF attachment, or --glb), its radiance volume and
// its APLs lighting a box room, rendered by lumx::render::study_depths at each n_b and as a reference; the
// images as EXR and PNG, differences against the reference, and the table with the suggested n_b.
#include "render_appearance_command.h"

#include "appearance_images.h"
#include "cli_support.h"
#include "progress.h"

#include <lumx/bake/gltf_reader.h>
#include <lumx/io/atomic_file.h>
#include <lumx/io/bundle_io.h>
#include <lumx/render/image_io.h>
#include <lumx/render/apl_room_background.h>
#include <lumx/render/appearance_study.h>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

namespace lumx_cli {

namespace {

RenderAppearanceArgs g_args;

/// The luminaire: --glb, or the bundle's attachment written to a scratch file that the glTF reader opens.
lumx::bake::LuminaireScene read_luminaire(const lumx::BundleReader& bundle, const RenderAppearanceArgs& a) {
  lumx::bake::GltfReadOptions ro;
  ro.warnings = [](const lumx::Diagnostic& d) { print_diag(d); };
  if (!a.glb.empty()) return lumx::bake::read_gltf_luminaire(a.glb, ro);
  const auto& attachments = bundle.manifest().attachments;
  for (std::size_t i = 0; i < attachments.size(); ++i) {
    const std::string& name = attachments[i].first.name;
    if (name != "luminaire.glb" && name != "luminaire.gltf") continue;
    const std::string bytes = bundle.read_attachment(i);
    const std::filesystem::path scratch = std::filesystem::path(a.out) / (".appearance-" + name);
    {
      std::ofstream f(scratch, std::ios::binary);
      f.write(bytes.data(), std::streamsize(bytes.size()));
      if (!f) lumx::throw_at_field(scratch.string(), "output", "cannot write the luminaire's scratch copy");
    }
    try {
      lumx::bake::LuminaireScene scene = lumx::bake::read_gltf_luminaire(scratch.string(), ro);
      std::filesystem::remove(scratch);
      scene.name = a.bundle + "/attachments/" + name;
      return scene;
    } catch (...) {
      std::error_code ec;
      std::filesystem::remove(scratch, ec);
      throw;
    }
  }
  lumx::throw_at_field(a.bundle, "attachments",
                       "the bundle ships no luminaire.glb or luminaire.gltf (bundles from lumx bake do); give --glb");
}

/// A 3/4 view from below: the eye on the diagonal (1, −1.3, −0.9) from the box's centre, far enough for the
/// bounding sphere to fill 80 % of the vertical field of view, kept inside the room.
lumx::render::PinholeCamera default_camera(const lumx::Aabb& box, const lumx::Aabb& room, double fov_deg) {
  lumx::render::PinholeCamera c;
  const glm::dvec3 centre = box.center();
  const double radius = std::max(0.5 * glm::length(box.extent()), 1e-3);
  const double distance = radius / std::sin(0.5 * 0.8 * fov_deg * lumx::kDegToRad);
  glm::dvec3 eye = centre + distance * glm::normalize(glm::dvec3(1.0, -1.3, -0.9));
  for (int a = 0; a < 3; ++a) eye[a] = std::clamp(eye[a], room.lo[a] + 0.02, room.hi[a] - 0.02);
  c.position = eye;
  c.look_at = centre;
  c.up = {0.0, 0.0, 1.0};
  c.vertical_fov_deg = fov_deg;
  return c;
}

std::string fixed(double v, int digits) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

}  // namespace

void add_render_appearance_command(CLI::App& render, int& status) {
  CLI::App* c = render.add_subcommand(
      "appearance",
      "The luminaire as a camera sees it: eye rays traced through its glass and metal up to n_b scattering events, "
      "then the radiance volume's glow, against a path-traced reference; the room around it lit by the APLs. "
      "Writes EXR and PNG per depth, differences against the reference, and a table of time, error and speed-up "
      "with the suggested n_b (docs/appearance.md)");
  RenderAppearanceArgs& a = g_args;
  c->add_option("bundle", a.bundle, "bundle folder (from lumx bake: it ships the luminaire's glTF and volume)")
      ->required();
  c->add_option("-o,--output", a.out, "output folder")->required();
  c->add_option("--depths", a.depths, "n_b values, comma-separated (default 0,1,2,4,8)")
      ->delimiter(',')
      ->check(CLI::Range(0, 1000));
  c->add_option("--spp", a.spp, "samples per pixel of each depth-limited image (default 16)")->check(CLI::Range(2, 1 << 20));
  c->add_option("--reference-spp", a.reference_spp, "samples per pixel of the reference (default 256)")
      ->check(CLI::Range(2, 1 << 24));
  c->add_option("--eye", a.eye, "camera position X Y Z, m (default: a 3/4 view from below)")->expected(3);
  c->add_option("--look-at", a.look_at, "point the camera looks at, X Y Z, m (default: the luminaire's centre)")
      ->expected(3);
  c->add_option("--fov", a.fov, "vertical field of view, degrees (default 40)")->check(CLI::Range(1.0, 170.0));
  c->add_option("--size", a.size, "image width and height, pixels (default 160 120)")
      ->expected(2)
      ->check(CLI::Range(1, 8192));
  c->add_option("--glb", a.glb, "luminaire geometry (.glb or .gltf) instead of the bundle's attachment");
  c->add_option("--background-level", a.background_level,
                "APL level index lighting the room's walls (default: the finest)")
      ->check(CLI::Range(-1, 1 << 20));
  c->add_option("--room-albedo", a.room_albedo, "albedo of the room's walls, floor and ceiling (default 0.5)")
      ->check(CLI::Range(0.0, 1.0));
  c->add_flag("--no-glow", a.no_glow, "leave the radiance volume out (black at n_b)");
  c->add_option("--seed", a.seed, "seed of the pixels' random streams (default 1)");
  c->add_option("--threads", a.threads, "threads (default: every core; the images are the same for any count)")
      ->check(CLI::Range(0u, 256u));
  c->add_option("--time-limit", a.time_limit,
                "seconds: the reference stops after the pass that crosses it (default: none)")
      ->check(CLI::Range(0.0, 1e7));
  c->add_flag("--json", a.json, "print the table as JSON");
  c->add_flag("--progress", a.progress, "show the progress bar even when stderr is not a terminal");
  c->callback([&status] { status = run_render_appearance(g_args); });
}

int run_render_appearance(const RenderAppearanceArgs& a) {
  return guarded(a.bundle, [&] {
    const lumx::BundleReader bundle(a.bundle);
    std::filesystem::create_directories(a.out);  // once the bundle is known to be one
    const lumx::bake::LuminaireScene scene = read_luminaire(bundle, a);
    std::optional<lumx::RadianceVolume> volume;
    if (!a.no_glow && bundle.has_volume()) volume.emplace(bundle.load_volume());

    // The room, lit by one APL level (the finest by default).
    const std::size_t levels = bundle.manifest().levels.size();
    if (levels == 0) lumx::throw_at_field(a.bundle, "levels", "the bundle has no APL level to light the room");
    const std::size_t level = a.background_level < 0 ? levels - 1 : std::size_t(a.background_level);
    if (level >= levels)
      lumx::throw_at_field(a.bundle, "--background-level",
                           "level " + std::to_string(level) + " does not exist (the bundle has " +
                               std::to_string(levels) + ")");
    lumx::AplSet set = bundle.empty_set();
    set.levels.push_back(bundle.load_level(level));

    lumx::Aabb box;
    for (const glm::vec3& p : scene.positions) {
      box.lo = glm::min(box.lo, glm::dvec3(p));
      box.hi = glm::max(box.hi, glm::dvec3(p));
    }
    if (!box.valid()) lumx::throw_at_field(scene.name, "triangles", "the luminaire has no triangles to render");
    lumx::render::AplRoomOptions room_options;
    room_options.room = lumx::render::default_room_around(box);
    room_options.albedo = a.room_albedo;
    const auto room = std::make_shared<lumx::render::AplRoomBackground>(set, 0, room_options);
    const lumx::render::AppearanceRenderer renderer(
        scene, volume ? &*volume : nullptr,
        [room](const glm::dvec3& o, const glm::dvec3& d) { return (*room)(o, d); });

    lumx::render::PinholeCamera camera = default_camera(box, room_options.room, a.fov);
    if (a.eye.size() == 3) camera.position = {a.eye[0], a.eye[1], a.eye[2]};
    if (a.look_at.size() == 3) camera.look_at = {a.look_at[0], a.look_at[1], a.look_at[2]};
    camera.width = a.size.at(0);
    camera.height = a.size.at(1);
    const std::string why = camera.invalid_reason();
    if (!why.empty()) lumx::throw_at_field("command line", "--eye/--look-at/--fov/--size", why);

    lumx::render::DepthStudyOptions o;
    o.depths = a.depths;
    o.samples_per_pixel = a.spp;
    o.reference_samples_per_pixel = a.reference_spp;
    o.seed = a.seed;
    o.threads = int(a.threads);
    o.glow = !a.no_glow;
    o.reference_time_limit_seconds = a.time_limit;
    ProgressBar bar(0, "", a.progress);
    o.progress = [&](const std::string& phase, double f) { bar.update(f, phase.c_str()); };
    const lumx::render::DepthStudy s = lumx::render::study_depths(renderer, camera, o);
    bar.done();

    // Images: linear EXR (cd/m²), tone-mapped PNG, differences against the reference.
    const std::filesystem::path dir(a.out);
    const double exposure = reinhard_exposure(s.reference.image);
    lumx::write_exr_image((dir / "reference.exr").string(), s.reference.image);
    write_tone_mapped_png(s.reference.image, exposure, (dir / "reference.png").string(), "Reference (path traced)",
                          std::to_string(s.reference.samples_per_pixel) + " spp, " + fixed(s.reference.seconds, 2) +
                              " s; Reinhard global, key 0.18");
    for (const lumx::render::DepthRow& r : s.rows) {
      const std::string tag = "depth_" + std::to_string(r.depth);
      lumx::write_exr_image((dir / (tag + ".exr")).string(), r.render.image);
      const std::string title = "n_b = " + std::to_string(r.depth) + (o.glow && volume ? " + glow" : "");
      const std::string caption = std::to_string(r.render.samples_per_pixel) + " spp, " + fixed(r.render.seconds, 3) +
                                  " s, error " + fixed(100 * r.error_luminaire, 1) + " % (luminaire), " +
                                  fixed(r.speedup, 1) + "x faster";
      write_tone_mapped_png(r.render.image, exposure, (dir / (tag + ".png")).string(), title, caption);
      write_difference_png(r.render.image, s.reference.image, (dir / ("difference_" + tag + ".png")).string(),
                           title + " against the reference", caption);
    }

    // The table.
    std::ostringstream t;
    t << "luminaire: " << scene.name << ", " << scene.triangle_count() << " triangles; glow: "
      << (o.glow && volume ? "radiance volume" : "none") << "; room lit by APL level " << level << " ("
      << set.levels[0].apls.size() << " APLs)\n";
    t << "camera: " << camera.width << " x " << camera.height << " px, eye " << fixed(camera.position.x, 3) << " "
      << fixed(camera.position.y, 3) << " " << fixed(camera.position.z, 3) << " m, fov " << fixed(camera.vertical_fov_deg, 1)
      << " deg; " << s.luminaire_pixels << " pixels on the luminaire\n";
    t << "reference: " << s.reference.samples_per_pixel << " spp, " << fixed(s.reference.seconds, 3)
      << " s, noise " << fixed(100 * s.reference_noise_luminaire, 2) << " % (luminaire), "
      << fixed(100 * s.reference_noise_all, 2) << " % (all); " << s.reference.depth_capped << " paths at the depth cap\n";
    t << "  n_b   spp    time s   error lum. %   error all %   noise %   noise-free %   speed-up   per sample\n";
    for (const lumx::render::DepthRow& r : s.rows) {
      char line[200];
      std::snprintf(line, sizeof line, "  %3d  %4d  %8.3f  %13.2f  %12.2f  %8.2f  %13.2f  %9.1f  %11.2f\n", r.depth,
                    r.render.samples_per_pixel, r.render.seconds, 100 * r.error_luminaire, 100 * r.error_all,
                    100 * r.noise_luminaire, 100 * r.bias_luminaire, r.speedup, r.speedup_per_sample);
      t << line;
    }
    t << "suggested n_b = " << s.suggested_depth << ": " << s.rule << "\n";
    lumx::write_file_atomically((dir / "table.txt").string(), t.str());

    nlohmann::json j;
    j["luminaire"] = scene.name;
    j["units"] = "cd/m^2 (linear Rec. 709 RGB; errors on luminance)";
    j["camera"] = {{"eye_m", {camera.position.x, camera.position.y, camera.position.z}},
                   {"look_at_m", {camera.look_at.x, camera.look_at.y, camera.look_at.z}},
                   {"vertical_fov_deg", camera.vertical_fov_deg},
                   {"width", camera.width},
                   {"height", camera.height}};
    j["glow"] = o.glow && volume.has_value();
    j["background_level"] = level;
    j["luminaire_pixels"] = s.luminaire_pixels;
    j["reference"] = {{"samples_per_pixel", s.reference.samples_per_pixel},
                      {"seconds", s.reference.seconds},
                      {"noise_luminaire", s.reference_noise_luminaire},
                      {"noise_all", s.reference_noise_all},
                      {"depth_capped", s.reference.depth_capped},
                      {"exr", "reference.exr"}};
    nlohmann::json rows = nlohmann::json::array();
    for (const lumx::render::DepthRow& r : s.rows)
      rows.push_back({{"depth", r.depth},
                      {"samples_per_pixel", r.render.samples_per_pixel},
                      {"seconds", r.render.seconds},
                      {"error_luminaire", r.error_luminaire},
                      {"error_all", r.error_all},
                      {"noise_luminaire", r.noise_luminaire},
                      {"noise_free_error_luminaire", r.bias_luminaire},
                      {"speedup", r.speedup},
                      {"speedup_per_sample", r.speedup_per_sample},
                      {"exr", "depth_" + std::to_string(r.depth) + ".exr"}});
    j["depths"] = rows;
    j["suggested_depth"] = s.suggested_depth;
    j["rule"] = s.rule;
    lumx::write_file_atomically((dir / "table.json").string(), j.dump(2) + "\n");

    if (a.json)
      std::printf("%s\n", j.dump(2).c_str());
    else
      std::printf("%s", t.str().c_str());
    return 0;
  });
}

}  // namespace lumx_cli
