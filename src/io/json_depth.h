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

/// Byte offset of the first '[' or '{' (outside strings) that opens nesting level `max_depth + 1`, or
/// std::string_view::npos if the text never nests that deep. Linear, no allocation.
inline std::size_t json_too_deep_at(std::string_view text, std::size_t max_depth = kMaxJsonDepth) {
  std::size_t depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return i;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return std::string_view::npos;
}

}  // namespace detail
LUMX_NAMESPACE_END
