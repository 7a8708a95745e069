// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/polar_plot.h — renders the polar intensity diagram (lumx/photometry/polar_diagram.h) with cairo.
#pragma once

#include <lumx/photometry/photometry.h>
#include <lumx/version.h>

#include <string>

LUMX_NAMESPACE_BEGIN

struct PolarPlotOptions {
  std::string title;     ///< overrides the default title (luminaire name, else file name) when not empty
  int size_px = 800;     ///< image width in pixels (the height is 1.02 times that); 200..8000
  bool force_cd = false; ///< plot absolute cd even for relative photometry (default: cd/klm when relative)
};

/// Draws the polar diagram of `p` and writes it to `out_path` as SVG or PNG, chosen by the extension
/// (.svg / .png, case-insensitive). The image is rendered in memory and written atomically, so a failure
/// never leaves a partial file. Throws lumx::Error: field "output" for an unknown extension or a cairo
/// failure, "size" for a size out of range, "intensity table" for unusable data; write errors as
/// lumx::write_file_atomically reports them.
void write_polar_plot(const Photometry& p, const std::string& out_path, const PolarPlotOptions& opts);

LUMX_NAMESPACE_END
