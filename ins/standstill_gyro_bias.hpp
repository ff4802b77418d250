// SPDX-License-Identifier: GPL-3.0-or-later
// The gyro biases measured while the platform stands still at the start of a record. A MEMS gyro's turn-on bias
// (degrees per second) otherwise has to be learnt in motion from the heading drift it causes, which at walking
// speed costs tens of degrees of heading; at rest the gyros read bias plus earth rate, so a few seconds measure it
// to the angle random walk's limit, ARW / sqrt(T).
//
// Standstill test, per window of `window_s` from the record's start: the angular rate's and the specific force's
// sample variance per axis within `variance_factor` times the datasheet's white noise (a parked vehicle's idling
// engine or a robot's motors pass, driving does not), and the window's means within `mean_sigmas` of the standstill
// so far, in sigmas of the noise measured (at least the datasheet's) plus the in-run bias instability (a start, a
// turn, a tilt). The span ends at the first window that fails or at `end_by_s`; the last window that passed is
// dropped as a margin. Motion at a constant velocity without rotation passes the test and is harmless (the gyros
// still read bias plus earth rate); a constant rotation from the first sample on is not detected.
//
// Bias = mean rate - the earth rate's vertical part (its direction from the mean specific force). The horizontal
// part (W cos L) is unknown without a heading and goes into the 1-sigma with the noise and the in-run instability:
//   sigma^2 = s_rate^2 / N + (W cos L)^2 + sigma_instability^2   per axis,
// s_rate the rate's sample standard deviation over the span (at least the datasheet's: real units are noisier than
// their datasheets, and vibration averages down only as its own variance says).
// Units: s, rad/s, m/s^2; body axes. Times are the IMU rows' (the end of each increment's interval).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>

#include "ins/imu_error_model.hpp"
#include "ins/nav_state.hpp"

namespace ultratrack::ins {

struct StandstillOptions {
  double window_s = 1.0;           // test window
  double min_duration_s = 5.0;     // shorter standstills give nothing
  double mean_sigmas = 6.0;        // a window's means against the standstill's, in sigmas of their difference
  double variance_factor = 100.0;  // a window's sample variance against the datasheet's white noise
};

struct StandstillGyroBias {
  double t_start_s = 0.0, t_end_s = 0.0;  // the intervals used: (t_start_s, t_end_s]
  Eigen::Vector3d gyro_bias_rps = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_rps = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_f_b = Eigen::Vector3d::Zero();  // mean specific force over the span [m/s^2]
};

// The standstill at the start of `imu` (sorted rows, at least two) and the gyro biases it measures, for a unit
// described by `spec` at latitude lat_rad; nothing when the record does not start at rest for min_duration_s.
std::optional<StandstillGyroBias> initial_standstill_gyro_bias(std::span<const ImuIncrement> imu, double lat_rad,
                                                               const ImuErrorSpec& spec, double end_by_s,
                                                               const StandstillOptions& options = {});

}  // namespace ultratrack::ins
