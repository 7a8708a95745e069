// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include "photometry/number_text.h"

#include <algorithm>
#include <charconv>
#include <cmath>

LUMX_NAMESPACE_BEGIN
namespace detail {

std::string format_number(double v, int significant_digits) {
  if (v == 0) return "0";
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general,
                               std::clamp(significant_digits, 1, 17));
  std::string s(buf, r.ptr);
  // to_chars "general" may choose exponent form for large or small magnitudes; LM-63 and EULUMDAT
  // readers in the wild expect plain decimals, so use fixed notation whenever it stays reasonable.
  if (s.find('e') != std::string::npos && std::abs(v) < 1e15) {
    const int exp10 = static_cast<int>(std::floor(std::log10(std::abs(v))));
    // At most 24 decimals: anything smaller is written as 0 (far below any photometric resolution).
    const int decimals = std::min(24, std::max(0, significant_digits - 1 - exp10));
    const auto r2 = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, decimals);
    s.assign(buf, r2.ptr);
    if (s.find('.') != std::string::npos) {
      while (s.back() == '0') s.pop_back();
      if (s.back() == '.') s.pop_back();
    }
    if (s == "-0") s = "0";
  }
  return s;
}

}  // namespace detail
LUMX_NAMESPACE_END
