// SPDX-License-Identifier: GPL-3.0-or-later
// The navigation settings shared by `fuse` and `receive --coupling loose|tight|ultra-tight` (the TOML keys of
// config/fuse_config_toml.hpp fill it): the IMU error preset and datasheet values, the initial state and its 1-sigmas,
// the alignment spans, the GNSS fix weights and lever arm, the filter's UKF and gate parameters, the receiver clock's
// oscillator and height aiding (tight), and GPS attitude's time origin and misalignment. Units: SI except where the
// name says deg.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "fusion/clock_model.hpp"
#include "fusion/gnss_ins_integration.hpp"
#include "ins/imu_datasheet.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::pipelines {

struct FuseConfig {
  std::string imu_preset = "hg1700ae";
  ins::ImuDatasheet imu_datasheet;                  // [imu] datasheet keys over the preset
  double imu_max_gap_s = 1.0;                       // [imu] max_gap_s: a longer gap between IMU rows is an input error
  std::optional<Eigen::Vector3d> attitude_deg;      // roll, pitch, yaw
  std::optional<Eigen::Vector3d> position_deg_m;    // lat_deg, lon_deg, height_m
  std::optional<Eigen::Vector3d> velocity_ned_mps;  // --align config without GNSS velocity (receive --imu)
  std::optional<Eigen::Vector3d> sigma_position_m, sigma_velocity_mps, sigma_attitude_deg;
  // IMU biases already estimated (`ultratrack align`'s alignment.json), body axes, with their 1-sigma: the filter
  // starts from them instead of zero and the preset's turn-on sigma (--align file:).
  std::optional<Eigen::Vector3d> initial_accel_bias_mps2, sigma_accel_bias_mps2;
  std::optional<Eigen::Vector3d> initial_gyro_bias_rps, sigma_gyro_bias_rps;
  double static_duration_s = 60.0;
  double motion_min_speed_mps = 5.0;
  double motion_window_s = 2.0;
  // Motion alignment from position-only fixes: the span of the position differences grows (5, 10, 20, 40 s) until
  // the heading's 1-sigma is at most this (slow platforms need a longer track).
  double motion_heading_sigma_deg = 5.0;
  // The gyro biases measured over a standstill at the record's start (ins/standstill_gyro_bias.hpp) start the
  // filter's bias states when better than the datasheet's turn-on sigma (motion alignment).
  bool standstill_gyro_bias = true;
  double velocity_sigma_mps = 0.1;
  double fix_min_interval_s = 0.0;       // [gnss] update_interval_s: a decorrelating interval between fixes used
  double fix_error_correlation_s = 0.0;  // [gnss] error_correlation_time_s: fixes' errors Gauss-Markov (0: white)
  // [gnss] error_correlation_time_s absent or "auto": `fuse` measures whether the file's fixes are white at their
  // rate (fusion/fix_error_whiteness.hpp) and, when not, carries the measured Gauss-Markov model as states. `receive`
  // makes its fixes as it goes and uses fix_error_correlation_s as it stands.
  bool fix_error_auto = true;
  // [gnss] error_sigma_ned_m: with a correlation time, the Gauss-Markov part's 1-sigma, carried as filter states
  // (fusion/fix_error_model.hpp) instead of inflating the fixes' variance.
  std::optional<Eigen::Vector3d> fix_error_sigma_ned_m;
  bool use_velocity = true;
  Eigen::Vector3d lever_arm_b = Eigen::Vector3d::Zero();
  fusion::UkfParameters ukf;
  fusion::GateOptions gate;
  fusion::LockoutRecoveryOptions recovery;  // [filter] recovery* keys
  fusion::LandVehicleOptions land;          // [vehicle] keys
  fusion::OdometerAidingOptions odometer;   // [odometer] keys (enabled by fuse --odometer)
  std::optional<double> odometer_rate_hz;   // [odometer] rate_hz: the odometer file's declared rate
  double propagation_interval_s = 0.05;
  double convergence_heading_sigma_deg = 1.0;
  std::optional<signals::GpsTime> attitude_gps_time_at_imu_zero;
  Eigen::Vector3d attitude_misalignment_deg = Eigen::Vector3d::Zero();  // roll, pitch, yaw of array -> IMU body
  double attitude_max_pitch_deg = 80.0;
  std::string clock_oscillator = "tcxo";
  fusion::OscillatorAllan clock_allan = *fusion::oscillator_preset("tcxo");  // preset, then h0 / h_minus2
  std::optional<double> clock_allan_h0, clock_allan_hm2;                     // as given in the file
  fusion::HeightAidingOptions height_aiding;
};

// The IMU error model the filter assumes: the preset with the configuration's datasheet values put in. Throws
// io::InputError for an unknown preset.
inline ins::ImuErrorSpec imu_error_spec(const FuseConfig& config) {
  return ins::apply_datasheet(ins::imu_preset(config.imu_preset), config.imu_datasheet);
}

}  // namespace ultratrack::pipelines
