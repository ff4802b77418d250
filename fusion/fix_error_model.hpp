// SPDX-License-Identifier: GPL-3.0-or-later
// Time-correlated GNSS fix errors as filter states (loose coupling): three first-order Gauss-Markov position-error
// states in NED, one per axis, appended after the filter's other states. The state is the error of the filter's
// estimate of the fix error (estimate minus truth, metres), where the fix error itself is fix minus true antenna
// position:
//   b' = -b / tau + w,   PSD 2 sigma^2 / tau   (stationary 1-sigma sigma per axis; discrete over dt:
//   Phi = exp(-dt / tau), Qd = sigma^2 (1 - exp(-2 dt / tau)))
// A fix is then z = true antenna position + b + white noise: receiver smoothing and multipath keep b for tens of
// seconds, and the filter carries it instead of averaging it down as if it were white. The fix's own sigmas are its
// total error: the white part left in each update is sqrt(max(sigma_fix^2 - sigma^2, (min_white_fraction
// sigma_fix)^2)) per axis. NED axes are those of the nav position (they turn by the distance over the earth's
// radius: negligible over a correlation time).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <utility>

#include "fusion/discretisation.hpp"
#include "fusion/filter_types.hpp"

namespace ultratrack::fusion {

struct FixErrorOptions {
  bool enabled = false;
  double correlation_time_s = 30.0;            // tau > 0
  Eigen::Vector3d sigma_ned_m{1.0, 1.0, 2.0};  // stationary 1-sigma of the correlated part, > 0
  double min_white_fraction = 0.1;             // the white part is at least this share of the fix's sigma
  bool IsValid(std::string* why = nullptr) const;
};

// The Gauss-Markov transition of one axis over dt with the filter's discretisation (Van Loan: exp(-dt / tau), as
// the matrix exponential gives; the second-order series: 1 - dt / tau + dt^2 / (2 tau^2), as discretise() gives).
double fix_error_transition(double dt, double tau_s, Discretisation method);

// The nominal (the filter's estimate of the fix error, NED metres) between fixes: it relaxes to zero as the process
// mean does.
inline Eigen::Vector3d propagate_fix_error(const Eigen::Vector3d& b_ned_m, double dt, double tau_s) {
  return b_ned_m * std::exp(-dt / tau_s);
}

// The white 1-sigma of a fix whose total 1-sigma is sigma_fix (per axis; see the file comment).
Eigen::Vector3d fix_white_sigma(const Eigen::Vector3d& sigma_fix_ned_m, const FixErrorOptions& o);

// A process model of NB states (a LinearProcessModel: InsErrorModel<15>, OdometerAugmentedModel<15>) with the three
// fix-error states appended at [NB, NB + 3). Satisfies LinearProcessModel<NB + 3>.
template <class Base, int NB>
class FixErrorAugmentedModel {
 public:
  static constexpr int N = NB + 3;
  static constexpr int kIndex = NB;  // first fix-error state
  static constexpr int kNoiseSize = Base::kNoiseSize + 3;

  FixErrorAugmentedModel(Base base, const FixErrorOptions& options, Discretisation method)
      : base_(std::move(base)), opt_(options), method_(method) {}

  template <class Lin>
  void set_linearisation(const Lin& lin) {
    base_.set_linearisation(lin);
  }
  const StateMatrix<N>& transition(double dt) const {
    if (dt != cached_dt_) {
      cached_phi_.setZero();
      cached_phi_.template topLeftCorner<NB, NB>() = base_.transition(dt);
      cached_phi_.template bottomRightCorner<3, 3>() =
          fix_error_transition(dt, opt_.correlation_time_s, method_) * Eigen::Matrix3d::Identity();
      cached_dt_ = dt;
    }
    return cached_phi_;
  }
  StateVector<N> f(const StateVector<N>& x, double dt) const { return transition(dt) * x; }
  StateMatrix<N> F(const StateVector<N>& x) const {
    StateMatrix<N> out = StateMatrix<N>::Zero();
    out.template topLeftCorner<NB, NB>() = base_.F(x.template head<NB>());
    out.template bottomRightCorner<3, 3>() = (-1.0 / opt_.correlation_time_s) * Eigen::Matrix3d::Identity();
    return out;
  }
  Eigen::Matrix<double, N, kNoiseSize> G(const StateVector<N>& x) const {
    Eigen::Matrix<double, N, kNoiseSize> g = Eigen::Matrix<double, N, kNoiseSize>::Zero();
    g.template topLeftCorner<NB, Base::kNoiseSize>() = base_.G(x.template head<NB>());
    g.template bottomRightCorner<3, 3>().setIdentity();
    return g;
  }
  Eigen::Matrix<double, kNoiseSize, kNoiseSize> Qc() const {
    Eigen::Matrix<double, kNoiseSize, kNoiseSize> q = Eigen::Matrix<double, kNoiseSize, kNoiseSize>::Zero();
    q.template topLeftCorner<Base::kNoiseSize, Base::kNoiseSize>() = base_.Qc();
    q.template bottomRightCorner<3, 3>() = (2.0 / opt_.correlation_time_s * opt_.sigma_ned_m.cwiseAbs2()).asDiagonal();
    return q;
  }
  const Base& base() const { return base_; }

 private:
  Base base_;
  FixErrorOptions opt_;
  Discretisation method_;
  mutable double cached_dt_ = -1.0;
  mutable StateMatrix<N> cached_phi_ = StateMatrix<N>::Identity();
};

// A covariance of NB states with the three fix-error states appended at their stationary variances, uncorrelated.
template <int NB>
StateMatrix<NB + 3> with_fix_error_states(const StateMatrix<NB>& P_base, const FixErrorOptions& o) {
  StateMatrix<NB + 3> P = StateMatrix<NB + 3>::Zero();
  P.template topLeftCorner<NB, NB>() = P_base;
  P.template bottomRightCorner<3, 3>() = o.sigma_ned_m.cwiseAbs2().asDiagonal();
  return P;
}

// A position fix measurement M of N states (rows: position NED first when it has one, then velocity) with the
// fix-error states at [K, K + 3): the position rows measure the antenna position plus the fix error. z has the
// nominal fix error b_nominal taken out; h(dx) subtracts the state's error of it (truth b = nominal - dx).
template <class M, int N, int K>
class FixErrorMeasurement {
 public:
  FixErrorMeasurement(M m, bool has_position, const Eigen::Vector3d& b_nominal_ned_m)
      : m_(std::move(m)), pos_(has_position), z_(m_.z()) {
    if (pos_) z_.template head<3>() -= b_nominal_ned_m;
  }
  Eigen::VectorXd z() const { return z_; }
  Eigen::VectorXd h(const StateVector<N>& dx) const {
    Eigen::VectorXd out = m_.h(dx);
    if (pos_) out.template head<3>() -= dx.template segment<3>(K);
    return out;
  }
  MeasurementJacobian<N> H(const StateVector<N>& dx) const {
    MeasurementJacobian<N> out = m_.H(dx);
    if (pos_) out.template block<3, 3>(0, K) = -Eigen::Matrix3d::Identity();
    return out;
  }
  Eigen::MatrixXd R() const { return m_.R(); }

 private:
  M m_;
  bool pos_;
  Eigen::VectorXd z_;
};

}  // namespace ultratrack::fusion
