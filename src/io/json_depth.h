// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// A nesting-depth check run on JSON text before nlohmann/json parses it. The parser itself does not recurse,
// but every '[' or '{' becomes a value of its own (some 80 bytes of heap each), so a file of brackets would
// cost ~80 times its size; lumx's documents (manifests, glTF, TM-33 JSON) nest less than 20 levels deep.
#pragma once

#include <lumx/version.h>

#include <cstddef>
#include <string_view>

LUMX_NAMESPACE_BEGIN
namespace detail {

/// Nesting depth no lumx reader accepts beyond (hard-cases.md §6 item 30).
constexpr std::size_t kMaxJsonDepth = 256;

/// Calls visit(i, c) for every byte of `text` outside JSON strings (and their escapes), in order, until it
/// returns true; the offset where it did, or npos.
template <class Visit>
std::size_t find_outside_strings(std::string_view text, Visit visit) {
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (visit(i, c)) {
      return i;
    }
  }
  return std::string_view::npos;
}

/// Byte offset of the first '[' or '{' (outside strings) that opens nesting level `max_depth + 1`, or
/// std::string_view::npos if the text never nests that deep. Linear, no allocation.
inline std::size_t json_too_deep_at(std::string_view text, std::size_t max_depth = kMaxJsonDepth) {
  std::size_t depth = 0;
  return find_outside_strings(text, [&](std::size_t, char c) {
    if (c == '[' || c == '{') return ++depth > max_depth;
    if ((c == ']' || c == '}') && depth > 0) --depth;
    return false;
  });
}

/// Byte offset of the first number token equal to `token` outside strings, or npos. nlohmann/json reports a
/// number beyond double's range (out_of_range 406) without its position; this finds it again.
inline std::size_t json_number_at(std::string_view text, std::string_view token) {
  const auto part_of_number = [](char c) { return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.' || c == 'e' || c == 'E'; };
  return find_outside_strings(text, [&](std::size_t i, char) {
    return text.compare(i, token.size(), token) == 0 && (i == 0 || !part_of_number(text[i - 1])) &&
           (i + token.size() == text.size() || !part_of_number(text[i + token.size()]));
  });
}

/// The position-free exception's number, quoted in its message ("... parsing '1e400'"), found in `text`.
inline std::size_t json_overflow_at(std::string_view text, const std::string& message) {
  const std::size_t open = message.find('\'');
  const std::size_t close = open == std::string::npos ? open : message.find('\'', open + 1);
  if (close == std::string::npos) return std::string_view::npos;
  return json_number_at(text, std::string_view(message).substr(open + 1, close - open - 1));
}

}  // namespace detail
LUMX_NAMESPACE_END
