// SPDX-License-Identifier: GPL-3.0-or-later
// AntennaPhaseTracker on constructed correlation epochs: prompts with a known between-antenna phase (closed
// form), thermal noise of a known C/N0, fades and phase steps, checked against that construction.
#include "receiver/antenna_phase_tracker.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>

#include "signals/ephemeris.hpp"

namespace ultratrack::receiver {
namespace {

constexpr double kFs = 2.6e6;
constexpr int kSamples = 52000;  // 20 ms

// A 20 ms epoch n whose antenna k prompt is the master's rotated by -2 pi sd_k (RINEX sense), plus complex noise of
// power per component noise_sigma^2 * N (the unnormalised sums' scale: signal amplitude N).
struct EpochMaker {
  std::mt19937_64 rng{42};
  double cn0_dbhz = 45.0;
  bool noise = true;
  CorrelationEpoch make(std::int64_t n, const std::array<double, 3>& sd_cycles, const std::array<bool, 3>& present,
                        double master_phase_rad) {
    CorrelationEpoch e;
    e.num_antennas = 3;
    e.first_sample = n * kSamples;
    e.num_samples = kSamples;
    e.integration_time_s = kSamples / kFs;
    e.num_code_periods = 20;
    // |P|^2 / noise power per epoch = C/N0 T: amplitude N, complex noise variance N^2 / (C/N0 T).
    const double snr = std::pow(10.0, cn0_dbhz / 10.0) * e.integration_time_s;
    std::normal_distribution<double> g(0.0, kSamples / std::sqrt(2.0 * snr));
    auto w = [&] { return noise ? std::complex<double>(g(rng), g(rng)) : std::complex<double>(0.0, 0.0); };
    for (int k = 0; k < 3; ++k) {
      const double phase = master_phase_rad - 2.0 * M_PI * sd_cycles[static_cast<std::size_t>(k)];
      const std::complex<double> s = present[static_cast<std::size_t>(k)] ? std::polar<double>(kSamples, phase) : 0.0;
      e.antenna[static_cast<std::size_t>(k)].prompt = std::complex<float>(s + w());
      e.antenna[static_cast<std::size_t>(k)].noise = std::complex<float>(w());
    }
    return e;
  }
};

TEST(AntennaPhaseTracker, FollowsAPhaseRampAcrossManyCyclesWithoutSlips) {
  // 0.5 cycles/s for 20 s (a 1 m baseline turning at ~5 deg/s): 10 whole cycles, wrapped 20 times in arg().
  AntennaPhaseTracker tracker(3);
  EpochMaker maker;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> data_phase(0.0, 2.0 * M_PI);  // replica error + data bit: cancel
  int slips = 0;
  double max_error = 0.0;
  for (std::int64_t n = 0; n < 1000; ++n) {
    const double t = (static_cast<double>(n) + 0.5) * kSamples / kFs;
    tracker.update(maker.make(n, {0.0, 0.3 + 0.5 * t, -0.2 - 0.25 * t}, {true, true, true}, data_phase(rng)), true,
                   kFs);
    const std::int64_t at = (n + 1) * kSamples;  // end of the epoch: extrapolated half an epoch
    const double t_at = static_cast<double>(at) / kFs;
    for (int k = 1; k < 3; ++k) {
      const AntennaPhaseSample s = tracker.report(k, at, kFs);
      ASSERT_TRUE(s.usable);
      if (n > 0) slips += s.slip;
      const double truth = k == 1 ? 0.3 + 0.5 * t_at : -0.2 - 0.25 * t_at;
      // The first epoch starts within half a cycle of the truth: the integer offset is 0 here.
      if (n > 50) max_error = std::max(max_error, std::abs(s.phase_cycles - truth));
    }
  }
  EXPECT_EQ(slips, 0);
  // Thermal noise at 45 dB-Hz, 20 ms: 1/sqrt(2 C/N0 T) = 0.028 rad per antenna, 0.04 rad = 0.0063 cycles between
  // two; 6 sigma over 2000 values.
  EXPECT_LT(max_error, 0.04);
}

TEST(AntennaPhaseTracker, FirstReportIsASlip) {
  AntennaPhaseTracker tracker(2);
  EpochMaker maker;
  tracker.update(maker.make(0, {0.0, 0.1, 0.0}, {true, true, true}, 0.0), true, kFs);
  EXPECT_TRUE(tracker.report(1, kSamples, kFs).slip);
  tracker.update(maker.make(1, {0.0, 0.1, 0.0}, {true, true, true}, 0.0), true, kFs);
  EXPECT_FALSE(tracker.report(1, 2 * kSamples, kFs).slip);
}

TEST(AntennaPhaseTracker, FadeMakesUnusableThenSlipOnRecovery) {
  AntennaPhaseTracker tracker(3);
  EpochMaker maker;
  auto run = [&](std::int64_t n, bool present2) {
    tracker.update(maker.make(n, {0.0, 0.1, 0.2}, {true, true, present2}, 1.0), true, kFs);
  };
  for (std::int64_t n = 0; n < 50; ++n) run(n, true);
  tracker.report(2, 50 * kSamples, kFs);
  EXPECT_FALSE(tracker.report(2, 50 * kSamples, kFs).slip);
  for (std::int64_t n = 50; n < 300; ++n) {  // 5 s blocked
    run(n, false);
    const auto s2 = tracker.report(2, (n + 1) * kSamples, kFs);
    EXPECT_FALSE(s2.usable) << n;
    EXPECT_TRUE(tracker.report(1, (n + 1) * kSamples, kFs).usable);  // the other antenna is unaffected
    EXPECT_FALSE(tracker.report(1, (n + 1) * kSamples, kFs).slip);
  }
  int first_usable = -1;
  for (std::int64_t n = 300; n < 320; ++n) {
    run(n, true);
    const auto s = tracker.report(2, (n + 1) * kSamples, kFs);
    if (s.usable && first_usable < 0) {
      first_usable = static_cast<int>(n);
      EXPECT_TRUE(s.slip);
    } else if (s.usable) {
      EXPECT_FALSE(s.slip);
    }
  }
  // Back after recover_epochs (3) good epochs plus the restart epoch: within 0.1 s of the signal.
  EXPECT_GE(first_usable, 300);
  EXPECT_LE(first_usable, 305);
}

TEST(AntennaPhaseTracker, PhaseStepIsASlip) {
  AntennaPhaseTracker tracker(2);
  EpochMaker maker;
  int flagged_at = -1;
  for (std::int64_t n = 0; n < 200; ++n) {
    const double sd = n < 100 ? 0.1 : 0.1 + 0.35;  // a 0.35-cycle step (e.g. a fade-free slip with a fraction)
    tracker.update(maker.make(n, {0.0, sd, 0.0}, {true, true, true}, 0.0), true, kFs);
    const auto s = tracker.report(1, (n + 1) * kSamples, kFs);
    if (n > 0 && s.slip && flagged_at < 0) flagged_at = static_cast<int>(n);
  }
  EXPECT_EQ(flagged_at, 100);
}

TEST(AntennaPhaseTracker, MasterOutOfLockRestarts) {
  AntennaPhaseTracker tracker(2);
  EpochMaker maker;
  for (std::int64_t n = 0; n < 10; ++n)
    tracker.update(maker.make(n, {0.0, 0.1, 0.0}, {true, true, true}, 0.0), true, kFs);
  tracker.report(1, 10 * kSamples, kFs);
  tracker.update(maker.make(10, {0.0, 0.1, 0.0}, {true, true, true}, 0.0), false, kFs);
  EXPECT_FALSE(tracker.report(1, 11 * kSamples, kFs).usable);
  tracker.update(maker.make(11, {0.0, 0.1, 0.0}, {true, true, true}, 0.0), true, kFs);
  EXPECT_TRUE(tracker.report(1, 12 * kSamples, kFs).slip);
}

TEST(AntennaPhaseTracker, NoFalseSlipsAt35DbHz) {
  // 10^4 epochs (200 s) at 35 dB-Hz: between-antenna noise 0.02 cycles per epoch; threshold 0.2 = 10 sigma.
  AntennaPhaseTracker tracker(2);
  EpochMaker maker;
  maker.cn0_dbhz = 35.0;
  int slips = 0, unusable = 0;
  for (std::int64_t n = 0; n < 10000; ++n) {
    tracker.update(maker.make(n, {0.0, 0.1, 0.0}, {true, true, true}, 0.0), true, kFs);
    const auto s = tracker.report(1, (n + 1) * kSamples, kFs);
    if (n > 20) {
      slips += s.slip;
      unusable += !s.usable;
    }
  }
  EXPECT_EQ(slips, 0);
  EXPECT_EQ(unusable, 0);
}

TEST(AntennaPhaseTracker, PerAntennaCn0FromTheNoiseTap) {
  AntennaPhaseTracker tracker(2);
  EpochMaker maker;
  maker.cn0_dbhz = 40.0;
  double sum = 0.0;
  int count = 0;
  for (std::int64_t n = 0; n < 2000; ++n) {
    tracker.update(maker.make(n, {0.0, 0.1, 0.0}, {true, true, true}, 0.0), true, kFs);
    if (n >= 100) {
      sum += tracker.report(1, (n + 1) * kSamples, kFs).cn0_dbhz;
      ++count;
    }
  }
  EXPECT_NEAR(sum / count, 40.0, 0.5);
}

TEST(AntennaObservation, LineOfSightAndPhases) {
  // A satellite straight above a point on the equator: the LOS is the local up, elevation 90 deg.
  signals::Ephemeris eph;  // a circular orbit: sqrt_a, no perturbations, at the time of toe
  eph.prn = 3;
  eph.week = 2190;
  eph.toe_s = 0.0;
  eph.toc_s = 0.0;
  eph.sqrt_a_sqrtm = std::sqrt(26560e3);
  eph.e = 0.0;
  eph.i0_rad = 0.0;
  eph.omega0_rad = 0.0;
  eph.omega_rad = 0.0;
  eph.m0_rad = 0.0;
  eph.omega_dot_radps = 7.2921151467e-5;  // Omega-dot = earth rate: the ascending node stays at longitude 0
  AntennaPhaseTracker tracker(2);
  EpochMaker maker;
  maker.noise = false;
  for (std::int64_t n = 0; n < 5; ++n)
    tracker.update(maker.make(n, {0.0, 0.25, 0.0}, {true, true, true}, 0.0), true, kFs);
  const Eigen::Vector3d r_rx(6378137.0, 0.0, 0.0);
  const double range = 26560e3 - 6378137.0;
  const auto o =
      make_antenna_observation(tracker, 3, 1000.0, 45.0, false, range, eph, {2190, 0.0}, 0.0, r_rx, 5 * kSamples, kFs);
  EXPECT_EQ(o.prn, 3);
  EXPECT_NEAR(o.carrier_phase_cycles[0], 1000.0, 1e-12);
  EXPECT_NEAR(o.carrier_phase_cycles[1], 1000.25, 1e-4);
  EXPECT_TRUE(o.usable[1]);
  EXPECT_TRUE(o.slip[1]);  // the first report of a track
  // Travel time 0.067 s: the satellite moved ~260 m along its orbit and the earth turned ~100 m: < 5e-5 rad.
  EXPECT_NEAR(o.los_e.x(), 1.0, 1e-6);
  EXPECT_NEAR(o.elevation_rad, M_PI / 2, 5e-5);
}

}  // namespace
}  // namespace ultratrack::receiver
