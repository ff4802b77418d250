// SPDX-License-Identifier: GPL-3.0-or-later
// Closed-loop GNSS/INS integration on ins/ trajectory simulations with the HG1700AE preset and GNSS simulated
// from the truth with known noise: position RMS below the GNSS-only RMS, NEES consistency, a 60 s outage,
// tight integration with 3 satellites, exact-time measurement application and the fallback.
// ULTRATRACK_FUSION_MC_RUNS=100 runs the outage Monte Carlo with 100 runs (default 8 to keep CI short).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fusion/gnss_ins_integration.hpp"
#include "fusion_sim.hpp"
#include "ins/nav_correction.hpp"
#include "ins/trajectory.hpp"
#include "ins/trajectory_simulator.hpp"
#include "receiver/chi_square.hpp"

namespace ultratrack::fusion {
namespace {

using test::RunResult;
using test::SimConfig;

int mc_runs() {
  const char* s = std::getenv("ULTRATRACK_FUSION_MC_RUNS");
  return s ? std::max(1, std::atoi(s)) : 8;
}

const char* name(Coupling c, FilterKind f) {
  if (c == Coupling::kLoose) return f == FilterKind::Ekf ? "loose EKF" : "loose UKF";
  return f == FilterKind::Ekf ? "tight EKF" : "tight UKF";
}

// Position RMS after convergence (t > 60 s) below the GNSS-only RMS; NEES averaged over the run and over
// a few runs inside the chi-square 95 % band for the pooled degrees of freedom (with a factor 2 margin on the
// upper side for the time correlation of the samples of one run and for unmodelled gyro output noise).
void check_accuracy_and_consistency(Coupling coupling, FilterKind filter) {
  const int runs = 4;
  double sum_ins = 0, sum_gnss = 0, nees_sum = 0, nees9_sum = 0;
  std::size_t nees_n = 0;
  int n_state = 0;
  for (int r = 0; r < runs; ++r) {
    SimConfig cfg;
    cfg.seed = 100 + r;
    cfg.duration_s = 240.0;
    const RunResult res = test::run_simulation(cfg, coupling, filter);
    n_state = res.state_size;
    const std::size_t from = 60;
    sum_ins += std::pow(test::rms3(res.pos_err_m, from), 2);
    sum_gnss += std::pow(test::rms(res.gnss_err_3d_m, from), 2);
    for (std::size_t i = from; i < res.nees.size(); ++i)
      nees_sum += res.nees[i], nees9_sum += res.nees_nav[i], ++nees_n;
    // Consistent measurements pass the 0.9999 gate: at most a rare one is refused.
    EXPECT_LE(res.rejected, 1 + res.accepted / 1000) << "rejected " << res.rejected << " of " << res.accepted;
  }
  const double ins_rms = std::sqrt(sum_ins / runs), gnss_rms = std::sqrt(sum_gnss / runs);
  const double nees = nees_sum / nees_n;
  std::printf("%s: 3-D position RMS %.2f m (GNSS-only %.2f m), mean NEES %.2f (%d states), %.2f (9 nav states)\n",
              name(coupling, filter), ins_rms, gnss_rms, nees, n_state, nees9_sum / nees_n);
  EXPECT_LT(ins_rms, gnss_rms);
  EXPECT_GT(nees, 0.5 * n_state);
  EXPECT_LT(nees, 2.0 * n_state);
}

TEST(LooseIntegration, EkfBeatsGnssAndIsConsistent) {
  check_accuracy_and_consistency(Coupling::kLoose, FilterKind::Ekf);
}
TEST(LooseIntegration, UkfBeatsGnssAndIsConsistent) {
  check_accuracy_and_consistency(Coupling::kLoose, FilterKind::Ukf);
}
TEST(TightIntegration, EkfBeatsGnssAndIsConsistent) {
  check_accuracy_and_consistency(Coupling::kTight, FilterKind::Ekf);
}
TEST(TightIntegration, UkfBeatsGnssAndIsConsistent) {
  check_accuracy_and_consistency(Coupling::kTight, FilterKind::Ukf);
}

// 60 s outage after 200 s of convergence: horizontal drift RMS over the Monte Carlo runs.
double outage_drift_rms(const std::string& preset, FilterKind filter, int runs, double& sigma_rms) {
  double s2 = 0.0, q2 = 0.0;
  for (int r = 0; r < runs; ++r) {
    SimConfig cfg;
    cfg.imu_preset = preset;
    cfg.seed = 500 + r;
    cfg.duration_s = 265.0;
    cfg.outage_start_s = 200.37;  // a GNSS time: the fix there is the last before the outage
    cfg.outage_length_s = 60.0;
    if (preset == "navigation") {
      // A navigation-grade unit comes with a good alignment and, like the 0.87 m anchor, RTK-grade fixes:
      // with 2 m SPS fixes the position error at the start of the outage alone is ~0.5 m and the velocity
      // error (~0.02 m/s) adds 1.2 m over 60 s (2.5 m RMS measured), whatever the IMU.
      cfg.sigma0_att_rad = Eigen::Vector3d(2e-4, 2e-4, 1e-3);
      cfg.sigma_pos_ned_m = Eigen::Vector3d(0.05, 0.05, 0.1);
      cfg.sigma_vel_n_mps = Eigen::Vector3d(0.01, 0.01, 0.02);
    }
    const RunResult res = test::run_simulation(cfg, Coupling::kLoose, filter);
    s2 += res.outage_drift_h_m * res.outage_drift_h_m;
    q2 += res.outage_sigma_h_m * res.outage_sigma_h_m;
  }
  sigma_rms = std::sqrt(q2 / runs);
  return std::sqrt(s2 / runs);
}

TEST(LooseIntegration, SixtySecondOutageDriftHg1700ae) {
  const int runs = mc_runs();
  double sigma = 0.0;
  const double drift = outage_drift_rms("hg1700ae", FilterKind::Ekf, runs, sigma);
  std::printf("HG1700AE 60 s outage: horizontal drift RMS %.2f m over %d runs (filter 1-sigma RMS %.2f m)\n", drift,
              runs, sigma);
  EXPECT_LE(drift, 10.0);  // issue 6 target
}

TEST(LooseIntegration, SixtySecondOutageDriftNavigationGrade) {
  const int runs = mc_runs();
  double sigma = 0.0;
  const double drift = outage_drift_rms("navigation", FilterKind::Ekf, runs, sigma);
  std::printf("navigation 60 s outage: horizontal drift RMS %.2f m over %d runs (filter 1-sigma RMS %.2f m)\n", drift,
              runs, sigma);
  EXPECT_LE(drift, 1.0);  // issue 6 target (anchor: 0.87 m 3-D RMS of an open navigation-grade system)
}

// Only 3 satellites after convergence: tight integration keeps the error far below the free INS's, where a
// PVT cannot fix at all. (With 3 satellites and the clock free, one direction is unobserved: the error grows
// there, but slowly, and the filter knows it: NEES stays below its 99.9 % quantile.)
TEST(TightIntegration, BoundedWithThreeSatellites) {
  for (FilterKind f : {FilterKind::Ekf, FilterKind::Ukf}) {
    SimConfig cfg;
    cfg.seed = 77;
    cfg.duration_s = 301.0;
    cfg.max_satellites = 3;
    cfg.reduce_after_s = 120.0;
    const RunResult with3 = test::run_simulation(cfg, Coupling::kTight, f);
    SimConfig free = cfg;  // the same run with no GNSS at all from 120 s: the free INS
    free.max_satellites = 0;
    free.outage_start_s = 119.9;
    free.outage_length_s = 180.0;
    const RunResult none = test::run_simulation(free, Coupling::kTight, f);
    double max_after = 0.0;
    for (std::size_t i = 0; i < with3.t_s.size(); ++i)
      if (with3.t_s[i] > 120.0) max_after = std::max(max_after, with3.pos_err_m[i].head<2>().norm());
    // receiver/pvt needs 4 satellites: it fixed only before the reduction (about 120 epochs).
    EXPECT_LE(with3.gnss_err_h_m.size(), 121u);
    std::printf("%s, 3 satellites for 180 s: horizontal error max %.2f m (end %.2f m); free INS %.2f m\n",
                f == FilterKind::Ekf ? "tight EKF" : "tight UKF", max_after, with3.pos_err_m.back().head<2>().norm(),
                none.outage_drift_h_m);
    EXPECT_LT(max_after, 0.5 * none.outage_drift_h_m);
    EXPECT_LT(with3.nees.back(), receiver::chi_square_lower_quantile(17, 0.999));
  }
}

// Measurements are applied at their exact time: precise fixes (1 cm) 4.3 ms after an IMU sample on a vehicle
// at 139 m/s. The filter is told of velocity noise (its position sigma reaches several cm between fixes), so a
// fix applied at the nearest IMU sample (0.6 m away along the track) would either pull the INS off by
// decimetres or be refused by the gate; applied at its time, every fix passes and the error stays at cm
// (the IMU carries an unmodelled 5 mg bias, so the INS drifts ~3 cm between fixes and each update matters).
TEST(LooseIntegration, AppliesFixesAtTheirExactTime) {
  const ins::TrajectorySpec spec = ins::profile_spec("circle", 30.0, 0.6, 2.1, 500.0);
  const ins::SimulatedRun run = ins::simulate(spec, 100.0);
  const ins::TruthInterpolator interp(run.truth);
  IntegrationOptions opt;  // ideal IMU: only the initial error and the fixes matter
  opt.sigma_pos_ned_m = Eigen::Vector3d::Constant(5.0);
  opt.sigma_vel_n_mps = Eigen::Vector3d::Constant(0.01);
  opt.sigma_att_rad = Eigen::Vector3d::Constant(1e-6);
  opt.model.accel.bias_sigma = 1e-9;
  opt.model.gyro.bias_sigma = 1e-12;
  opt.model.accel.white_noise_psd = 0.01;  // (m/s^2)^2/Hz
  ins::NavState init = run.truth[0].nav();
  ins::correct_position(init, Eigen::Vector3d(-4.0, 3.0, -2.0));  // 4, -3, 2 m error
  GnssInsIntegration integ(init, opt);
  double worst = 0.0;
  for (std::size_t k = 0; k + 1 < run.truth.size(); ++k) {
    const double t_fix = std::floor(run.truth[k].t_s) + 0.0043;
    const bool fix_here = t_fix > run.truth[k].t_s && t_fix <= run.truth[k + 1].t_s;
    if (fix_here) {
      GnssFix fix;
      fix.t_s = t_fix;
      test::geodetic_from_ecef(interp.antenna(t_fix, Eigen::Vector3d::Zero()).r_e, fix.lat_rad, fix.lon_rad,
                               fix.height_m);
      fix.sigma_pos_ned_m = Eigen::Vector3d::Constant(0.01);
      integ.add_fix(fix);
    }
    ins::ImuIncrement inc = run.imu[k];
    inc.dv_b.x() += 0.05 * (run.truth[k + 1].t_s - run.truth[k].t_s);  // unmodelled 5 mg: the INS drifts between fixes
    integ.add_imu(inc);
    if (fix_here && run.truth[k].t_s > 2.0) {
      const double e = ins::position_error_ned(integ.output().nav, run.truth[k + 1].nav()).norm();
      worst = std::max(worst, e);
    }
  }
  std::printf("exact-time fixes: worst position error after an update %.5f m, %lld accepted, %lld rejected\n", worst,
              integ.counters().accepted, integ.counters().rejected);
  EXPECT_LT(worst, 0.05);
  EXPECT_GE(integ.counters().accepted, 29);
  EXPECT_EQ(integ.counters().rejected, 0);
}

// Fallback ([OhAttINS]): epochs with position only, velocity only, or nothing still run the filter.
TEST(LooseIntegration, FallsBackToWhatIsPresent) {
  SimConfig cfg;
  cfg.seed = 9;
  cfg.duration_s = 150.0;
  cfg.velocity = false;  // position only
  const RunResult pos_only = test::run_simulation(cfg, Coupling::kLoose, FilterKind::Ekf);
  EXPECT_LT(test::rms3(pos_only.pos_err_m, 60), test::rms(pos_only.gnss_err_3d_m, 60));
  EXPECT_GT(pos_only.accepted, 140);
  // Velocity-only fixes through the public API: position error cannot be observed, but velocity is.
  const ins::TrajectorySpec spec = ins::profile_spec("land", 60.0, 0.6, 2.1, 50.0);
  const ins::SimulatedRun run = ins::simulate(spec, 100.0);
  IntegrationOptions opt;
  ins::NavState init = run.truth[0].nav();
  init.v_n += Eigen::Vector3d(0.5, -0.5, 0.2);
  GnssInsIntegration integ(init, opt);
  for (std::size_t k = 0; k + 1 < run.truth.size(); ++k) {
    if (k % 100 == 50) {
      GnssFix fix;
      fix.t_s = run.truth[k].t_s;  // exactly at the INS time: applied at once
      fix.has_position = false;
      fix.has_velocity = true;
      fix.v_n_mps = run.truth[k].v_n;
      fix.sigma_vel_n_mps = Eigen::Vector3d::Constant(0.02);
      integ.add_fix(fix);
    }
    integ.add_imu(run.imu[k]);
  }
  EXPECT_LT((integ.output().nav.v_n - run.truth.back().v_n).norm(), 0.1);
  EXPECT_GT(integ.output().sigma_pos_ned_m.x(), 9.0);  // position unobserved: stays near its 10 m prior
}

TEST(Integration, RejectsWrongInputKind) {
  IntegrationOptions opt;
  GnssInsIntegration loose(ins::NavState{}, opt);
  EXPECT_THROW(loose.add_observations({}, {}), std::logic_error);
  // Non-finite or out-of-order data are ignored and counted, never propagated into the solution.
  ins::ImuIncrement bad;
  bad.t_s = 0.01;
  bad.dv_b.x() = std::nan("");
  loose.add_imu(bad);
  GnssFix nan_fix;
  nan_fix.t_s = 0.5;
  nan_fix.lat_rad = std::nan("");
  loose.add_fix(nan_fix);
  ins::ImuIncrement past;
  past.t_s = -1.0;
  loose.add_imu(past);
  EXPECT_EQ(loose.counters().invalid, 3);
  EXPECT_TRUE(loose.output().nav.v_n.allFinite());
  EXPECT_EQ(loose.output().nav.t_s, 0.0);
  opt.sigma_pos_ned_m.x() = 0.0;
  EXPECT_THROW(GnssInsIntegration(ins::NavState{}, opt), std::invalid_argument);
}

}  // namespace
}  // namespace ultratrack::fusion
