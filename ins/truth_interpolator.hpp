// SPDX-License-Identifier: GPL-3.0-or-later
// Truth at any time between simulator samples, and the motion of an antenna on the vehicle in ECEF:
// r_ant_e = r_imu_e + C_en C_nb l_b, v_ant_e = C_en v_n + C_en C_nb (w_eb_b x l_b). Antenna position and
// velocity are cubic-Hermite interpolated (position and velocity match at both samples), attitude is slerped.
// This is the motion function the IF synthesiser takes (tools/ wires it). Time: seconds on the run's line.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "ins/trajectory_simulator.hpp"

namespace ultratrack::ins {

struct EcefMotion {
  Eigen::Vector3d r_e = Eigen::Vector3d::Zero();  // m
  Eigen::Vector3d v_e = Eigen::Vector3d::Zero();  // m/s
};

// Antenna motion exactly at a truth sample.
EcefMotion antenna_motion_at_sample(const TruthSample& s, const Eigen::Vector3d& lever_arm_b);

class TruthInterpolator {
 public:
  // samples: strictly increasing times (as produced by simulate()); at least two.
  explicit TruthInterpolator(std::vector<TruthSample> samples);

  double start_s() const { return samples_.front().t_s; }
  double end_s() const { return samples_.back().t_s; }
  // Antenna motion at t (clamped to [start, end]); lever arm in body axes [m].
  EcefMotion antenna(double t_s, const Eigen::Vector3d& lever_arm_b) const;
  // Attitude body->NED at t (slerp).
  Eigen::Quaterniond attitude(double t_s) const;
  const std::vector<TruthSample>& samples() const { return samples_; }

 private:
  std::size_t index(double t_s) const;  // i with samples_[i].t <= t < samples_[i+1].t
  std::vector<TruthSample> samples_;
  double uniform_dt_ = 0.0;  // > 0 when the samples are evenly spaced: O(1) look-up
};

}  // namespace ultratrack::ins
