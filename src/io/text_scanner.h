// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Internal: line splitting, tokenising and strict number parsing shared by the text-format readers.
#pragma once

#include <lumx/core/diagnostic.h>

#include "photometry/number_text.h"  // format_number, which the writers use

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace detail {

/// One physical line (without its terminator) and its 1-based number.
struct Line {
  std::string_view text;
  int number = 0;
};

/// Reads lines one at a time (CRLF, LF or lone CR; a UTF-8 BOM at the start is skipped), so a reader
/// that needs only a file's first lines does not split all of it.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text);
  /// The next line, or false at the end of the text.
  bool next(Line& line);
  /// Byte offset and number of the line that next() would return.
  std::size_t offset() const { return pos_; }
  int number() const { return number_; }
  std::string_view text() const { return text_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int number_ = 1;
};

/// Splits on CRLF, LF or lone CR. A UTF-8 byte-order mark at the start is dropped. A final line
/// without a terminator is kept; trailing empty lines are kept too (callers skip them).
std::vector<Line> split_lines(std::string_view text);

/// Strips leading and trailing blanks (space, tab, and stray NUL / form feed).
std::string_view trim(std::string_view s);

/// Text as UTF-8: returned unchanged if it is valid UTF-8, else decoded as ISO-8859-1 (Latin-1), the
/// other encoding real IES files use (formats.md §1.6).
std::string to_utf8(std::string_view s);

/// Strict decimal number: optional sign, digits with optional '.', optional exponent; the whole token
/// must be consumed; NaN and infinities are refused. Accepts ".5" and "5.".
bool parse_number(std::string_view token, double& out);


/// At most `max_bytes` of `s`, made valid UTF-8 (for quoting file content in diagnostics, which end up
/// in JSON).
std::string excerpt(std::string_view s, std::size_t max_bytes = 40);

/// A token of a numeric stream with the line it came from.
struct Token {
  std::string_view text;
  int line = 0;
};


}  // namespace detail
LUMX_NAMESPACE_END
