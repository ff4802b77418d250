// SPDX-License-Identifier: GPL-3.0-or-later
// The odometer (VMS) measurement with non-holonomic constraints of [KimVMS] (eqs. 11-15) on the 19-state model
// (fusion/odometer_error_model.hpp), and its gating rule (eqs. 16-17).
// Measurement, in the vehicle frame v (x forward, y right, z down; C_bv = ins::C_bv_from_misalignment):
//   z = [s, 0, 0]   s: VMS speed = distance counted over the last window / window length
//   h = [(1 + k) (v_v,x - T a_v,x),  v_v,y,  v_v,z]
//   v_v = C_vb(pitch, yaw) (C_bn v_n + w_nb_b x l)   (velocity of the wheels' point, lever arm l from the IMU)
//   a_v = C_vb a_b   (the vehicle's mean acceleration over the window, body axes; a known input)
//   T   = window / 2 + delay   (the window's mean speed is the speed at its middle; the VMS lags by the delay)
// with the corrected nominal and odometer parameters (scale factor k, delay, pitch, yaw) of the error state.
// Seed 004 writes the forward axis as y and the same first-order model as eq. 15; here the rows are forward,
// lateral, vertical and H is the exact first-order Jacobian of h (tested against central differences).
// Gating (eqs. 16-17): an update only when |heading change over the window| / window < threshold and the VMS
// speed > min_speed (kGated); kAlways updates every window. Units: m/s, m/s^2, rad, s.
#pragma once

#include <Eigen/Core>

#include "fusion/filter_types.hpp"
#include "fusion/ins_error_state.hpp"
#include "fusion/odometer_error_model.hpp"

namespace ultratrack::fusion {

// One odometer update's data: the VMS speed over (t_s - window_s, t_s].
struct OdometerSpeed {
  double t_s = 0.0;
  double speed_mps = 0.0;
  double window_s = 1.0;
};

class VmsMeasurement {
 public:
  static constexpr int kMeasurementSize = 3;
  // w_ib_b: compensated body rate at t; a_b: the vehicle's acceleration over the window in body axes.
  VmsMeasurement(const NominalState& nominal, const OdometerNominal& odometer, const Eigen::Vector3d& w_ib_b,
                 const Eigen::Vector3d& a_b, const OdometerSpeed& speed, const OdometerAidingOptions& options);

  Eigen::VectorXd z() const { return z_; }
  Eigen::VectorXd h(const StateVector<19>& dx) const;
  MeasurementJacobian<19> H(const StateVector<19>& dx) const;
  Eigen::MatrixXd R() const { return R_; }

 private:
  NominalState nominal_;
  OdometerNominal odo_;
  Eigen::Vector3d w_ib_b_, a_b_, lever_b_;
  double half_window_s_;
  Eigen::VectorXd z_;
  Eigen::MatrixXd R_;
};

// Which of the rules of eqs. 16-17 a window passes (both: update).
struct OdometerGate {
  bool yaw_rate_ok = true;
  bool speed_ok = true;
  bool update() const { return yaw_rate_ok && speed_ok; }
};

// What became of a filter's odometer windows: updates accepted / refused by the innovation gate; gated out by the
// heading-rate rule and by the speed rule (a window failing both counts in both); unusable (no INS history over the
// window yet, or a non-finite speed). Summed over the filters of one run (tight, then ultra-tight).
struct OdometerCounters {
  long long accepted = 0, rejected = 0, gated_yaw_rate = 0, gated_speed = 0, unusable = 0;
  OdometerCounters& operator+=(const OdometerCounters& o) {
    accepted += o.accepted;
    rejected += o.rejected;
    gated_yaw_rate += o.gated_yaw_rate;
    gated_speed += o.gated_speed;
    unusable += o.unusable;
    return *this;
  }
};

// heading_change_rad: INS heading at the window's end minus at its start (wrapped inside).
OdometerGate odometer_gate(const OdometerAidingOptions& options, double heading_change_rad, double window_s,
                           double vms_speed_mps);

}  // namespace ultratrack::fusion
