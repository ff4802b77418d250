// SPDX-License-Identifier: GPL-3.0-or-later
// fusion::FalseLockMonitor: both averagings against hand-computed means, and the block averaging with the
// ultra-tight loop's settings against closed forms on simulated offsets.
#include "fusion/false_lock_monitor.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using ultratrack::fusion::FalseLockMonitor;

// 0.1 s blocks of 20 ms epochs: five offsets per block. 1..5 Hz: the block completes on the fifth with mean 3 Hz
// (and the last five's mean is 3 Hz too); NaN is not an epoch; after reset(2) the next two offsets are skipped and
// the block of 6, 7, 8, 9, 10 Hz has mean 8 Hz, its last five 8 Hz, while epochs 7..10 alone average 8.5 Hz.
TEST(FalseLockMonitor, BlockMeansByHand) {
  FalseLockMonitor m(FalseLockMonitor::Averaging::kBlock, 0.1);
  for (int k = 1; k <= 4; ++k) EXPECT_FALSE(m.add(k, 0.02));
  EXPECT_FALSE(m.add(NAN, 0.02));
  EXPECT_EQ(m.epochs(), 4);
  EXPECT_TRUE(m.add(5.0, 0.02));
  EXPECT_DOUBLE_EQ(m.mean_hz(), 3.0);
  EXPECT_DOUBLE_EQ(m.recent_hz(), 3.0);
  EXPECT_EQ(m.epochs(), 0);
  m.reset(2);
  EXPECT_DOUBLE_EQ(m.mean_hz(), 3.0);    // the last block's mean stays until the next one
  EXPECT_DOUBLE_EQ(m.recent_hz(), 3.0);  // no epoch since the reset: the block mean
  EXPECT_FALSE(m.add(100.0, 0.02));
  EXPECT_FALSE(m.add(100.0, 0.02));
  for (int k = 6; k <= 9; ++k) EXPECT_FALSE(m.add(k, 0.02));
  EXPECT_DOUBLE_EQ(m.recent_hz(), 7.5);  // 6, 7, 8, 9
  EXPECT_TRUE(m.add(10.0, 0.02));
  EXPECT_DOUBLE_EQ(m.mean_hz(), 8.0);
  EXPECT_DOUBLE_EQ(m.recent_hz(), 8.0);
  EXPECT_TRUE(!m.add(11.0, 0.02) && std::abs(m.recent_hz() - 9.0) < 1e-12);  // 7, 8, 9, 10, 11
}

// 0.5 s running mean of 0.1 s epochs: weight 0.2. 10, 10, 0 Hz from zero: 2, 3.6, 2.88 Hz; three epochs. A reset
// returns it to zero; an epoch longer than the averaging time replaces the mean (weight capped at 1).
TEST(FalseLockMonitor, RunningMeanByHand) {
  FalseLockMonitor m(FalseLockMonitor::Averaging::kRunning, 0.5);
  EXPECT_TRUE(m.add(10.0, 0.1));
  EXPECT_NEAR(m.mean_hz(), 2.0, 1e-12);
  EXPECT_TRUE(m.add(10.0, 0.1));
  EXPECT_NEAR(m.mean_hz(), 3.6, 1e-12);
  EXPECT_TRUE(m.add(0.0, 0.1));
  EXPECT_NEAR(m.mean_hz(), 2.88, 1e-12);
  EXPECT_FALSE(m.add(INFINITY, 0.1));
  EXPECT_EQ(m.epochs(), 3);
  m.reset();
  EXPECT_EQ(m.mean_hz(), 0.0);
  EXPECT_EQ(m.epochs(), 0);
  EXPECT_TRUE(m.add(-7.0, 1.0));
  EXPECT_EQ(m.mean_hz(), -7.0);
}

// The block monitor with the ultra-tight loop's settings (1 s blocks of 20 ms epochs) against closed forms. A locked
// channel: per-epoch offsets with the 0.46 Hz standard deviation measured at 18 dB-Hz (cn0_18_file_0, 9 locked
// channels) and a 0.3 Hz bias: every 1 s block mean lies within the bias +- 5 sigma of a 50-epoch mean (0.33 Hz; white,
// so a bound, not a sampling estimate), far inside the 5 Hz threshold. A runaway: offsets ramping at 8 Hz/s from 0
// (runaways seen drift 3-25 Hz/s): a block's mean is the ramp at its middle (4 Hz for the first, 12 Hz for the second,
// which is caught), and recent_hz the ramp at the middle of the last 5 epochs.
TEST(FalseLockMonitor, BlockMeansOfLockedNoiseStayNearTheBiasAndARampIsCaughtWithItsCurrentOffset) {
  constexpr double kT = 0.020, kAverage = 1.0, kSigma = 0.46, kBias = 0.3;
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, kSigma);
  FalseLockMonitor locked(FalseLockMonitor::Averaging::kBlock, kAverage);
  int blocks = 0;
  double worst = 0.0;
  for (int k = 0; k < 50 * 600; ++k)
    if (locked.add(kBias + noise(rng), kT)) {
      ++blocks;
      worst = std::max(worst, std::abs(locked.mean_hz() - kBias));
    }
  EXPECT_EQ(blocks, 600);
  EXPECT_LT(worst, 5.0 * kSigma / std::sqrt(50.0));

  // A ramp of 8 Hz/s sampled at the epochs' middles (k + 0.5) T: block b (epochs 50 b .. 50 b + 49) has the mean
  // 8 (b + 0.5) Hz; recent_hz at its end is the ramp at epoch 50 b + 47 (the middle of the last 5: k - 2).
  FalseLockMonitor ramp(FalseLockMonitor::Averaging::kBlock, kAverage);
  int caught = -1;
  for (int k = 0; k < 500 && caught < 0; ++k)
    if (ramp.add(8.0 * (k + 0.5) * kT, kT) && std::abs(ramp.mean_hz()) > 5.0) {
      caught = k;
      EXPECT_NEAR(ramp.mean_hz(), 8.0 * (std::floor(k / 50.0) + 0.5), 1e-9);
      EXPECT_NEAR(ramp.recent_hz(), 8.0 * (k - 2.0 + 0.5) * kT, 1e-9);
    }
  EXPECT_EQ(caught, 99);  // the second block (mean 12 Hz; 15.6 Hz now)
  // After a reset with settle 3, the next 3 offsets are not counted: a block needs 53 more epochs.
  ramp.reset(3);
  int n = 0;
  while (!ramp.add(1.0, kT)) ++n;
  EXPECT_EQ(n, 52);
  EXPECT_NEAR(ramp.mean_hz(), 1.0, 1e-12);
}
