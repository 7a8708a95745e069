// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// converters/progress.h — a one-line progress bar with rate and ETA on stderr, for long runs.
//
// Updates at most ten times a second, and only when stderr is a terminal (or when forced), so logs and
// test output stay clean. `done()` ends the line.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

#include <unistd.h>

namespace lumx_cli {

class ProgressBar {
 public:
  /// `total_items` (e.g. rays) turns the fraction into a rate; 0 shows percentages only.
  explicit ProgressBar(double total_items, const char* unit, bool force = false)
      : total_(total_items), unit_(unit), enabled_(force || ::isatty(STDERR_FILENO)),
        start_(std::chrono::steady_clock::now()) {}
  ~ProgressBar() { done(); }

  /// `status`, when given, replaces the computed rate and ETA (a caller that knows better, e.g. a bake's
  /// passes and error).
  void update(double fraction, const char* phase, const char* status = nullptr) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (fraction < 1.0 && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    fraction = fraction < 0 ? 0 : (fraction > 1 ? 1 : fraction);
    const int width = 30, filled = int(fraction * width + 0.5);
    std::string bar(std::size_t(filled), '#');
    bar.resize(std::size_t(width), '.');
    char tail[200] = "";
    if (status) {
      std::snprintf(tail, sizeof tail, "  %s", status);
    } else if (fraction > 0.01 && elapsed > 0.2) {
      const double eta = elapsed * (1 - fraction) / fraction;
      if (total_ > 0)
        std::snprintf(tail, sizeof tail, "  %.2f M%s/s  ETA %.0f s", total_ * fraction / elapsed / 1e6, unit_, eta);
      else
        std::snprintf(tail, sizeof tail, "  ETA %.0f s", eta);
    }
    std::fprintf(stderr, "\r%-8s [%s] %3.0f %%%s   ", phase, bar.c_str(), 100 * fraction, tail);
    std::fflush(stderr);
    shown_ = true;
  }

  void done() {
    if (shown_) std::fprintf(stderr, "\n");
    shown_ = false;
  }

 private:
  double total_;
  const char* unit_;
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_, last_{};
};

}  // namespace lumx_cli
