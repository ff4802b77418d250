// SPDX-License-Identifier: GPL-3.0-or-later
// Frames and angles of the attitude solver: the local NED frame at an ECEF position (WGS-84 geodetic latitude and
// longitude from GeographicLib), z-y-x Euler angles (yaw, pitch, roll) of C_nb (body to NED), and the propagation of
// a small-rotation covariance into Euler-angle covariance. Radians.
#pragma once

#include <Eigen/Core>

namespace ultratrack::receiver {

// C_en: rotates NED components into ECEF components at r_e.
Eigen::Matrix3d ned_to_ecef_rotation(const Eigen::Vector3d& r_e);

struct EulerAngles {
  double roll_rad = 0.0, pitch_rad = 0.0, yaw_rad = 0.0;  // yaw in [0, 2 pi), pitch in [-pi/2, pi/2]
};
// C_nb = Rz(yaw) Ry(pitch) Rx(roll).
EulerAngles euler_from_C_nb(const Eigen::Matrix3d& C_nb);
Eigen::Matrix3d C_nb_from_euler(const EulerAngles& e);

// Covariance of (roll, pitch, yaw) from the covariance of a small rotation eps_n (rad^2) with
// C_nb_true = exp([eps_n x]) C_nb: J P J^T, J = d euler / d eps_n (numerical, central differences).
Eigen::Matrix3d euler_covariance(const Eigen::Matrix3d& C_nb, const Eigen::Matrix3d& rotation_covariance_n);

// exp([v x]) (Rodrigues).
Eigen::Matrix3d rotation_from_vector(const Eigen::Vector3d& v);

}  // namespace ultratrack::receiver
