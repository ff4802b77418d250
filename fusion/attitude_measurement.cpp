// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/attitude_measurement.hpp"

#include <cmath>
#include <stdexcept>

namespace ultratrack::fusion {

Eigen::Matrix3d euler_rate_to_rotation_n(const ins::EulerAngles& e) {
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(e.yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d Ry = Eigen::AngleAxisd(e.pitch_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  Eigen::Matrix3d M;
  M.col(0) = Rz * Ry * Eigen::Vector3d::UnitX();
  M.col(1) = Rz * Eigen::Vector3d::UnitY();
  M.col(2) = Eigen::Vector3d::UnitZ();
  return M;
}

Eigen::Quaterniond measured_q_nb(const GnssAttitude& a, const Eigen::Quaterniond& q_ba) {
  return (ins::quaternion_from_euler(a.euler_a) * q_ba.conjugate()).normalized();
}

bool attitude_usable(const GnssAttitude& a, const AttitudeAidingOptions& o) {
  const auto& e = a.euler_a;
  return std::isfinite(a.t_s) && std::isfinite(e.roll_rad) && std::isfinite(e.pitch_rad) && std::isfinite(e.yaw_rad) &&
         a.sigma_euler_rad.allFinite() && (a.sigma_euler_rad.array() > 0.0).all() &&
         std::abs(e.pitch_rad) <= o.max_abs_pitch_rad;
}

template <int N>
AttitudeMeasurement<N>::AttitudeMeasurement(const NominalState& nominal, const GnssAttitude& a,
                                            const AttitudeAidingOptions& o)
    : nominal_(nominal), q_nb_ins_(nominal.nav.q_nb.normalized()) {
  if (!attitude_usable(a, o)) throw std::invalid_argument("GPS attitude not usable (non-finite, or near vertical)");
  z_ = ins::rotation_vector_from_quaternion(measured_q_nb(a, o.q_ba) * q_nb_ins_.conjugate());
  // The mounting rotation is known exactly: the error of C_nb is the array attitude's error, same NED axes.
  const Eigen::Matrix3d M = euler_rate_to_rotation_n(a.euler_a);
  R_ = M * a.sigma_euler_rad.cwiseAbs2().asDiagonal() * M.transpose();
}

template <int N>
Eigen::VectorXd AttitudeMeasurement<N>::h(const StateVector<N>& dx) const {
  const NominalState s = corrected<N>(nominal_, dx);
  return ins::rotation_vector_from_quaternion(s.nav.q_nb * q_nb_ins_.conjugate());
}

template <int N>
MeasurementJacobian<N> AttitudeMeasurement<N>::H(const StateVector<N>&) const {
  MeasurementJacobian<N> H = MeasurementJacobian<N>::Zero(3, N);
  H.template block<3, 3>(0, ix::kAtt).setIdentity();
  return H;
}

template class AttitudeMeasurement<15>;
template class AttitudeMeasurement<17>;

}  // namespace ultratrack::fusion
