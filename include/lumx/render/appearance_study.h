// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/render/appearance_study.h — the luminaire's appearance at several depths n_b against the path-traced
// reference (lumx/render/appearance.h): time, error and speed-up per depth, and the depth to use.
//
// Error. Relative RMSE of luminance Y (Rec. 709 weights of the R G B channels, cd/m²) against the reference,
//   e = sqrt(Σ_p (Y_p − Y_ref,p)²) / sqrt(Σ_p Y_ref,p²),
// over the pixels whose centre ray hits the luminaire ("luminaire") and over all pixels ("all").
// Noise. Each image holds two independent halves (even and odd samples), A and B. The mean's noise per
// pixel has variance ≈ (A − B)²/4, so an image's relative noise is ν = sqrt(Σ (Y_A − Y_B)²/4) / sqrt(Σ Y_ref²)
// on the same pixels: the part of e that Monte Carlo noise alone explains is sqrt(ν² + ν_ref²).
//
// Noise-free error. E[e²] = b² + ν² + ν_ref², with b the relative RMSE between the two images' expectations
// (the bias of stopping at n_b, and of the glow); b is estimated as sqrt(max(0, e² − ν² − ν_ref²)).
//
// Suggested n_b (000 §5.4 leaves the choice open). Over the depths measured, d_0 < d_1 < …, the smallest d_k
// whose noise-free error no deeper depth beats by more than the reference's noise, on the luminaire's pixels:
//   b(d_k) ≤ min_{j>k} b(d_j) + ν_ref
// — a deeper image is closer to the reference only by what the reference itself cannot resolve. When no
// pixel shows the luminaire, the rule runs on all pixels. It needs a reference whose noise is below the
// differences between depths (raise its samples otherwise); the noise estimates from halves are themselves
// uncertain for heavy-tailed estimates (rare long paths), which makes b uncertain by a similar amount.
//
// Speed-up = reference time / depth-limited time, each for its own samples per pixel (stated in the table);
// per sample, the same ratio with each time divided by its samples per pixel.
#pragma once

#include <lumx/render/appearance.h>

#include <functional>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace render {

/// Relative RMSE of the luminance of `image` against `reference` over the pixels where `mask` (one channel)
/// is > 0.5, or every pixel when `mask` is null. Both images have R G B channels and the same size; throws
/// std::invalid_argument otherwise. 0 when the reference is black on those pixels and the image too; +inf
/// when only the reference is black.
double relative_rmse(const Image& image, const Image& reference, const Image* mask);

/// Relative noise ν of an image from its two halves (see above), normalised by `reference`'s luminance.
double relative_noise(const Image& first_half, const Image& second_half, const Image& reference, const Image* mask);

struct DepthStudyOptions {
  std::vector<int> depths{0, 1, 2, 4, 8};  ///< n_b values, each ≥ 0 (sorted and de-duplicated)
  int samples_per_pixel = 16;              ///< per depth-limited image
  int reference_samples_per_pixel = 256;
  std::uint64_t seed = 1;
  int threads = 0;
  bool glow = true;
  double reference_time_limit_seconds = 0;  ///< 0 = none (see AppearanceOptions::time_limit_seconds)
  /// Progress: phase ("reference", "n_b = 2") and the fraction of that phase done.
  std::function<void(const std::string& phase, double fraction)> progress;
};

struct DepthRow {
  int depth = 0;
  AppearanceImage render;
  double error_luminaire = 0;  ///< relative RMSE over the luminaire's pixels
  double error_all = 0;        ///< relative RMSE over all pixels
  double noise_luminaire = 0;  ///< ν of this image over the luminaire's pixels
  double bias_luminaire = 0;   ///< noise-free error b over the luminaire's pixels
  double speedup = 0;          ///< reference seconds / this image's seconds
  /// The same per sample per pixel: (reference seconds / its spp) / (seconds / spp), what a sample of the
  /// depth-limited image costs against one of the reference.
  double speedup_per_sample = 0;
};

struct DepthStudy {
  AppearanceImage reference;
  Image mask;                        ///< one channel: 1 on the luminaire's pixels
  std::size_t luminaire_pixels = 0;
  double reference_noise_luminaire = 0;  ///< ν_ref over the luminaire's pixels
  double reference_noise_all = 0;
  std::vector<DepthRow> rows;        ///< increasing depth
  int suggested_depth = 0;
  std::string rule;                  ///< the rule above, with the numbers that decided it
};

/// Renders the reference, then each depth, and applies the rule. Throws lumx::Error for invalid options.
DepthStudy study_depths(const AppearanceRenderer& renderer, const PinholeCamera& camera, const DepthStudyOptions& options);

/// sqrt(max(0, e² − ν² − ν_ref²)): the error e with both images' noise removed.
double noise_free_error(double error, double noise, double reference_noise);

/// The rule alone: index into `errors` (increasing depth) of the suggested depth, given each depth's own
/// noise and the reference's. Throws std::invalid_argument for empty or mismatched inputs.
std::size_t suggest_depth_index(const std::vector<double>& errors, const std::vector<double>& noises,
                                double reference_noise);

}  // namespace render
LUMX_NAMESPACE_END
