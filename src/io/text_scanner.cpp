// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
#include "io/text_scanner.h"

#include <algorithm>
#include <charconv>
#include <cmath>

LUMX_NAMESPACE_BEGIN
namespace detail {

LineCursor::LineCursor(std::string_view text) : text_(text) {
  if (text.size() >= 3 && static_cast<unsigned char>(text[0]) == 0xEF &&
      static_cast<unsigned char>(text[1]) == 0xBB && static_cast<unsigned char>(text[2]) == 0xBF)
    pos_ = 3;
}

bool LineCursor::next(Line& line) {
  if (pos_ >= text_.size()) return false;
  const std::size_t b = pos_;
  std::size_t e = b;
  while (e < text_.size() && text_[e] != '\n' && text_[e] != '\r') ++e;
  line = {text_.substr(b, e - b), number_++};
  pos_ = e;
  if (pos_ < text_.size()) pos_ += (text_[pos_] == '\r' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '\n') ? 2 : 1;
  return true;
}

std::vector<Line> split_lines(std::string_view text) {
  if (text.size() >= 3 && static_cast<unsigned char>(text[0]) == 0xEF &&
      static_cast<unsigned char>(text[1]) == 0xBB && static_cast<unsigned char>(text[2]) == 0xBF)
    text.remove_prefix(3);
  std::vector<Line> lines;
  std::size_t start = 0;
  int number = 1;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n' || c == '\r') {
      lines.push_back({text.substr(start, i - start), number++});
      if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
      start = i + 1;
    }
  }
  if (start < text.size()) lines.push_back({text.substr(start), number});
  return lines;
}

std::string_view trim(std::string_view s) {
  auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\0' || c == '\f' || c == '\v'; };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

namespace {
bool valid_utf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    std::size_t n = 0;
    if (c < 0x80) n = 0;
    else if ((c >> 5) == 0x6) n = 1;
    else if ((c >> 4) == 0xE) n = 2;
    else if ((c >> 3) == 0x1E) n = 3;
    else return false;
    if (n > 0 && i + n >= s.size()) return false;  // sequence cut off by the end
    for (std::size_t k = 1; k <= n; ++k)
      if ((static_cast<unsigned char>(s[i + k]) >> 6) != 0x2) return false;
    i += n + 1;
  }
  return true;
}
}  // namespace

std::string to_utf8(std::string_view s) {
  if (valid_utf8(s)) return std::string(s);
  std::string out;
  out.reserve(s.size() + s.size() / 4);
  for (char ch : s) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c < 0x80) {
      out.push_back(ch);
    } else {
      out.push_back(static_cast<char>(0xC0 | (c >> 6)));
      out.push_back(static_cast<char>(0x80 | (c & 0x3F)));
    }
  }
  return out;
}

bool parse_number(std::string_view token, double& out) {
  if (token.empty()) return false;
  if (token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  // from_chars would accept "nan", "inf" and hex-free forms only; refuse anything not starting like a number.
  const char c0 = token.front();
  if (!(c0 == '-' || c0 == '.' || (c0 >= '0' && c0 <= '9'))) return false;
  double v = 0;
  const auto r = std::from_chars(token.data(), token.data() + token.size(), v, std::chars_format::general);
  if (r.ec != std::errc() || r.ptr != token.data() + token.size()) return false;
  if (!std::isfinite(v)) return false;
  out = v;
  return true;
}

std::string excerpt(std::string_view s, std::size_t max_bytes) {
  return to_utf8(s.substr(0, max_bytes));
}


}  // namespace detail
LUMX_NAMESPACE_END
