// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// src/photometry/number_text.h — numbers as the photometry writers and messages print them.
#pragma once

#include <lumx/version.h>

#include <string>

LUMX_NAMESPACE_BEGIN
namespace detail {

/// Shortest decimal text with at most `significant_digits` significant digits ("12.5", "1000", "0.001"),
/// locale-independent, never "-0". Used by the writers and by validation messages.
std::string format_number(double v, int significant_digits);

}  // namespace detail
LUMX_NAMESPACE_END
