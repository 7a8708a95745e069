// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/appearance_images.h — the PNG pictures of `lumx render appearance`: a luminance image tone-mapped
// for display, and the false-colour difference of an image against a reference with its colour bar.
//
// Tone mapping (one operator for every image of a comparison, so that they can be compared): Reinhard et al.
// 2002's global operator on each channel, c' = k c / (1 + k c), with the exposure k = 0.18 / L̄ fixed by the
// reference's log-average luminance L̄ = exp(mean ln(δ + Y)) over its non-black pixels (δ = 10⁻⁶ cd/m²),
// then the sRGB transfer curve (IEC 61966-2-1). Differences are (Y − Y_ref) / max(Y_ref, 1 % of the
// reference's 99th-percentile luminance), clamped to ±100 %, blue (darker than the reference) through white
// to red (brighter).
#pragma once

#include <lumx/render/image.h>

#include <string>

namespace lumx_cli {

/// The exposure k of the operator above for `reference` (R G B, cd/m²); 1 for a black image.
double reinhard_exposure(const lumx::render::Image& reference);

/// Writes `image` tone-mapped with exposure k as a PNG (upscaled by whole pixels to at least 320 wide), with
/// `title` and `caption` above. Throws lumx::Error naming `path`.
void write_tone_mapped_png(const lumx::render::Image& image, double exposure, const std::string& path,
                           const std::string& title, const std::string& caption);

/// Writes the signed relative luminance difference of `image` against `reference` as a false-colour PNG with a
/// colour bar (−100 % … +100 %). Throws lumx::Error naming `path`.
void write_difference_png(const lumx::render::Image& image, const lumx::render::Image& reference,
                          const std::string& path, const std::string& title, const std::string& caption);

}  // namespace lumx_cli
