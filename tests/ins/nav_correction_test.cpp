// SPDX-License-Identifier: GPL-3.0-or-later
// Error-state corrections: errors measured independently (ECEF differences, psi-angle of the two
// quaternions) and fed back must return the estimate onto the truth.
#include "ins/nav_correction.hpp"

#include <gtest/gtest.h>

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"

using namespace ultratrack::ins;

TEST(NavCorrection, FeedingBackMeasuredErrorsRecoversTheTruth) {
  NavState truth;
  truth.lat_rad = 0.6;
  truth.lon_rad = 2.2;
  truth.height_m = 350.0;
  truth.v_n = {10.0, -3.0, 0.5};
  truth.q_nb = quaternion_from_euler({0.1, -0.05, 1.2});
  NavState est = truth;
  est.lat_rad += 3e-6;  // ~19 m north
  est.lon_rad -= 5e-6;  // ~25 m west
  est.height_m -= 7.0;
  est.v_n += Eigen::Vector3d(0.2, -0.1, 0.05);
  est.q_nb = quaternion_from_rotation_vector(Eigen::Vector3d(1e-3, -2e-3, 5e-3)) * truth.q_nb;

  const Eigen::Vector3d dr = position_error_ned(est, truth);
  EXPECT_NEAR(dr.z(), 7.0, 1e-3);  // 7 m too low = +7 m down
  correct_position(est, dr);
  correct_velocity(est, est.v_n - truth.v_n);
  correct_attitude(est, attitude_error_n(est.q_nb, truth.q_nb));
  // first-order position correction over ~30 m: residual of order (30 m)^2 / R ~ 1e-4 m
  EXPECT_LT(position_error_ned(est, truth).norm(), 1e-3);
  EXPECT_LT((est.v_n - truth.v_n).norm(), 1e-15);
  EXPECT_LT(attitude_error_n(est.q_nb, truth.q_nb).norm(), 1e-14);
}
