// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include "render_room_command.h"

#include "cli_support.h"
#include "progress.h"
#include "room_plot.h"

#include <lumx/bake/tracer.h>
#include <lumx/io/bundle_io.h>
#include <lumx/render/image_io.h>
#include <lumx/io/atomic_file.h>
#include <lumx/render/room_render.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <unistd.h>

namespace lumx_cli {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

[[noreturn]] void option_error(const std::string& field, const std::string& message) {
  lumx::Diagnostic d;
  d.file = "lumx render room";
  d.field = field;
  d.message = message;
  throw lumx::Error(d);
}

glm::dvec3 vec3_of(const std::vector<double>& v, std::size_t i = 0) { return {v[i], v[i + 1], v[i + 2]}; }

struct MethodResult {
  std::string name;      // file stem: reference, apl-8, lod, far-field
  std::string label;     // for the table and pictures
  std::size_t apls = 0;  // 0: reference
  double seconds = 0;
  double relative_rmse = 0;
  lumx::render::Image view;
};

}  // namespace

int run_render_room(const RenderRoomArgs& a) {
  return guarded(a.bundle, [&] {
    namespace render = lumx::render;
    const auto start = Clock::now();
    lumx::BundleReader bundle(a.bundle);
    const lumx::AplSet set = bundle.load();
    const lumx::AplSet far = lumx::render::far_field_set_of_bundle(bundle);

    render::Room room;
    if (a.room.size() != 3) option_error("--room", "needs three lengths W D H in metres");
    room.size_m = vec3_of(a.room);
    room.albedo = a.albedo;
    if (a.occluders.size() % 6 != 0) option_error("--occluder", "needs six numbers x0 y0 z0 x1 y1 z1 (m)");
    for (std::size_t i = 0; i + 5 < a.occluders.size(); i += 6) room.occluders.push_back({vec3_of(a.occluders, i), vec3_of(a.occluders, i + 3)});
    room.luminaire_position_m = a.luminaire_at.size() == 3 ? vec3_of(a.luminaire_at)
                                                           : render::default_luminaire_position(room.size_m, set.bounds);
    if (!a.luminaire_at.empty() && a.luminaire_at.size() != 3) option_error("--luminaire-at", "needs X Y Z (m)");
    if (const std::string why = render::invalid_reason(room); !why.empty()) option_error("room", why);
    const render::RoomScene scene(room);

    render::PinholeCamera camera = render::default_room_camera(room);
    if (!a.eye.empty()) camera.position = vec3_of(a.eye);
    if (!a.look_at.empty()) camera.look_at = vec3_of(a.look_at);
    if (a.fov > 0) camera.vertical_fov_deg = a.fov;
    if (a.size.size() == 2) {
      camera.width = a.size[0];
      camera.height = a.size[1];
    }
    if (const std::string why = camera.invalid_reason(); !why.empty()) option_error("camera", why);

    std::vector<std::size_t> level_indices;
    for (std::size_t k = 0; k < set.levels.size(); ++k)
      if (a.levels.empty() || std::find(a.levels.begin(), a.levels.end(), set.levels[k].size()) != a.levels.end())
        level_indices.push_back(k);
    for (std::size_t n : a.levels) {
      bool found = false;
      for (const auto& l : set.levels) found = found || l.size() == n;
      if (!found) option_error("--levels", "the bundle has no level of " + std::to_string(n) + " APLs");
    }

    std::filesystem::create_directories(a.out);
    const int threads = int(a.threads);
    ProgressBar bar(double(a.particles), "particles", a.progress);

    // The reference: particles through the luminaire's geometry, on to the room, reconstructed per surface.
    MethodResult ref;
    ref.name = "reference";
    const auto t_ref = Clock::now();
    const std::string scratch = (std::filesystem::temp_directory_path() /
                                 ("lumx_render_room_" + std::to_string(::getpid()))).string();
    const lumx::bake::LuminaireScene luminaire = render::luminaire_of_bundle(bundle, scratch);
    std::filesystem::remove_all(scratch);
    const lumx::bake::Tracer tracer(luminaire);
    render::ReferenceOptions ro;
    ro.particles = a.particles;
    ro.seed = a.seed;
    ro.threads = threads;
    ro.time_limit_s = a.time_limit;
    ro.kernel.threads = threads;
    ro.progress = [&](double f) { bar.update(f, "trace"); };
    const render::RoomDeposits deposits = render::trace_room_particles(tracer, scene, room.luminaire_position_m, ro);
    bar.update(1.0, "kernel");
    const render::ReferenceRoomIlluminance reference(scene, deposits, ro.kernel);
    ref.view = render::render_room_view(scene, camera, reference, threads);
    ref.seconds = seconds_since(t_ref);
    const render::SurfaceMaps& ref_maps = reference.texel_maps();
    const double noise = render::half_noise(scene, reference.even_half_maps(), reference.odd_half_maps(), ref_maps);
    ref.label = "reference (" + std::to_string(deposits.particles) + " particles)";

    // The cheaper representations.
    std::vector<MethodResult> methods;
    auto run = [&](const std::string& name, const std::string& label, std::size_t apls, const lumx::AplSet& s, int level) {
      bar.update(double(methods.size() + 1) / double(level_indices.size() + 3), name.c_str());
      MethodResult m;
      m.name = name;
      m.label = label;
      m.apls = apls;
      const auto t = Clock::now();
      const render::AplRoomIlluminance method(s, level, room.luminaire_position_m, scene, a.seed);
      const render::SurfaceMaps maps = render::illuminance_maps(scene, method, threads);
      m.view = render::render_room_view(scene, camera, method, threads);
      m.seconds = seconds_since(t);
      m.relative_rmse = render::relative_rmse(scene, maps, ref_maps);
      methods.push_back(std::move(m));
    };
    for (std::size_t k : level_indices) {
      const std::size_t n = set.levels[k].size();
      run("apl-" + std::to_string(n), std::to_string(n) + (n == 1 ? " APL" : " APLs"), n, set, int(k));
    }
    run("lod", "level of detail (eq. 6.2)", 0, set, render::AplRoomIlluminance::kLevelOfDetail);
    run("far-field", "far field (one point, IES)", 1, far, 0);
    bar.done();

    // Pictures: the same contour levels and white point for every method.
    const std::vector<double> levels = lumx::log_contour_levels(ref.view);
    const double white = lumx::positive_quantile(ref.view, ref.view.channel_index("Y"), 0.995);
    auto caption = [&](const MethodResult& m) {
      char c[200];
      if (m.apls == 0 && &m == &ref)
        std::snprintf(c, sizeof c, "L = rho E / pi, rho = %.2f; iso-lines every 10^(1/4); noise %.2f %%; %.2f s", room.albedo,
                      100 * noise, m.seconds);
      else
        std::snprintf(c, sizeof c, "iso-lines every 10^(1/4) cd/m2; rel. RMSE %.2f %%; %.3f s; %.1fx faster", 100 * m.relative_rmse,
                      m.seconds, ref.seconds / std::max(m.seconds, 1e-9));
      return std::string(c);
    };
    nlohmann::json files = nlohmann::json::object();
    auto write_method = [&](const MethodResult& m) {
      const std::string stem = (std::filesystem::path(a.out) / ("room_" + m.name)).string();
      lumx::write_exr_image(stem + ".exr", m.view);
      lumx::write_contour_png(stem + ".png", m.view, white, levels, "Room lit by " + m.label, caption(m));
      nlohmann::json f = {{"exr", stem + ".exr"}, {"png", stem + ".png"}};
      if (&m != &ref) {
        lumx::write_difference_png(stem + "_difference.png", m.view, ref.view, a.difference_range,
                                   m.label + " against the reference", "(E - E_ref) / E_ref per pixel");
        f["difference_png"] = stem + "_difference.png";
      }
      files[m.name] = f;
    };
    write_method(ref);
    for (const MethodResult& m : methods) write_method(m);
    // Reference | finest level | far field, side by side.
    if (!level_indices.empty()) {
      const std::string dir = a.out + "/";
      const std::string finest = "apl-" + std::to_string(set.levels[level_indices.back()].size());
      lumx::write_side_by_side_png(dir + "room_comparison.png",
                                   {dir + "room_reference.png", dir + "room_" + finest + ".png", dir + "room_far-field.png"});
    }

    // The table.
    nlohmann::json j;
    j["bundle"] = a.bundle;
    j["room_m"] = {room.size_m.x, room.size_m.y, room.size_m.z};
    j["albedo"] = room.albedo;
    j["luminaire_position_m"] = {room.luminaire_position_m.x, room.luminaire_position_m.y, room.luminaire_position_m.z};
    j["occluders_m"] = nlohmann::json::array();
    for (const auto& b : room.occluders) j["occluders_m"].push_back({b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z});
    j["camera"] = {{"eye_m", {camera.position.x, camera.position.y, camera.position.z}},
                   {"look_at_m", {camera.look_at.x, camera.look_at.y, camera.look_at.z}},
                   {"vertical_fov_deg", camera.vertical_fov_deg},
                   {"size_px", {camera.width, camera.height}}};
    j["contour_levels_cd_m2"] = levels;
    j["reference"] = {{"particles", deposits.particles},
                      {"seed", a.seed},
                      {"emitted_lm", deposits.emitted_lm},
                      {"exited_lm", deposits.exited_lm},
                      {"deposited_lm", deposits.deposited_lm},
                      {"noise_relative_rmse", noise},
                      {"seconds", ref.seconds}};
    j["methods"] = nlohmann::json::array();
    j["methods"].push_back({{"name", "reference"}, {"apls", nullptr}, {"relative_rmse", 0.0}, {"seconds", ref.seconds},
                            {"speedup", 1.0}, {"files", files["reference"]}});
    for (const MethodResult& m : methods)
      j["methods"].push_back({{"name", m.name},
                              {"apls", m.name == "lod" ? nlohmann::json(nullptr) : nlohmann::json(m.apls)},
                              {"relative_rmse", m.relative_rmse},
                              {"seconds", m.seconds},
                              {"speedup", ref.seconds / std::max(m.seconds, 1e-9)},
                              {"files", files[m.name]}});
    j["total_seconds"] = seconds_since(start);

    std::string text;
    char line[256];
    std::snprintf(line, sizeof line, "room %.3g x %.3g x %.3g m, albedo %.2f, luminaire at (%.3f, %.3f, %.3f) m, %zu occluders\n",
                  room.size_m.x, room.size_m.y, room.size_m.z, room.albedo, room.luminaire_position_m.x,
                  room.luminaire_position_m.y, room.luminaire_position_m.z, room.occluders.size());
    text += line;
    std::snprintf(line, sizeof line,
                  "reference: %llu particles, %.1f lm emitted, %.1f lm on the room's surfaces; its own noise %.2f %%\n",
                  (unsigned long long)deposits.particles, deposits.emitted_lm, deposits.deposited_lm, 100 * noise);
    text += line;
    text += "relative RMSE of illuminance over the room's texels (area-weighted, relative to the reference's RMS)\n";
    std::snprintf(line, sizeof line, "%-28s %12s %10s %10s\n", "method", "rel. RMSE", "time (s)", "speed-up");
    text += line;
    std::snprintf(line, sizeof line, "%-28s %11.2f%% %10.3f %10.1f\n", "reference", 0.0, ref.seconds, 1.0);
    text += line;
    for (const MethodResult& m : methods) {
      std::snprintf(line, sizeof line, "%-28s %11.2f%% %10.3f %10.1f\n", m.label.c_str(), 100 * m.relative_rmse, m.seconds,
                    ref.seconds / std::max(m.seconds, 1e-9));
      text += line;
    }
    lumx::write_file_atomically(a.out + "/room_table.txt", text);
    lumx::write_file_atomically(a.out + "/room_table.json", j.dump(2) + "\n");
    if (a.json)
      std::printf("%s\n", j.dump(2).c_str());
    else
      std::printf("%s(pictures, EXR images and the table in %s)\n", text.c_str(), a.out.c_str());
    return 0;
  });
}

}  // namespace lumx_cli
