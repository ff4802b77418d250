// SPDX-License-Identifier: GPL-3.0-or-later
// Extended (error-state) Kalman filter on a fixed-size state: prediction through the model's f with the
// covariance propagated by the discretised continuous model (discretisation.hpp), measurement update in
// Joseph form P = (I - K H) P (I - K H)' + K R K' (stays symmetric PSD under rounding and suboptimal gains),
// innovation chi-square gating. Takes the same model objects as the UKF (filter_types.hpp concepts).
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <limits>

#include "fusion/covariance_utils.hpp"
#include "fusion/discretisation.hpp"
#include "fusion/filter_types.hpp"
#include "fusion/innovation_gate.hpp"
#include "receiver/chi_square.hpp"

namespace ultratrack::fusion {

struct EkfOptions {
  Discretisation discretisation = Discretisation::VanLoan;
  GateOptions gate;
};

template <int N>
class Ekf {
 public:
  using Vector = StateVector<N>;
  using Matrix = StateMatrix<N>;
  static constexpr int kStateSize = N;

  Ekf(const Vector& x0, const Matrix& P0, EkfOptions options = {}) : x_(x0), P_(P0), opt_(options) {}

  // x <- f(x, dt); P <- Phi P Phi' + Qd with Phi, Qd from F, G, Qc evaluated at the prior x. dt >= 0.
  template <class M>
  requires ProcessModel<M, N>
  void predict(const M& model, double dt) {
    const Matrix F = model.F(x_);
    const Eigen::Matrix<double, N, M::kNoiseSize> G = model.G(x_);
    const Matrix Qs = G * model.Qc() * G.transpose();
    const DiscreteProcess<N> d = discretise<N>(F, Qs, dt, opt_.discretisation);
    x_ = model.f(x_, dt);
    P_ = d.Phi * P_ * d.Phi.transpose() + d.Qd;
    symmetrise(P_);
    ++counters_.predictions;
  }

  // Linearised update at the current estimate. Rejected (state unchanged) if the gate refuses it or the
  // innovation covariance is not positive definite.
  template <class M>
  requires MeasurementModel<M, N> UpdateResult update(const M& model) {
    UpdateResult r;
    const Eigen::VectorXd z = model.z();
    const MeasurementJacobian<N> H = model.H(x_);
    const Eigen::MatrixXd R = model.R();
    r.dof = static_cast<int>(z.size());
    r.innovation = z - model.h(x_);
    const Eigen::Matrix<double, Eigen::Dynamic, N> HP = H * P_;
    Eigen::MatrixXd S = HP * H.transpose() + R;
    S = 0.5 * (S + S.transpose());
    Eigen::LLT<Eigen::MatrixXd> llt;
    if (!passes_innovation_gate(opt_.gate, S, r, llt)) {
      ++counters_.rejected;
      return r;
    }
    // K = P H' S^-1 = (S^-1 H P)'
    const Eigen::Matrix<double, N, Eigen::Dynamic> K = llt.solve(HP).transpose();
    x_ += K * r.innovation;
    const Matrix IKH = Matrix::Identity() - K * H;
    P_ = IKH * P_ * IKH.transpose() + K * R * K.transpose();
    symmetrise(P_);
    r.accepted = true;
    ++counters_.accepted;
    return r;
  }

  const Vector& x() const { return x_; }
  const Matrix& P() const { return P_; }
  // For closed-loop feedback (error state reset to zero after correcting the nominal state) and restarts.
  void set_x(const Vector& x) { x_ = x; }
  void set_P(const Matrix& P) { P_ = P; }
  const FilterCounters& counters() const { return counters_; }
  const EkfOptions& options() const { return opt_; }

 private:
  Vector x_;
  Matrix P_;
  EkfOptions opt_;
  FilterCounters counters_;
};

}  // namespace ultratrack::fusion
