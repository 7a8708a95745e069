// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Studies of the far field lumx build attaches as IES (docs/apl_sets.md, "Honest error": the local linear
// kernel and the IES far field of the Lambertian emitters). Every error is the relative RMSE (eq. 5.1)
// against the exact irradiance at the patch centres of each measurement sphere, in percent. The CSV
// columns are described in studies/study_support.h.
#include <lumx/apl/builder.h>
#include <lumx/apl/error.h>
#include <lumx/apl/far_field.h>
#include <lumx/apl/map_fit.h>
#include <lumx/photometry/intensity_table.h>

#include "honest_error_support.h"
#include "study_support.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

using namespace lumx;
using namespace lumx_test;
using lumx_study::cell;
using lumx_study::StudyArgs;
using lumx_study::StudyCsv;

namespace {

// wider-kernels: the IES far field of the Lambertian disk and rectangle (the suite's rays, seeds 11 and
// 12, built without the held-out fit): level 0's maps at R 64 under each kernel, tabulated on the Type C
// grid (far_field_photometry), as irradiance from the bounding-sphere centre at d = 2, 5, 10, beside the
// floor of a point at that centre with the exact intensity (I(ω) = r² E(c + r ω) at r = 10⁴ m).
// Kernels: none, plain σ 1.5 and 6 texel widths, sharpened 3 and 6, local linear 1.5, 3 and 4.5.
// Keys: emitter, level0_apls, level0_R (as built), kernel (exact intensity, none, plain, sharpened,
// local linear), R (the maps', empty for the exact intensity), sigma_deg. Quantities per d:
// relative_rmse_pct, horizon_share_pct (the share of the squared error within 15° of the emitters'
// horizon, z = 0). --quick changes nothing.
void wider_kernels(const StudyArgs&, std::FILE* out) {
  StudyCsv csv(out, {"emitter", "level0_apls", "level0_R", "kernel", "R", "sigma_deg"});
  for (int which : {0, 1}) {
    const std::unique_ptr<AnalyticEmitter> em = suite_emitter(which);
    auto rays = em->source(kSuiteRays, 11 + std::uint64_t(which));
    AplBuildOptions bo;
    bo.threads = 2;
    const AplSet set = build_apl_set(*rays, bo);
    AplErrorOptions eo;
    eo.relative_distances = {2, 5, 10};
    const MeasurementSpheres ms(set.bounds, eo);
    const ExactOnSpheres exact = exact_on_spheres(*em, ms, 1);
    const std::vector<glm::dvec3> dirs = ms.evaluation_directions(1);
    const double near_horizon = std::sin(15.0 * kDegToRad);
    const auto put_errors = [&](const std::string& kernel, const std::string& R, double sigma_deg, auto&& intensity) {
      const std::vector<std::string> key = {
          em->name(), cell(set.levels[0].size()), cell(set.levels[0].map_resolution), kernel, R, cell(sigma_deg)};
      for (std::size_t s = 0; s < ms.sphere_count(); ++s) {
        std::vector<double> model(dirs.size());
        double all = 0, band = 0;
        for (std::size_t p = 0; p < dirs.size(); ++p) {
          const glm::dvec3 x = ms.centre() + ms.radius(s) * dirs[p];
          const glm::dvec3 d = x - set.bounds.center;
          const double r = glm::length(d);
          const glm::dvec3 w = d / r;
          model[p] = intensity(w) * std::max(0.0, glm::dot(dirs[p], w)) / (r * r);
          const double sq = (model[p] - exact.at_centre[s][p]) * (model[p] - exact.at_centre[s][p]);
          all += sq;
          if (std::abs(w.z) < near_horizon) band += sq;
        }
        const double d = ms.relative_distances()[s];
        csv.put(key, "relative_rmse_pct", d, 100 * compare_irradiance(exact.at_centre[s], model).relative_rmse);
        csv.put(key, "horizon_share_pct", d, all > 0 ? 100 * band / all : 0.0);
      }
    };
    put_errors("exact intensity", "", 0.0, [&](const glm::dvec3& w) {
      const double r = 1e4;
      return r * r * em->irradiance(set.bounds.center + r * w, -w);
    });
    const int R = 64;
    const double texel = std::sqrt(4.0 * kPi / (2.0 * double(R) * double(R)));
    const std::pair<double, KernelMode> kernels[] = {{0.0, KernelMode::plain},        {1.5, KernelMode::plain},
                                                     {3.0, KernelMode::sharpened},    {6.0, KernelMode::plain},
                                                     {6.0, KernelMode::sharpened},    {1.5, KernelMode::local_linear},
                                                     {3.0, KernelMode::local_linear}, {4.5, KernelMode::local_linear}};
    for (const auto& [widths, mode] : kernels) {
      const double kappa = widths > 0 ? 1.0 / ((widths * texel) * (widths * texel)) : 0.0;
      AplSet far_set = set;
      far_set.levels.resize(1);
      far_set.levels[0] = fitted_level(set.levels[0], R, kappa, mode);
      const IntensityTable t(far_field_photometry(far_set, 0));
      put_errors(lumx_study::kernel_label(kernel_mode_name(mode), kappa), cell(R), widths * texel * 180 / kPi,
                 [&](const glm::dvec3& w) { return t.intensity(w); });
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  return lumx_study::study_main(
      argc, argv, "Studies of the IES far field (docs/apl_sets.md, \"Honest error\"): CSV of the figures.",
      {{"wider-kernels", "level 0's maps at R 64 under each kernel as IES, the Lambertian disk and rectangle",
        wider_kernels}});
}
