// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/cli_support.h — what every lumx subcommand shares: printing diagnostics and turning library
// errors into a located message and exit status 1.
#pragma once

#include <lumx/core/diagnostic.h>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <exception>
#include <string>

namespace lumx_cli {

inline void print_diag(const lumx::Diagnostic& d) { std::fprintf(stderr, "%s\n", d.str().c_str()); }

inline nlohmann::json diag_json(const lumx::Diagnostic& d) {
  nlohmann::json j = {{"severity", lumx::to_string(d.severity)}, {"field", d.field}, {"message", d.message}};
  if (d.line > 0) j["line"] = d.line;
  if (d.byte_offset >= 0) j["byte_offset"] = d.byte_offset;
  if (!d.file.empty()) j["file"] = d.file;
  return j;
}

/// Runs a subcommand body, turning library errors into a located message on stderr and status 1.
template <class Body>
int guarded(const std::string& file, Body body) {
  try {
    return body();
  } catch (const lumx::Error& e) {
    print_diag(e.diagnostic());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", file.c_str(), e.what());
    return 1;
  }
}

}  // namespace lumx_cli
