// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// Shared helpers for the test suite: where the test data lives.
#pragma once

#include <lumx/photometry/intensity_table.h>
#include <lumx/photometry/photometric_frame.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace lumx_test {

/// A path in the temporary folder unique to this test process (name + pid), so that concurrent test runs
/// never share scratch files.
inline std::filesystem::path unique_temp_path(const std::string& name) {
  const std::filesystem::path n(name);  // the pid goes before the extension: "rays.tm25ray" -> "rays_123.tm25ray"
  return std::filesystem::temp_directory_path() /
         (n.stem().string() + "_" + std::to_string(::getpid()) + n.extension().string());
}

/// unique_temp_path(name) as an empty folder (whatever a previous run left there is removed).
inline std::filesystem::path fresh_temp_dir(const std::string& name) {
  const std::filesystem::path p = unique_temp_path(name);
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

/// True in the sanitizer build (Debug at -Og, ASan + UBSan: about three times slower, ten at -O0), where the
/// longest tests run a short form of the same code paths (coarser maps, fewer rays); the release run keeps
/// the full form and its figures.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

/// In the sanitizer build (about three times slower), every `stride`-th item of a sweep over real files, and
/// how many the release build's bound on the count should be divided by; elsewhere everything, and 1.
/// Sweeps keep every file in the release run; under the sanitizers a subset runs the same code paths.
#if defined(__SANITIZE_ADDRESS__)
constexpr std::size_t kSanitizerStride = 4;
#else
constexpr std::size_t kSanitizerStride = 1;
#endif
template <class T>
std::vector<T> sanitizer_subset(const std::vector<T>& all) {
  std::vector<T> out;
  for (std::size_t i = 0; i < all.size(); i += kSanitizerStride) out.push_back(all[i]);
  return out;
}

/// tests/data in the source tree: only files lumx made itself (bad-input corpus, synthetic fixtures).
inline std::filesystem::path data_dir() { return LUMX_TEST_DATA_DIR; }

/// True under CI (CI=true in the environment), where ../shared is always present.
inline bool in_ci() {
  const char* ci = std::getenv("CI");
  return ci && *ci && std::string(ci) != "false" && std::string(ci) != "0";
}

/// ../shared beside the repository (or $LUMX_SHARED_DIR). Empty path if absent: tests that need it
/// use LUMX_SKIP_WITHOUT_SHARED then. Third-party files (real IES/LDT and ray files) are read there in
/// place and never copied into the repository.
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

/// shared/data/photometry/<relative>, or an empty path if ../shared is absent.
inline std::filesystem::path shared_photometry(const std::string& relative) {
  const auto root = shared_dir();
  return root.empty() ? std::filesystem::path() : root / "data" / "photometry" / relative;
}

/// Largest |I_a − I_b| (cd) over every stored direction of `a`'s expanded grid: what a conversion changed
/// where `a` has data.
inline double max_candela_difference(const lumx::Photometry& a, const lumx::Photometry& b) {
  const lumx::IntensityTable ta(a), tb(b);
  double worst = 0;
  for (double h : ta.horizontal_deg())
    for (double v : a.vertical_deg) {
      const glm::dvec3 d = lumx::direction_from_angles(a.type, h, v);
      worst = std::max(worst, std::abs(ta.intensity(d) - tb.intensity(d)));
    }
  return worst;
}

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace lumx_test

/// Ends a test that needs ../shared/<what> when it is absent: a skip with a clear message on a developer's
/// machine, a failure under CI (which always has ../shared beside the clone).
#define LUMX_SKIP_WITHOUT_SHARED(what)                                                              \
  do {                                                                                              \
    if (::lumx_test::in_ci()) FAIL() << "../shared/" << (what) << " is missing, but CI always has it"; \
    GTEST_SKIP() << "../shared/" << (what) << " is not present (real-world data is read in place there)"; \
  } while (0)
