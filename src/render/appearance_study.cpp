// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// The depth study of lumx/render/appearance_study.h: errors, noise from halves, the suggested n_b.
#include <lumx/render/appearance_study.h>

#include <lumx/core/diagnostic.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN
namespace render {

namespace {

void check_pair(const Image& a, const Image& b, const Image* mask, const char* who) {
  if (a.width != b.width || a.height != b.height || a.channel_count() != 3 || b.channel_count() != 3)
    throw std::invalid_argument(std::string(who) + ": images must be R G B and of the same size");
  if (mask && (mask->width != a.width || mask->height != a.height || mask->channel_count() < 1))
    throw std::invalid_argument(std::string(who) + ": mask must be of the images' size");
}

double luminance_at(const Image& image, std::size_t p) {
  return 0.2126 * image.pixels[3 * p] + 0.7152 * image.pixels[3 * p + 1] + 0.0722 * image.pixels[3 * p + 2];
}

bool selected(const Image* mask, std::size_t p) {
  return !mask || mask->pixels[p * mask->channel_count()] > 0.5f;
}

}  // namespace

double relative_rmse(const Image& image, const Image& reference, const Image* mask) {
  check_pair(image, reference, mask, "relative_rmse");
  double diff = 0.0, norm = 0.0;
  for (std::size_t p = 0; p < image.pixel_count(); ++p) {
    if (!selected(mask, p)) continue;
    const double y = luminance_at(image, p), r = luminance_at(reference, p);
    diff += (y - r) * (y - r);
    norm += r * r;
  }
  if (!(norm > 0.0)) return diff > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
  return std::sqrt(diff / norm);
}

double relative_noise(const Image& first_half, const Image& second_half, const Image& reference, const Image* mask) {
  check_pair(first_half, second_half, mask, "relative_noise");
  check_pair(first_half, reference, mask, "relative_noise");
  double var = 0.0, norm = 0.0;
  for (std::size_t p = 0; p < first_half.pixel_count(); ++p) {
    if (!selected(mask, p)) continue;
    const double d = luminance_at(first_half, p) - luminance_at(second_half, p), r = luminance_at(reference, p);
    var += 0.25 * d * d;  // Var(mean of A and B) ≈ (A − B)² / 4 for independent, equally noisy halves
    norm += r * r;
  }
  if (!(norm > 0.0)) return var > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
  return std::sqrt(var / norm);
}

double noise_free_error(double error, double noise, double reference_noise) {
  return std::sqrt(std::max(0.0, error * error - noise * noise - reference_noise * reference_noise));
}

std::size_t suggest_depth_index(const std::vector<double>& errors, const std::vector<double>& noises,
                                double reference_noise) {
  if (errors.empty() || errors.size() != noises.size())
    throw std::invalid_argument("suggest_depth_index: one noise per error, at least one depth");
  std::vector<double> bias(errors.size());
  for (std::size_t k = 0; k < errors.size(); ++k) bias[k] = noise_free_error(errors[k], noises[k], reference_noise);
  for (std::size_t k = 0; k < errors.size(); ++k) {
    double best_deeper = std::numeric_limits<double>::infinity();
    for (std::size_t j = k + 1; j < errors.size(); ++j) best_deeper = std::min(best_deeper, bias[j]);
    if (!(bias[k] > best_deeper + reference_noise)) return k;  // NaN errors stop here too
  }
  return errors.size() - 1;
}

DepthStudy study_depths(const AppearanceRenderer& renderer, const PinholeCamera& camera, const DepthStudyOptions& o) {
  std::vector<int> depths = o.depths;
  std::sort(depths.begin(), depths.end());
  depths.erase(std::unique(depths.begin(), depths.end()), depths.end());
  if (depths.empty()) throw_at_field("options", "depths", "at least one depth is needed");
  if (depths.front() < 0) throw_at_field("options", "depths", "depths must be >= 0");
  if (o.reference_samples_per_pixel < 2)
    throw_at_field("options", "reference_samples_per_pixel", "at least 2 (two independent halves)");
  if (o.samples_per_pixel < 2) throw_at_field("options", "samples_per_pixel", "at least 2 (two independent halves)");

  DepthStudy study;
  study.mask = renderer.luminaire_mask(camera);
  for (float m : study.mask.pixels) study.luminaire_pixels += m > 0.5f ? 1 : 0;
  const Image* on_luminaire = study.luminaire_pixels > 0 ? &study.mask : nullptr;

  AppearanceOptions ro;
  ro.depth = kReferenceDepth;
  ro.samples_per_pixel = o.reference_samples_per_pixel;
  ro.seed = o.seed;
  ro.threads = o.threads;
  ro.time_limit_seconds = o.reference_time_limit_seconds;
  ro.pass_samples = std::max(2, std::min(16, o.reference_samples_per_pixel / 16));
  if (o.progress) ro.progress = [&](double f) { o.progress("reference", f); };
  study.reference = renderer.render(camera, ro);
  const Image& ref = study.reference.image;
  study.reference_noise_luminaire =
      relative_noise(study.reference.first_half, study.reference.second_half, ref, on_luminaire);
  study.reference_noise_all = relative_noise(study.reference.first_half, study.reference.second_half, ref, nullptr);

  std::vector<double> errors, noises;
  for (int d : depths) {
    AppearanceOptions ao;
    ao.depth = d;
    ao.samples_per_pixel = o.samples_per_pixel;
    // An independent seed: the depth-limited image's noise must not correlate with the reference's.
    ao.seed = o.seed + 0x9e3779b9ULL * std::uint64_t(d + 1);
    ao.threads = o.threads;
    ao.glow = o.glow;
    ao.pass_samples = o.samples_per_pixel;
    const std::string phase = "n_b = " + std::to_string(d);
    if (o.progress) ao.progress = [&](double f) { o.progress(phase, f); };
    DepthRow row;
    row.depth = d;
    row.render = renderer.render(camera, ao);
    row.error_luminaire = relative_rmse(row.render.image, ref, on_luminaire);
    row.error_all = relative_rmse(row.render.image, ref, nullptr);
    row.noise_luminaire = relative_noise(row.render.first_half, row.render.second_half, ref, on_luminaire);
    row.bias_luminaire = noise_free_error(row.error_luminaire, row.noise_luminaire, study.reference_noise_luminaire);
    row.speedup = study.reference.seconds / std::max(row.render.seconds, 1e-9);
    row.speedup_per_sample = row.speedup * double(row.render.samples_per_pixel) /
                             double(std::max(1, study.reference.samples_per_pixel));
    errors.push_back(row.error_luminaire);
    noises.push_back(row.noise_luminaire);
    study.rows.push_back(std::move(row));
  }
  const std::size_t k = suggest_depth_index(errors, noises, study.reference_noise_luminaire);
  study.suggested_depth = depths[k];
  double best_deeper = std::numeric_limits<double>::infinity();
  for (std::size_t j = k + 1; j < errors.size(); ++j) best_deeper = std::min(best_deeper, study.rows[j].bias_luminaire);
  char buf[512];
  if (k + 1 < errors.size())
    std::snprintf(buf, sizeof buf,
                  "n_b = %d: its noise-free error %.4f on the %s pixels is within the reference's noise %.4f of the "
                  "best deeper one, %.4f (the smallest depth no deeper one beats by more)",
                  depths[k], study.rows[k].bias_luminaire, on_luminaire ? "luminaire's" : "image's",
                  study.reference_noise_luminaire, best_deeper);
  else
    std::snprintf(buf, sizeof buf,
                  "n_b = %d: the deepest depth measured; every shallower one is beaten by more than the reference's "
                  "noise (try deeper depths)",
                  depths[k]);
  study.rule = buf;
  return study;
}

}  // namespace render
LUMX_NAMESPACE_END
