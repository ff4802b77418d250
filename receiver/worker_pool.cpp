// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/worker_pool.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

namespace ultratrack::receiver {

WorkerPool::WorkerPool(int threads) {
  if (threads == 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (threads < 1 || threads > 256)
    throw std::invalid_argument("WorkerPool: " + std::to_string(threads) + " threads outside 1..256");
  workers_.reserve(static_cast<std::size_t>(threads - 1));
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { worker_loop(); });
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (auto& w : workers_) w.join();
}

void WorkerPool::run_task(BackgroundTask& task, std::unique_lock<std::mutex>& lock) {
  task.state_ = BackgroundTask::State::kRunning;
  lock.unlock();
  try {
    task.run();
  } catch (...) {
    task.error_ = std::current_exception();
  }
  lock.lock();
  task.state_ = BackgroundTask::State::kDone;
  done_.notify_all();
}

void WorkerPool::worker_loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || batch_next_ < batch_size_ || queued_ != nullptr; });
    if (stop_) return;
    // Batch jobs first: the caller is waiting for them; the background task has a deadline further away.
    if (batch_next_ < batch_size_) {
      const int i = batch_next_++;
      void* job = job_;
      const Call call = call_;
      lock.unlock();
      std::exception_ptr error;
      try {
        call(job, i);
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      if (error && !batch_error_) batch_error_ = error;
      if (--batch_remaining_ == 0) done_.notify_all();
      continue;
    }
    BackgroundTask* task = std::exchange(queued_, nullptr);
    run_task(*task, lock);
  }
}

void WorkerPool::run_batch(int n, void* job, Call call) {
  if (n <= 0) return;
  if (workers_.empty() || n == 1) {
    for (int i = 0; i < n; ++i) call(job, i);
    return;
  }
  std::unique_lock lock(mutex_);
  job_ = job;
  call_ = call;
  batch_size_ = n;
  batch_next_ = 0;
  batch_remaining_ = n;
  batch_error_ = nullptr;
  wake_.notify_all();
  while (batch_next_ < batch_size_) {
    const int i = batch_next_++;
    lock.unlock();
    std::exception_ptr error;
    try {
      call(job, i);
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    if (error && !batch_error_) batch_error_ = error;
    --batch_remaining_;
  }
  done_.wait(lock, [this] { return batch_remaining_ == 0; });
  batch_size_ = batch_next_ = 0;
  job_ = nullptr;
  call_ = nullptr;
  if (batch_error_) std::rethrow_exception(std::exchange(batch_error_, nullptr));
}

void WorkerPool::start(BackgroundTask& task) {
  std::lock_guard lock(mutex_);
  if (queued_ != nullptr) throw std::logic_error("WorkerPool::start: a task is already queued");
  task.state_ = BackgroundTask::State::kQueued;
  task.error_ = nullptr;
  if (workers_.empty()) return;  // wait() runs it
  queued_ = &task;
  wake_.notify_one();
}

void WorkerPool::wait(BackgroundTask& task) {
  std::unique_lock lock(mutex_);
  if (task.state_ == BackgroundTask::State::kQueued) {
    if (queued_ == &task) queued_ = nullptr;
    run_task(task, lock);
  }
  done_.wait(
      lock, [&] { return task.state_ == BackgroundTask::State::kDone || task.state_ == BackgroundTask::State::kIdle; });
  task.state_ = BackgroundTask::State::kIdle;
  if (task.error_) std::rethrow_exception(std::exchange(task.error_, nullptr));
}

}  // namespace ultratrack::receiver
