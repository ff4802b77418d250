// SPDX-License-Identifier: GPL-3.0-or-later
// No gate lock-out (fusion/lockout_recovery.hpp): the monitor's two triggers, the covariance it opens, and the
// integration's recovery from a start 50 m and 20 deg off and from a 30 s burst of fixes 200 m off, each beside
// the same run without recovery to show the lock-out the recovery removes.
#include "fusion/lockout_recovery.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "fusion/ins_error_state.hpp"
#include "fusion_sim.hpp"
#include "receiver/chi_square.hpp"

namespace ultratrack::fusion {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(LockoutMonitor, ConsecutiveRejectionsMustAlsoSpanTheMinimumTime) {
  LockoutRecoveryOptions o;
  o.consecutive_rejections = 5;
  o.min_span_s = 2.0;
  o.nis_window = 0;
  LockoutMonitor m(o);
  // 5 Hz: five rejections span 0.8 s, not enough; the eleventh (2.0 s after the first) trips it.
  for (int k = 0; k < 10; ++k) EXPECT_FALSE(m.observe(0.2 * k, false, 50.0, 3)) << k;
  const auto e = m.observe(2.0, false, 50.0, 3);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->t_s, 2.0);
  EXPECT_NE(e->reason.find("11 consecutive rejections over 2.0 s"), std::string::npos) << e->reason;
  // An accepted update in between starts the count again.
  for (int k = 0; k < 10; ++k) EXPECT_FALSE(m.observe(3.0 + 0.2 * k, k != 5, 50.0, 3)) << k;
}

TEST(LockoutMonitor, WindowedNisFarAboveItsBandTrips) {
  LockoutRecoveryOptions o;
  o.nis_window = 20;
  o.nis_window_probability = 1e-6;
  const double limit = receiver::chi_square_upper_quantile(60, 1e-6);  // 20 updates of 3 dof
  {
    LockoutMonitor m(o);  // each just below the limit's mean: never
    for (int k = 0; k < 100; ++k) EXPECT_FALSE(m.observe(k, true, 0.95 * limit / 20.0, 3)) << k;
  }
  LockoutMonitor m(o);  // each accepted, but the sum beyond the limit: trips when the window is full
  for (int k = 0; k < 19; ++k) EXPECT_FALSE(m.observe(k, true, 1.05 * limit / 20.0, 3)) << k;
  const auto e = m.observe(19.0, true, 1.05 * limit / 20.0, 3);
  ASSERT_TRUE(e);
  EXPECT_NE(e->reason.find("windowed NIS"), std::string::npos);
}

TEST(InflateForRecovery, OpensWhatTheFixesObserveAndKeepsTheBiases) {
  Eigen::MatrixXd P = Eigen::MatrixXd::Identity(15, 15) * 0.01;
  P(ix::kPos, ix::kGyroBias) = P(ix::kGyroBias, ix::kPos) = 0.001;
  P(ix::kAccelBias, ix::kGyroBias + 1) = P(ix::kGyroBias + 1, ix::kAccelBias) = 0.002;
  LockoutRecoveryOptions o;
  const Eigen::MatrixXd Q = inflate_for_recovery(P, Eigen::Vector3d(30.0, -40.0, 5.0), std::nullopt, 10.0, o);
  EXPECT_NEAR(Q(ix::kPos, ix::kPos), 4.0 * 900.0 + 1.0, 1e-9);
  EXPECT_NEAR(Q(ix::kPos + 1, ix::kPos + 1), 4.0 * 1600.0 + 1.0, 1e-9);
  EXPECT_NEAR(Q(ix::kVel, ix::kVel), 4.0 * std::pow(2.0 * std::sqrt(2525.0) / 10.0, 2) + 1.0, 1e-9);  // 2 |dp| / span
  EXPECT_NEAR(Q(ix::kAtt + 2, ix::kAtt + 2), o.attitude_sigma_rad.z() * o.attitude_sigma_rad.z(), 1e-15);
  EXPECT_EQ(Q(ix::kPos, ix::kGyroBias), 0.0);
  EXPECT_EQ(Q(ix::kAccelBias, ix::kGyroBias + 1), 0.002);
  EXPECT_EQ(Q(ix::kGyroBias, ix::kGyroBias), 0.01);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Q);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
}

// The loose filter on the harness's 300 s land trajectory (HG1700AE, 1 Hz fixes at 2/2/4 m): horizontal RMS over
// the last 100 s and the share of rejected fixes, with and without recovery.
struct Outcome {
  double horizontal_rms_m = 0.0;
  double rejected_share = 0.0;
  long long recoveries = 0;
};

Outcome run(test::SimConfig cfg, bool recovery, FilterKind filter) {
  cfg.recovery.enabled = recovery;
  const test::RunResult r = test::run_simulation(cfg, Coupling::kLoose, filter);
  Outcome o;
  double h2 = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < r.t_s.size(); ++i) {
    if (r.t_s[i] < cfg.duration_s - 100.0) continue;
    h2 += r.pos_err_m[i].head<2>().squaredNorm();
    ++n;
  }
  o.horizontal_rms_m = std::sqrt(h2 / std::max(n, 1));
  o.rejected_share = double(r.counters.fix_rejected) / double(r.counters.fix_accepted + r.counters.fix_rejected);
  o.recoveries = r.counters.recoveries;
  return o;
}

// The bound: the fixes' own horizontal 1-sigma (2.83 m); a converged loose filter is below it.
constexpr double kFixHorizontalSigma_m = 2.83;

TEST(LockoutRecovery, StartFiftyMetresAndTwentyDegreesOffRecovers) {
  for (FilterKind filter : {FilterKind::Ekf, FilterKind::Ukf}) {
    test::SimConfig cfg;
    cfg.initial_offset_pos_m = Eigen::Vector3d(35.0, 35.0, 0.0);  // 49.5 m
    cfg.initial_offset_att_rad = Eigen::Vector3d(0.0, 0.0, 20.0 * kDeg);
    const Outcome with = run(cfg, true, filter);
    const Outcome without = run(cfg, false, filter);
    std::printf("start off, %s: with recovery %.2f m (%lld recoveries, %.1f %% rejected); without %.1f m\n",
                filter == FilterKind::Ekf ? "EKF" : "UKF", with.horizontal_rms_m, with.recoveries,
                100.0 * with.rejected_share, without.horizontal_rms_m);
    EXPECT_GE(with.recoveries, 1);
    EXPECT_LT(with.horizontal_rms_m, kFixHorizontalSigma_m);
    EXPECT_LE(with.rejected_share, 0.10);
    // Without it the filter believes its wrong start and refuses the fixes that would correct it.
    EXPECT_GT(without.horizontal_rms_m, 10.0 * kFixHorizontalSigma_m);
  }
}

TEST(LockoutRecovery, ThirtySecondsOfFixesTwoHundredMetresOffDoNotLockTheFilterOut) {
  for (FilterKind filter : {FilterKind::Ekf, FilterKind::Ukf}) {
    test::SimConfig cfg;
    cfg.bias_start_s = 100.0;
    cfg.bias_length_s = 30.0;
    cfg.bias_offset_ned_m = Eigen::Vector3d(200.0, 0.0, 0.0);
    const Outcome with = run(cfg, true, filter);
    std::printf("burst, %s: with recovery %.2f m (%lld recoveries, %.1f %% rejected)\n",
                filter == FilterKind::Ekf ? "EKF" : "UKF", with.horizontal_rms_m, with.recoveries,
                100.0 * with.rejected_share);
    EXPECT_GE(with.recoveries, 1);
    EXPECT_LT(with.horizontal_rms_m, kFixHorizontalSigma_m);
    EXPECT_LE(with.rejected_share, 0.10);
  }
}

}  // namespace
}  // namespace ultratrack::fusion
