// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/ins_error_state.hpp"

#include "ins/attitude.hpp"
#include "ins/nav_correction.hpp"

namespace ultratrack::fusion {

template <int N>
NominalState corrected(const NominalState& nominal, const StateVector<N>& dx) {
  static_assert(N == 15 || N == 17);
  NominalState out = nominal;
  ins::correct_position(out.nav, dx.template segment<3>(ix::kPos));
  ins::correct_velocity(out.nav, dx.template segment<3>(ix::kVel));
  ins::correct_attitude(out.nav, dx.template segment<3>(ix::kAtt));
  out.accel_bias_b += dx.template segment<3>(ix::kAccelBias);
  out.gyro_bias_b += dx.template segment<3>(ix::kGyroBias);
  if constexpr (N == 17) {
    out.clock_bias_m -= dx(ix::kClockBias);
    out.clock_drift_mps -= dx(ix::kClockDrift);
  }
  return out;
}

template <int N>
StateVector<N> error_state(const NominalState& nominal, const NominalState& truth) {
  static_assert(N == 15 || N == 17);
  StateVector<N> dx = StateVector<N>::Zero();
  dx.template segment<3>(ix::kPos) = ins::position_error_ned(nominal.nav, truth.nav);
  dx.template segment<3>(ix::kVel) = nominal.nav.v_n - truth.nav.v_n;
  dx.template segment<3>(ix::kAtt) = ins::attitude_error_n(nominal.nav.q_nb, truth.nav.q_nb);
  dx.template segment<3>(ix::kAccelBias) = truth.accel_bias_b - nominal.accel_bias_b;
  dx.template segment<3>(ix::kGyroBias) = truth.gyro_bias_b - nominal.gyro_bias_b;
  if constexpr (N == 17) {
    dx(ix::kClockBias) = nominal.clock_bias_m - truth.clock_bias_m;
    dx(ix::kClockDrift) = nominal.clock_drift_mps - truth.clock_drift_mps;
  }
  return dx;
}

template NominalState corrected<15>(const NominalState&, const StateVector<15>&);
template NominalState corrected<17>(const NominalState&, const StateVector<17>&);
template StateVector<15> error_state<15>(const NominalState&, const NominalState&);
template StateVector<17> error_state<17>(const NominalState&, const NominalState&);

}  // namespace ultratrack::fusion
