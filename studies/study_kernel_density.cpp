// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Studies of the adaptive-kernel reconstruction of illuminance from deposits
// (lumx/render/adaptive_kernel_density.h) against exact fields on a 3 m × 2 m wall
// (tests/kernel_density_test_support.h): the table of docs/render.md, "Adaptive-kernel reconstruction".
// The CSV columns are described in studies/study_support.h.
#include <lumx/render/adaptive_kernel_density.h>

#include "kernel_density_test_support.h"
#include "study_support.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

using namespace lumx_test;
using lumx_study::cell;
using lumx_study::StudyArgs;
using lumx_study::StudyCsv;

namespace {

// figures: each field (uniform, point source, shadow edge, narrow spot) at 10⁴ and 10⁵ deposits over
// seeds 1000, 1001, … (--seeds N: N seeds, 32 by default; --quick: 8), reconstructed by the adaptive
// kernel, a fixed kernel (sensitivity 0) and a histogram (run_study), on the kGridX × kGridY cell centres,
// per region (all, peak, sparse; a region without points is left out). Keys: field, deposits, seeds,
// region, estimator (adaptive, fixed, histogram, adaptive - fixed). Quantities (no d), relative to the
// region's mean exact illuminance (ErrorFigures): bias_pct, sd_pct, rmse_pct, seed_sd_pct (the sd of one
// seed's RMSE); for adaptive - fixed, the paired difference of one seed's RMSE: mean_pct, sd_pct.
void figures(const StudyArgs& args, std::FILE* out) {
  StudyCsv csv(out, {"field", "deposits", "seeds", "region", "estimator"});
  const int seeds = args.seeds > 0 ? args.seeds : args.quick ? 8 : 32;
  if (seeds < 2) throw std::invalid_argument("figures needs --seeds 2 or more");
  for (const WallField& field : {uniform_field(), point_source_field(), shadow_edge_field(), spot_field()}) {
    const auto exact = exact_grid(field, kGridX, kGridY);
    for (const std::size_t n : {std::size_t(10000), std::size_t(100000)}) {
      const Study s = run_study(field, n, seeds, 1000);
      for (const Region r : {Region::all, Region::peak, Region::sparse}) {
        const auto mask = region_mask(exact, r);
        if (std::find(mask.begin(), mask.end(), 1) == mask.end()) continue;
        const char* region = r == Region::all ? "all" : r == Region::peak ? "peak" : "sparse";
        const ErrorFigures a = error_figures(s.adaptive, exact, mask), f = error_figures(s.fixed, exact, mask),
                           h = error_figures(s.histogram, exact, mask);
        const auto put = [&](const char* estimator, const ErrorFigures& e) {
          const std::vector<std::string> key = {field.name, cell(n), cell(seeds), region, estimator};
          csv.put(key, "bias_pct", 100 * e.relative_bias);
          csv.put(key, "sd_pct", 100 * e.relative_sd);
          csv.put(key, "rmse_pct", 100 * e.relative_rmse);
          csv.put(key, "seed_sd_pct", 100 * e.rmse_standard_error * std::sqrt(double(seeds)));
        };
        put("adaptive", a);
        put("fixed", f);
        put("histogram", h);
        double gap = 0.0, gap2 = 0.0;
        for (std::size_t k = 0; k < std::size_t(seeds); ++k) {
          const double d = a.per_seed_rmse[k] - f.per_seed_rmse[k];
          gap += d / seeds;
          gap2 += d * d / seeds;
        }
        const std::vector<std::string> key = {field.name, cell(n), cell(seeds), region, "adaptive - fixed"};
        csv.put(key, "mean_pct", 100 * gap);
        csv.put(key, "sd_pct", 100 * std::sqrt(std::max(0.0, gap2 - gap * gap) * seeds / (seeds - 1)));
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  return lumx_study::study_main(
      argc, argv,
      "Studies of the adaptive-kernel illuminance reconstruction (docs/render.md, \"Adaptive-kernel "
      "reconstruction\"): CSV of the figures.",
      {{"figures",
        "bias, sd and RMSE of the adaptive kernel, a fixed kernel and a histogram (--seeds N, 32; --quick: 8)",
        figures}});
}
