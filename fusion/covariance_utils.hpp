// SPDX-License-Identifier: GPL-3.0-or-later
// Numerically safe covariance handling shared by the filters: symmetrisation, a positive-semidefinite
// repair (eigenvalues clamped at zero) and a Cholesky square root that falls back to the repaired
// matrix (with a relative jitter) when the plain factorisation fails.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace ultratrack::fusion {

template <class Derived>
void symmetrise(Eigen::MatrixBase<Derived>& P) {
  P = (0.5 * (P + P.transpose())).eval();
}

// Nearest (Frobenius) positive-semidefinite matrix of the symmetric part of P.
template <int N>
Eigen::Matrix<double, N, N> psd_repair(const Eigen::Matrix<double, N, N>& P) {
  const Eigen::Matrix<double, N, N> S = 0.5 * (P + P.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> es(S);
  Eigen::Matrix<double, N, 1> d = es.eigenvalues().cwiseMax(0.0);
  Eigen::Matrix<double, N, N> out = es.eigenvectors() * d.asDiagonal() * es.eigenvectors().transpose();
  return 0.5 * (out + out.transpose());
}

// Lower-triangular L with L L' = P (P symmetric PSD). When P is only semidefinite or slightly indefinite
// from rounding, P is repaired and a jitter of 1e-12 * trace(P) / N (at least 1e-300) is added to the
// diagonal before factorising again. Returns false only if even that fails (non-finite input).
template <int N>
bool safe_cholesky(const Eigen::Matrix<double, N, N>& P, Eigen::Matrix<double, N, N>& L) {
  if (!P.allFinite()) return false;
  Eigen::LLT<Eigen::Matrix<double, N, N>> llt(0.5 * (P + P.transpose()));
  if (llt.info() == Eigen::Success) {
    L = llt.matrixL();
    return true;
  }
  Eigen::Matrix<double, N, N> R = psd_repair<N>(P);
  const double jitter = std::max(1e-12 * R.trace() / N, 1e-300);
  R.diagonal().array() += jitter;
  llt.compute(R);
  if (llt.info() != Eigen::Success) return false;
  L = llt.matrixL();
  return true;
}

}  // namespace ultratrack::fusion
