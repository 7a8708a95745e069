// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Repeated member names in one JSON object (RFC 8259 §4: names SHOULD be unique; hard-cases.md §6 item 31).
// nlohmann/json keeps the last of two equal names, other parsers the first, so a document with both would
// mean different things to different tools: lumx's readers refuse it, naming the member by JSON pointer.
#pragma once

#include <lumx/version.h>

#include <set>
#include <string>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace detail {

/// A parser callback for nlohmann::basic_json::parse that records the JSON pointer of the first member
/// name repeated within one object. Use: `RepeatedMemberWatch<json> w; j = json::parse(b, e, w.callback());
/// if (!w.repeated().empty()) ...`. The callback keeps every value (it never filters).
template <class Json>
class RepeatedMemberWatch {
 public:
  typename Json::parser_callback_t callback() {
    return [this](int, typename Json::parse_event_t event, Json& parsed) {
      using E = typename Json::parse_event_t;
      switch (event) {
        case E::object_start: frames_.push_back({false, 0, {}, {}}); break;
        case E::array_start: frames_.push_back({true, 0, {}, {}}); break;
        case E::key:
          if (!frames_.empty()) {
            Frame& f = frames_.back();
            f.key = parsed.template get<std::string>();
            if (!f.names.insert(f.key).second && repeated_.empty()) repeated_ = pointer();
          }
          break;
        case E::object_end:
        case E::array_end:
          if (!frames_.empty()) frames_.pop_back();
          next_element();
          break;
        case E::value: next_element(); break;
      }
      return true;
    };
  }
  /// JSON pointer of the first repeated member ("/a/0/b"), or "" if every object's names are unique.
  const std::string& repeated() const { return repeated_; }

 private:
  struct Frame {
    bool is_array;
    std::size_t index;  // arrays: the element being read
    std::string key;    // objects: the member being read
    std::set<std::string> names;
  };
  void next_element() {
    if (!frames_.empty() && frames_.back().is_array) ++frames_.back().index;
  }
  std::string pointer() const {
    std::string p;
    for (const Frame& f : frames_) {
      p += '/';
      if (f.is_array) {
        p += std::to_string(f.index);
        continue;
      }
      for (char c : f.key) p += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
    }
    return p;
  }
  std::vector<Frame> frames_;
  std::string repeated_;
};

}  // namespace detail
LUMX_NAMESPACE_END
