// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/core/diagnostic.h — located errors and warnings.
//
// Every problem lumx reports is one Diagnostic: where (file, line or byte offset), which field, and what.
// Library code never prints and never exits: fatal problems are thrown as lumx::Error (carrying the
// Diagnostic), and warnings are passed to a caller-supplied DiagnosticSink.
#pragma once

#include <lumx/version.h>

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

LUMX_NAMESPACE_BEGIN

enum class Severity { note, warning, error };

inline const char* to_string(Severity s) {
  switch (s) {
    case Severity::note: return "note";
    case Severity::warning: return "warning";
    case Severity::error: return "error";
  }
  return "error";
}

/// One located finding. `line` is 1-based (0 = unknown); for binary data `byte_offset` is used instead
/// (-1 = unknown). `field` names the file-format field ("vertical angle count", "Isym", ...).
struct Diagnostic {
  Severity severity = Severity::error;
  std::string file;
  int line = 0;
  std::int64_t byte_offset = -1;
  std::string field;
  std::string message;

  /// Renders "file:line: severity: field: message" (compiler style, so editors can jump to it).
  std::string str() const {
    std::string s = file.empty() ? std::string("<input>") : file;
    if (line > 0) {
      s += ':' + std::to_string(line);
    } else if (byte_offset >= 0) {
      s += ":@" + std::to_string(byte_offset);
    }
    s += ": ";
    s += to_string(severity);
    s += ": ";
    if (!field.empty()) s += field + ": ";
    s += message;
    return s;
  }
};

/// Receives warnings and notes. May be empty (warnings are then dropped).
using DiagnosticSink = std::function<void(const Diagnostic&)>;

/// A sink that stores everything it receives, for callers that want a list.
struct DiagnosticList {
  std::vector<Diagnostic> items;
  DiagnosticSink sink() {
    return [this](const Diagnostic& d) { items.push_back(d); };
  }
  bool has_errors() const {
    for (const auto& d : items)
      if (d.severity == Severity::error) return true;
    return false;
  }
};

/// The one exception type lumx throws for bad input or failed I/O. what() is Diagnostic::str().
class Error : public std::runtime_error {
 public:
  explicit Error(Diagnostic d) : std::runtime_error(d.str()), diag_(std::move(d)) {}
  const Diagnostic& diagnostic() const noexcept { return diag_; }

 private:
  Diagnostic diag_;
};

/// Convenience: throw an Error about a field of a file, located at a byte offset of a binary file
/// (offset ≥ 0), or without a position (offset −1: folders, JSON located by a pointer in `field`).
[[noreturn]] inline void throw_at_offset(const std::string& file, std::int64_t offset, std::string field,
                                         std::string message) {
  Diagnostic d;
  d.file = file;
  d.byte_offset = offset;
  d.field = std::move(field);
  d.message = std::move(message);
  throw Error(std::move(d));
}

/// Convenience: throw an Error about a field of a file without a position.
[[noreturn]] inline void throw_at_field(const std::string& file, std::string field, std::string message) {
  throw_at_offset(file, -1, std::move(field), std::move(message));
}

/// Convenience: throw an Error located at a line of a text file.
[[noreturn]] inline void throw_at_line(const std::string& file, int line, std::string field,
                                       std::string message) {
  Diagnostic d;
  d.file = file;
  d.line = line;
  d.field = std::move(field);
  d.message = std::move(message);
  throw Error(std::move(d));
}

LUMX_NAMESPACE_END
