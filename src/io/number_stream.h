// Internal: a cursor over numeric tokens that reports every problem at the token's line.
#pragma once

#include <lumx/diagnostic.h>

#include "io/text_scanner.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace detail {

class NumberStream {
 public:
  using Warn = std::function<void(int line, const std::string& field, const std::string& message)>;

  /// `line_before` locates an error when the stream is empty (the line the numbers should follow).
  NumberStream(const std::vector<Token>& tokens, std::string file, int line_before)
      : tokens_(tokens), file_(std::move(file)), last_line_(line_before) {}

  std::size_t remaining() const { return tokens_.size() - pos_; }
  int last_line() const { return last_line_; }
  int peek_line() const { return pos_ < tokens_.size() ? tokens_[pos_].line : last_line_; }

  [[noreturn]] void fail_at_last(const std::string& field, const std::string& message) const {
    throw_at_line(file_, last_line_, field, message);
  }

  /// Next value as a finite number.
  double next_number(const std::string& field) {
    if (pos_ >= tokens_.size()) throw_at_line(file_, last_line_, field, "file ends before this value");
    const Token& t = tokens_[pos_++];
    last_line_ = t.line;
    double v = 0;
    if (!parse_number(t.text, v))
      throw_at_line(file_, t.line, field, "expected a finite number, found '" + excerpt(t.text) + "'");
    return v;
  }

  /// Next value as a whole number in [lo, hi]; "3.7", "1e10" (out of range) and "nan" are refused.
  long next_integer(const std::string& field, long lo, long hi) {
    const double v = next_number(field);
    if (v != std::floor(v))
      throw_at_line(file_, last_line_, field, "expected a whole number, found " + format(v));
    if (v < static_cast<double>(lo) || v > static_cast<double>(hi))
      throw_at_line(file_, last_line_, field,
                    "value " + format(v) + " outside the accepted range " + std::to_string(lo) + ".." + std::to_string(hi));
    return static_cast<long>(v);
  }

  /// Throws unless at least `n` values remain (checked before anything is sized from `n`).
  void require_remaining(std::size_t n, const std::string& field) const {
    if (remaining() < n)
      throw_at_line(file_, tokens_.empty() ? last_line_ : tokens_.back().line, field,
                    "file ends after " + std::to_string(remaining()) + " of the " + std::to_string(n) +
                        " values that follow");
  }

  /// Next `n` finite numbers; `lines` (optional) receives each value's line. Storage grows only with
  /// values actually present, so a hostile count cannot allocate more than the file holds.
  std::vector<double> next_values(std::size_t n, const std::string& field, std::vector<std::uint32_t>* lines) {
    std::vector<double> out;
    out.reserve(std::min(n, remaining()));
    if (lines) lines->reserve(std::min(n, remaining()));
    for (std::size_t i = 0; i < n; ++i) {
      if (pos_ >= tokens_.size())
        throw_at_line(file_, last_line_, field,
                      "file ends after " + std::to_string(i) + " of " + std::to_string(n) + " values (missing value " +
                          std::to_string(i + 1) + ")");
      const Token& t = tokens_[pos_++];
      last_line_ = t.line;
      double v = 0;
      if (!parse_number(t.text, v))  // the field name is only built on failure (hot path)
        throw_at_line(file_, t.line, field + " " + std::to_string(i + 1) + " of " + std::to_string(n),
                      "expected a finite number, found '" + excerpt(t.text) + "'");
      out.push_back(v);
      if (lines) lines->push_back(static_cast<std::uint32_t>(last_line_));
    }
    return out;
  }

 private:
  static std::string format(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.10g", v);
    return buf;
  }

  const std::vector<Token>& tokens_;
  std::string file_;
  std::size_t pos_ = 0;
  int last_line_ = 0;
};

}  // namespace detail
LUMX_NAMESPACE_END
