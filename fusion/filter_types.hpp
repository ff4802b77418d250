// SPDX-License-Identifier: GPL-3.0-or-later
// Shared vocabulary of the generic filters (ekf.hpp, ukf.hpp): fixed-size state vectors and covariances,
// the process and measurement model concepts both filters accept, innovation gating and update results.
// Units are whatever the model uses; covariances are of the state's own units.
#pragma once

#include <Eigen/Core>
#include <concepts>
#include <utility>

namespace ultratrack::fusion {

template <int N>
using StateVector = Eigen::Matrix<double, N, 1>;
template <int N>
using StateMatrix = Eigen::Matrix<double, N, N>;
// Measurement-side quantities vary in size per epoch (k satellites): dynamic rows, fixed state columns.
template <int N>
using MeasurementJacobian = Eigen::Matrix<double, Eigen::Dynamic, N>;

// A process model over one propagation interval dt:
//   f(x, dt): the state after dt starting from x, without noise (may be nonlinear);
//   F(x):     the continuous-time Jacobian d(xdot)/dx at x (the EKF discretises it to Phi; both filters use it
//             with G and Qc for the discrete process noise Qd);
//   G(x):     noise input matrix N x kNoiseSize (xdot = ... + G w);
//   Qc():     power spectral density of the continuous white noise w (kNoiseSize x kNoiseSize, units^2 / Hz).
// For a linear model f(x, dt) must equal Phi(dt) x with Phi the discretisation of F (the INS error models do).
template <class M, int N>
concept ProcessModel = requires(const M& m, const StateVector<N>& x, double dt) {
  { M::kNoiseSize } -> std::convertible_to<int>;
  { m.f(x, dt) } -> std::convertible_to<StateVector<N>>;
  { m.F(x) } -> std::convertible_to<StateMatrix<N>>;
  { m.G(x) } -> std::convertible_to<Eigen::Matrix<double, N, M::kNoiseSize>>;
  { m.Qc() } -> std::convertible_to<Eigen::Matrix<double, M::kNoiseSize, M::kNoiseSize>>;
};

// One measurement (of any size k >= 1, fixed for the object's life):
//   z():   the measured vector (k);
//   h(x):  the predicted measurement for state x (the full nonlinear function: the UKF evaluates it at the
//          sigma points, the EKF at the estimate);
//   H(x):  the Jacobian dh/dx at x (k x N; used by the EKF only, tested against numerical differentiation);
//   R():   the measurement noise covariance (k x k).
// A process model that is linear, f(x, dt) = transition(dt) x: the UKF then propagates P = Phi P Phi' + Qd
// directly, which is what its sigma points give for a linear f (to rounding), at a fraction of the cost.
template <class M, int N>
concept LinearProcessModel = ProcessModel<M, N> && requires(const M& m, double dt) {
  { m.transition(dt) } -> std::convertible_to<StateMatrix<N>>;
};

template <class M, int N>
concept MeasurementModel = requires(const M& m, const StateVector<N>& x) {
  { m.z() } -> std::convertible_to<Eigen::VectorXd>;
  { m.h(x) } -> std::convertible_to<Eigen::VectorXd>;
  { m.H(x) } -> std::convertible_to<MeasurementJacobian<N>>;
  { m.R() } -> std::convertible_to<Eigen::MatrixXd>;
};

// The number of rows of a measurement model: M::kMeasurementSize when the model declares one (every z it
// gives then has that many rows), else Eigen::Dynamic (the size is z().size() at run time).
template <class M>
inline constexpr int measurement_size_v = Eigen::Dynamic;
template <class M>
requires requires { M::kMeasurementSize; }
inline constexpr int measurement_size_v<M> = M::kMeasurementSize;

// Innovation chi-square gate: a measurement is rejected (no state change) when its normalised innovation
// squared nu' S^-1 nu exceeds the chi-square quantile with k degrees of freedom at `probability` (the
// probability that a measurement consistent with the model passes).
struct GateOptions {
  bool enabled = true;
  double probability = 0.9999;
};

struct UpdateResult {
  bool accepted = false;
  double nis = 0.0;            // normalised innovation squared
  double threshold = 0.0;      // gate threshold used (infinity when gating is off)
  int dof = 0;                 // measurement size k
  Eigen::VectorXd innovation;  // z - predicted (EKF: h(x); UKF: weighted mean of h at the sigma points)
};

// A measurement written for NIn states used in a filter of NOut > NIn states: the extra states do not enter it.
template <class M, int NIn, int NOut>
class PaddedMeasurement {
 public:
  explicit PaddedMeasurement(M m) : m_(std::move(m)) {}
  Eigen::VectorXd z() const { return m_.z(); }
  Eigen::VectorXd h(const StateVector<NOut>& dx) const { return m_.h(dx.template head<NIn>()); }
  MeasurementJacobian<NOut> H(const StateVector<NOut>& dx) const {
    const MeasurementJacobian<NIn> hin = m_.H(dx.template head<NIn>());
    MeasurementJacobian<NOut> out = MeasurementJacobian<NOut>::Zero(hin.rows(), NOut);
    out.leftCols(NIn) = hin;
    return out;
  }
  Eigen::MatrixXd R() const { return m_.R(); }

 private:
  M m_;
};

struct FilterCounters {
  long long predictions = 0;
  long long accepted = 0;  // measurement updates applied
  long long rejected = 0;  // measurement updates refused by the gate (or numerically unusable: S not positive)
};

}  // namespace ultratrack::fusion
