// SPDX-License-Identifier: GPL-3.0-or-later
// Non-holonomic constraints of a land vehicle ([KimVMS] eqs. 11-15 without the odometer row): a wheeled vehicle
// neither slides sideways nor leaves the road, so at its non-holonomic point (the rear axle's centre, at
// lever_arm_b from the IMU in body axes) the body-frame velocity has zero lateral (y) and vertical (z)
// components. As a pseudo-measurement it makes heading observable at any speed without horizontal acceleration
// (a heading error psi_d shows as a lateral velocity v psi_d), which is what a MEMS gyro's bias of degrees per
// second needs between turns. The sigma covers sideslip, suspension and mounting errors; updates are spaced
// (LandVehicleOptions::nhc_interval_s) because those errors are correlated in time.
//   z = [0, 0];  h(dx) = rows y, z of C_bn v_n + w_nb_b x l  of the corrected nominal;
//   H = rows y, z of [0, -C_bn, C_bn [v_n x], 0, 0] (psi-angle error state, fusion/ins_error_state.hpp).
// Units: m/s, rad, m. The IMU body axes are taken as the vehicle's (x forward, y right, z down).
#pragma once

#include <Eigen/Core>

#include "fusion/filter_types.hpp"
#include "fusion/ins_error_state.hpp"

namespace ultratrack::fusion {

struct LandVehicleOptions {
  bool nhc = false;                                       // apply the constraints
  double nhc_sigma_mps = 0.3;                             // 1-sigma of each constrained body velocity
  double nhc_interval_s = 0.5;                            // at most one update per interval
  Eigen::Vector3d lever_arm_b = Eigen::Vector3d::Zero();  // IMU -> non-holonomic point, body axes [m]
};

template <int N>
class NhcMeasurement {
 public:
  // w_ib_b: the compensated body rate at the update time.
  NhcMeasurement(const NominalState& nominal, const Eigen::Vector3d& w_ib_b, const LandVehicleOptions& options);

  Eigen::VectorXd z() const { return Eigen::Vector2d::Zero(); }
  Eigen::VectorXd h(const StateVector<N>& dx) const;
  MeasurementJacobian<N> H(const StateVector<N>& dx) const;
  Eigen::MatrixXd R() const { return R_; }
  int size() const { return 2; }

 private:
  NominalState nominal_;
  Eigen::Vector3d w_ib_b_, lever_b_;
  Eigen::Matrix2d R_;
};

// The body-frame velocity at the point lever_b of a nav state with body rate w_ib_b [m/s].
Eigen::Vector3d body_velocity_at(const ins::NavState& nav, const Eigen::Vector3d& w_ib_b,
                                 const Eigen::Vector3d& lever_b);

extern template class NhcMeasurement<15>;
extern template class NhcMeasurement<17>;

}  // namespace ultratrack::fusion
