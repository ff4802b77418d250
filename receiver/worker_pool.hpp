// SPDX-License-Identifier: GPL-3.0-or-later
// A fixed pool of worker threads for the receiver: parallel_for over a handful of independent jobs (one per
// tracking channel and sample block; the calling thread works too, so N threads = the caller + N - 1 workers)
// and one background task at a time (a re-acquisition search) that runs beside them. Nothing is allocated
// per call: jobs are passed by reference, never copied into std::function. Results are the caller's business;
// the pool decides only which thread runs a job, never the order in which the caller consumes the results.
#pragma once

#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace ultratrack::receiver {

// Work handed to WorkerPool::start(): run() once, on some thread, after start() and before wait() returns.
class BackgroundTask {
 public:
  virtual ~BackgroundTask() = default;
  virtual void run() = 0;

 private:
  friend class WorkerPool;
  enum class State { kIdle, kQueued, kRunning, kDone };
  State state_ = State::kIdle;
  std::exception_ptr error_;
};

class WorkerPool final {
 public:
  // threads: 1..256 in all, including the caller (1 = everything inline on the caller); 0 = the number of
  // hardware threads. Throws std::invalid_argument outside that range.
  explicit WorkerPool(int threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls job(i) for every i in [0, n), each exactly once, spread over the workers and the caller; returns
  // when all have finished. The first exception a job throws is rethrown here (after all jobs finished).
  // Job 0 always runs on the caller (it claims it before any worker can see the batch): the receiver engine's
  // pipelined vector loop relies on this to keep its output on the caller thread.
  template <class Job>
  void parallel_for(int n, Job& job) {
    run_batch(n, &job, [](void* j, int i) { (*static_cast<Job*>(j))(i); });
  }

  // Queues task to run on a worker (with one thread: nothing yet, wait() runs it). One task at a time per
  // object; it must stay alive until wait(task) has returned.
  void start(BackgroundTask& task);
  // Returns once task has run (running it on the caller if no worker has taken it yet); rethrows its exception.
  void wait(BackgroundTask& task);

 private:
  using Call = void (*)(void*, int);
  void run_batch(int n, void* job, Call call);
  void worker_loop();
  void run_task(BackgroundTask& task, std::unique_lock<std::mutex>& lock);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;  // workers: a batch or a task is available, or stop
  std::condition_variable done_;  // the caller: a batch's last job or a task finished
  bool stop_ = false;
  // The current batch (at most one: parallel_for is called from one thread).
  void* job_ = nullptr;
  Call call_ = nullptr;
  int batch_size_ = 0, batch_next_ = 0, batch_remaining_ = 0;
  std::exception_ptr batch_error_;
  BackgroundTask* queued_ = nullptr;  // a started task no thread has taken yet
};

}  // namespace ultratrack::receiver
