// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/loose_measurements.hpp"

#include <stdexcept>

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"

namespace ultratrack::fusion {

Eigen::Vector3d antenna_position_e(const ins::NavState& nav, const Eigen::Vector3d& lever_arm_b) {
  const Eigen::Matrix3d C_en = ins::C_en(nav.lat_rad, nav.lon_rad);
  return ins::ecef_from_geodetic(nav.lat_rad, nav.lon_rad, nav.height_m) + C_en * (nav.q_nb * lever_arm_b);
}

Eigen::Vector3d antenna_velocity_n(const ins::NavState& nav, const Eigen::Vector3d& w_ib_b,
                                   const Eigen::Vector3d& lever_arm_b) {
  const Eigen::Vector3d w_in =
      ins::earth_rate_n(nav.lat_rad) + ins::transport_rate_n(nav.lat_rad, nav.height_m, nav.v_n);
  const Eigen::Vector3d w_nb_b = w_ib_b - nav.q_nb.conjugate() * w_in;
  return nav.v_n + nav.q_nb * w_nb_b.cross(lever_arm_b);
}

template <int N>
LooseMeasurement<N>::LooseMeasurement(const NominalState& nominal, const GnssFix& fix,
                                      const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b)
    : nominal_(nominal), lever_b_(lever_arm_b), w_ib_b_(w_ib_b), pos_(fix.has_position), vel_(fix.has_velocity) {
  if (!pos_ && !vel_) throw std::invalid_argument("GNSS fix without position and velocity");
  r_ref_e_ = antenna_position_e(nominal.nav, lever_b_);
  C_ne_ref_ = ins::C_en(nominal.nav.lat_rad, nominal.nav.lon_rad).transpose();
  const int k = 3 * (pos_ ? 1 : 0) + 3 * (vel_ ? 1 : 0);
  z_.resize(k);
  R_ = Eigen::MatrixXd::Zero(k, k);
  int row = 0;
  if (pos_) {
    z_.segment<3>(0) = C_ne_ref_ * (ins::ecef_from_geodetic(fix.lat_rad, fix.lon_rad, fix.height_m) - r_ref_e_);
    R_.block<3, 3>(0, 0) = fix.sigma_pos_ned_m.cwiseAbs2().asDiagonal();
    row = 3;
  }
  if (vel_) {
    z_.segment<3>(row) = fix.v_n_mps;
    R_.block<3, 3>(row, row) = fix.sigma_vel_n_mps.cwiseAbs2().asDiagonal();
  }
}

template <int N>
Eigen::VectorXd LooseMeasurement<N>::h(const StateVector<N>& dx) const {
  const NominalState s = corrected<N>(nominal_, dx);
  Eigen::VectorXd out(z_.size());
  int row = 0;
  if (pos_) {
    out.segment<3>(0) = C_ne_ref_ * (antenna_position_e(s.nav, lever_b_) - r_ref_e_);
    row = 3;
  }
  if (vel_) out.segment<3>(row) = antenna_velocity_n(s.nav, w_ib_b_ - dx.template segment<3>(ix::kGyroBias), lever_b_);
  return out;
}

template <int N>
MeasurementJacobian<N> LooseMeasurement<N>::H(const StateVector<N>&) const {
  // First order about the nominal (terms of relative size |l| / R_earth are left out).
  MeasurementJacobian<N> H = MeasurementJacobian<N>::Zero(z_.size(), N);
  const Eigen::Matrix3d C = nominal_.nav.q_nb.toRotationMatrix();
  const Eigen::Vector3d l_n = C * lever_b_;
  int row = 0;
  if (pos_) {
    H.template block<3, 3>(0, ix::kPos) = -Eigen::Matrix3d::Identity();
    H.template block<3, 3>(0, ix::kAtt) = -ins::skew(l_n);
    row = 3;
  }
  if (vel_) {
    const ins::NavState& nav = nominal_.nav;
    const Eigen::Vector3d w_in =
        ins::earth_rate_n(nav.lat_rad) + ins::transport_rate_n(nav.lat_rad, nav.height_m, nav.v_n);
    H.template block<3, 3>(row, ix::kVel) = -Eigen::Matrix3d::Identity();
    H.template block<3, 3>(row, ix::kAtt) = -ins::skew(C * w_ib_b_.cross(lever_b_)) + ins::skew(w_in) * ins::skew(l_n);
    H.template block<3, 3>(row, ix::kGyroBias) = C * ins::skew(lever_b_);
  }
  return H;
}

template class LooseMeasurement<15>;
template class LooseMeasurement<17>;

}  // namespace ultratrack::fusion
