// SPDX-License-Identifier: GPL-3.0-or-later
// Attitude helpers: Euler angles (yaw-pitch-roll, z-y-x), body-to-NED quaternions q_nb / DCMs C_nb,
// rotation vectors and small-angle attitude errors. Angles in radians; C_nb = Rz(yaw) Ry(pitch) Rx(roll),
// v_n = q_nb * v_b.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ultratrack::ins {

struct EulerAngles {
  double roll_rad = 0.0;
  double pitch_rad = 0.0;
  double yaw_rad = 0.0;  // heading from north towards east, in (-pi, pi]
};

Eigen::Quaterniond quaternion_from_euler(const EulerAngles& e);
EulerAngles euler_from_quaternion(const Eigen::Quaterniond& q_nb);
EulerAngles euler_from_dcm(const Eigen::Matrix3d& C_nb);

// Quaternion of the rotation by the rotation vector phi (|phi| rad about phi/|phi|); exact at any size.
Eigen::Quaterniond quaternion_from_rotation_vector(const Eigen::Vector3d& phi);
// The rotation vector of a unit quaternion (angle in [0, pi]).
Eigen::Vector3d rotation_vector_from_quaternion(const Eigen::Quaterniond& q);

Eigen::Matrix3d skew(const Eigen::Vector3d& v);

// Attitude error of an estimate in the psi-angle (NED) convention: C_nb_est = (I - [psi x]) C_nb_true,
// returned exactly as the rotation vector of C_nb_true * C_nb_est^T (small-angle psi for small errors).
Eigen::Vector3d attitude_error_n(const Eigen::Quaterniond& q_nb_est, const Eigen::Quaterniond& q_nb_true);

// Wraps an angle into (-pi, pi].
double wrap_pi(double a);

}  // namespace ultratrack::ins
