// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/nhc_measurement.hpp"

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"

namespace ultratrack::fusion {

Eigen::Vector3d body_velocity_at(const ins::NavState& nav, const Eigen::Vector3d& w_ib_b,
                                 const Eigen::Vector3d& lever_b) {
  const Eigen::Vector3d w_in =
      ins::earth_rate_n(nav.lat_rad) + ins::transport_rate_n(nav.lat_rad, nav.height_m, nav.v_n);
  const Eigen::Vector3d w_nb_b = w_ib_b - nav.q_nb.conjugate() * w_in;
  return nav.q_nb.conjugate() * nav.v_n + w_nb_b.cross(lever_b);
}

template <int N>
NhcMeasurement<N>::NhcMeasurement(const NominalState& nominal, const Eigen::Vector3d& w_ib_b,
                                  const LandVehicleOptions& o)
    : nominal_(nominal), w_ib_b_(w_ib_b), lever_b_(o.lever_arm_b) {
  R_ = Eigen::Matrix2d::Identity() * (o.nhc_sigma_mps * o.nhc_sigma_mps);
}

template <int N>
Eigen::VectorXd NhcMeasurement<N>::h(const StateVector<N>& dx) const {
  const NominalState s = corrected<N>(nominal_, dx);
  const Eigen::Vector3d v_b = body_velocity_at(s.nav, w_ib_b_ - dx.template segment<3>(ix::kGyroBias), lever_b_);
  return v_b.tail<2>();
}

template <int N>
MeasurementJacobian<N> NhcMeasurement<N>::H(const StateVector<N>&) const {
  // First order about the nominal; the lever arm's rotation terms are second order for the short levers of a
  // car and left out, except the gyro bias' direct effect on w x l.
  MeasurementJacobian<N> H = MeasurementJacobian<N>::Zero(2, N);
  const Eigen::Matrix3d C_bn = nominal_.nav.q_nb.conjugate().toRotationMatrix();
  const Eigen::Matrix3d C_v = C_bn * ins::skew(nominal_.nav.v_n);
  const Eigen::Matrix3d L = ins::skew(lever_b_);
  H.template block<2, 3>(0, ix::kVel) = -C_bn.template bottomRows<2>();
  H.template block<2, 3>(0, ix::kAtt) = C_v.template bottomRows<2>();
  H.template block<2, 3>(0, ix::kGyroBias) = L.template bottomRows<2>();
  return H;
}

template class NhcMeasurement<15>;
template class NhcMeasurement<17>;

}  // namespace ultratrack::fusion
