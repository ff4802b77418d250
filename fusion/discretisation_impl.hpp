// SPDX-License-Identifier: GPL-3.0-or-later
// Template implementation of discretisation.hpp (included from it).
#pragma once

#include <unsupported/Eigen/MatrixFunctions>

namespace ultratrack::fusion {

template <int N>
DiscreteProcess<N> discretise(const StateMatrix<N>& F, const StateMatrix<N>& Qs, double dt, Discretisation method) {
  DiscreteProcess<N> d;
  if (dt == 0.0) return d;
  if (method == Discretisation::VanLoan) {
    Eigen::Matrix<double, 2 * N, 2 * N> M = Eigen::Matrix<double, 2 * N, 2 * N>::Zero();
    M.template topLeftCorner<N, N>() = -F * dt;
    M.template topRightCorner<N, N>() = Qs * dt;
    M.template bottomRightCorner<N, N>() = F.transpose() * dt;
    const Eigen::Matrix<double, 2 * N, 2 * N> E = M.exp();
    d.Phi = E.template bottomRightCorner<N, N>().transpose();
    d.Qd = d.Phi * E.template topRightCorner<N, N>();
  } else {
    const StateMatrix<N> F2 = F * F;
    d.Phi = StateMatrix<N>::Identity() + F * dt + F2 * (0.5 * dt * dt);
    const StateMatrix<N> FQ = F * Qs;
    d.Qd = Qs * dt + (FQ + FQ.transpose()) * (0.5 * dt * dt) + F * Qs * F.transpose() * (dt * dt * dt / 3.0);
  }
  d.Qd = 0.5 * (d.Qd + d.Qd.transpose());
  return d;
}

}  // namespace ultratrack::fusion
