// SPDX-License-Identifier: GPL-3.0-or-later
// GPS attitude (multi-antenna receiver, [OhAttINS]; [KimAlign] eqs. 10-17) as a measurement of the INS
// psi-angle attitude error. The receiver gives roll/pitch/yaw of its antenna-array frame a; the known
// misalignment q_ba (array -> IMU body) turns it into a measured C_nb = C_na C_ab.
//
// Innovation form: the measurement is the small rotation between the INS and the GPS attitude,
//   z = rotvec(C_nb_gps C_nb_ins^T)            (NED, rad; equals psi_ins + GPS error to first order)
//   h(dx) = rotvec(C_nb(corrected(dx)) C_nb_ins^T) = psi part of dx (exactly: the feedback rotates by psi),
// so H = [0 0 I 0 0]. Seed 000 eq. 16 instead differences the Euler angles through H_G, which has 1/cos(pitch)
// terms and needs yaw wrapping; the rotation vector has neither (no wrap at +-180 deg yaw, no singularity at
// pitch +-90 deg) and carries the same information (H_G = -M^-1 below, tested). The receiver's Euler sigmas
// are mapped to the rotation's covariance R = M diag(sigma^2) M^T with M = d(eps_n)/d(roll, pitch, yaw).
// Near pitch +-90 deg roll and yaw turn about the same axis: M loses rank, R would claim a perfect axis,
// and per-angle sigmas no longer describe the error; such attitudes are refused (attitude_usable).
// Angles in rad; frames: n = NED, b = IMU body, a = antenna array.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <numbers>

#include "fusion/filter_types.hpp"
#include "fusion/ins_error_state.hpp"
#include "ins/attitude.hpp"

namespace ultratrack::fusion {

// One GPS attitude at its time of validity on the run's time line.
struct GnssAttitude {
  double t_s = 0.0;
  ins::EulerAngles euler_a;                                           // array frame a relative to NED
  Eigen::Vector3d sigma_euler_rad = Eigen::Vector3d::Constant(1e-3);  // 1-sigma roll, pitch, yaw
};

struct AttitudeAidingOptions {
  Eigen::Quaterniond q_ba = Eigen::Quaterniond::Identity();    // antenna array -> IMU body (known mounting)
  double max_abs_pitch_rad = 80.0 * std::numbers::pi / 180.0;  // beyond: refused (Euler sigmas degenerate)
};

// M: the NED small rotation eps_n of C_na produced by small Euler-angle errors, eps_n = M (droll, dpitch, dyaw).
// Columns: the roll axis Rz(yaw) Ry(pitch) e_x, the pitch axis Rz(yaw) e_y, the yaw axis e_z.
Eigen::Matrix3d euler_rate_to_rotation_n(const ins::EulerAngles& e);

// The INS-side C_nb the GPS attitude measures: q_na * q_ba^-1.
Eigen::Quaterniond measured_q_nb(const GnssAttitude& a, const Eigen::Quaterniond& q_ba);

// True when the attitude may be used: finite angles, positive finite sigmas, |pitch| <= the limit.
bool attitude_usable(const GnssAttitude& a, const AttitudeAidingOptions& o);

template <int N>
class AttitudeMeasurement {
 public:
  // Throws std::invalid_argument when !attitude_usable(a, o).
  AttitudeMeasurement(const NominalState& nominal, const GnssAttitude& a, const AttitudeAidingOptions& o);

  Eigen::VectorXd z() const { return z_; }  // rotation vector, NED, rad
  Eigen::VectorXd h(const StateVector<N>& dx) const;
  MeasurementJacobian<N> H(const StateVector<N>& dx) const;
  Eigen::MatrixXd R() const { return R_; }
  int size() const { return 3; }

 private:
  NominalState nominal_;
  Eigen::Quaterniond q_nb_ins_;
  Eigen::VectorXd z_;
  Eigen::MatrixXd R_;
};

extern template class AttitudeMeasurement<15>;
extern template class AttitudeMeasurement<17>;

}  // namespace ultratrack::fusion
