// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// `lumx bake --preview DIR` (bake_preview.h).
#include "bake_preview.h"

#include "bundle_plot.h"
#include "polar_plot.h"

#include <lumx/apl/far_field.h>
#include <lumx/io/atomic_file.h>
#include <lumx/rays/intensity_preview.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

namespace lumx_cli {
namespace {

std::string percent(double v) {
  if (!std::isfinite(v)) return "-";
  char s[32];
  std::snprintf(s, sizeof s, "%.2f", 100 * v);
  return s;
}

}  // namespace

BakePreview::BakePreview(std::string dir, int resolution) : dir_(std::move(dir)), resolution_(resolution) {
  std::filesystem::create_directories(dir_);
}

void BakePreview::on_pass(const lumx::bake::BakePass& pass, lumx::RaySource& exits) {
  const lumx::IntensityPreview p = lumx::intensity_preview(exits, resolution_);
  Row row;
  row.pass = pass;
  std::size_t stable = 0, upsampled = 0;
  for (lumx::PullPushTexel k : p.kind) {
    stable += k == lumx::PullPushTexel::stable;
    upsampled += k == lumx::PullPushTexel::upsampled;
  }
  row.stable = double(stable) / double(p.kind.size());
  row.upsampled = double(upsampled) / double(p.kind.size());
  const std::vector<float>& now = p.filtered.values();
  if (previous_.size() == now.size()) {  // eq. 5.1 between successive previews
    double sq = 0, sum = 0;
    for (std::size_t i = 0; i < now.size(); ++i) {
      sq += (double(now[i]) - previous_[i]) * (double(now[i]) - previous_[i]);
      sum += now[i];
    }
    if (sum > 0) row.change = std::sqrt(sq / double(now.size())) / (sum / double(now.size()));
  }
  previous_ = now;
  rows_.push_back(row);

  char tag[32];
  std::snprintf(tag, sizeof tag, "pass%02zu", rows_.size());
  const std::string particles = std::to_string(pass.particles);
  lumx::MapImageOptions mo;
  mo.title = "pull-push preview after " + particles + " particles (stable " + percent(row.stable) + " %)";
  lumx::write_sphere_map_image(p.filtered, dir_ + "/intensity_" + tag + ".png", mo);
  lumx::write_sphere_map_image(p.filtered, dir_ + "/intensity.png", mo);
  mo.title = "histogram after " + particles + " particles";
  lumx::write_sphere_map_image(p.histogram, dir_ + "/histogram_" + tag + ".png", mo);

  // The preview as one point's far field: its polar diagram.
  lumx::AplSet set;
  lumx::AplLevel level;
  level.map_resolution = resolution_;
  lumx::Apl apl;
  apl.map = p.filtered;
  apl.flux = apl.map.integral();
  level.apls.push_back(std::move(apl));
  set.levels.push_back(std::move(level));
  const lumx::Photometry far = lumx::far_field_photometry(set, 0);
  lumx::PolarPlotOptions po;
  po.title = "preview after " + particles + " particles";
  lumx::write_polar_plot(far, dir_ + "/polar_" + tag + ".png", po);
  lumx::write_polar_plot(far, dir_ + "/polar.png", po);

  std::string table =
      "# lumx bake --preview: errors against passes. Level and far-field errors: relative RMSE (eq. 5.1) at "
      "the target distance, graded on held-out particles, upper bounds, % ('-': no target error, no grading).\n"
      "# change: relative RMSE of the preview against the previous pass's, %. stable/upsampled: texels of the "
      "preview, %.\n"
      "pass  particles      seconds  finest_level  far_field  change  stable  upsampled\n";
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    const Row& r = rows_[i];
    char line[256];
    std::snprintf(line, sizeof line, "%4zu  %10llu  %9.2f  %12s  %9s  %6s  %6s  %9s\n", i + 1,
                  (unsigned long long)r.pass.particles, r.pass.seconds, percent(r.pass.error).c_str(),
                  percent(r.pass.far_field_error).c_str(), percent(r.change).c_str(), percent(r.stable).c_str(),
                  percent(r.upsampled).c_str());
    table += line;
  }
  lumx::write_file_atomically(dir_ + "/convergence.txt", table);
}

}  // namespace lumx_cli
