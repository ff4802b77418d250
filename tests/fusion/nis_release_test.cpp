// SPDX-License-Identifier: GPL-3.0-or-later
// The windowed NIS test (fusion/windowed_nis.hpp) against the chi-square law it assumes (the upper tail's closed
// form for even dof, the mean and the false-alarm rate of windows of simulated chi-square NIS), and the channel
// releases built on it (fusion/nis_release.hpp): a channel whose updates contradict the filter is released after
// the number of updates the window's budget gives, the others stay; most channels at once is the filter's fault
// (the pooled windows), logged once; a minute of consistent updates releases nothing.
#include "fusion/nis_release.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "fusion/windowed_nis.hpp"
#include "receiver/chi_square.hpp"

namespace ultratrack::fusion {
namespace {

// chi-square(dof), optionally with a mean offset delta on the first component (a contradicted prediction).
double draw_nis(std::mt19937_64& rng, int dof, double delta = 0.0) {
  std::normal_distribution<double> n;
  double s = 0.0;
  for (int k = 0; k < dof; ++k) {
    const double z = n(rng) + (k == 0 ? delta : 0.0);
    s += z * z;
  }
  return s;
}

// P(X > x) for X ~ chi-square(2 m): exp(-x / 2) sum_{k < m} (x / 2)^k / k! (independent of receiver/chi_square).
double even_dof_upper_tail(int two_m, double x) {
  double term = 1.0, sum = 0.0;
  for (int k = 0; k < two_m / 2; ++k) {
    if (k > 0) term *= 0.5 * x / k;
    sum += term;
  }
  return std::exp(-0.5 * x) * sum;
}

TEST(WindowedNis, LimitIsTheChiSquareQuantileOfTheSummedDof) {
  WindowedNisOptions o;
  o.window = 10;
  o.probability = 1e-6;
  WindowedNis w(o);
  EXPECT_EQ(w.limit(), 0.0);
  for (int k = 0; k < 10; ++k) w.add(1.0, 2);  // 10 updates of 2 dof: chi-square(20)
  ASSERT_TRUE(w.full());
  EXPECT_EQ(w.dof(), 20);
  EXPECT_NEAR(even_dof_upper_tail(20, w.limit()), 1e-6, 1e-9);
  // A mixed window: 6 x 2 dof + 4 x 6 dof = 36 dof.
  for (int k = 0; k < 4; ++k) w.add(1.0, 6);
  EXPECT_EQ(w.dof(), 36);
  EXPECT_NEAR(even_dof_upper_tail(36, w.limit()), 1e-6, 1e-9);
}

TEST(WindowedNis, SlidesCapsAndRestarts) {
  WindowedNisOptions o;
  o.window = 3;
  o.cap_per_dof = 10.0;
  WindowedNis w(o);
  EXPECT_FALSE(w.add(1.0, 1));
  EXPECT_FALSE(w.add(2.0, 1));
  EXPECT_FALSE(w.full());
  w.add(1e9, 1);  // capped at 10
  EXPECT_TRUE(w.full());
  EXPECT_DOUBLE_EQ(w.sum(), 13.0);
  w.add(NAN, 1);  // non-finite: at the cap; the oldest (1.0) leaves
  EXPECT_DOUBLE_EQ(w.sum(), 22.0);
  EXPECT_EQ(w.updates(), 3);
  w.reset();
  EXPECT_EQ(w.updates(), 0);
  EXPECT_EQ(w.sum(), 0.0);
  WindowedNisOptions bad;
  bad.window = 0;
  EXPECT_THROW(WindowedNis{bad}, std::invalid_argument);
}

// Independent full windows of chi-square(3) NIS: the sum's mean is W dof and its tail beyond limit() has the
// chosen probability (binomial 4-sigma bands).
TEST(WindowedNis, SumsOfChiSquareNisFollowTheClosedForm) {
  WindowedNisOptions o;
  o.window = 20;
  o.probability = 0.01;
  std::mt19937_64 rng(7);
  const int windows = 20000;
  int above = 0;
  double mean = 0.0;
  WindowedNis w(o);
  for (int n = 0; n < windows; ++n) {
    w.reset();
    bool tripped = false;
    for (int k = 0; k < o.window; ++k) tripped = w.add(draw_nis(rng, 3), 3);
    mean += w.sum() / windows;
    above += tripped;
  }
  EXPECT_NEAR(mean, 60.0, 4.0 * std::sqrt(120.0 / windows));  // var of chi-square(60) = 120
  const double sigma = std::sqrt(o.probability * (1.0 - o.probability) / windows);
  EXPECT_NEAR(static_cast<double>(above) / windows, o.probability, 4.0 * sigma);
}

// Eight channels of the ultra-tight I&Q form (6 dof per 20 ms update) with the defaults (1 s windows, 1e-6,
// margin 3, the 0.9999 gate). From update 100 on, PRN 5's prediction is 6 sigma off on one tap (NIS ~42, mostly
// at the gate's cap c = 27.9). From a window of clean updates (mean m0 = 6) the release comes once
// k (c - m0) > L - W m0, L = 3 q(300, 1e-6): after k ~ 45 updates, within one window (each above L / W = 26).
TEST(NisRelease, AContradictedChannelIsReleasedWithinTheBudgetAndTheOthersStay) {
  NisReleaseOptions o;
  NisReleaseMonitor m(o);
  const double L = m.limit(300);
  const double cap = receiver::chi_square_upper_quantile(6, 1e-4);
  const double expected_k = (L - 50 * 6.0) / (cap - 6.0);
  std::mt19937_64 rng(11);
  int released_at = -1;
  for (int epoch = 0; epoch < 400; ++epoch) {
    for (int prn = 1; prn <= 8; ++prn) m.add(prn, draw_nis(rng, 6, prn == 5 && epoch >= 100 ? 6.0 : 0.0), 6);
    const NisVerdict v = m.evaluate();
    EXPECT_FALSE(v.filter) << epoch;
    for (int prn : v.released) {
      EXPECT_EQ(prn, 5) << "epoch " << epoch;
      if (prn == 5 && released_at < 0) released_at = epoch;
    }
  }
  ASSERT_GE(released_at, 100);
  std::printf("released %d updates after the contradiction began (budget %.1f)\n", released_at - 100 + 1, expected_k);
  EXPECT_NEAR(released_at - 100 + 1, expected_k, 4.0);
  EXPECT_LE(released_at - 100 + 1, o.window);  // each contradicting update above L / W: within one window
}

// Six of eight channels contradicted at once: the pooled windows pass their band (at ~42 updates: 8 x 300 + 6 k
// (27.9 - 6) > 3 q(2400, 1e-6)) before any channel's own (~45), and the filter event comes once the pool has stayed
// out filter_persistence evaluations in a row; no channel blamed meanwhile nor after; while the contradiction lasts,
// nothing more (the pool stays out: logged once); once it ends and the pool is back inside, channels are judged again.
TEST(NisRelease, MostChannelsOutsideAtOnceIsTheFilterLoggedOnce) {
  NisReleaseMonitor m(NisReleaseOptions{});
  std::mt19937_64 rng(3);
  int filter_events = 0, first_event = -1;
  for (int epoch = 0; epoch < 600; ++epoch) {
    const bool contradicted = epoch >= 60 && epoch < 400;
    for (int prn = 1; prn <= 8; ++prn) m.add(prn, draw_nis(rng, 6, contradicted && prn <= 6 ? 8.0 : 0.0), 6);
    const NisVerdict v = m.evaluate();
    EXPECT_TRUE(v.released.empty()) << epoch;
    if (v.filter) {
      ++filter_events;
      if (first_event < 0) first_event = epoch;
      EXPECT_NE(v.reasons.front().find("of 8 channels"), std::string::npos) << v.reasons.front();
    }
    if (epoch == 399) {
      EXPECT_TRUE(m.filter_out());
    }
  }
  EXPECT_EQ(filter_events, 1);
  EXPECT_NEAR(first_event - 60 + 1,
              (m.limit(2400) - 2400.0) / (6.0 * (receiver::chi_square_upper_quantile(6, 1e-4) - 6.0)) +
                  (NisReleaseOptions{}.filter_persistence - 1),
              4.0);
  EXPECT_FALSE(m.filter_out());  // back inside after the contradiction ended
}

// A transient that most channels share (a C/N0 step, whose estimates lag the signal): the pool goes out of its band
// (a monitor that needs no persistence logs the filter), but for fewer than filter_persistence evaluations in a row:
// no filter event, and no channel blamed.
TEST(NisRelease, ASharedTransientShorterThanThePersistenceIsNoFilterEvent) {
  NisReleaseOptions at_once;
  at_once.filter_persistence = 1;
  NisReleaseMonitor m(NisReleaseOptions{}), eager(at_once);
  std::mt19937_64 rng(5);
  int events = 0, eager_filter_events = 0;
  for (int epoch = 0; epoch < 400; ++epoch) {
    const bool transient = epoch >= 100 && epoch < 160;  // 1.2 s: the pool out from ~42 updates in, for ~25
    for (int prn = 1; prn <= 8; ++prn) {
      const double nis = draw_nis(rng, 6, transient && prn <= 6 ? 8.0 : 0.0);
      m.add(prn, nis, 6);
      eager.add(prn, nis, 6);
    }
    const NisVerdict v = m.evaluate();
    events += static_cast<int>(v.released.size()) + v.filter;
    eager_filter_events += eager.evaluate().filter;
  }
  EXPECT_EQ(eager_filter_events, 1);  // the transient does take the pool out of its band
  EXPECT_EQ(events, 0);
  EXPECT_FALSE(m.filter_out());
}

// A consistent filter: 10 channels for 3000 updates each (a minute at 50 Hz) with 6 dof, and 10 with 2 (the
// vector filter's pseudorange and rate rows): no release. Per full window a consistent filter passes
// q(W dof, 1e-6) with probability 1e-6; margin 3 leaves a real filter's over-dispersion room besides.
TEST(NisRelease, AMinuteOfConsistentUpdatesReleasesNothing) {
  for (int dof : {6, 2}) {
    NisReleaseMonitor m(NisReleaseOptions{});
    std::mt19937_64 rng(static_cast<unsigned>(dof));
    int events = 0;
    for (int epoch = 0; epoch < 3000; ++epoch) {
      for (int prn = 1; prn <= 10; ++prn) m.add(prn, draw_nis(rng, dof), dof);
      const NisVerdict v = m.evaluate();
      events += static_cast<int>(v.released.size()) + v.filter;
    }
    EXPECT_EQ(events, 0) << dof << " dof";
  }
}

TEST(ReleaseLog, CountsPerReasonAndWritesTheLog) {
  ReleaseLog log;
  log.add(1.5, 5, "channel_nis", "windowed NIS 900 over 50 updates (limit 876)");
  log.add(2.0, 0, "filter_nis");
  log.add(3.25, 7, "channel_nis");
  EXPECT_EQ(log.count("channel_nis"), 2);
  EXPECT_EQ(log.count("filter_nis"), 1);
  EXPECT_EQ(log.count("jump"), 0);
  EXPECT_EQ(log.total(), 3);
  const std::string j = log.json_members();
  EXPECT_NE(j.find("\"releases_by_reason\": {\"channel_nis\": 2, \"filter_nis\": 1}"), std::string::npos) << j;
  EXPECT_NE(j.find("{\"t_s\": 1.500, \"prn\": 5, \"reason\": \"channel_nis\""), std::string::npos) << j;
  EXPECT_EQ(ReleaseLog().json_members(), "\"releases_by_reason\": {}, \"release_log\": []");
}

}  // namespace
}  // namespace ultratrack::fusion
