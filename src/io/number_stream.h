// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Internal: a cursor over the numbers of a text, reporting every problem at the number's line.
//
// It scans the text in place (numbers separated by blanks, tabs, commas or line breaks — the LM-63-2002
// delimiters), so reading a file costs no memory beyond the values kept: a hostile or huge file cannot
// make the reader allocate per token. remaining() counts ahead without storing anything.
#pragma once

#include <lumx/core/diagnostic.h>

#include "io/text_scanner.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace detail {

class NumberStream {
 public:
  using Warn = std::function<void(int line, const std::string& field, const std::string& message)>;

  /// Numbers of `text` from byte `offset` on, where line `line_at_offset` begins; that line also
  /// locates an error when no number is left.
  NumberStream(std::string_view text, std::size_t offset, int line_at_offset, std::string file)
      : text_(text), pos_(std::min(offset, text.size())), line_(line_at_offset), file_(std::move(file)),
        last_line_(std::max(1, line_at_offset - 1)) {}

  /// How many numbers (tokens) are left; scans ahead, allocates nothing.
  std::size_t remaining() const {
    std::size_t p = pos_, n = 0;
    int line = line_;
    std::string_view tok;
    while (scan(p, line, tok)) ++n;
    return n;
  }
  int last_line() const { return last_line_; }
  /// Line of the next token (or the last line read, at the end).
  int peek_line() const {
    std::size_t p = pos_;
    int line = line_;
    std::string_view tok;
    return scan(p, line, tok) ? line : last_line_;
  }

  [[noreturn]] void fail_at_last(const std::string& field, const std::string& message) const {
    throw_at_line(file_, last_line_, field, message);
  }

  /// Next value as a finite number.
  double next_number(const std::string& field) {
    std::string_view tok;
    if (!scan(pos_, line_, tok)) throw_at_line(file_, last_line_, field, "file ends before this value");
    last_line_ = line_;
    double v = 0;
    if (!parse_number(tok, v))
      throw_at_line(file_, line_, field, "expected a finite number, found '" + excerpt(tok) + "'");
    return v;
  }

  /// Next value as a whole number in [lo, hi]; "3.7", "1e10" (out of range) and "nan" are refused.
  long next_integer(const std::string& field, long lo, long hi) {
    const double v = next_number(field);
    if (v != std::floor(v)) throw_at_line(file_, last_line_, field, "expected a whole number, found " + format(v));
    if (v < static_cast<double>(lo) || v > static_cast<double>(hi))
      throw_at_line(file_, last_line_, field,
                    "value " + format(v) + " outside the accepted range " + std::to_string(lo) + ".." +
                        std::to_string(hi));
    return static_cast<long>(v);
  }

  /// Next value as a count in [lo, limit], where `limit` comes from an option the error names
  /// ("ReadLimits::max_angles"), so that an embedder knows what to raise.
  long next_count(const std::string& field, long lo, std::size_t limit, const char* limit_name) {
    const long hi = static_cast<long>(std::min<std::size_t>(limit, static_cast<std::size_t>(LONG_MAX)));
    const double v = next_number(field);
    if (v != std::floor(v)) throw_at_line(file_, last_line_, field, "expected a whole number, found " + format(v));
    if (v < static_cast<double>(lo))
      throw_at_line(file_, last_line_, field, "value " + format(v) + " is below " + std::to_string(lo));
    if (v > static_cast<double>(hi))
      throw_at_line(file_, last_line_, field,
                    "value " + format(v) + " exceeds " + limit_name + " (" + std::to_string(limit) + ")");
    return static_cast<long>(v);
  }

  /// Throws unless at least `n` values remain (checked before anything is sized from `n`).
  void require_remaining(std::size_t n, const std::string& field) const {
    const std::size_t left = remaining();
    if (left < n)
      throw_at_line(file_, last_line_, field,
                    "file ends after " + std::to_string(left) + " of the " + std::to_string(n) + " values that follow");
  }

  /// Next `n` finite numbers; `lines` (optional) receives each value's line. Storage grows only with
  /// values actually present, so a hostile count cannot allocate more than the file holds.
  std::vector<double> next_values(std::size_t n, const std::string& field, std::vector<std::uint32_t>* lines) {
    std::vector<double> out;
    const std::size_t expect = std::min(n, remaining());
    out.reserve(expect);
    if (lines) lines->reserve(expect);
    for (std::size_t i = 0; i < n; ++i) {
      std::string_view tok;
      if (!scan(pos_, line_, tok))
        throw_at_line(file_, last_line_, field,
                      "file ends after " + std::to_string(i) + " of " + std::to_string(n) + " values (missing value " +
                          std::to_string(i + 1) + ")");
      last_line_ = line_;
      double v = 0;
      if (!parse_number(tok, v))  // the field name is only built on failure (hot path)
        throw_at_line(file_, line_, field + " " + std::to_string(i + 1) + " of " + std::to_string(n),
                      "expected a finite number, found '" + excerpt(tok) + "'");
      out.push_back(v);
      if (lines) lines->push_back(static_cast<std::uint32_t>(line_));
    }
    return out;
  }

 private:
  static bool delimiter(char c) {
    return c == ' ' || c == '\t' || c == ',' || c == '\0' || c == '\f' || c == '\v';
  }

  /// Advances `p` past delimiters and line breaks (CR LF, LF or lone CR each count one line) to the
  /// next token; false at the end of the text.
  bool scan(std::size_t& p, int& line, std::string_view& tok) const {
    const std::size_t n = text_.size();
    while (p < n) {
      const char c = text_[p];
      if (c == '\n' || c == '\r') {
        ++line;
        p += (c == '\r' && p + 1 < n && text_[p + 1] == '\n') ? 2 : 1;
      } else if (delimiter(c)) {
        ++p;
      } else {
        break;
      }
    }
    if (p >= n) return false;
    const std::size_t b = p;
    while (p < n && !delimiter(text_[p]) && text_[p] != '\n' && text_[p] != '\r') ++p;
    tok = text_.substr(b, p - b);
    return true;
  }

  static std::string format(double v) { return format_number(v, 10); }

  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 1;  ///< line at pos_
  std::string file_;
  int last_line_ = 0;
};

}  // namespace detail
LUMX_NAMESPACE_END
