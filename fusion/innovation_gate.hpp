// SPDX-License-Identifier: GPL-3.0-or-later
// The innovation test both filters apply before an update: factor the innovation covariance S, compute the
// normalised innovation squared nu' S^-1 nu and compare it with the chi-square gate (GateOptions). One copy,
// so that the EKF and the UKF accept and reject by exactly the same rule.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <limits>

#include "fusion/filter_types.hpp"
#include "receiver/chi_square.hpp"

namespace ultratrack::fusion {

// Fills r.threshold and r.nis from r.innovation and S (symmetric, k x k, k = r.dof) and leaves S's Cholesky
// factor in `llt`. True when the update may go ahead: S positive definite, the innovation finite and inside
// the gate. r.nis is infinity when S or the innovation is unusable.
// The gate's chi-square quantile, remembered per thread for the latest probability of each small dof (a filter
// updating every 20 ms asks for the same few values; the quantile's series costs more than the update's algebra).
inline double gate_threshold(double probability, int dof) {
  constexpr int kMemo = 32;
  thread_local std::array<double, kMemo> memo_p = [] {
    std::array<double, kMemo> a;
    a.fill(std::numeric_limits<double>::quiet_NaN());  // matches no probability
    return a;
  }();
  thread_local std::array<double, kMemo> memo_q{};
  if (dof <= 0 || dof >= kMemo) return receiver::chi_square_lower_quantile(dof, probability);
  const auto i = static_cast<std::size_t>(dof);
  if (memo_p[i] != probability) {
    memo_q[i] = receiver::chi_square_lower_quantile(dof, probability);
    memo_p[i] = probability;
  }
  return memo_q[i];
}

// SMatrix: Eigen::MatrixXd, or a fixed k x k matrix when the measurement's size is known at compile time.
template <class SMatrix>
bool passes_innovation_gate(const GateOptions& gate, const SMatrix& S, UpdateResult& r, Eigen::LLT<SMatrix>& llt) {
  r.threshold = gate.enabled ? gate_threshold(gate.probability, r.dof) : std::numeric_limits<double>::infinity();
  llt.compute(S);
  if (llt.info() != Eigen::Success || !r.innovation.allFinite()) {
    r.nis = std::numeric_limits<double>::infinity();
    return false;
  }
  r.nis = r.innovation.dot(llt.solve(r.innovation));
  return r.nis <= r.threshold;
}

}  // namespace ultratrack::fusion
