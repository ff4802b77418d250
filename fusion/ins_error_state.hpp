// SPDX-License-Identifier: GPL-3.0-or-later
// The INS error state in NED (psi-angle form, [KimAlign] eqs. 2-9 extended with position as in [ChoUKF] eq. 10):
//   [0,3)  dr_n  position error, NED metres          [3,6)  dv_n  velocity error, NED m/s
//   [6,9)  psi   attitude error, rad (ins/nav_state.hpp convention: C_nb_est = (I - [psi x]) C_nb_true)
//   [9,12) ba    residual accelerometer bias, body, m/s^2   [12,15) bg residual gyro bias, body, rad/s
//   [15]   clock bias error, m   [16] clock drift error, m/s            (17-state model only)
// Position, velocity, attitude and clock errors are estimate minus truth; a residual bias is what remains in the
// compensated IMU output (compensated = true + residual). A state dx thus means truth = nominal "minus" dx.
#pragma once

#include <Eigen/Core>

#include "fusion/filter_types.hpp"
#include "ins/nav_state.hpp"

namespace ultratrack::fusion {

namespace ix {
inline constexpr int kPos = 0;
inline constexpr int kVel = 3;
inline constexpr int kAtt = 6;
inline constexpr int kAccelBias = 9;
inline constexpr int kGyroBias = 12;
inline constexpr int kClockBias = 15;
inline constexpr int kClockDrift = 16;
}  // namespace ix

// The nominal (total) quantities the error state corrects: the INS solution, the IMU bias estimates being
// subtracted from the raw samples, and the receiver clock (c * offset receiver - GPS time, and its rate).
struct NominalState {
  ins::NavState nav;
  Eigen::Vector3d accel_bias_b = Eigen::Vector3d::Zero();  // m/s^2, subtracted from raw dv / dt
  Eigen::Vector3d gyro_bias_b = Eigen::Vector3d::Zero();   // rad/s, subtracted from raw dtheta / dt
  double clock_bias_m = 0.0;
  double clock_drift_mps = 0.0;
};

// The nominal corrected by an error state dx (N = 15 or 17): truth estimate = nominal with dx removed
// (ins/nav_correction for position, velocity and attitude; biases: b_est + residual; clock: nominal - dx).
template <int N>
NominalState corrected(const NominalState& nominal, const StateVector<N>& dx);

// Error of a nominal relative to a truth, as the state vector (for NEES and tests). Bias and clock truths
// are total values (what the IMU / clock really has).
template <int N>
StateVector<N> error_state(const NominalState& nominal, const NominalState& truth);

}  // namespace ultratrack::fusion
