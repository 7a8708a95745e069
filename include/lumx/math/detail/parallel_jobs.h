// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/detail/parallel_jobs.h — independent jobs spread over a few threads, for the header-only
// modules (the compiled ones use TBB).
//
// Thread t runs jobs t, t + T, t + 2T, …: interleaved, so jobs whose cost grows or shrinks with their
// index (a map's chunks of texels, mostly empty at one end) still split evenly. Each job must write only
// its own outputs; then the result is the same for any thread count.
#pragma once

#include <lumx/version.h>

#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace detail {

/// job(j) for j in [0, jobs) on up to `threads` threads (0: the hardware's, at most 8), and no more threads
/// than jobs / min_jobs_per_thread (jobs too cheap to be worth a thread each).
template <class Job>
void parallel_jobs(std::size_t jobs, unsigned threads, Job&& job, std::size_t min_jobs_per_thread = 1) {
  if (threads == 0) threads = std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
  threads = unsigned(
      std::min<std::size_t>(threads, std::max<std::size_t>(1, jobs / std::max<std::size_t>(1, min_jobs_per_thread))));
  if (threads <= 1) {
    for (std::size_t j = 0; j < jobs; ++j) job(j);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(threads);
  for (unsigned t = 0; t < threads; ++t)
    pool.emplace_back([&job, jobs, threads, t] {
      for (std::size_t j = t; j < jobs; j += threads) job(j);
    });
  for (std::thread& t : pool) t.join();
}

}  // namespace detail
LUMX_NAMESPACE_END
