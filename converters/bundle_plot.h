// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/bundle_plot.h — cairo renderers for APL bundles: one sphere map as a false-colour image, and
// the APL positions of one level as three orthographic views.
#pragma once

#include <lumx/apl/apl_set.h>
#include <lumx/math/sphere_map.h>
#include <lumx/version.h>

#include <string>

LUMX_NAMESPACE_BEGIN

struct MapImageOptions {
  std::string title;        ///< drawn above the image when not empty
  int scale = 0;            ///< pixels per texel; 0 = choose so the image is about 1024 px wide (min 1)
  bool log_scale = true;    ///< tone mapping: log10 over 4 decades below the peak; false = linear
  std::string unit = "cd";  ///< shown on the colour bar
};

/// Writes one sphere map (lumx::SphereMap, layout 2R × R: left square = upper hemisphere z ≥ 0, right
/// square = lower hemisphere) as a PNG or SVG, chosen by the extension (.png / .svg, case-insensitive): a
/// false-colour image of the luminance (1 channel: the value; 3 channels: Rec. 709 Y = 0.2126 R +
/// 0.7152 G + 0.0722 B), nearest-neighbour upscaled, the two hemispheres labelled, a colour bar with the
/// value scale in `unit`, and the peak value and its direction. NaN and negative values are drawn as 0;
/// an all-zero map is drawn black with a 0..1 bar and the note "all zero". The image is rendered in
/// memory and written atomically. Throws lumx::Error: field "output" for an unknown extension or a cairo
/// failure, "map" for an empty map, "scale" for a negative scale or an image wider than 8192 px; write
/// errors as lumx::write_file_atomically reports them.
void write_sphere_map_image(const SphereMap& map, const std::string& out_path, const MapImageOptions& o);

struct AplPlotOptions {
  std::string title;             ///< drawn above the views when not empty
  int size_px = 1200;            ///< image width in pixels, 300..8000 (the height follows from the layout)
  std::string flux_unit = "lm";  ///< shown in the caption and the legend
};

/// Writes the APL positions of one level as three orthographic views side by side: top (x–y, looking down
/// −Z), front (x–z, looking along +Y) and side (y–z, looking along −X), all at the same metric scale and
/// fitted to the union of the positions and the `bounds` sphere (drawn dashed; a minimum extent of 1 mm
/// keeps coincident APLs and a zero radius drawable). Each APL is a translucent disc whose area is
/// proportional to its flux (flux.x for one channel, Rec. 709 luminance for RGB; the largest flux gets
/// the maximum radius, none is smaller than 1.5 px), nearer APLs drawn over farther ones. Axes carry
/// metre ticks; a legend gives the flux of the largest disc. SVG or PNG by extension, written atomically.
/// APLs with non-finite positions (or beyond 1e6 m) are skipped and counted in the caption. Throws
/// lumx::Error: field "output" for an unknown extension or a cairo failure, "size" for a width outside
/// 300..8000; write errors as lumx::write_file_atomically reports them.
void write_apl_positions_plot(const AplLevel& level, ChannelLayout channels, const BoundingSphere& bounds,
                              const std::string& out_path, const AplPlotOptions& o);

LUMX_NAMESPACE_END
