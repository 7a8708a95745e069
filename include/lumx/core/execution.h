// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/core/execution.h — how long-running engine calls run: threads, progress and cancellation, passed
// once as one object.
#pragma once

#include <lumx/version.h>

#include <algorithm>
#include <atomic>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>

LUMX_NAMESPACE_BEGIN

/// Thrown by an engine call that saw ExecutionContext::cancel set; nothing it was writing is left behind.
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("cancelled") {}
};

/// Threads, progress and cancellation of one call. Results never depend on `threads` (every engine sums in
/// a fixed order), only the time they take.
struct ExecutionContext {
  /// Worker threads; 0 means one per hardware thread. The only meaning of 0 anywhere in lumx.
  unsigned threads = 0;
  /// Called from the calling thread with the fraction done in [0, 1] and a short stage name; may be empty.
  std::function<void(double fraction, const std::string& stage)> progress;
  /// Polled between units of work; when it reads true the call throws Cancelled. May be null.
  const std::atomic<bool>* cancel = nullptr;

  /// `threads` resolved: at least 1.
  unsigned thread_count() const {
    return threads != 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
  }
  void report(double fraction, const std::string& stage) const {
    if (progress) progress(std::clamp(fraction, 0.0, 1.0), stage);
  }
  /// Throws Cancelled when cancellation was asked for.
  void check_cancelled() const {
    if (cancel && cancel->load(std::memory_order_relaxed)) throw Cancelled();
  }
};

LUMX_NAMESPACE_END
