// SPDX-License-Identifier: GPL-3.0-or-later
// The initial covariance of an alignment whose attitude error is, to first order, a linear function of the IMU
// biases plus an independent part: psi = J [b_a; b_g] + e (fusion/fuse_motion_alignment.hpp: levelling with
// biased accelerometers tilts by about b_a / g). Given P with cov(e) in the attitude block, the biases' covariance
// in theirs and no cross terms between them, the exact covariance of (psi, b) is
//   P_psi,psi = cov(e) + J P_bb J',   P_psi,b = J P_bb,   P_bb unchanged,
// so the filter knows that the attitude and the biases err together (independent priors would make it believe
// their combination, which the fixes observe first, more uncertain and each part, once that is seen, more certain
// than it is). Units: rad per m/s^2 and per rad/s; error-state layout of fusion/ins_error_state.hpp.
#pragma once

#include <Eigen/Core>

#include "fusion/filter_types.hpp"
#include "fusion/ins_error_state.hpp"

namespace ultratrack::fusion {

// Columns 0-2: d psi / d b_a (body), columns 3-5: d psi / d b_g (body).
using AttitudePerBias = Eigen::Matrix<double, 3, 6>;

template <int N>
void correlate_attitude_with_biases(StateMatrix<N>& P, const AttitudePerBias& J) {
  static_assert(ix::kGyroBias == ix::kAccelBias + 3, "the bias states are adjacent");
  const Eigen::Matrix<double, 6, 6> P_bb = P.template block<6, 6>(ix::kAccelBias, ix::kAccelBias);
  const AttitudePerBias P_ab = J * P_bb;
  P.template block<3, 3>(ix::kAtt, ix::kAtt) += P_ab * J.transpose();
  P.template block<3, 6>(ix::kAtt, ix::kAccelBias) += P_ab;
  P.template block<6, 3>(ix::kAccelBias, ix::kAtt) += P_ab.transpose();
}

}  // namespace ultratrack::fusion
