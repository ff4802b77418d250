// SPDX-License-Identifier: GPL-3.0-or-later
// Unscented Kalman filter on a fixed-size state with scaled sigma points ([ChoUKF] eqs. 18-37):
// lambda = alpha^2 (n + kappa) - n, sigma points x +- columns of the Cholesky factor of (n + lambda) P,
// weights Wm0 = lambda / (n + lambda), Wc0 = Wm0 + 1 - alpha^2 + beta, Wi = 1 / (2 (n + lambda)) ([ChoUKF]
// eq. 23 prints lambda in the numerator of Wi: a typo, the weights would not sum to one). Process noise is
// additive: Qd from the model's F, G, Qc at the prior mean (discretisation.hpp), the same as the EKF's.
// Covariances are symmetrised after every step and repaired to the nearest PSD matrix if the Cholesky
// factorisation fails (negative Wc0 for small alpha can make them indefinite under rounding).
// For a linear model the transform is exact for any (alpha, beta, kappa) with n + lambda > 0; alpha = 1,
// beta = 0 or 2, kappa = 0 keeps all weights O(1) and the result equals the Kalman filter to rounding.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "fusion/covariance_utils.hpp"
#include "fusion/discretisation.hpp"
#include "fusion/filter_types.hpp"
#include "fusion/innovation_gate.hpp"
#include "receiver/chi_square.hpp"

namespace ultratrack::fusion {

struct UkfParameters {
  double alpha = 1.0;  // spread of the sigma points ([ChoUKF]: 1e-4 <= alpha <= 1)
  double beta = 2.0;   // prior knowledge of the distribution (2 optimal for Gaussian)
  double kappa = 0.0;  // secondary scaling
};

struct UkfOptions {
  UkfParameters sigma;
  Discretisation discretisation = Discretisation::VanLoan;  // for Qd only
  GateOptions gate;
};

template <int N>
struct SigmaWeights {
  double lambda = 0.0;
  double mean0 = 0.0, cov0 = 0.0, other = 0.0;
};

// Throws std::invalid_argument when n + lambda <= 0 or a parameter is not finite.
template <int N>
SigmaWeights<N> sigma_weights(const UkfParameters& p) {
  if (!(p.alpha > 0.0) || !std::isfinite(p.beta) || !std::isfinite(p.kappa))
    throw std::invalid_argument("UKF: alpha must be positive and beta, kappa finite");
  SigmaWeights<N> w;
  w.lambda = p.alpha * p.alpha * (N + p.kappa) - N;
  if (!(N + w.lambda > 0.0)) throw std::invalid_argument("UKF: n + lambda must be positive");
  w.mean0 = w.lambda / (N + w.lambda);
  w.cov0 = w.mean0 + 1.0 - p.alpha * p.alpha + p.beta;
  w.other = 0.5 / (N + w.lambda);
  return w;
}

template <int N>
class Ukf {
 public:
  using Vector = StateVector<N>;
  using Matrix = StateMatrix<N>;
  using Sigmas = Eigen::Matrix<double, N, 2 * N + 1>;
  static constexpr int kStateSize = N;

  Ukf(const Vector& x0, const Matrix& P0, UkfOptions options = {})
      : x_(x0), P_(P0), opt_(options), w_(sigma_weights<N>(options.sigma)) {}

  // Sigma points through f, weighted mean and covariance plus Qd. dt >= 0. A LinearProcessModel skips the
  // sigma points: with f(x) = Phi x they give mean Phi x and covariance Phi (sum_i Wc_i (X_i - x)(X_i - x)') Phi'
  // = Phi L L' Phi' = Phi P Phi' (the weights of the 2N symmetric points sum to 1 / (N + lambda)), exactly.
  template <class M>
  requires ProcessModel<M, N>
  void predict(const M& model, double dt) {
    const Matrix F = model.F(x_);
    const Eigen::Matrix<double, N, M::kNoiseSize> G = model.G(x_);
    const Matrix Qs = G * model.Qc() * G.transpose();
    const DiscreteProcess<N> d = discretise<N>(F, Qs, dt, opt_.discretisation);
    if constexpr (LinearProcessModel<M, N>) {
      const Matrix& Phi = model.transition(dt);  // a reference: some models return their own
      x_ = Phi * x_;
      P_ = Phi * P_ * Phi.transpose() + d.Qd;
      keep_psd();
      ++counters_.predictions;
      return;
    }
    Sigmas X = sigma_points();
    for (int i = 0; i < 2 * N + 1; ++i) X.col(i) = model.f(Vector(X.col(i)), dt);
    Vector mean = w_.mean0 * X.col(0);
    for (int i = 1; i < 2 * N + 1; ++i) mean += w_.other * X.col(i);
    Matrix P = d.Qd;
    for (int i = 0; i < 2 * N + 1; ++i) {
      const Vector dx = X.col(i) - mean;
      P += (i == 0 ? w_.cov0 : w_.other) * dx * dx.transpose();
    }
    x_ = mean;
    P_ = P;
    keep_psd();
    ++counters_.predictions;
  }

  // Sigma points of the current (x, P) through h; Kalman gain from the cross covariance.
  // A model with a compile-time size (static constexpr int kMeasurementSize, measurement_size_v) runs on
  // fixed-size matrices: no heap allocation in the sums over the sigma points.
  template <class M>
  requires MeasurementModel<M, N> UpdateResult update(const M& model) {
    constexpr int K = measurement_size_v<M>;
    using ZVector = Eigen::Matrix<double, K, 1>;
    using ZMatrix = Eigen::Matrix<double, K, K>;
    UpdateResult r;
    const ZVector& z = model.z();
    const ZMatrix& R = model.R();
    const int k = static_cast<int>(z.size());
    r.dof = k;
    const Sigmas X = sigma_points();
    Eigen::Matrix<double, K, 2 * N + 1> Z(k, 2 * N + 1);
    for (int i = 0; i < 2 * N + 1; ++i) Z.col(i) = model.h(Vector(X.col(i)));
    ZVector zbar = w_.mean0 * Z.col(0);
    for (int i = 1; i < 2 * N + 1; ++i) zbar += w_.other * Z.col(i);
    ZMatrix S = R;
    Eigen::Matrix<double, N, K> Pxz = Eigen::Matrix<double, N, K>::Zero(N, k);
    Z.colwise() -= zbar;  // the deviations, in place (no temporary per sigma point)
    for (int i = 0; i < 2 * N + 1; ++i) {
      const double wc = i == 0 ? w_.cov0 : w_.other;
      S.noalias() += (wc * Z.col(i)) * Z.col(i).transpose();
      Pxz.noalias() += (wc * (X.col(i) - x_)) * Z.col(i).transpose();
    }
    S = 0.5 * (S + S.transpose());
    r.innovation = z - zbar;
    Eigen::LLT<ZMatrix> llt;
    if (!passes_innovation_gate(opt_.gate, S, r, llt)) {
      ++counters_.rejected;
      return r;
    }
    const Eigen::Matrix<double, N, K> gain = llt.solve(Pxz.transpose()).transpose();
    x_ += gain * r.innovation;
    P_ -= gain * S * gain.transpose();
    keep_psd();
    r.accepted = true;
    ++counters_.accepted;
    return r;
  }

  // The 2N+1 sigma points of the current estimate (column 0 = mean).
  Sigmas sigma_points() const {
    Matrix L;
    if (!safe_cholesky<N>(P_, L)) throw std::runtime_error("UKF: covariance is not finite");
    L *= std::sqrt(N + w_.lambda);
    Sigmas X;
    X.col(0) = x_;
    for (int i = 0; i < N; ++i) {
      X.col(1 + i) = x_ + L.col(i);
      X.col(1 + N + i) = x_ - L.col(i);
    }
    return X;
  }

  const Vector& x() const { return x_; }
  const Matrix& P() const { return P_; }
  void set_x(const Vector& x) { x_ = x; }
  void set_P(const Matrix& P) { P_ = P; }
  const FilterCounters& counters() const { return counters_; }
  const UkfOptions& options() const { return opt_; }
  const SigmaWeights<N>& weights() const { return w_; }

 private:
  void keep_psd() {
    symmetrise(P_);
    Eigen::LLT<Matrix> llt(P_);
    if (llt.info() != Eigen::Success) P_ = psd_repair<N>(P_);
  }

  Vector x_;
  Matrix P_;
  UkfOptions opt_;
  SigmaWeights<N> w_;
  FilterCounters counters_;
};

}  // namespace ultratrack::fusion
