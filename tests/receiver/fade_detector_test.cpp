// SPDX-License-Identifier: GPL-3.0-or-later
// FadeDetector on simulated 20 ms taps: complex Gaussian noise of unit power per tap (E|w|^2 = 2, sigma 1 per
// component) plus a signal of amplitude sqrt(2 C/N0 T) on the prompt, made here without the code under test. The
// channel's C/N0 estimate is given as the level before any change (the estimator lags a blockage by its window).
#include "receiver/fade_detector.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>

namespace ultratrack::receiver {
namespace {

constexpr double kT = 0.020;

struct Taps {
  std::mt19937_64 rng{11};
  std::normal_distribution<float> g{0.0f, 1.0f};
  std::complex<float> noise() { return {g(rng), g(rng)}; }
  // One epoch's prompt at cn0_dbhz (below -50: no signal) with a carrier phase of 0.3 rad.
  std::complex<float> prompt(double cn0_dbhz) {
    const double a = cn0_dbhz < -50.0 ? 0.0 : std::sqrt(2.0 * std::pow(10.0, cn0_dbhz / 10.0) * kT);
    return noise() + std::polar(static_cast<float>(a), 0.3f);
  }
};

// Feeds `epochs` epochs at cn0_dbhz (the estimate says estimate_dbhz); returns the first epoch (1-based) after which
// faded() equals `until`, or 0 if it never does.
int feed(FadeDetector& d, Taps& taps, double cn0_dbhz, double estimate_dbhz, int epochs, bool until) {
  for (int k = 1; k <= epochs; ++k) {
    d.add(taps.prompt(cn0_dbhz), taps.noise(), estimate_dbhz, kT);
    if (d.faded() == until) return k;
  }
  return 0;
}

// The header's error rates of the presence test that ends a step-down fade, from the exact law.
TEST(FadeDetector, PresenceRatesOfTheHeader) {
  const FadeDetectorOptions o;
  const int n = static_cast<int>(std::lround(o.present_window_s / kT));
  EXPECT_EQ(n, 25);
  EXPECT_LT(1.0 - presence_absent_probability(-100.0, n, kT, o.present_dbhz), 2e-4);
  EXPECT_LT(presence_absent_probability(25.0, n, kT, o.present_dbhz), 1e-5);
}

// 10 minutes of a steady 34 dB-Hz signal (the weakest level tested, SNR 50): no fade.
TEST(FadeDetector, ASteadySignalNeverFades) {
  Taps taps;
  FadeDetector d;
  EXPECT_EQ(feed(d, taps, 34.0, 34.0, 30000, true), 0);
  EXPECT_EQ(d.fades(), 0);
}

// A blockage of a 45 dB-Hz signal is seen in its first epoch or the next (noise above the threshold: exp(-63));
// the fade lasts while the signal is away and ends 5 epochs after it returns.
TEST(FadeDetector, ABlockageIsSeenAtOnceAndEndsWhenTheSignalReturns) {
  Taps taps;
  FadeDetector d;
  ASSERT_EQ(feed(d, taps, 45.0, 45.0, 100, true), 0);
  EXPECT_LE(feed(d, taps, -100.0, 45.0, 100, true), 2);
  EXPECT_EQ(feed(d, taps, -100.0, 45.0, 250, false), 0);  // 5 s blocked: still faded
  EXPECT_EQ(feed(d, taps, 45.0, 45.0, 100, false), 5);
  EXPECT_EQ(d.fades(), 1);
}

// A step from 45 to 30 dB-Hz (15 dB in one epoch) looks like a fade; the presence test finds the signal within two
// windows (1 s) and the fade ends with the mean at the new level, which then holds without a new fade.
TEST(FadeDetector, AStepDownEndsByThePresenceTest) {
  Taps taps;
  FadeDetector d;
  ASSERT_EQ(feed(d, taps, 45.0, 45.0, 100, true), 0);
  EXPECT_LE(feed(d, taps, 30.0, 45.0, 5, true), 2);
  const int end = feed(d, taps, 30.0, 45.0, 100, false);
  EXPECT_GE(end, 20);
  EXPECT_LE(end, 50);
  EXPECT_EQ(feed(d, taps, 30.0, 30.0, 3000, true), 0);  // 60 s more at 30 dB-Hz
  EXPECT_EQ(d.fades(), 1);
}

// Below the tested level (SNR < 50) a channel is not tested: a blockage of a 30 dB-Hz signal is left to the
// loss-of-lock test.
TEST(FadeDetector, AWeakChannelIsNotTested) {
  Taps taps;
  FadeDetector d;
  ASSERT_EQ(feed(d, taps, 30.0, 30.0, 100, true), 0);
  EXPECT_EQ(feed(d, taps, -100.0, 30.0, 100, true), 0);
}

// 1 ms epochs at 45 dB-Hz (SNR 32) are not tested either; bit sync's 20 ms epochs restart the mean, which is tested
// once it has run reference_time_s.
TEST(FadeDetector, ANewEpochLengthRestartsTheMean) {
  Taps taps;
  FadeDetector d;
  for (int k = 0; k < 1000; ++k) d.add(taps.prompt(45.0) * 0.2236f, taps.noise(), 45.0, 0.001);  // ~1 ms scale
  EXPECT_FALSE(d.faded());
  d.add(taps.prompt(45.0), taps.noise(), 45.0, kT);
  for (int k = 0; k < 10; ++k) d.add(taps.prompt(-100.0), taps.noise(), 45.0, kT);
  EXPECT_FALSE(d.faded());  // only 0.22 s of 20 ms epochs: not yet tested
}

}  // namespace
}  // namespace ultratrack::receiver
