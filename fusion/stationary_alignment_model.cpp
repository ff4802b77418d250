// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/stationary_alignment_model.hpp"

#include <cmath>

#include "fusion/discretisation.hpp"
#include "ins/earth_model.hpp"

namespace ultratrack::fusion {

using align_ix::kAccelBias;
using align_ix::kAtt;
using align_ix::kGyroBias;
using align_ix::kVel;

StationaryAlignmentModelOptions alignment_model_options(const ins::ImuErrorSpec& spec, double lat_rad,
                                                        double gravity_mps2) {
  StationaryAlignmentModelOptions o;
  o.lat_rad = lat_rad;
  o.gravity_mps2 = gravity_mps2;
  o.accel_white_psd = spec.accel.random_walk * spec.accel.random_walk;
  o.gyro_white_psd = spec.gyro.random_walk * spec.gyro.random_walk;
  auto walk = [](const ins::SensorErrorSpec& s) {
    return s.bias_instability_sigma > 0.0
               ? 2.0 * s.bias_instability_sigma * s.bias_instability_sigma / s.bias_correlation_time_s
               : 0.0;
  };
  o.accel_bias_walk_psd = walk(spec.accel);
  o.gyro_bias_walk_psd = walk(spec.gyro);
  return o;
}

AlignmentMatrix stationary_error_dynamics(const Eigen::Matrix3d& C_nb, const StationaryAlignmentModelOptions& o) {
  const Eigen::Vector3d W = ins::earth_rate_n(o.lat_rad);  // (Omega_N, 0, Omega_D)
  const double WN = W.x(), WD = W.z(), g = o.gravity_mps2;
  Eigen::Matrix3d F11, F12, F22;
  F11 << 0.0, 2.0 * WD, 0.0,     //
      -2.0 * WD, 0.0, 2.0 * WN,  //
      0.0, -2.0 * WN, 0.0;       // eq. 6
  F12 << 0.0, g, 0.0,            //
      -g, 0.0, 0.0,              //
      0.0, 0.0, 0.0;             // eq. 7
  F22 << 0.0, WD, 0.0,           //
      -WD, 0.0, WN,              //
      0.0, -WN, 0.0;             // eq. 8
  AlignmentMatrix A = AlignmentMatrix::Zero();
  A.block<3, 3>(kVel, kVel) = F11;
  A.block<3, 3>(kVel, kAtt) = F12;
  A.block<3, 3>(kAtt, kAtt) = F22;
  A.block<3, 3>(kVel, kAccelBias) = C_nb;  // eq. 9
  A.block<3, 3>(kAtt, kGyroBias) = -C_nb;
  return A;
}

Eigen::Matrix3d euler_error_from_psi(const ins::EulerAngles& e) {
  const double cg = std::cos(e.yaw_rad), sg = std::sin(e.yaw_rad);
  const double cb = std::cos(e.pitch_rad), tb = std::tan(e.pitch_rad);
  Eigen::Matrix3d H;
  H << -cg / cb, -sg / cb, 0.0,  //
      sg, -cg, 0.0,              //
      -tb * cg, -tb * sg, -1.0;  // eq. 16
  return H;
}

StationaryAlignmentModel::StationaryAlignmentModel(const Eigen::Matrix3d& C_nb,
                                                   const StationaryAlignmentModelOptions& o)
    : A_(stationary_error_dynamics(C_nb, o)) {
  G_.setZero();
  G_.block<3, 3>(kVel, 0) = C_nb;  // white specific-force noise in body axes
  G_.block<3, 3>(kAtt, 3) = -C_nb;
  G_.block<3, 3>(kAccelBias, 6).setIdentity();
  G_.block<3, 3>(kGyroBias, 9).setIdentity();
  Qc_.setZero();
  Qc_.diagonal() << Eigen::Vector3d::Constant(o.accel_white_psd), Eigen::Vector3d::Constant(o.gyro_white_psd),
      Eigen::Vector3d::Constant(o.accel_bias_walk_psd), Eigen::Vector3d::Constant(o.gyro_bias_walk_psd);
}

AlignmentMatrix StationaryAlignmentModel::transition(double dt) const {
  return discretise<12>(A_, AlignmentMatrix::Zero(), dt, Discretisation::VanLoan).Phi;
}

Eigen::Matrix<double, 3, 12> ZeroVelocityMeasurement::H(const AlignmentVector&) const {
  Eigen::Matrix<double, 3, 12> H = Eigen::Matrix<double, 3, 12>::Zero();
  H.block<3, 3>(0, kVel).setIdentity();
  return H;
}

namespace {
Eigen::Vector3d euler_difference(const ins::EulerAngles& a, const ins::EulerAngles& b) {
  return {a.roll_rad - b.roll_rad, a.pitch_rad - b.pitch_rad, ins::wrap_pi(a.yaw_rad - b.yaw_rad)};
}
}  // namespace

EulerAttitudeMeasurement::EulerAttitudeMeasurement(const Eigen::Quaterniond& q_nb_ins,
                                                   const Eigen::Quaterniond& q_nb_gps,
                                                   const Eigen::Vector3d& sigma_euler_rad)
    : q_ins_(q_nb_ins.normalized()), e_ins_(ins::euler_from_quaternion(q_ins_)) {
  z_ = euler_difference(e_ins_, ins::euler_from_quaternion(q_nb_gps));
  R_ = sigma_euler_rad.cwiseAbs2().asDiagonal();
  H_G_ = euler_error_from_psi(e_ins_);
}

Eigen::Vector3d EulerAttitudeMeasurement::h(const AlignmentVector& x) const {
  // The truth the state implies: C_nb_true = exp([psi x]) C_nb_ins (ins/nav_state.hpp's correction).
  const Eigen::Quaterniond q_true = ins::quaternion_from_rotation_vector(x.segment<3>(kAtt)) * q_ins_;
  return euler_difference(e_ins_, ins::euler_from_quaternion(q_true));
}

Eigen::Matrix<double, 3, 12> EulerAttitudeMeasurement::H(const AlignmentVector&) const {
  Eigen::Matrix<double, 3, 12> H = Eigen::Matrix<double, 3, 12>::Zero();
  H.block<3, 3>(0, kAtt) = H_G_;
  return H;
}

}  // namespace ultratrack::fusion
