// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// lumx/math/detail/parallel_jobs.h — independent jobs spread over a few threads, for the header-only
// modules (the compiled ones use TBB).
//
// Thread t runs jobs t, t + T, t + 2T, …: interleaved, so jobs whose cost grows or shrinks with their
// index (a map's chunks of texels, mostly empty at one end) still split evenly. Each job must write only
// its own outputs; then the result is the same for any thread count. The calling thread is thread 0. An
// exception from a job stops that thread's remaining jobs and is rethrown to the caller once every thread
// has finished (the lowest thread's first); a thread that cannot be started has its jobs run by the caller.
#pragma once

#include <lumx/version.h>

#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

LUMX_NAMESPACE_BEGIN
namespace detail {

/// The threads parallel_jobs(jobs, threads, …, min_jobs_per_thread) runs on: `threads` (0: the
/// hardware's, at most 8), no more than jobs / min_jobs_per_thread (jobs too cheap to be worth a thread
/// each), at least 1.
inline unsigned parallel_threads(std::size_t jobs, unsigned threads, std::size_t min_jobs_per_thread = 1) {
  if (threads == 0) threads = std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
  const std::size_t worth = std::max<std::size_t>(1, jobs / std::max<std::size_t>(1, min_jobs_per_thread));
  return unsigned(std::min<std::size_t>(threads, worth));
}

/// job(j) for j in [0, jobs) on parallel_threads(jobs, threads, min_jobs_per_thread) threads.
template <class Job>
void parallel_jobs(std::size_t jobs, unsigned threads, Job&& job, std::size_t min_jobs_per_thread = 1) {
  threads = parallel_threads(jobs, threads, min_jobs_per_thread);
  if (threads <= 1) {
    for (std::size_t j = 0; j < jobs; ++j) job(j);
    return;
  }
  std::vector<std::exception_ptr> failed(threads);
  const auto run = [&job, &failed, jobs, threads](unsigned t) {
    try {
      for (std::size_t j = t; j < jobs; j += threads) job(j);
    } catch (...) {
      failed[t] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  unsigned started = 1;
  try {
    pool.reserve(threads - 1);
    for (; started < threads; ++started) pool.emplace_back(run, started);
  } catch (...) {
    // No more threads to be had: the caller runs the rest.
  }
  run(0);
  for (unsigned t = started; t < threads; ++t) run(t);
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
}

}  // namespace detail
LUMX_NAMESPACE_END
