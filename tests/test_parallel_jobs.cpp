// SPDX-License-Identifier: Apache-2.0
// Copyright Contributors to the lumx project.
// detail::parallel_jobs: every job runs exactly once, for any thread count and job count, on no more
// threads than asked or than the jobs are worth; a job's exception reaches the caller.
#include <lumx/math/detail/parallel_jobs.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

using lumx::detail::parallel_jobs;

TEST(ParallelJobs, EveryJobRunsOnceForAnyThreadCount) {
  for (std::size_t jobs : {0u, 1u, 7u, 8u, 33u, 1000u}) {
    for (unsigned threads : {0u, 1u, 2u, 3u, 8u, 64u}) {
      for (std::size_t per_thread : {1u, 8u}) {
        std::vector<int> runs(jobs, 0);
        std::mutex m;
        std::set<std::thread::id> ids;
        parallel_jobs(
            jobs, threads,
            [&](std::size_t j) {
              std::lock_guard<std::mutex> lock(m);
              ++runs[j];
              ids.insert(std::this_thread::get_id());
            },
            per_thread);
        for (std::size_t j = 0; j < jobs; ++j)
          ASSERT_EQ(runs[j], 1) << jobs << " jobs, " << threads << " threads, job " << j;
        // Threads used: at most the ones asked for (0: the hardware's, capped at 8), and one per
        // per_thread jobs at most.
        const std::size_t asked = threads == 0 ? 8 : threads;
        const std::size_t worth = std::max<std::size_t>(1, jobs / per_thread);
        EXPECT_LE(ids.size(), std::min(asked, worth)) << jobs << " jobs, " << threads << " threads";
      }
    }
  }
}

TEST(ParallelJobs, OneThreadRunsTheJobsInOrderOnTheCaller) {
  std::vector<std::size_t> order;
  const std::thread::id caller = std::this_thread::get_id();
  bool elsewhere = false;
  parallel_jobs(5, 1, [&](std::size_t j) {
    order.push_back(j);
    elsewhere |= std::this_thread::get_id() != caller;
  });
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3, 4}));
  EXPECT_FALSE(elsewhere);
}

TEST(ParallelJobs, AJobsExceptionReachesTheCallerAfterEveryThreadEnds) {
  for (const unsigned threads : {1u, 2u, 4u}) {
    std::mutex m;
    std::vector<int> runs(40, 0);
    EXPECT_THROW(parallel_jobs(40, threads,
                               [&](std::size_t j) {
                                 {
                                   std::lock_guard<std::mutex> lock(m);
                                   ++runs[j];
                                 }
                                 if (j == 5) throw std::runtime_error("job 5");
                               }),
                 std::runtime_error)
        << threads;
    // No job runs twice, and the threads without a failing job ran all of theirs.
    for (std::size_t j = 0; j < runs.size(); ++j) {
      EXPECT_LE(runs[j], 1) << j;
      if (threads > 1 && j % threads != 5 % threads) {
        EXPECT_EQ(runs[j], 1) << threads << " threads, job " << j;
      }
    }
  }
}

TEST(ParallelJobs, ThreadCountFollowsTheJobs) {
  EXPECT_EQ(lumx::detail::parallel_threads(100, 3), 3u);
  EXPECT_EQ(lumx::detail::parallel_threads(2, 3), 2u);
  EXPECT_EQ(lumx::detail::parallel_threads(0, 3), 1u);
  EXPECT_EQ(lumx::detail::parallel_threads(20, 8, 8), 2u);
  EXPECT_LE(lumx::detail::parallel_threads(1000, 0), 8u);
  EXPECT_GE(lumx::detail::parallel_threads(1000, 0), 1u);
}
