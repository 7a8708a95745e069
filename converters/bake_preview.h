// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/bake_preview.h — `lumx bake --preview DIR`: after every pass, the luminaire's intensity
// distribution so far as a histogram image and as its pull-push filtered preview (lumx/rays/intensity_preview.h,
// seed 002 §5), the preview's polar diagram, and a table of the errors against passes.
#pragma once

#include <lumx/bake/bake.h>

#include <string>
#include <vector>

namespace lumx_cli {

class BakePreview {
 public:
  /// Creates `dir`. `resolution` is the sphere maps' R (a power of two).
  BakePreview(std::string dir, int resolution);

  /// Writes the pass's images (intensity_passNN.png, histogram_passNN.png, polar_passNN.png, and
  /// intensity.png / polar.png for the latest pass) and rewrites convergence.txt.
  void on_pass(const lumx::bake::BakePass& pass, lumx::RaySource& exits);

 private:
  struct Row {
    lumx::bake::BakePass pass;
    double change = NAN;         // relative RMSE of this preview against the previous pass's
    double stable = 0;           // fraction of stable texels
    double upsampled = 0;        // fraction of texels filled from coarser levels
  };
  std::string dir_;
  int resolution_;
  std::vector<Row> rows_;
  std::vector<float> previous_;
};

}  // namespace lumx_cli
