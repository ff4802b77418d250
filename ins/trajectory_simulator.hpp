// SPDX-License-Identifier: GPL-3.0-or-later
// Truth and exact IMU increments for a TrajectorySpec. The vehicle kinematics (speed, heading, height,
// Euler attitude) are smooth analytic functions of the commands, plus the vibration tones' sinusoids
// (TrajectorySpec::vibrations); position is integrated with RK4 on fine sub-steps (at most 2.5 ms, 40 per period of
// the fastest tone), and delta-theta / delta-v are the integrals of w_ib_b and f_b over each IMU interval on the same
// sub-steps, so an ideal IMU run through Strapdown reproduces the truth (with vibration, to the mechanisation's coning
// and sculling truncation). Units SI; frames as nav_state.hpp.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <vector>

#include "ins/nav_state.hpp"
#include "ins/trajectory.hpp"

namespace ultratrack::ins {

struct TruthSample {
  double t_s = 0.0;
  double lat_rad = 0.0, lon_rad = 0.0, height_m = 0.0;
  Eigen::Vector3d v_n = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_nb = Eigen::Quaterniond::Identity();
  Eigen::Vector3d w_ib_b = Eigen::Vector3d::Zero();  // true body rate at t_s [rad/s]
  Eigen::Vector3d f_b = Eigen::Vector3d::Zero();     // true specific force at t_s [m/s^2]
  double distance_m = 0.0;                           // path length travelled since the start

  NavState nav() const { return NavState{t_s, lat_rad, lon_rad, height_m, v_n, q_nb}; }
};

// Streams truth and IMU increments one IMU interval at a time (no storage: usable for hours at 1 kHz).
class TrajectoryGenerator {
 public:
  TrajectoryGenerator(TrajectorySpec spec, double imu_rate_hz);

  const TruthSample& truth() const { return truth_; }  // the current sample (t = 0 before any advance)
  bool done() const;                                   // the trajectory's duration has been reached
  // Advances one IMU interval: returns the ideal increment over it and updates truth().
  ImuIncrement advance();
  double dt_s() const { return dt_; }

 private:
  using State = std::array<double, 12>;  // speed, heading, lat, lon, h, distance, int(w_ib_b), int(f_b)
  struct Commands {
    double a, r, climb, grade;      // values
    double da, dr, dclimb, dgrade;  // time derivatives
  };
  Commands commands(double t) const;
  State derivative(double t, const State& y) const;
  void fill_truth(double t, const State& y, TruthSample& out) const;

  TrajectorySpec spec_;
  double dt_ = 0.0;
  int substeps_ = 1;
  long long k_ = 0;
  long long n_steps_ = 0;
  std::vector<double> seg_start_;
  State y_{};
  TruthSample truth_;
};

struct SimulatedRun {
  std::vector<TruthSample> truth;  // truth[0] at t = 0, truth[k] at k / rate
  std::vector<ImuIncrement> imu;   // imu[k] covers (truth[k].t_s, truth[k+1].t_s]
};

SimulatedRun simulate(const TrajectorySpec& spec, double imu_rate_hz);

}  // namespace ultratrack::ins
