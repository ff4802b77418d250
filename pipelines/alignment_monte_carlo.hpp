// SPDX-License-Identifier: GPL-3.0-or-later
// Filter-level Monte Carlo of the stationary alignment ([KimAlign] section IV.1, Table 2): per run, an IMU at rest
// (closed-form earth rate and gravity increments at the IMU rate, corrupted by errors drawn from the IMU spec) and
// GPS attitudes (the array's truth attitude plus white Euler noise at the attitude rate), aligned by
// fusion::align_stationary; statistics of the final errors over the runs beside the filter's own 1-sigma.
// Angles rad; times s; seeds make every run reproducible.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "fusion/attitude_measurement.hpp"
#include "fusion/stationary_alignment.hpp"
#include "ins/attitude.hpp"
#include "ins/imu_error_model.hpp"
#include "ins/nav_state.hpp"

namespace ultratrack::pipelines {

struct StationaryScenario {
  ins::EulerAngles attitude;  // IMU body relative to NED (truth)
  double lat_rad = 0.0, height_m = 0.0;
  double duration_s = 100.0;
  double imu_rate_hz = 100.0;
  double attitude_rate_hz = 1.0;
  double attitude_offset_s = 0.005;  // first attitude time (IMU rows at k / rate, k >= 1)
  Eigen::Vector3d gps_sigma_euler_rad = Eigen::Vector3d::Constant(1e-3);  // white noise of each GPS attitude
  Eigen::Quaterniond q_ba = Eigen::Quaterniond::Identity();               // true mounting, array -> body
  ins::ImuErrorSpec imu;
};

struct StationaryInputs {
  std::vector<ins::ImuIncrement> imu;
  std::vector<fusion::GnssAttitude> gps;  // array attitudes; sigma = the scenario's
  ins::ImuErrors errors;                  // the drawn turn-on errors
};

StationaryInputs simulate_stationary_inputs(const StationaryScenario& scenario, std::uint64_t seed);

struct AxisStatistics {
  double mean = 0.0, std = 0.0, rms = 0.0;  // of the final error over the runs
  double mean_sigma = 0.0;                  // the filter's final 1-sigma, averaged over the runs
  int outside_3sigma = 0;                   // runs whose error exceeds 3 of their own sigma
};

struct AlignmentMonteCarloResult {
  int runs = 0;
  AxisStatistics roll, pitch, yaw;
};

// Runs seeds first_seed .. first_seed + runs - 1 through align_stationary (options.duration_s, lat etc. are
// taken from the scenario).
AlignmentMonteCarloResult alignment_monte_carlo(const StationaryScenario& scenario,
                                                fusion::StationaryAlignmentOptions options, int runs,
                                                std::uint64_t first_seed = 1);

}  // namespace ultratrack::pipelines
