// SPDX-License-Identifier: GPL-3.0-or-later
// The worker pool: every job of a parallel_for runs exactly once whatever the thread count, a background task
// runs beside the jobs and wait() returns only after it, exceptions come back to the caller, and one thread
// means everything inline on the caller.
#include "receiver/worker_pool.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

using namespace ultratrack::receiver;

TEST(WorkerPool, EveryJobRunsExactlyOnceForAnyThreadCount) {
  for (int threads : {1, 2, 3, 8}) {
    WorkerPool pool(threads);
    EXPECT_EQ(pool.threads(), threads);
    for (int n : {0, 1, 2, 7, 100}) {
      std::vector<std::atomic<int>> hits(static_cast<std::size_t>(n));
      auto job = [&](int i) { hits[static_cast<std::size_t>(i)].fetch_add(1); };
      for (int round = 0; round < 20; ++round) pool.parallel_for(n, job);
      for (int i = 0; i < n; ++i)
        EXPECT_EQ(hits[static_cast<std::size_t>(i)].load(), 20) << threads << " " << n << " " << i;
    }
  }
}

// The pipelined vector loop is job 0 and writes the receiver's outputs: it must run on the caller's thread.
TEST(WorkerPool, JobZeroAlwaysRunsOnTheCaller) {
  for (int threads : {1, 2, 3, 8}) {
    WorkerPool pool(threads);
    const std::thread::id caller = std::this_thread::get_id();
    int elsewhere = 0;
    auto job = [&](int i) {
      if (i == 0 && std::this_thread::get_id() != caller) ++elsewhere;
    };
    for (int round = 0; round < 500; ++round) pool.parallel_for(1 + round % 9, job);
    EXPECT_EQ(elsewhere, 0) << threads << " threads";
  }
}

TEST(WorkerPool, UsesSeveralThreadsWhenGiven) {
  WorkerPool pool(2);
  std::atomic<int> inside{0}, overlap{0};
  auto job = [&](int) {
    if (inside.fetch_add(1) > 0) overlap.store(1);
    const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(20);
    while (std::chrono::steady_clock::now() < until) {
    }
    inside.fetch_sub(1);
  };
  for (int round = 0; round < 10 && overlap.load() == 0; ++round) pool.parallel_for(2, job);
  EXPECT_EQ(overlap.load(), 1);  // two jobs ran at the same time at least once (even on a loaded machine)
}

namespace {
struct Counting final : BackgroundTask {
  std::atomic<int> runs{0};
  std::thread::id where;
  bool fail = false;
  void run() override {
    where = std::this_thread::get_id();
    runs.fetch_add(1);
    if (fail) throw std::runtime_error("task failed");
  }
};
}  // namespace

TEST(WorkerPool, BackgroundTaskRunsOnceBesideJobs) {
  for (int threads : {1, 2}) {
    WorkerPool pool(threads);
    Counting task;
    for (int round = 0; round < 5; ++round) {
      pool.start(task);
      std::atomic<int> jobs{0};
      auto job = [&](int) { jobs.fetch_add(1); };
      pool.parallel_for(4, job);
      EXPECT_EQ(jobs.load(), 4);
      pool.wait(task);
      EXPECT_EQ(task.runs.load(), round + 1);
    }
    if (threads == 1) {
      EXPECT_EQ(task.where, std::this_thread::get_id());  // inline, in wait()
    }
  }
}

TEST(WorkerPool, ExceptionsComeBackToTheCaller) {
  for (int threads : {1, 2}) {
    WorkerPool pool(threads);
    auto job = [](int i) {
      if (i == 3) throw std::runtime_error("job 3");
    };
    EXPECT_THROW(pool.parallel_for(6, job), std::runtime_error);
    std::atomic<int> after{0};
    auto fine = [&](int) { after.fetch_add(1); };
    pool.parallel_for(6, fine);  // still usable
    EXPECT_EQ(after.load(), 6);
    Counting task;
    task.fail = true;
    pool.start(task);
    EXPECT_THROW(pool.wait(task), std::runtime_error);
  }
  EXPECT_THROW(WorkerPool(-1), std::invalid_argument);
  EXPECT_THROW(WorkerPool(257), std::invalid_argument);
  EXPECT_GE(WorkerPool(0).threads(), 1);
}
