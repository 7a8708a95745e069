// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include <lumx/math/constants.h>
#include <lumx/photometry/luminous_area.h>

#include <algorithm>
#include <cmath>

LUMX_NAMESPACE_BEGIN

double LuminousArea::projected_m2(const glm::dvec3& d) const {
  const double sx = size_x_m, sy = size_y_m;
  const double down = std::max(0.0, -d.z);                       // cos gamma towards the bottom face
  const double horizontal = std::sqrt(d.x * d.x + d.y * d.y);    // sin gamma
  // Height of the sides seen from d: the faces facing +-X and +-Y, weighted by how much of each is seen.
  auto side_height = [&](double ux, double uy) {
    const double wx = std::abs(ux), wy = std::abs(uy);
    if (wx + wy <= 0) return 0.0;
    return (wx * side_height_m[ux >= 0 ? 0 : 2] + wy * side_height_m[uy >= 0 ? 1 : 3]) / (wx + wy);
  };
  switch (kind) {
    case Kind::none: return 0.0;
    case Kind::rectangle: {
      const double sides = sy * side_height_m[d.x >= 0 ? 0 : 2] * std::abs(d.x) +
                           sx * side_height_m[d.y >= 0 ? 1 : 3] * std::abs(d.y);
      return sx * sy * down + sides;
    }
    case Kind::ellipse: {
      double a = kPi * sx * sy / 4 * down;
      if (horizontal > 0) {
        const double ux = d.x / horizontal, uy = d.y / horizontal;
        // Silhouette width of a vertical elliptic cylinder seen from (ux, uy): 2 sqrt(a² uy² + b² ux²).
        const double width = std::sqrt(sx * sx * uy * uy + sy * sy * ux * ux);
        a += width * side_height(ux, uy) * horizontal;
      }
      return a;
    }
    case Kind::sphere: return kPi * sx * sx / 4;
    case Kind::cylinder_x:
      return sx * sy * std::sqrt(std::max(0.0, 1 - d.x * d.x)) + kPi * sy * sy / 4 * std::abs(d.x);
    case Kind::cylinder_y:
      return sy * sx * std::sqrt(std::max(0.0, 1 - d.y * d.y)) + kPi * sx * sx / 4 * std::abs(d.y);
    case Kind::disk_x: return kPi * sy * side_height_m[0] / 4 * std::abs(d.x);
  }
  return 0.0;
}

LuminousArea luminous_area(const Photometry& p) {
  LuminousArea a;
  if (p.source.format == "EULUMDAT") {
    const double len = std::abs(p.ldt.area_length_mm) / 1000, wid = std::abs(p.ldt.area_width_mm) / 1000;
    for (int k = 0; k < 4; ++k) a.side_height_m[k] = std::max(0.0, p.ldt.area_height_mm[k] / 1000);
    if (len > 0 && wid > 0) {
      a.kind = LuminousArea::Kind::rectangle;
      a.size_x_m = len;
      a.size_y_m = wid;
    } else if (len > 0) {  // width 0: circular, the length is the diameter
      a.kind = LuminousArea::Kind::ellipse;
      a.size_x_m = a.size_y_m = len;
    }
    return a;
  }
  const LuminousOpening& o = p.opening;
  const double w = std::abs(o.width_m), l = std::abs(o.length_m), h = std::abs(o.height_m);
  auto all_sides = [&](double v) {
    for (double& s : a.side_height_m) s = v;
  };
  switch (o.shape()) {
    case LuminousShape::rectangle:
    case LuminousShape::rectangle_with_luminous_sides:
      a.kind = LuminousArea::Kind::rectangle;
      a.size_x_m = l;
      a.size_y_m = w;
      all_sides(h);
      break;
    case LuminousShape::circle:
    case LuminousShape::ellipse:
    case LuminousShape::vertical_cylinder:
    case LuminousShape::vertical_elliptical_cylinder:
      a.kind = LuminousArea::Kind::ellipse;
      a.size_x_m = l;
      a.size_y_m = w;
      all_sides(h);
      break;
    case LuminousShape::sphere:
    case LuminousShape::ellipsoid:
      a.kind = LuminousArea::Kind::sphere;
      a.size_x_m = a.size_y_m = (w + l + h) / 3;
      break;
    case LuminousShape::horizontal_cylinder_along_length:
    case LuminousShape::horizontal_elliptical_cylinder_along_length:
      a.kind = LuminousArea::Kind::cylinder_x;
      a.size_x_m = l;
      a.size_y_m = (w + h) / 2;
      break;
    case LuminousShape::horizontal_cylinder_along_width:
    case LuminousShape::horizontal_elliptical_cylinder_along_width:
      a.kind = LuminousArea::Kind::cylinder_y;
      a.size_y_m = w;
      a.size_x_m = (l + h) / 2;
      break;
    case LuminousShape::vertical_circle:
    case LuminousShape::vertical_ellipse:
      a.kind = LuminousArea::Kind::disk_x;
      a.size_y_m = w;
      all_sides(h);
      break;
    case LuminousShape::point:
    case LuminousShape::unknown: break;
  }
  return a;
}

std::string missing_luminous_area_reason(const Photometry& p) {
  if (p.source.format != "EULUMDAT" && p.opening.shape() == LuminousShape::unknown)
    return "the opening's signs (width " + std::to_string(p.opening.width_m) + ", length " +
           std::to_string(p.opening.length_m) + ", height " + std::to_string(p.opening.height_m) +
           " m) match no shape of LM-63-2019 Table 1";
  return "none given (a point source)";
}

LUMX_NAMESPACE_END
