// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Shared helpers for the test suite: where the test data lives.
#pragma once

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace lumx_test {

/// tests/data in the source tree.
inline std::filesystem::path data_dir() { return LUMX_TEST_DATA_DIR; }

/// ../shared beside the repository (or $LUMX_SHARED_DIR). Empty path if absent: tests that need it
/// call GTEST_SKIP() with a message then (outside CI only; CI always has it).
inline std::filesystem::path shared_dir() {
  const char* env = std::getenv("LUMX_SHARED_DIR");
  std::filesystem::path p = env && *env ? env : LUMX_SHARED_DIR_DEFAULT;
  return std::filesystem::exists(p / "data" / "photometry") ? p : std::filesystem::path();
}

/// Every file under shared/data/photometry with one of the given lower-case extensions, sorted.
inline std::vector<std::filesystem::path> shared_photometry_files(const std::vector<std::string>& exts) {
  std::vector<std::filesystem::path> out;
  const auto root = shared_dir();
  if (root.empty()) return out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(root / "data" / "photometry")) {
    if (!e.is_regular_file()) continue;
    std::string ext = e.path().extension().string();
    for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    for (const auto& want : exts)
      if (ext == want) out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace lumx_test
