// SPDX-License-Identifier: GPL-3.0-or-later
// Fine alignment of a strapdown INS at rest from zero velocity and a multi-antenna receiver's GPS attitude
// ([KimAlign], Fig. 1): the INS runs at the IMU rate from the first usable GPS attitude; every filter interval the
// 12-state filter (fusion/stationary_alignment_model.hpp, EKF or UKF) predicts, takes the zero-velocity
// measurement and the latest GPS attitude of the interval, and its estimate is fed back into the INS (attitude,
// velocity, bias estimates) and reset: a closed loop, as the seed's strapdown computation corrected by the filter.
// Times on the IMU file's time line (s); angles rad; biases body axes (m/s^2, rad/s).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "fusion/attitude_measurement.hpp"
#include "fusion/filter_types.hpp"
#include "fusion/gnss_ins_integration.hpp"
#include "fusion/stationary_alignment_model.hpp"
#include "fusion/ukf.hpp"
#include "ins/imu_error_model.hpp"
#include "ins/nav_state.hpp"

namespace ultratrack::fusion {

struct StationaryAlignmentOptions {
  FilterKind filter = FilterKind::Ekf;
  UkfParameters ukf;
  GateOptions gate;
  double filter_interval_s = 1.0;  // [KimAlign]: 1 s
  double duration_s = 0.0;         // from the first GPS attitude; 0: to the end of the IMU data
  double lat_rad = 0.0, lon_rad = 0.0, height_m = 0.0;
  ins::ImuErrorSpec imu;                 // noise PSDs and initial bias 1-sigmas (floors 1e-5 m/s^2, 1e-8 rad/s)
  double zero_velocity_sigma_mps = 0.0;  // 0: the accelerometer's output white noise, at least 1 mm/s
  double initial_velocity_sigma_mps = 0.01;
  Eigen::Quaterniond q_ba = Eigen::Quaterniond::Identity();    // antenna array -> IMU body (known mounting)
  double max_abs_pitch_rad = 80.0 * std::numbers::pi / 180.0;  // GPS attitudes beyond are not used

  // Interval positive, sigmas and position finite, q_ba a unit quaternion, pitch limit in (0, 90] deg.
  bool IsValid(std::string* why) const;
};

// The state after one filter epoch (after feedback).
struct AlignmentEpoch {
  double t_s = 0.0;
  ins::EulerAngles euler;
  Eigen::Vector3d sigma_euler_rad = Eigen::Vector3d::Zero();  // roll, pitch, yaw 1-sigma (H_G P_psi H_G')
  Eigen::Vector3d accel_bias_b = Eigen::Vector3d::Zero(), gyro_bias_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_n = Eigen::Vector3d::Zero();
  bool attitude_used = false;
};

struct StationaryAlignmentResult {
  double start_s = 0.0, end_s = 0.0;
  ins::NavState nav;  // at end_s
  Eigen::Vector3d accel_bias_b = Eigen::Vector3d::Zero(), gyro_bias_b = Eigen::Vector3d::Zero();
  AlignmentMatrix P = AlignmentMatrix::Zero();  // of the (reset) error state at end_s
  Eigen::Vector3d sigma_euler_rad = Eigen::Vector3d::Zero();
  std::vector<AlignmentEpoch> history;
  long long zero_velocity_updates = 0, zero_velocity_rejected = 0, attitude_updates = 0, attitude_rejected = 0,
            attitude_unusable = 0;
};

// Throws std::invalid_argument when no usable GPS attitude lies inside the IMU data, or the IMU holds fewer than
// two rows after it (pipelines turn that into an input error naming the files).
StationaryAlignmentResult align_stationary(std::span<const ins::ImuIncrement> imu,
                                           std::span<const GnssAttitude> attitudes,
                                           const StationaryAlignmentOptions& options);

}  // namespace ultratrack::fusion
