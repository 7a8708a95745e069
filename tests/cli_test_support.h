// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Running the lumx command-line tool and the sample programs from tests, as a user would (popen).
#pragma once

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include <sys/wait.h>

namespace lumx_test {

struct CliRun {
  int status = -1;
  std::string out;  ///< stdout, and stderr when merged
};

/// Runs `PROGRAM ARGS`; stderr is merged into `out` unless `stderr_too` is false (then discarded).
inline CliRun run_program(const std::string& program, const std::string& args, bool stderr_too = true) {
  const std::string cmd = "\"" + program + "\" " + args + (stderr_too ? " 2>&1" : " 2>/dev/null");
  CliRun r;
  FILE* f = popen(cmd.c_str(), "r");
  if (!f) return r;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = fread(buf.data(), 1, buf.size(), f)) > 0) r.out.append(buf.data(), n);
  const int st = pclose(f);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

/// Runs `lumx ARGS` (see run_program).
inline CliRun run_cli(const std::string& args, bool stderr_too = true) { return run_program(LUMX_CLI_PATH, args, stderr_too); }

/// A path in double quotes, for a shell command line.
inline std::string quoted(const std::filesystem::path& p) { return "\"" + p.string() + "\""; }

}  // namespace lumx_test
