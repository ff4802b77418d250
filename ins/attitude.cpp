// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/attitude.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ultratrack::ins {

Eigen::Quaterniond quaternion_from_euler(const EulerAngles& e) {
  const Eigen::Quaterniond q = Eigen::AngleAxisd(e.yaw_rad, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(e.pitch_rad, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(e.roll_rad, Eigen::Vector3d::UnitX());
  return q.normalized();
}

EulerAngles euler_from_dcm(const Eigen::Matrix3d& C) {
  EulerAngles e;
  e.roll_rad = std::atan2(C(2, 1), C(2, 2));
  e.pitch_rad = -std::asin(std::clamp(C(2, 0), -1.0, 1.0));
  e.yaw_rad = std::atan2(C(1, 0), C(0, 0));
  return e;
}

EulerAngles euler_from_quaternion(const Eigen::Quaterniond& q_nb) {
  return euler_from_dcm(q_nb.normalized().toRotationMatrix());
}

Eigen::Quaterniond quaternion_from_rotation_vector(const Eigen::Vector3d& phi) {
  const double n2 = phi.squaredNorm();
  double c, s;       // cos(n/2), sin(n/2)/n
  if (n2 < 1e-12) {  // series keeps full precision for tiny angles
    c = 1.0 - n2 / 8.0 + n2 * n2 / 384.0;
    s = 0.5 - n2 / 48.0 + n2 * n2 / 3840.0;
  } else {
    const double n = std::sqrt(n2);
    c = std::cos(0.5 * n);
    s = std::sin(0.5 * n) / n;
  }
  return Eigen::Quaterniond(c, s * phi.x(), s * phi.y(), s * phi.z());
}

Eigen::Vector3d rotation_vector_from_quaternion(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double vn = q.vec().norm();
  if (vn < 1e-300) return Eigen::Vector3d::Zero();
  const double angle = 2.0 * std::atan2(vn, q.w());
  return q.vec() * (angle / vn);
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Vector3d attitude_error_n(const Eigen::Quaterniond& q_nb_est, const Eigen::Quaterniond& q_nb_true) {
  // C_true C_est^T = (I + [psi x]) to first order, i.e. the rotation taking the estimate back to the truth.
  return rotation_vector_from_quaternion(q_nb_true * q_nb_est.conjugate());
}

double wrap_pi(double a) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  a = std::fmod(a, kTwoPi);
  if (a <= -std::numbers::pi) a += kTwoPi;
  if (a > std::numbers::pi) a -= kTwoPi;
  return a;
}

}  // namespace ultratrack::ins
