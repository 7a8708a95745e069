// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/bounding_sphere.h — a sphere enclosing a luminaire's emitting points (a rayset's start
// points, an APL set's positions); relative distances d are measured from its centre in units of its radius.
#pragma once

#include <lumx/version.h>

#include <glm/vec3.hpp>

LUMX_NAMESPACE_BEGIN

struct BoundingSphere {
  glm::dvec3 center{0.0};
  double radius = 0;  ///< m
};

LUMX_NAMESPACE_END
