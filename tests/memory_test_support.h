// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Memory measurements for the tests that bound a reader's or writer's peak memory (Linux /proc).
#pragma once

#include <cstring>
#include <fstream>
#include <string>

namespace lumx_test {

/// A field of /proc/self/status in kB ("VmRSS:", "VmHWM:"); -1 if absent.
inline long proc_status_kb(const char* key) {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind(key, 0) == 0) return std::stol(line.substr(std::strlen(key)));
  return -1;
}

/// Resets the peak RSS (VmHWM) to the current RSS (Linux clear_refs 5), so that a test measures its own
/// peak even after other tests ran in the same process; false if the kernel refuses.
inline bool reset_peak_rss() {
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
  f.flush();
  return static_cast<bool>(f);
}

}  // namespace lumx_test
