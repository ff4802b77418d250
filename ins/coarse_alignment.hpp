// SPDX-License-Identifier: GPL-3.0-or-later
// Coarse (analytic) self-alignment from stationary IMU data ([ParkSDINS] eq. 17, in its levelling +
// gyrocompassing form): roll and pitch from the mean specific force, heading from the mean body rate
// resolved in the levelled frame. Also the closed-form alignment errors caused by sensor biases.
// Angles in rad; biases in body axes (rad/s, m/s^2); errors as NED psi-angles (see attitude_error_n).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <span>

#include "ins/attitude.hpp"
#include "ins/imu_error_model.hpp"
#include "ins/nav_state.hpp"

namespace ultratrack::ins {

struct AlignmentResult {
  Eigen::Quaterniond q_nb = Eigen::Quaterniond::Identity();
  EulerAngles euler;
  Eigen::Vector3d mean_f_b = Eigen::Vector3d::Zero();     // m/s^2
  Eigen::Vector3d mean_w_ib_b = Eigen::Vector3d::Zero();  // rad/s
  double duration_s = 0.0;
};

// Attitude from the mean specific force and body rate of a stationary vehicle at latitude lat_rad.
// Heading needs a horizontal earth-rate component: unreliable near the poles.
AlignmentResult coarse_align(const Eigen::Vector3d& mean_f_b, const Eigen::Vector3d& mean_w_ib_b, double lat_rad);

// The same from increments: means are sum(dv)/T and sum(dtheta)/T over the interval from t_start_s to the
// last increment's t_s. Throws std::invalid_argument when the span is empty or has no duration.
AlignmentResult coarse_align(std::span<const ImuIncrement> imu, double t_start_s, double lat_rad);

// First-order alignment error (psi-angle, NED) produced by constant accelerometer and gyro biases
// (body axes) for a vehicle at rest with attitude q_nb at lat_rad:
//   psi_N = b_E / g,  psi_E = -b_N / g,  psi_D = eps_E / (W cos L) - (b_E / g) tan L,
// where b and eps are the biases resolved in NED.
Eigen::Vector3d alignment_error_from_biases(const Eigen::Vector3d& accel_bias_b, const Eigen::Vector3d& gyro_bias_b,
                                            const Eigen::Quaterniond& q_nb, double lat_rad, double gravity_mps2);

// 1-sigma alignment error (north, east, down psi-angles) from the white noise of an IMU spec averaged
// over T seconds: the mean rate error is sqrt(RW^2 / T + 2 w^2 / T^2) per axis (random walk RW, output white
// noise w, which telescopes), mapped by the same closed form: tilt / g, heading / (W cos L), plus the
// tilt-to-heading term tan L.
Eigen::Vector3d alignment_noise_sigma(const ImuErrorSpec& spec, double duration_s, double lat_rad, double gravity_mps2);

}  // namespace ultratrack::ins
