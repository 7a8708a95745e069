// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// the grading of APL levels at points against rays (apl/error.h).
#include "apl/error_detail.h"

LUMX_NAMESPACE_BEGIN

IrradianceErrors compare_irradiance(const std::vector<double>& reference, const std::vector<double>& model) {
  if (reference.size() != model.size())
    throw std::invalid_argument("compare_irradiance: " + std::to_string(reference.size()) + " reference values, " +
                                std::to_string(model.size()) + " model values");
  IrradianceErrors e;
  const std::size_t n = reference.size();
  if (n == 0) return e;
  double sum_ref = 0, sum_model = 0, sq = 0;
  bool non_negative = true;
  for (std::size_t i = 0; i < n; ++i) {
    sum_ref += reference[i];
    sum_model += model[i];
    sq += (reference[i] - model[i]) * (reference[i] - model[i]);
    non_negative = non_negative && reference[i] >= 0 && model[i] >= 0;
  }
  const double mean_ref = sum_ref / double(n);
  if (mean_ref != 0) e.relative_rmse = std::sqrt(sq / double(n)) / mean_ref;
  if (!non_negative || !(sum_ref > 0) || !(sum_model > 0)) return e;
  double l2 = 0, h = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double p = reference[i] / sum_ref, q = model[i] / sum_model;
    l2 += (p - q) * (p - q);
    h += (std::sqrt(p) - std::sqrt(q)) * (std::sqrt(p) - std::sqrt(q));
  }
  e.l2 = std::sqrt(l2);
  e.hellinger = std::sqrt(0.5 * h);
  return e;
}

IrradianceErrors compare_irradiance(const std::vector<double>& reference, const std::vector<double>& model,
                                    const std::vector<double>& variance, const std::vector<double>* border) {
  IrradianceErrors e = compare_irradiance(reference, model);
  if (variance.size() != reference.size())
    throw std::invalid_argument("compare_irradiance: " + std::to_string(variance.size()) + " variances for " +
                                std::to_string(reference.size()) + " patches");
  if (border && !border->empty() && border->size() != reference.size())
    throw std::invalid_argument("compare_irradiance: " + std::to_string(border->size()) + " border terms for " +
                                std::to_string(reference.size()) + " patches");
  double b = 0;
  if (border)
    for (double x : *border) b += std::max(0.0, x);
  const std::size_t n = reference.size();
  double sum_ref = 0, sq = 0, var = 0, u2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r2 = (model[i] - reference[i]) * (model[i] - reference[i]), v = std::max(0.0, variance[i]);
    sum_ref += reference[i];
    sq += r2;
    var += v;
    u2 += 2 * v * v + 4 * std::max(0.0, r2 - v) * v;
  }
  if (n == 0 || !(sum_ref > 0)) return e;
  const double m2 = (sum_ref / double(n)) * (sum_ref / double(n));
  const double excess = (sq - var) / double(n) / m2;  // ε² − σ²
  const double u = std::sqrt(u2) / double(n) / m2;
  e.relative_rmse_noise_removed = std::sqrt(std::max(0.0, excess));
  const double allowance = b / double(n) / m2;
  e.noise_removed_upper = std::sqrt(std::max(0.0, excess) + 2 * u + allowance);
  e.noise_removed_standard_error = u;
  // Resolved: out of the reference's noise and of what its borders may hide.
  e.resolved = excess > 2 * u + allowance;
  return e;
}

double noise_floor(const std::vector<double>& half_a, const std::vector<double>& half_b) {
  if (half_a.size() != half_b.size()) throw std::invalid_argument("noise_floor: the halves have different sizes");
  const std::size_t n = half_a.size();
  if (n == 0) return NAN;
  double sum = 0, sq = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sum += 0.5 * (half_a[i] + half_b[i]);
    sq += (half_a[i] - half_b[i]) * (half_a[i] - half_b[i]);
  }
  if (!(sum > 0)) return NAN;
  return 0.5 * std::sqrt(sq / double(n)) / (sum / double(n));
}

ReferenceIrradiance gather_reference(RaySource& rays, const BoundingSphere& bounds, const AplErrorOptions& options) {
  ReferenceIrradiance ref;
  ref.spheres = MeasurementSpheres(bounds, options);
  ref.quantity = rays.info().quantity;
  const MeasurementSpheres& ms = ref.spheres;
  const std::size_t ns = ms.sphere_count(), np = ms.patch_count();
  // Per sphere, flux sums of the even and odd rays (the full sum is their sum).
  std::vector<std::vector<double>> even(ns, std::vector<double>(np, 0.0)), odd = even, squares = even;
  std::vector<double> radius2(ns);
  ref.sphere.resize(ns);
  for (std::size_t s = 0; s < ns; ++s) {
    ref.sphere[s].relative_distance = ms.relative_distances()[s];
    ref.sphere[s].radius = ms.radius(s);
    ref.sphere[s].patch_area = ms.patch_area(s);
    radius2[s] = ms.radius(s) * ms.radius(s);
  }
  const glm::dvec3 c = ms.centre();
  const std::uint64_t expected = rays.info().ray_count;
  RayChunk chunk;
  rays.rewind();
  std::uint64_t index = 0;
  int reported = -1;
  while (rays.next(chunk, std::max<std::size_t>(1, options.chunk_rays))) {
    for (std::size_t i = 0; i < chunk.size(); ++i, ++index) {
      const double flux = chunk.flux[i];
      const glm::dvec3 o = glm::dvec3(chunk.position(i)) - c;
      const glm::dvec3 w(chunk.direction(i));
      const double a = glm::dot(w, w);
      if (!(flux >= 0) || !std::isfinite(flux) || !std::isfinite(o.x + o.y + o.z) || !std::isfinite(a) || !(a > 0))
        throw std::invalid_argument("apl_error: ray " + std::to_string(index) +
                                    " has a non-finite position, a zero or non-finite direction, or a negative or "
                                    "non-finite flux");
      if (flux == 0) {
        ++ref.zero_flux_rays;
        continue;
      }
      ref.flux += flux;
      // |o + tω|² = ρ²  ⇔  a t² + 2 b t + (|o|² − ρ²) = 0; the exit is the larger root.
      const double b = glm::dot(o, w), oo = glm::dot(o, o);
      for (std::size_t s = 0; s < ns; ++s) {
        SphereReference& sr = ref.sphere[s];
        const double cc = oo - radius2[s];
        const double disc = b * b - a * cc;
        if (cc > 0) {  // starts outside: only the exit of a crossing ahead counts
          ++sr.started_outside;
          if (disc < 0 || -b + std::sqrt(disc) <= 0) {
            ++sr.missed;
            continue;
          }
        }
        const double t = (-b + std::sqrt(std::max(0.0, disc))) / a;
        const glm::dvec3 h = o + t * w;
        const double len = glm::length(h);
        // On the sphere |h| = ρ > 0; guard anyway so a degenerate case lands in a fixed patch.
        const glm::vec3 u = len > 0 ? glm::vec3(h / len) : glm::vec3(0, 0, 1);
        const std::size_t p = ms.patch_of(u);
        (index % 2 == 0 ? even : odd)[s][p] += flux;
        squares[s][p] += flux * flux;
        sr.flux += flux;
        ++sr.rays;
      }
    }
    if (options.progress && expected > 0) {
      const int pct = int(100.0 * double(index) / double(expected));
      if (pct != reported) {
        options.progress(std::min(1.0, double(index) / double(expected)), "rays");
        reported = pct;
      }
    }
  }
  ref.rays = index;
  for (std::size_t s = 0; s < ns; ++s) {
    SphereReference& sr = ref.sphere[s];
    const double inv_area = 1.0 / sr.patch_area;
    sr.irradiance.resize(np);
    sr.half_even.resize(np);
    sr.half_odd.resize(np);
    sr.variance.resize(np);
    const double M = double(std::max<std::uint64_t>(sr.rays, 1));
    for (std::size_t p = 0; p < np; ++p) {
      const double f = even[s][p] + odd[s][p];
      sr.irradiance[p] = f * inv_area;
      sr.half_even[p] = 2.0 * even[s][p] * inv_area;
      sr.half_odd[p] = 2.0 * odd[s][p] * inv_area;
      sr.variance[p] = std::max(0.0, squares[s][p] - f * f / M) * inv_area * inv_area;
    }
    detail::refresh_noise_floors(sr);
  }
  return ref;
}

LevelErrors evaluate_level(const AplSet& set, std::size_t k, const ReferenceIrradiance& ref,
                           const AplErrorOptions& options) {
  const AplLevel& level = set.levels.at(k);
  LevelErrors row;
  row.level = int(k);
  row.apls = level.size();
  row.map_resolution = level.map_resolution;
  row.bytes = level.map_bytes();
  row.masked = level.has_masks();
  detail::evaluate_rows(ref, options, row,
                        [&](std::size_t, const glm::vec3& x, const glm::vec3& n, std::size_t* clamped) {
                          return detail::level_luminance_at(set, k, x, n, options.irradiance, clamped);
                        });
  return row;
}

double far_field_irradiance(const AplSet& set, const glm::vec3& x, const glm::vec3& n, const IrradianceOptions& options,
                            std::size_t* clamped) {
  const AplLevel& level = set.levels.at(0);
  const glm::vec3 d = x - glm::vec3(set.bounds.center);
  float r2 = glm::dot(d, d);
  const float r = std::sqrt(r2);
  const glm::vec3 w = r > 0 ? d * (1.0f / r) : glm::vec3(0, 0, -1);
  const float min_r = float(detail::effective_min_distance(set, options));
  if (r < min_r) {
    r2 = min_r * min_r;
    if (clamped) ++*clamped;
  }
  const float cosine = options.ignore_normal ? 1.0f : -glm::dot(n, w);
  if (cosine <= 0.0f) return 0.0;
  return luminance_of(set.channels, far_field_intensity(level, w)) * double(cosine) / double(r2);
}

LevelErrors evaluate_far_field(const AplSet& set, const ReferenceIrradiance& ref, const AplErrorOptions& options) {
  const AplLevel& level = set.levels.at(0);
  LevelErrors row;
  row.level = -1;
  row.apls = 1;
  row.map_resolution = level.map_resolution;
  row.bytes = level.map_bytes();
  detail::evaluate_rows(ref, options, row,
                        [&](std::size_t, const glm::vec3& x, const glm::vec3& n, std::size_t* clamped) {
                          return far_field_irradiance(set, x, n, options.irradiance, clamped);
                        });
  return row;
}

AplErrorReport evaluate_apl_errors(const AplSet& set, RaySource& rays, const AplErrorOptions& options,
                                   const AplSet* pilot, const std::vector<MaskEvidence>& evidence) {
  if (set.levels.empty()) throw std::invalid_argument("apl_error: the set has no level");
  AplErrorReport report;
  report.reference = gather_reference(rays, set.bounds, options);
  if (pilot && centring_applies(options)) {
    AplErrorOptions fine = options;
    fine.patch_resolution = 2 * options.patch_resolution;
    fine.progress = nullptr;
    report.reference =
        checked_centred_reference(report.reference, gather_reference(rays, set.bounds, fine), *pilot, options);
    if (!evidence.empty()) border_allowance(report.reference, *pilot, evidence, options.threads);
  }
  const std::size_t rows = set.levels.size() + (options.far_field ? 1 : 0);
  for (std::size_t k = 0; k < set.levels.size(); ++k) {
    report.levels.push_back(evaluate_level(set, k, report.reference, options));
    if (options.progress) options.progress(double(k + 1) / double(rows), "levels");
  }
  if (options.far_field) {
    report.far_field = evaluate_far_field(set, report.reference, options);
    if (options.progress) options.progress(1.0, "levels");
  }
  return report;
}

AplErrorReport evaluate_independent(const AplSet& set, RaySource& rays, const AplSetBuilder& build_pilot,
                                    const AplErrorOptions& options, const AplSet* lit_borders,
                                    std::uint64_t lit_border_rays) {
  if (!centring_applies(options)) return evaluate_apl_errors(set, rays, options);
  AplSet own, pilot;
  std::uint64_t pilot_rays = 0;
  try {
    RayHalf even(rays, 0);
    pilot_rays = even.info().ray_count;
    own = centring_pilot(build_pilot(static_cast<RaySource&>(even)), centring_pilot_sigma(options.patch_resolution));
    pilot = lit_borders ? pilot_with_known_borders(own, *lit_borders) : own;
  } catch (const std::invalid_argument&) {
    return evaluate_apl_errors(set, rays, options);
  }
  RayHalf odd(rays, 1);
  return evaluate_apl_errors(set, odd, options, &pilot, mask_evidence(own, pilot_rays, lit_borders, lit_border_rays));
}

AplErrorReport evaluate_held_out(RaySource& rays, const AplSetBuilder& build, const AplErrorOptions& options) {
  AplSet set;
  std::uint64_t train_rays = 0;
  {
    RayHalf train(rays, 0);
    set = build(static_cast<RaySource&>(train));
    train_rays = train.info().ray_count;
  }
  // The odd rays are to this set what another run's rays are: the pilot from rays 1, 5, 9, …, the
  // grading on rays 3, 7, 11, ….
  RayHalf odd(rays, 1);
  return evaluate_independent(set, odd, build, options, &set, train_rays);
}

ErrorTable error_table(const LevelErrors& row, const ReferenceIrradiance& ref) {
  ErrorTable t;
  for (std::size_t s = 0; s < row.errors.size() && s < ref.sphere.size(); ++s) {
    // The noise-removed point error where the reference has a variance, at its upper bound when the
    // reference cannot resolve it (a level is never stored as better than the rays can tell).
    const IrradianceErrors& x = row.errors[s];
    const double e = std::isfinite(x.relative_rmse_noise_removed)
                         ? (x.resolved ? x.relative_rmse_noise_removed : x.noise_removed_upper)
                         : x.relative_rmse;
    if (!std::isfinite(e) || e < 0) continue;
    t.relative_distance.push_back(ref.sphere[s].relative_distance);
    t.relative_rmse.push_back(e);
  }
  return t;
}

void store_error_tables(AplSet& set, const AplErrorReport& report) {
  if (report.levels.size() != set.levels.size())
    throw std::invalid_argument("store_error_tables: the report has " + std::to_string(report.levels.size()) +
                                " levels, the set " + std::to_string(set.levels.size()));
  for (std::size_t k = 0; k < set.levels.size(); ++k)
    if (report.levels[k].level != int(k) || report.levels[k].apls != set.levels[k].size())
      throw std::invalid_argument("store_error_tables: level " + std::to_string(k) +
                                  " of the report does not match the set's");
  for (std::size_t k = 0; k < set.levels.size(); ++k)
    set.levels[k].error = error_table(report.levels[k], report.reference);
}

LUMX_NAMESPACE_END
