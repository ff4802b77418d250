// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/vms_measurement.hpp"

#include <cmath>

#include "fusion/nhc_measurement.hpp"
#include "ins/attitude.hpp"
#include "ins/odometer.hpp"

namespace ultratrack::fusion {
namespace {

// d C_bv / d pitch and d C_bv / d yaw for C_bv = Rz(yaw) Ry(pitch).
void C_bv_derivatives(double pitch, double yaw, Eigen::Matrix3d& d_pitch, Eigen::Matrix3d& d_yaw) {
  const double cp = std::cos(pitch), sp = std::sin(pitch), cy = std::cos(yaw), sy = std::sin(yaw);
  Eigen::Matrix3d Rz, Ry, dRz, dRy;
  Rz << cy, -sy, 0.0, sy, cy, 0.0, 0.0, 0.0, 1.0;
  Ry << cp, 0.0, sp, 0.0, 1.0, 0.0, -sp, 0.0, cp;
  dRz << -sy, -cy, 0.0, cy, -sy, 0.0, 0.0, 0.0, 0.0;
  dRy << -sp, 0.0, cp, 0.0, 0.0, 0.0, -cp, 0.0, -sp;
  d_pitch = Rz * dRy;
  d_yaw = dRz * Ry;
}

}  // namespace

VmsMeasurement::VmsMeasurement(const NominalState& nominal, const OdometerNominal& odometer,
                               const Eigen::Vector3d& w_ib_b, const Eigen::Vector3d& a_b, const OdometerSpeed& speed,
                               const OdometerAidingOptions& o)
    : nominal_(nominal),
      odo_(odometer),
      w_ib_b_(w_ib_b),
      a_b_(a_b),
      lever_b_(o.lever_arm_b),
      half_window_s_(0.5 * speed.window_s),
      z_(3),
      R_(Eigen::MatrixXd::Zero(3, 3)) {
  z_ << speed.speed_mps, 0.0, 0.0;
  R_.diagonal() << o.sigma_forward_mps * o.sigma_forward_mps, o.sigma_lateral_mps * o.sigma_lateral_mps,
      o.sigma_vertical_mps * o.sigma_vertical_mps;
}

Eigen::VectorXd VmsMeasurement::h(const StateVector<19>& dx) const {
  const NominalState s = corrected<15>(nominal_, dx.head<15>());
  const OdometerNominal p = corrected(odo_, dx);
  const Eigen::Vector3d v_b = body_velocity_at(s.nav, w_ib_b_ - dx.segment<3>(ix::kGyroBias), lever_b_);
  const Eigen::Matrix3d C_vb = ins::C_bv_from_misalignment(p.pitch_rad, p.yaw_rad).transpose();
  const Eigen::Vector3d v_v = C_vb * v_b, a_v = C_vb * a_b_;
  Eigen::VectorXd out(3);
  out << (1.0 + p.scale_factor) * (v_v.x() - (half_window_s_ + p.delay_s) * a_v.x()), v_v.y(), v_v.z();
  return out;
}

MeasurementJacobian<19> VmsMeasurement::H(const StateVector<19>&) const {
  // First order about the nominal (as fusion/nhc_measurement.hpp: the lever arm's rotation terms are second
  // order for a car's short levers, the gyro bias' direct effect on w x l is kept).
  const ins::NavState& nav = nominal_.nav;
  const Eigen::Matrix3d C_bn = nav.q_nb.conjugate().toRotationMatrix();
  const Eigen::Matrix3d C_vb = ins::C_bv_from_misalignment(odo_.pitch_rad, odo_.yaw_rad).transpose();
  const Eigen::Vector3d v_b = body_velocity_at(nav, w_ib_b_, lever_b_);
  const Eigen::Vector3d v_v = C_vb * v_b, a_v = C_vb * a_b_;
  const double T = half_window_s_ + odo_.delay_s, gain = 1.0 + odo_.scale_factor;

  // d v_b / d(state) for the INS states (columns of the 15-state part).
  Eigen::Matrix<double, 3, 15> Jb = Eigen::Matrix<double, 3, 15>::Zero();
  Jb.block<3, 3>(0, ix::kVel) = -C_bn;
  Jb.block<3, 3>(0, ix::kAtt) = C_bn * ins::skew(nav.v_n);
  Jb.block<3, 3>(0, ix::kGyroBias) = ins::skew(lever_b_);
  const Eigen::Matrix<double, 3, 15> Jv = C_vb * Jb;

  // Misalignment states: truth = nominal - dx, and C_vb = C_bv'.
  Eigen::Matrix3d dC_pitch, dC_yaw;
  C_bv_derivatives(odo_.pitch_rad, odo_.yaw_rad, dC_pitch, dC_yaw);
  const Eigen::Vector3d dv_pitch = -(dC_pitch.transpose() * v_b), dv_yaw = -(dC_yaw.transpose() * v_b);
  const Eigen::Vector3d da_pitch = -(dC_pitch.transpose() * a_b_), da_yaw = -(dC_yaw.transpose() * a_b_);

  MeasurementJacobian<19> H = MeasurementJacobian<19>::Zero(3, 19);
  H.block<1, 15>(0, 0) = gain * Jv.row(0);
  H.block<2, 15>(1, 0) = Jv.bottomRows<2>();
  H(0, ix::kOdoDelay) = gain * a_v.x();  // delay truth = nominal - dx: h grows with dx by a_v,x
  H(0, ix::kOdoPitch) = gain * (dv_pitch.x() - T * da_pitch.x());
  H(0, ix::kOdoYaw) = gain * (dv_yaw.x() - T * da_yaw.x());
  H(0, ix::kOdoScale) = -(v_v.x() - T * a_v.x());
  H(1, ix::kOdoPitch) = dv_pitch.y();
  H(1, ix::kOdoYaw) = dv_yaw.y();
  H(2, ix::kOdoPitch) = dv_pitch.z();
  H(2, ix::kOdoYaw) = dv_yaw.z();
  return H;
}

OdometerGate odometer_gate(const OdometerAidingOptions& o, double heading_change_rad, double window_s,
                           double vms_speed_mps) {
  OdometerGate g;
  if (o.mode == OdometerMode::kAlways) return g;
  g.yaw_rate_ok = std::abs(ins::wrap_pi(heading_change_rad)) / window_s < o.yaw_rate_threshold_rad_s;
  g.speed_ok = std::abs(vms_speed_mps) > o.min_speed_mps;
  return g;
}

}  // namespace ultratrack::fusion
