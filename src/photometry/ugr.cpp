// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/core/diagnostic.h>
#include <lumx/math/constants.h>
#include <lumx/photometry/guth_position_index.h>
#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/luminous_area.h>
#include <lumx/photometry/ugr.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>

LUMX_NAMESPACE_BEGIN
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// One cell of the lower hemisphere: the horizontal offset (in units of the mounting height) at which its
// central ray meets a plane below, and the flux (lm) the luminaire sends into it.
struct Cell {
  double along_x_h, along_y_h, lm;
};

// The downward hemisphere on a 0.5° (gamma) × 1° (C) midpoint grid. The floor weight below is continuous
// and the intensity bilinear, so the midpoint rule's error is O(step²): well under 0.1 % of the flux.
std::vector<Cell> downward_cells(const IntensityTable& t, double& down_lm) {
  constexpr int ng = 180, nc = 360;
  const double dg = 90.0 / ng * kDegToRad, dc = 360.0 / nc * kDegToRad;
  std::vector<Cell> cells;
  cells.reserve(static_cast<std::size_t>(ng) * nc);
  down_lm = 0;
  for (int ig = 0; ig < ng; ++ig) {
    const double g = (ig + 0.5) * dg;
    const double sg = std::sin(g), cg = std::cos(g), tg = sg / cg;
    for (int ic = 0; ic < nc; ++ic) {
      const double c = (ic + 0.5) * dc;
      const glm::dvec3 d(sg * std::cos(c), sg * std::sin(c), -cg);
      const double lm = t.intensity(d) * sg * dg * dc;
      down_lm += lm;
      cells.push_back(Cell{tg * std::cos(c), tg * std::sin(c), lm});
    }
  }
  return cells;
}

[[noreturn]] void throw_about(const Photometry& p, int ldt_line, const char* field, const std::string& message) {
  throw_at_line(p.source.file, p.source.format == "EULUMDAT" ? ldt_line : 0, field, message);
}

}  // namespace

std::vector<UgrRoom> standard_ugr_rooms() {
  return {{2, 2}, {2, 3}, {2, 4}, {2, 6}, {2, 8}, {2, 12}, {4, 2},  {4, 3}, {4, 4}, {4, 6},
          {4, 8}, {4, 12}, {8, 4}, {8, 6}, {8, 8}, {8, 12}, {12, 4}, {12, 6}, {12, 8}};
}

std::vector<Reflectances> standard_ugr_reflectances() {
  return {{0.7, 0.5, 0.2}, {0.7, 0.3, 0.2}, {0.5, 0.5, 0.2}, {0.5, 0.3, 0.2}, {0.3, 0.3, 0.2}};
}

double UgrTable::background_cd_m2(std::size_t room, std::size_t reflectance, UgrView view) const {
  const UgrRoomTerms& tm = terms[view == UgrView::crosswise ? 0 : 1].at(room);
  const UgrRoom& r = options.rooms.at(room);
  const double h = options.height_m, x = r.x_h * h, y = r.y_h * h;
  const WallTransferFactors f = wall_transfer_factors(x, y, h, options.reflectances.at(reflectance));
  const double walls_m2 = 2 * h * (x + y);
  // CIE 190 eq. 7/8b: indirect illuminance of the walls, E_WID = N / A_w · Σ Φ_X F_T,XW.
  const double e_wid = static_cast<double>(tm.luminaires) / walls_m2 *
                       (tm.floor_lm * f.floor_to_walls + tm.walls_lm * f.walls_to_walls_minus_one +
                        tm.ceiling_lm * f.ceiling_to_walls);
  return e_wid / kPi;
}

UgrTable ugr_table(const Photometry& p, const UgrTableOptions& o) {
  if (!(o.spacing_to_height > 0) || !(o.height_m > 0) || !std::isfinite(o.spacing_to_height * o.height_m))
    throw std::invalid_argument("UGR: spacing-to-height ratio and height must be finite and > 0");
  for (const UgrRoom& r : o.rooms) {
    if (!(r.x_h > 0) || !(r.y_h > 0) || !std::isfinite(r.x_h * r.y_h))
      throw std::invalid_argument("UGR: room sizes must be finite and > 0");
    if (r.x_h / o.spacing_to_height > 4096 || r.y_h / o.spacing_to_height > 4096)
      throw std::invalid_argument("UGR: more than 4096 luminaires along a room side");
  }
  for (const Reflectances& r : o.reflectances)
    for (double v : {r.ceiling, r.walls, r.floor})
      if (!(v >= 0 && v < 1)) throw std::invalid_argument("UGR: reflectances must lie in [0, 1)");

  const LuminousArea area = luminous_area(p);
  if (area.kind == LuminousArea::Kind::none)
    throw_about(p, 16, "luminous area",
                missing_luminous_area_reason(p) + ": the UGR needs the luminous area to turn intensity into luminance");
  const IntensityTable t(p);
  UgrTable out;
  out.options = o;
  out.luminaire_flux_lm = t.flux_lm();
  if (!(out.luminaire_flux_lm > 0) || !std::isfinite(out.luminaire_flux_lm))
    throw_about(p, 0, "flux", "the luminaire emits no flux: there is no glare to rate");
  double down_lm = 0;
  const std::vector<Cell> cells = downward_cells(t, down_lm);
  const double up_lm = std::max(0.0, out.luminaire_flux_lm - down_lm);

  const double h = o.height_m, s = o.spacing_to_height * h;
  const std::size_t nrefl = o.reflectances.size();
  for (int view = 0; view < 2; ++view) {
    const bool endwise = view == 1;
    out.terms[view].reserve(o.rooms.size());
    for (const UgrRoom& room : o.rooms) {
      const double x = room.x_h * h, y = room.y_h * h;
      UgrRoomTerms tm;
      // Direct flux to the floor from luminaires spread evenly over the ceiling: a ray leaving at horizontal
      // offset (dx, dy) lands inside the X × Y floor for a fraction (1 - |dx|/X)(1 - |dy|/Y) of the
      // luminaire positions. Crosswise the photometric X axis runs along the room's depth Y.
      double floor_lm = 0;
      for (const Cell& c : cells) {
        const double across = std::abs(endwise ? c.along_x_h : c.along_y_h) * h;  // along X (room width)
        const double along = std::abs(endwise ? c.along_y_h : c.along_x_h) * h;   // along Y (room depth)
        if (across < x && along < y) floor_lm += c.lm * (1 - across / x) * (1 - along / y);
      }
      tm.floor_lm = floor_lm;
      tm.walls_lm = std::max(0.0, down_lm - floor_lm);
      tm.ceiling_lm = up_lm;

      const int nx = std::max(1, static_cast<int>(std::floor(x / s + 1e-9)));
      const int ny = std::max(1, static_cast<int>(std::floor(y / s + 1e-9)));
      tm.luminaires = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
      const double t0 = -(nx - 1) * s / 2, r0 = (y - (ny - 1) * s) / 2;
      double sum = 0;
      for (int j = 0; j < ny; ++j) {
        const double r = r0 + j * s;  // ahead of the eye, along the line of sight
        for (int i = 0; i < nx; ++i) {
          const double tt = t0 + i * s;  // to the side
          const double pidx = guth_position_index(tt / r, h / r);
          if (std::isnan(pidx)) continue;  // outside the field of view of CIE 117 Table 4.1
          const double r2 = r * r + tt * tt + h * h;
          const glm::dvec3 d = glm::normalize(endwise ? glm::dvec3(tt, r, -h) : glm::dvec3(r, tt, -h));
          const double cd = t.intensity(d);
          const double ap = area.projected_m2(d);
          ++tm.in_view;
          if (!(cd > 0) || !(ap > 0)) continue;  // nothing luminous is seen from the eye
          // L² ω = (I / A_p)² · A_p / r² = I² / (A_p r²).
          sum += cd * cd / (ap * r2) / (pidx * pidx);
        }
      }
      tm.glare_sum = sum;
      out.terms[view].push_back(tm);
    }
    out.values[view].assign(o.rooms.size() * nrefl, kNan);
    for (std::size_t ir = 0; ir < o.rooms.size(); ++ir)
      for (std::size_t k = 0; k < nrefl; ++k) {
        const double lb = out.background_cd_m2(ir, k, endwise ? UgrView::endwise : UgrView::crosswise);
        const double sum = out.terms[view][ir].glare_sum;
        if (sum > 0 && lb > 0) out.values[view][ir * nrefl + k] = 8 * std::log10(0.25 / lb * sum);
      }
  }
  return out;
}

LUMX_NAMESPACE_END
