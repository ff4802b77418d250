// SPDX-License-Identifier: GPL-3.0-or-later
// The antenna array's mounting on the IMU ([KimAlign] Table 3): the rotation q_ba (array -> IMU body) from the mean
// of the GPS array attitudes over a span and an attitude of the body from elsewhere (a reference INS, or the IMU's
// own levelling and gyrocompassing), q_ba = q_nb_ref^-1 * mean(q_na). Its 1-sigma: the reference's NED psi-angle
// covariance plus that of the mean GPS attitude (each attitude's Euler sigmas through euler_rate_to_rotation_n,
// taken as independent between epochs), rotated into the array frame; as roll, pitch, yaw of q_ba this holds for
// small mounting angles (a few degrees). Angles rad.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <span>

#include "fusion/attitude_measurement.hpp"
#include "ins/attitude.hpp"

namespace ultratrack::fusion {

struct MountingEstimate {
  Eigen::Quaterniond q_ba = Eigen::Quaterniond::Identity();
  ins::EulerAngles angles;                                        // roll, pitch, yaw of q_ba
  Eigen::Vector3d sigma_rad = Eigen::Vector3d::Zero();            // 1-sigma of those angles
  Eigen::Quaterniond q_na_mean = Eigen::Quaterniond::Identity();  // the averaged GPS attitude
  int samples = 0;
};

// Throws std::invalid_argument when array_attitudes is empty.
MountingEstimate estimate_mounting(std::span<const GnssAttitude> array_attitudes, const Eigen::Quaterniond& q_nb_ref,
                                   const Eigen::Matrix3d& P_ref_psi_n);

}  // namespace ultratrack::fusion
