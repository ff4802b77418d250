// SPDX-License-Identifier: GPL-3.0-or-later
// Attitude helpers: Euler angles against the explicit DCM of [ParkSDINS] eq. (12) (transposed: C_bn),
// rotation vectors against Eigen's AngleAxis, and the psi-angle error convention.
#include "ins/attitude.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace ultratrack::ins;

TEST(Attitude, EulerDcmMatchesSeed002Eq12) {
  const double phi = 0.3, theta = -0.2, psi = 2.5;
  const double sf = std::sin(phi), cf = std::cos(phi), st = std::sin(theta), ct = std::cos(theta);
  const double sp = std::sin(psi), cp = std::cos(psi);
  Eigen::Matrix3d C_bn;  // [ParkSDINS] eq. (12): the n -> b transformation
  // clang-format off
  C_bn << ct * cp,                ct * sp,                -st,
          sf * st * cp - cf * sp, sf * st * sp + cf * cp, sf * ct,
          cf * st * cp + sf * sp, cf * st * sp - sf * cp, cf * ct;
  // clang-format on
  const Eigen::Quaterniond q = quaternion_from_euler({phi, theta, psi});
  EXPECT_LT((q.toRotationMatrix().transpose() - C_bn).norm(), 1e-15);
  const EulerAngles e = euler_from_quaternion(q);
  EXPECT_NEAR(e.roll_rad, phi, 1e-14);
  EXPECT_NEAR(e.pitch_rad, theta, 1e-14);
  EXPECT_NEAR(e.yaw_rad, psi, 1e-14);
}

TEST(Attitude, RotationVectorRoundTripAtAllSizes) {
  for (double angle : {1e-12, 1e-7, 1e-3, 0.5, 3.0}) {
    const Eigen::Vector3d axis = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
    const Eigen::Quaterniond q = quaternion_from_rotation_vector(angle * axis);
    const Eigen::Quaterniond ref(Eigen::AngleAxisd(angle, axis));
    EXPECT_LT((q.coeffs() - ref.coeffs()).norm(), 1e-15) << angle;
    EXPECT_LT((rotation_vector_from_quaternion(q) - angle * axis).norm(), 1e-15 * std::max(1.0, angle)) << angle;
  }
}

TEST(Attitude, PsiAngleConvention) {
  const Eigen::Quaterniond q_true = quaternion_from_euler({0.1, 0.2, -1.0});
  const Eigen::Vector3d psi(1e-4, -2e-4, 3e-4);
  // C_est = (I - [psi x]) C_true, built to first order and re-orthonormalised by the exact rotation.
  const Eigen::Quaterniond q_est = quaternion_from_rotation_vector(-psi) * q_true;
  EXPECT_LT((attitude_error_n(q_est, q_true) - psi).norm(), 1e-15);
  const Eigen::Matrix3d first_order = (Eigen::Matrix3d::Identity() - skew(psi)) * q_true.toRotationMatrix();
  EXPECT_LT((q_est.toRotationMatrix() - first_order).norm(), 1e-7);
}

TEST(Attitude, WrapPi) {
  EXPECT_NEAR(wrap_pi(3.0 * std::numbers::pi), std::numbers::pi, 1e-12);
  EXPECT_NEAR(wrap_pi(-0.5), -0.5, 1e-15);
  EXPECT_NEAR(wrap_pi(2.0 * std::numbers::pi + 0.25), 0.25, 1e-12);
}
