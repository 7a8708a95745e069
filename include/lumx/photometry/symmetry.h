// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/photometry/symmetry.h — lossless expansion of a stored intensity subset to the whole sphere, and back.
//
// IES states symmetry implicitly through its horizontal-angle range, EULUMDAT explicitly (Isym); the
// model stores the subset plus a Symmetry tag (formats.md §1.4, §2.2). The model's stored range for each
// symmetry is the IES one: rotational {C0}, C0-C180 plane [0,180], C90-C270 plane [90,270], quadrant
// [0,90], lateral (A/B) H in [0, ...]. compact(expand(x)) == x exactly; expand introduces no new values,
// only mirrored copies.
#pragma once

#include <lumx/photometry/photometry.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN

/// A plain angle grid with candela values, horizontal-major (candela[ih * nv + iv]).
struct AngleTable {
  std::vector<double> horizontal_deg;
  std::vector<double> vertical_deg;
  std::vector<double> candela;
  double at(std::size_t ih, std::size_t iv) const { return candela[ih * vertical_deg.size() + iv]; }
};

/// The stored subset of `p` as an AngleTable.
inline AngleTable stored_table(const Photometry& p) {
  return {p.horizontal_deg, p.vertical_deg, p.candela};
}

/// The horizontal range [first, last] in degrees that `s` stores in the model (Type C; lateral: [0, *]).
/// Returns false for Symmetry::none (any full range) — and for rotational the range is a single plane.
inline bool stored_range(Symmetry s, double& first, double& last) {
  switch (s) {
    case Symmetry::rotational: first = last = 0; return true;
    case Symmetry::plane_c0_c180: first = 0; last = 180; return true;
    case Symmetry::plane_c90_c270: first = 90; last = 270; return true;
    case Symmetry::quadrant: first = 0; last = 90; return true;
    case Symmetry::none:
    case Symmetry::lateral: return false;
  }
  return false;
}

/// Symmetry implied by an IES Type C horizontal range (LM-63-2002 §3.21, formats.md §1.4). Returns nullopt
/// for ranges the standard does not define (e.g. 0..270, 0..45).
inline std::optional<Symmetry> symmetry_from_ies_range(PhotometricType type, double first, double last,
                                                       std::size_t count) {
  auto eq = [](double a, double b) { return std::abs(a - b) < 1e-6; };
  if (type != PhotometricType::C) {
    if (eq(first, 0) && count > 1) return Symmetry::lateral;
    if (count == 1 && eq(first, 0)) return Symmetry::lateral;
    return Symmetry::none;
  }
  if (count == 1) return eq(first, 0) ? std::optional<Symmetry>(Symmetry::rotational) : std::nullopt;
  if (eq(first, 0) && eq(last, 90)) return Symmetry::quadrant;
  if (eq(first, 0) && eq(last, 180)) return Symmetry::plane_c0_c180;
  if (eq(first, 90) && eq(last, 270)) return Symmetry::plane_c90_c270;
  if (eq(first, 0) && eq(last, 360)) return Symmetry::none;
  return std::nullopt;
}

namespace detail {
inline void append_plane(AngleTable& out, double h, const AngleTable& in, std::size_t ih) {
  out.horizontal_deg.push_back(h);
  const std::size_t nv = in.vertical_deg.size();
  out.candela.insert(out.candela.end(), in.candela.begin() + static_cast<long>(ih * nv),
                     in.candela.begin() + static_cast<long>((ih + 1) * nv));
}
/// Sorts planes by angle, dropping exact duplicates (a mirror of a plane onto itself).
inline AngleTable sort_planes(const AngleTable& t) {
  const std::size_t nh = t.horizontal_deg.size(), nv = t.vertical_deg.size();
  std::vector<std::size_t> order(nh);
  for (std::size_t i = 0; i < nh; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return t.horizontal_deg[a] < t.horizontal_deg[b]; });
  AngleTable out;
  out.vertical_deg = t.vertical_deg;
  for (std::size_t k = 0; k < nh; ++k) {
    const std::size_t i = order[k];
    if (!out.horizontal_deg.empty() && std::abs(out.horizontal_deg.back() - t.horizontal_deg[i]) < 1e-9)
      continue;
    append_plane(out, t.horizontal_deg[i], t, i);
  }
  (void)nv;
  return out;
}
inline double wrap360(double a) {
  a = std::fmod(a, 360.0);
  if (a < 0) a += 360.0;
  return a;
}
}  // namespace detail

/// Mirrors the stored subset to the full horizontal circle (Type C) or to negative H (lateral).
/// Rotational data stays a single plane (it holds for every C). Throws std::invalid_argument if the
/// stored range does not match the symmetry.
inline AngleTable expand(const AngleTable& stored, Symmetry s) {
  double first = 0, last = 0;
  const auto& h = stored.horizontal_deg;
  if (h.empty()) throw std::invalid_argument("expand: no horizontal angles");
  if (stored_range(s, first, last) &&
      (std::abs(h.front() - first) > 1e-6 || std::abs(h.back() - last) > 1e-6))
    throw std::invalid_argument(std::string("expand: stored horizontal range does not match symmetry ") +
                                to_string(s));
  AngleTable out;
  out.vertical_deg = stored.vertical_deg;
  switch (s) {
    case Symmetry::none:
    case Symmetry::rotational:
      return stored;
    case Symmetry::plane_c0_c180:
      for (std::size_t i = 0; i < h.size(); ++i) {
        detail::append_plane(out, h[i], stored, i);
        if (h[i] > 0 && h[i] < 180) detail::append_plane(out, 360.0 - h[i], stored, i);
      }
      break;
    case Symmetry::plane_c90_c270:
      for (std::size_t i = 0; i < h.size(); ++i) {
        detail::append_plane(out, h[i], stored, i);
        if (h[i] > 90 && h[i] < 270) detail::append_plane(out, detail::wrap360(180.0 - h[i]), stored, i);
      }
      break;
    case Symmetry::quadrant:
      for (std::size_t i = 0; i < h.size(); ++i) {
        const double c = h[i];
        detail::append_plane(out, c, stored, i);
        detail::append_plane(out, 180.0 - c, stored, i);
        detail::append_plane(out, 180.0 + c, stored, i);
        if (c > 0) detail::append_plane(out, 360.0 - c, stored, i);
      }
      break;
    case Symmetry::lateral:
      for (std::size_t i = 0; i < h.size(); ++i) {
        detail::append_plane(out, h[i], stored, i);
        if (h[i] > 0) detail::append_plane(out, -h[i], stored, i);
      }
      break;
  }
  return detail::sort_planes(out);
}

/// Inverse of expand(): selects the planes `s` stores. Returns nullopt if `full` lacks a plane the
/// symmetry needs (e.g. no C90 plane for quadrant symmetry). It does not check that the data really is
/// symmetric.
inline std::optional<AngleTable> compact(const AngleTable& full, Symmetry s) {
  if (s == Symmetry::none) return full;
  AngleTable out;
  out.vertical_deg = full.vertical_deg;
  double first = 0, last = 0;
  if (s == Symmetry::lateral) {
    first = 0;
    last = 1e300;
  } else {
    stored_range(s, first, last);
  }
  bool have_first = false, have_last = (s == Symmetry::lateral);
  for (std::size_t i = 0; i < full.horizontal_deg.size(); ++i) {
    const double c = full.horizontal_deg[i];
    if (c < first - 1e-9 || c > last + 1e-9) continue;
    if (std::abs(c - first) < 1e-9) have_first = true;
    if (std::abs(c - last) < 1e-9) have_last = true;
    detail::append_plane(out, c, full, i);
    if (s == Symmetry::rotational) break;
  }
  if (s == Symmetry::rotational && full.horizontal_deg.size() >= 1 && !have_first) {
    // A rotationally symmetric table may name its single plane other than 0; keep it as C0.
    out.horizontal_deg.clear();
    out.candela.clear();
    detail::append_plane(out, 0.0, full, 0);
    return out;
  }
  if (!have_first || !have_last) return std::nullopt;
  return out;
}

LUMX_NAMESPACE_END
