// SPDX-License-Identifier: GPL-3.0-or-later
// AttitudeSolver over sequences of epochs (1 Hz, nominal constellation, seed geometry, 3 mm noise): ambiguities
// carried, flagged and unflagged cycle slips, a 5 s blockage of one antenna, a satellite rising, an array turning at
// 10 deg/s, and the line-bias calibration. Truth from attitude_phase_simulator.hpp. The invariant everywhere: a
// valid output has the right integers and an attitude within 5 sigma of the truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "attitude_phase_simulator.hpp"
#include "receiver/attitude_solver.hpp"

using namespace ultratrack::receiver;
using testsim::PhaseSimulator;
using ultratrack::io::kRadPerDeg;

namespace {

AttitudeSolver seed_solver() {
  AttitudeSolverOptions o;
  o.array.lever_arm_body_m = testsim::seed_lever_arms();
  return AttitudeSolver(o);
}

bool ambiguities_correct(const AttitudeSolution& s, PhaseSimulator& sim) {
  std::map<int, SdAmbiguity> anchor;
  for (const SdAmbiguity& a : s.ambiguities) {
    auto it = anchor.find(a.antenna);
    if (it == anchor.end()) {
      anchor[a.antenna] = a;
    } else if (a.cycles - it->second.cycles != sim.true_dd(a.antenna, a.prn, it->second.prn)) {
      return false;
    }
  }
  return !s.ambiguities.empty();
}

// The invariant of every valid output.
void expect_right(const AttitudeSolution& s, PhaseSimulator& sim, double roll, double pitch, double yaw, int epoch) {
  ASSERT_TRUE(ambiguities_correct(s, sim)) << "epoch " << epoch;
  const double err[3] = {std::remainder(s.roll_rad - roll, 2 * M_PI), std::remainder(s.pitch_rad - pitch, 2 * M_PI),
                         std::remainder(s.yaw_rad - yaw, 2 * M_PI)};
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(std::abs(err[i]), 5.0 * std::sqrt(s.covariance_rad2(i, i))) << "epoch " << epoch << " angle " << i;
  }
}

bool has_ambiguity(const AttitudeSolution& s, int antenna, int prn) {
  return std::any_of(s.ambiguities.begin(), s.ambiguities.end(),
                     [&](const SdAmbiguity& a) { return a.antenna == antenna && a.prn == prn; });
}

// The first whole hour of day 2 of week 2300 from which the nominal constellation shows at least 8 satellites above
// 10 deg at the seed location for the next `seconds`.
double start_with_eight(const PhaseSimulator& sim, double seconds) {
  for (double t = 86400.0;; t += 600.0) {
    bool ok = true;
    for (double dt = 0.0; dt <= seconds && ok; dt += 10.0) ok = sim.nominal_sky({2300, t + dt}).size() >= 8;
    if (ok) return t;
  }
}

}  // namespace

TEST(AttitudeTracking, SlipsAndBlockageNeverGiveAWrongAttitudeAndRefixAtOnce) {
  PhaseSimulator sim(testsim::seed_lever_arms(), 21);
  AttitudeSolver solver = seed_solver();
  const double roll = 3 * kRadPerDeg, pitch = -4 * kRadPerDeg, yaw = 123 * kRadPerDeg;
  const Eigen::Matrix3d C_nb = testsim::dcm_nb(roll, pitch, yaw);
  const double kT0 = start_with_eight(sim, 60);
  int valid = 0;
  for (int i = 0; i < 60; ++i) {
    const auto sky = sim.nominal_sky({2300, kT0 + i});
    ASSERT_GE(sky.size(), 8u);
    const int a = sky[0].prn, b = sky[1].prn, c = sky[2].prn, d = sky[3].prn;
    std::vector<bool> blocked(3, false);
    if (i == 10) sim.ambiguity(1, a) += 7;                            // flagged below
    if (i == 20) sim.ambiguity(2, b) += 1;                            // not flagged
    if (i == 30) sim.ambiguity(0, c) -= 3;                            // master, flagged
    if (i == 40) sim.ambiguity(0, d) += 1, sim.ambiguity(1, c) -= 2;  // two, not flagged
    if (i >= 45 && i < 50) blocked[2] = true;  // antenna 2 blocked for 5 s, then back with new integers
    if (i == 50) {
      for (const auto& s : sky) sim.ambiguity(2, s.prn) += 1000 + s.prn;
    }
    AntennaPhaseEpoch e = sim.epoch(sky, C_nb, kT0 + i, blocked);
    if (i == 55) {
      // No position: no frame, no output; the ambiguities are still good at the next epoch.
      e.master_position_e = Eigen::Vector3d::Zero();
      EXPECT_FALSE(solver.update(e).valid);
      e.master_position_e = sim.r_master_e;
    }
    for (auto& o : e.satellites) {
      if (i == 10 && o.prn == a) o.slip[1] = true;
      if (i == 30 && o.prn == c) o.slip[0] = true;
      if (i == 50) o.slip[2] = true;
    }
    const AttitudeSolution s = solver.update(e);
    if (s.valid) {
      ++valid;
      EXPECT_TRUE(s.fixed);
      expect_right(s, sim, roll, pitch, yaw, i);
    }
    if (i >= 45 && i < 50) {
      EXPECT_FALSE(s.valid) << "one baseline cannot give a full attitude";
      continue;
    }
    EXPECT_TRUE(s.valid) << "epoch " << i;
    if (i == 0) {
      EXPECT_TRUE(s.new_fix);
    }
    if (i == 10) {
      // The flagged ambiguity restarted and rejoined in the same epoch (rounded against the carried attitude).
      EXPECT_NE(std::find(s.slipped_prns.begin(), s.slipped_prns.end(), a), s.slipped_prns.end());
      EXPECT_FALSE(s.new_fix);
      EXPECT_TRUE(has_ambiguity(s, 1, a));
    }
    if (i == 20 || i == 40) {
      // The unflagged slip fails the residual check: everything restarts and is resolved again this epoch.
      EXPECT_FALSE(s.slipped_prns.empty()) << i;
      EXPECT_TRUE(s.new_fix) << i;
    }
    if (i == 30) {
      EXPECT_TRUE(has_ambiguity(s, 1, c) && has_ambiguity(s, 2, c));
    }
    if (i == 11 || i == 21 || i == 31 || i == 51 || i == 55) {
      EXPECT_FALSE(s.new_fix) << i;
    }
  }
  EXPECT_EQ(valid, 55);
}

TEST(AttitudeTracking, TurningArrayAndARisingSatellite) {
  PhaseSimulator sim(testsim::seed_lever_arms(), 22);
  AttitudeSolver solver = seed_solver();
  double sum_sq_yaw = 0.0, sum_var_yaw = 0.0;
  int n = 0;
  int rising_prn = 0;
  const double kT0 = start_with_eight(sim, 60) - 7200;
  for (int i = 0; i < 60; ++i) {
    const double t = i;  // 1 Hz: the array turns 10 deg between epochs
    const double yaw = std::fmod(10.0 * kRadPerDeg * t, 2 * M_PI);
    const double roll = 10 * kRadPerDeg * std::sin(2 * M_PI * t / 20.0),
                 pitch = 5 * kRadPerDeg * std::cos(2 * M_PI * t / 15.0);
    auto sky = sim.nominal_sky({2300, kT0 + 7200 + t});
    ASSERT_GE(sky.size(), 8u);
    if (i == 0) rising_prn = sky.back().prn;
    if (i < 20) {
      sky.erase(std::remove_if(sky.begin(), sky.end(), [&](const auto& s) { return s.prn == rising_prn; }), sky.end());
    }
    const AttitudeSolution s = solver.update(sim.epoch(sky, testsim::dcm_nb(roll, pitch, yaw), kT0 + 7200 + t));
    ASSERT_TRUE(s.valid) << i;
    EXPECT_EQ(s.new_fix, i == 0) << i;
    expect_right(s, sim, roll, pitch, yaw, i);
    EXPECT_EQ(s.num_sats, static_cast<int>(sky.size())) << i;
    if (i == 20) {
      EXPECT_TRUE(has_ambiguity(s, 1, rising_prn) && has_ambiguity(s, 2, rising_prn));
    }
    const double e = std::remainder(s.yaw_rad - yaw, 2 * M_PI);
    sum_sq_yaw += e * e;
    sum_var_yaw += s.covariance_rad2(2, 2);
    ++n;
  }
  std::printf("turning array: yaw RMS %.3f deg, theory %.3f deg over %d epochs\n",
              std::sqrt(sum_sq_yaw / n) / kRadPerDeg, std::sqrt(sum_var_yaw / n) / kRadPerDeg, n);
  EXPECT_LE(std::sqrt(sum_sq_yaw / n) / kRadPerDeg, 0.15 * 1.5);  // 60 samples: RMS known to ~10 %
}

TEST(AttitudeTracking, LineBiasCalibrationMatchesTheSimulatedBias) {
  PhaseSimulator sim(testsim::seed_lever_arms(), 23);
  AttitudeSolver solver = seed_solver();
  const Eigen::Matrix3d C_nb = testsim::dcm_nb(-2 * kRadPerDeg, 1 * kRadPerDeg, 250 * kRadPerDeg);
  AttitudeSolution s;
  const double kT0 = start_with_eight(sim, 100) - 20000;
  for (int i = 0; i < 100; ++i) {
    s = solver.update(sim.epoch(sim.nominal_sky({2300, kT0 + 20000 + i}), C_nb, kT0 + 20000 + i));
    ASSERT_TRUE(s.valid);
  }
  for (int k = 1; k < 3; ++k) {
    const double truth = sim.line_bias_cycles[static_cast<std::size_t>(k)] - sim.line_bias_cycles[0];
    const double err = std::remainder(s.line_bias_cycles[static_cast<std::size_t>(k)] - truth, 1.0);
    std::printf("line bias %d: %.4f cycles (truth mod 1 %.4f), sigma %.4f\n", k,
                s.line_bias_cycles[static_cast<std::size_t>(k)], std::remainder(truth, 1.0),
                s.line_bias_sigma_cycles[static_cast<std::size_t>(k)]);
    EXPECT_GE(s.line_bias_cycles[static_cast<std::size_t>(k)], -0.5);
    EXPECT_LT(s.line_bias_cycles[static_cast<std::size_t>(k)], 0.5);
    // The SDs' common mode looks up, so each epoch's bias carries the vertical baseline error (~5 mm, 0.03 cycles
    // at 0.3 deg of roll/pitch): 100 epochs give about 0.003 cycles.
    EXPECT_LT(s.line_bias_sigma_cycles[static_cast<std::size_t>(k)], 0.005);
    EXPECT_LE(std::abs(err), 5.0 * s.line_bias_sigma_cycles[static_cast<std::size_t>(k)] + 1e-4);
  }
}

TEST(AttitudeTracking, FourAntennasKeepTheAttitudeWhileOneIsBlocked) {
  std::vector<Eigen::Vector3d> lever = testsim::seed_lever_arms();
  lever.push_back(Eigen::Vector3d(1.0, 1.025, 0.0));
  PhaseSimulator sim(lever, 24);
  AttitudeSolverOptions o;
  o.array.lever_arm_body_m = lever;
  AttitudeSolver solver(o);
  const double roll = -5 * kRadPerDeg, pitch = 2 * kRadPerDeg, yaw = 42 * kRadPerDeg;
  const double kT0 = start_with_eight(sim, 20);
  for (int i = 0; i < 20; ++i) {
    const auto sky = sim.nominal_sky({2300, kT0 + i});
    std::vector<bool> blocked(4, false);
    blocked[3] = i >= 5 && i < 10;
    if (i == 10) {
      for (const auto& s : sky) sim.ambiguity(3, s.prn) -= 500 + 3 * s.prn;
    }
    AntennaPhaseEpoch e = sim.epoch(sky, testsim::dcm_nb(roll, pitch, yaw), kT0 + i, blocked);
    for (auto& ob : e.satellites) ob.slip[3] = i == 10;
    const AttitudeSolution s = solver.update(e);
    ASSERT_TRUE(s.valid) << i;
    EXPECT_EQ(s.new_fix, i == 0) << i;
    expect_right(s, sim, roll, pitch, yaw, i);
    EXPECT_EQ(has_ambiguity(s, 3, sky[0].prn), !(i >= 5 && i < 10)) << i;
    EXPECT_EQ(s.baseline_n_m.size(), 3u);
  }
}
