// SPDX-License-Identifier: GPL-3.0-or-later
// Loosely coupled GNSS measurements of the INS error state: antenna position (geodetic fix expressed as
// NED metres about a reference point, so the numbers stay small) and antenna velocity in NED, with the
// IMU-to-antenna lever arm l_b: r_ant = r_imu + C_nb l_b, v_ant_n = v_n + C_nb (w_nb_b x l_b).
// h(dx) evaluates these functions exactly on the nominal corrected by dx (ins_error_state.hpp), so the UKF
// sees the full nonlinearity; H is their analytic first-order Jacobian. Satisfies MeasurementModel.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "fusion/filter_types.hpp"
#include "fusion/ins_error_state.hpp"

namespace ultratrack::fusion {

// A GNSS fix at the antenna. Either part may be absent (fallback: the filter updates with what is there).
struct GnssFix {
  double t_s = 0.0;  // time of validity on the run's time line (the IMU's)
  bool has_position = true;
  double lat_rad = 0.0, lon_rad = 0.0, height_m = 0.0;
  Eigen::Vector3d sigma_pos_ned_m = Eigen::Vector3d::Constant(3.0);
  bool has_velocity = false;
  Eigen::Vector3d v_n_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_vel_n_mps = Eigen::Vector3d::Constant(0.1);
};

// Antenna position (ECEF) and velocity (NED of the nav position) of a nominal state with the lever arm;
// w_ib_b is the compensated body rate (the model subtracts the residual gyro bias of the state).
Eigen::Vector3d antenna_position_e(const ins::NavState& nav, const Eigen::Vector3d& lever_arm_b);
Eigen::Vector3d antenna_velocity_n(const ins::NavState& nav, const Eigen::Vector3d& w_ib_b,
                                   const Eigen::Vector3d& lever_arm_b);

template <int N>
class LooseMeasurement {
 public:
  // fix must have a position or a velocity (else std::invalid_argument). w_ib_b: compensated body rate at
  // the fix time (only the velocity part uses it).
  LooseMeasurement(const NominalState& nominal, const GnssFix& fix, const Eigen::Vector3d& lever_arm_b,
                   const Eigen::Vector3d& w_ib_b);

  // Rows: [north, east, down position (m) if present][north, east, down velocity (m/s) if present].
  Eigen::VectorXd z() const { return z_; }
  Eigen::VectorXd h(const StateVector<N>& dx) const;
  MeasurementJacobian<N> H(const StateVector<N>& dx) const;
  Eigen::MatrixXd R() const { return R_; }
  int size() const { return static_cast<int>(z_.size()); }

 private:
  NominalState nominal_;
  Eigen::Vector3d lever_b_, w_ib_b_;
  bool pos_ = false, vel_ = false;
  Eigen::Vector3d r_ref_e_;   // reference point of the position rows (nominal antenna position)
  Eigen::Matrix3d C_ne_ref_;  // ECEF -> NED at the reference point
  Eigen::VectorXd z_;
  Eigen::MatrixXd R_;
};

extern template class LooseMeasurement<15>;
extern template class LooseMeasurement<17>;

}  // namespace ultratrack::fusion
