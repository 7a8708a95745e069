// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Internal: the element tree that both TM-33 syntaxes (XML and the JSON form) are read into and written
// from, so that one mapping to the photometry model serves both (docs/tm33.md).
//
// Reading locates every node: the line of an XML element, the JSON pointer of a JSON value. Both parsers
// bound what they build: a DTD is refused (no entity expansion), nesting deeper than kMaxDepth is
// refused, and the input size is bounded by the caller (ReadLimits::max_file_bytes).
#pragma once

#include <lumx/core/diagnostic.h>
#include <lumx/photometry/photometry.h>

#include <string>
#include <string_view>
#include <utility>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace detail {

/// Strips XML white space (space, tab, CR, LF) from both ends.
inline std::string_view trim_space(std::string_view s) {
  const std::size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

/// Deepest element nesting accepted (TM-33 documents nest about 7 deep).
inline constexpr int kTm33MaxDepth = 64;

struct Tm33Node {
  std::string name;
  std::vector<std::pair<std::string, std::string>> attributes;
  std::string text;  ///< character content, untrimmed
  std::vector<Tm33Node> children;
  int line = 0;         ///< XML: line of the start tag (0 = unknown)
  std::string pointer;  ///< JSON: pointer to the value ("/IESTM33-22/Emitter/0/Quantity")

  const Tm33Node* child(std::string_view n) const {
    for (const auto& c : children)
      if (c.name == n) return &c;
    return nullptr;
  }
  Tm33Node& add(std::string n, std::string t = {}) {
    children.push_back(Tm33Node{std::move(n), {}, std::move(t), {}, 0, {}});
    return children.back();
  }
};

/// Parses XML with libxml2 (no network, no DTD). Throws lumx::Error located by line.
Tm33Node parse_tm33_xml_tree(std::string_view text, const std::string& file);
/// Parses the JSON form: {"<root>": {...}}; keys "@name" are attributes, "#text" the character content,
/// arrays repeat an element. Throws lumx::Error located by JSON pointer (syntax errors by line).
Tm33Node parse_tm33_json_tree(std::string_view text, const std::string& file);

/// XML text of a tree (UTF-8, two-space indentation).
std::string tm33_tree_to_xml(const Tm33Node& root);
/// JSON text of a tree in the form parse_tm33_json_tree reads.
std::string tm33_tree_to_json(const Tm33Node& root);

/// Kept data <-> tree nodes (locations dropped / left empty).
DataElement to_data_element(const Tm33Node& n);
Tm33Node to_tm33_node(const DataElement& e);

}  // namespace detail
LUMX_NAMESPACE_END
