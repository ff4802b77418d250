// SPDX-License-Identifier: GPL-3.0-or-later
#include "interrupt_guard.hpp"

#include <semaphore.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <mutex>
#include <thread>
#include <vector>

namespace ultratrack::tools {
namespace {

// The handler may only do async-signal-safe work: it posts a semaphore. A watcher thread, alive while any guard
// is, waits on it and requests a stop on every live guard's source.
sem_t g_posted;
volatile std::sig_atomic_t g_closing = 0;
volatile std::sig_atomic_t g_signal = 0;  // the last SIGINT/SIGTERM a guard caught

extern "C" void ultratrack_interrupt_guard_sigint(int sig) {
  g_signal = sig;
  sem_post(&g_posted);
}

struct Registry {
  std::mutex mutex;
  std::vector<std::stop_source*> sources;
  std::thread watcher;
  void (*previous_int)(int) = SIG_DFL;
  void (*previous_term)(int) = SIG_DFL;
};

Registry& registry() {
  static Registry r;
  return r;
}

void watch() {
  for (;;) {
    while (sem_wait(&g_posted) != 0 && errno == EINTR) {
    }
    if (g_closing) return;
    Registry& r = registry();
    const std::lock_guard lock(r.mutex);
    for (std::stop_source* s : r.sources) s->request_stop();
  }
}

}  // namespace

int interrupt_signal() { return g_signal; }

InterruptGuard::InterruptGuard() {
  Registry& r = registry();
  const std::lock_guard lock(r.mutex);
  r.sources.push_back(&source_);
  if (r.sources.size() > 1) return;
  sem_init(&g_posted, 0, 0);
  g_closing = 0;
  r.watcher = std::thread(watch);
  r.previous_int = std::signal(SIGINT, ultratrack_interrupt_guard_sigint);
  r.previous_term = std::signal(SIGTERM, ultratrack_interrupt_guard_sigint);
}

InterruptGuard::~InterruptGuard() {
  Registry& r = registry();
  std::thread watcher;
  {
    const std::lock_guard lock(r.mutex);
    r.sources.erase(std::find(r.sources.begin(), r.sources.end(), &source_));
    if (!r.sources.empty()) return;
    std::signal(SIGINT, r.previous_int == SIG_ERR ? SIG_DFL : r.previous_int);
    std::signal(SIGTERM, r.previous_term == SIG_ERR ? SIG_DFL : r.previous_term);
    g_closing = 1;
    sem_post(&g_posted);
    watcher = std::move(r.watcher);
  }
  watcher.join();  // outside the lock: the watcher may be waiting for it
  sem_destroy(&g_posted);
}

}  // namespace ultratrack::tools
