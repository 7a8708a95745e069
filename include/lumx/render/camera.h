// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/render/camera.h — a pinhole camera: pixel → eye ray and point → pixel, in lumx's world frame
// (metres, +Z up, as the photometric frame of lumx/photometry/photometry.h).
//
// The image plane sits at distance 1 in front of the eye; its half-height is tan(fov/2) and its half-width
// that times width/height (square pixels). Pixel (px, py) is continuous: (0, 0) is the top-left corner of
// the top-left pixel and pixel centres are at half-integers, so a renderer jitters inside [x, x+1) × [y, y+1).
#pragma once

#include <lumx/math/constants.h>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <cmath>
#include <string>

LUMX_NAMESPACE_BEGIN
namespace render {

struct CameraRay {
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0.0, 0.0, -1.0};  ///< unit
};

struct PinholeCamera {
  glm::dvec3 position{0.0, -1.4, 1.0};  ///< eye, m
  glm::dvec3 look_at{0.0, 0.0, 1.0};    ///< a point the optical axis passes through, m
  glm::dvec3 up{0.0, 0.0, 1.0};         ///< need not be orthogonal to the axis, only not parallel to it
  double vertical_fov_deg = 60.0;       ///< full vertical field of view, degrees, in (0, 180)
  int width = 480;                      ///< pixels
  int height = 320;                     ///< pixels

  /// Empty when the camera can form an image; otherwise why not (for a located CLI error).
  std::string invalid_reason() const {
    if (!(width > 0 && height > 0 && width <= 16384 && height <= 16384)) return "image size must be 1…16384 pixels";
    if (!(vertical_fov_deg > 0.0 && vertical_fov_deg < 179.0)) return "vertical field of view must be in (0, 179) degrees";
    const glm::dvec3 axis = look_at - position;
    if (!(glm::length(axis) > 1e-9)) return "eye and look-at point coincide";
    const glm::dvec3 side = glm::cross(axis, up);
    if (!(glm::length(side) > 1e-9 * glm::length(axis) * glm::length(up))) return "up is parallel to the view axis";
    return {};
  }

  /// Orthonormal frame: forward (optical axis), right, and the image's up (right-handed, right × up = −forward).
  void frame(glm::dvec3& forward, glm::dvec3& right, glm::dvec3& image_up) const {
    forward = glm::normalize(look_at - position);
    right = glm::normalize(glm::cross(forward, up));
    image_up = glm::cross(right, forward);
  }

  /// The eye ray through the continuous pixel position (px, py).
  CameraRay ray(double px, double py) const {
    glm::dvec3 f, r, u;
    frame(f, r, u);
    const double th = std::tan(0.5 * vertical_fov_deg * kDegToRad);
    const double tw = th * double(width) / double(height);
    const double sx = (2.0 * px / double(width) - 1.0) * tw;
    const double sy = (1.0 - 2.0 * py / double(height)) * th;
    return {position, glm::normalize(f + sx * r + sy * u)};
  }

  /// The continuous pixel position where `p` is seen; false when `p` is not in front of the eye. (px, py)
  /// may fall outside the image.
  bool project(const glm::dvec3& p, double& px, double& py) const {
    glm::dvec3 f, r, u;
    frame(f, r, u);
    const glm::dvec3 v = p - position;
    const double z = glm::dot(v, f);
    if (!(z > 0.0)) return false;
    const double th = std::tan(0.5 * vertical_fov_deg * kDegToRad);
    const double tw = th * double(width) / double(height);
    px = 0.5 * double(width) * (glm::dot(v, r) / (z * tw) + 1.0);
    py = 0.5 * double(height) * (1.0 - glm::dot(v, u) / (z * th));
    return true;
  }
};

}  // namespace render
LUMX_NAMESPACE_END
