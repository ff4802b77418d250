// SPDX-License-Identifier: GPL-3.0-or-later
// The navigation state of the strapdown INS and the IMU increment it consumes.
// Conventions (for the fusion layer applying error-state corrections):
//   position: geodetic WGS-84 latitude/longitude [rad], ellipsoidal height [m];
//   v_n: velocity over the earth in NED [m/s];
//   q_nb: unit quaternion body -> NED (v_n = q_nb * v_b); body axes x forward, y right, z down.
//   A psi-angle attitude error psi_n (C_nb_est = (I - [psi x]) C_nb_true) is corrected by
//   q_nb <- quaternion_from_rotation_vector(psi_n) * q_nb; position errors by subtracting from lat/lon/h.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ultratrack::ins {

struct NavState {
  double t_s = 0.0;  // time of validity, seconds on the run's time line
  double lat_rad = 0.0;
  double lon_rad = 0.0;
  double height_m = 0.0;
  Eigen::Vector3d v_n = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_nb = Eigen::Quaterniond::Identity();
};

// IMU output: angle and velocity increments in the body frame over the interval ending at t_s,
// i.e. dtheta_b = integral of w_ib_b dt [rad], dv_b = integral of f_b dt [m/s].
struct ImuIncrement {
  double t_s = 0.0;
  Eigen::Vector3d dtheta_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d dv_b = Eigen::Vector3d::Zero();
};

}  // namespace ultratrack::ins
