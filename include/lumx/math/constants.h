// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/constants.h — π and the degree/radian factors, in double precision.
#pragma once

#include <lumx/version.h>

LUMX_NAMESPACE_BEGIN

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;

LUMX_NAMESPACE_END
