// SPDX-License-Identifier: GPL-3.0-or-later
// Discrete transition matrix Phi and process noise Qd over dt from a continuous linear(ised) model
// xdot = F x + G w, E[w w'] = Qc delta(t). Van Loan (exact for constant F over dt, via the matrix exponential
// of [[-F, G Qc G'], [0, F']] dt) or the second-order series (Phi = I + F dt + F^2 dt^2 / 2,
// Qd = Qs dt + (F Qs + Qs F') dt^2 / 2 + F Qs F' dt^3 / 3 with Qs = G Qc G'), cheaper and accurate while
// |F| dt << 1 (INS error dynamics: |F| ~ 1e-3 /s, dt <= 1 s).
#pragma once

#include <Eigen/Core>

#include "fusion/filter_types.hpp"

namespace ultratrack::fusion {

enum class Discretisation { VanLoan, SecondOrderSeries };

template <int N>
struct DiscreteProcess {
  StateMatrix<N> Phi = StateMatrix<N>::Identity();
  StateMatrix<N> Qd = StateMatrix<N>::Zero();
};

// Qs = G Qc G' (N x N, the state-space noise density). Qd is returned exactly symmetric.
template <int N>
DiscreteProcess<N> discretise(const StateMatrix<N>& F, const StateMatrix<N>& Qs, double dt, Discretisation method);

}  // namespace ultratrack::fusion

#include "fusion/discretisation_impl.hpp"
