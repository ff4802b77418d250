// SPDX-License-Identifier: GPL-3.0-or-later
// The residual IMU bias covariance across a closed-loop attitude correction. The bias states are body axes
// (fusion/ins_error_state.hpp), but everything the filter learns about them arrives through their effect in the nav
// frame, C_nb b (velocity and attitude rates). When the feedback turns the nominal attitude from C_old to C_new,
// the body axes the filter maps the biases through turn by T = C_new' C_old; carrying the covariance with them,
//   b_new = T b_old   (accelerometer and gyro blocks; P <- Tf P Tf'),
// keeps the nav-frame bias covariance C P_bb C' and its cross terms with the other states as they were.
// Why: left in body axes, each tilt correction changes how the filter maps the same bias into the velocity (the
// vertical row of C_nb picks up sin(roll) of the lateral bias), so a series of corrections on a straight road
// "observes" the horizontal accelerometer bias apart from the tilt, which only rotation can separate. The EKF then
// trusts a tilt it does not know: Jacobians evaluated at the latest estimates observe more than the system does
// ([HuangOC]). On an ADIS16405-class unit (50 mg, 3 deg/s turn-on biases) it made the tilt NEES 2-3 times its
// dimension (docs/validation.md, section 14).
// Invariant: T orthonormal, so the reset changes no variance of a nav-frame quantity; identity when the
// attitude is not corrected.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "fusion/filter_types.hpp"
#include "fusion/ins_error_state.hpp"

namespace ultratrack::fusion {

template <int N>
StateMatrix<N> reset_bias_frame(const StateMatrix<N>& P, const Eigen::Quaterniond& q_nb_before,
                                const Eigen::Quaterniond& q_nb_after) {
  static_assert(ix::kGyroBias == ix::kAccelBias + 3, "the bias states are adjacent");
  const Eigen::Matrix3d T = q_nb_after.toRotationMatrix().transpose() * q_nb_before.toRotationMatrix();
  Eigen::Matrix<double, 6, 6> T6 = Eigen::Matrix<double, 6, 6>::Zero();
  T6.topLeftCorner<3, 3>() = T;
  T6.bottomRightCorner<3, 3>() = T;
  StateMatrix<N> out = P;
  out.template middleRows<6>(ix::kAccelBias) = T6 * P.template middleRows<6>(ix::kAccelBias);
  const Eigen::Matrix<double, N, 6> columns = out.template middleCols<6>(ix::kAccelBias) * T6.transpose();
  out.template middleCols<6>(ix::kAccelBias) = columns;
  return 0.5 * (out + out.transpose());
}

}  // namespace ultratrack::fusion
