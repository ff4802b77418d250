// SPDX-License-Identifier: GPL-3.0-or-later
// tools::InterruptGuard: SIGINT and SIGTERM become a stop request on every live guard's token (nested guards too),
// and the handlers that were there before come back when the last guard goes.
#include "interrupt_guard.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <thread>

namespace {

volatile std::sig_atomic_t g_previous_called = 0;
extern "C" void previous_handler(int) { g_previous_called = 1; }

// The watcher thread turns the signal into the request: wait for it (bounded).
bool stopped_soon(const ultratrack::tools::InterruptGuard& g) {
  for (int k = 0; k < 500 && !g.interrupted(); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  return g.interrupted();
}

}  // namespace

TEST(InterruptGuard, SigintStopsEveryLiveGuardAndThePreviousHandlerReturns) {
  const auto before = std::signal(SIGINT, previous_handler);
  {
    ultratrack::tools::InterruptGuard outer;
    EXPECT_FALSE(outer.interrupted());
    {
      ultratrack::tools::InterruptGuard inner;
      std::raise(SIGINT);
      EXPECT_TRUE(stopped_soon(inner));
      EXPECT_TRUE(stopped_soon(outer));
      EXPECT_TRUE(inner.token().stop_requested());
    }
    EXPECT_EQ(g_previous_called, 0);  // the guards had it
  }
  {
    ultratrack::tools::InterruptGuard again;  // a new guard starts unstopped
    EXPECT_FALSE(again.interrupted());
  }
  std::raise(SIGINT);
  EXPECT_EQ(g_previous_called, 1);
  std::signal(SIGINT, before);
}

TEST(InterruptGuard, SigtermStopsTheGuardAndThePreviousHandlerReturns) {
  g_previous_called = 0;
  const auto before = std::signal(SIGTERM, previous_handler);
  {
    ultratrack::tools::InterruptGuard guard;
    std::raise(SIGTERM);
    EXPECT_TRUE(stopped_soon(guard));
    EXPECT_EQ(g_previous_called, 0);
  }
  std::raise(SIGTERM);
  EXPECT_EQ(g_previous_called, 1);
  std::signal(SIGTERM, before);
}
