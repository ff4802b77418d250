// SPDX-License-Identifier: GPL-3.0-or-later
// The ultra-tight filter's measurement of one satellite over one integration period (fusion/ultratight_integration):
// the replica that ran over [t0, t0 + T] against the signal the 17-state error dx predicts, seen by the filter at
// the update time t_u >= t0 + T, in two forms: the I&Q taps (6 rows: I_E, I_P, I_L, Q_E, Q_P, Q_L, unit noise per
// I or Q, fusion/iq_measurements.hpp) and the discriminators (2 rows: range error m, range-rate error m/s).
// State: dx of fusion/ins_error_state.hpp at t_u ([0,3) dr_n m NED, [3,6) dv_n m/s, [6,9) psi rad, [9,12) ba m/s^2,
// [12,15) bg rad/s, [15] clock bias m, [16] clock drift m/s; estimate minus truth). The chain, per satellite:
//   e(dx)  = ReplicaErrors17::errors: replica minus signal range (m) and rate (m/s) at t_u, linear in dx to first
//            order (its Jacobian J_rep, taken at the nominal);
//   p(dx)  = M(span) e(dx) + offset: what the period's taps see, the mean range error over the period (m) and the
//            rate error at a third of it (m/s) (period_replica_errors); M = [1, -span / 2; 0, 1], span =
//            2 (t_u - t0) - T (the period's mean range sits span / 2 before t_u, the rate error held), offset =
//            the replica that ran minus the nominal's signal (period_signal_offset);
//   taps   = expected_iq(code = p0 / chip length (293.05 m), frequency = p1 / L1 wavelength (0.1903 m) Hz,
//            start phase rad).
// Both forms' H are that chain's derivatives with J_rep (taken at dx = 0) in place of de/ddx. J_rep leaves out the
// tight model's small terms (tight_measurements.hpp): the antenna velocity turning with position, |v| / R_earth
// (m/s) per metre, and the receiver's share of the travel-time rate, a fraction (|v_sat| + w_e |r_sat|) / c
// (< 2e-5) of the rate entries; away from dx = 0 also the cross terms (attitude with gyro bias in the lever-arm
// velocity, attitude with position). tests/fusion/ultratight_measurement_models_test.cpp bounds each.
#pragma once

#include <Eigen/Core>

#include "fusion/filter_types.hpp"
#include "fusion/ins_error_state.hpp"
#include "fusion/iq_measurements.hpp"
#include "fusion/tight_measurements.hpp"

namespace ultratrack::fusion {

// M(span): (range error, rate error) at t_u -> (mean range error over the period, rate error), span in s.
Eigen::Matrix2d period_mixing(double span_s);
// span = 2 (t_update - t_start) - T, s: twice the distance from the period's mean time to the update.
double period_span_s(double t_update_s, double replica_t_start_s, double period_s);

// The replica that ran (start range at t0 in m, constant rate m/s) minus the nominal's signal over the period
// [t0, t0 + T], as the taps see it (period_replica_errors: mean range error m, rate error at T / 3 m/s). The
// signal's rate changes linearly at signal_rate_slope_mps2 (m/s^2); the nominal's prediction at t_u (range m,
// rate m/s) is carried back to the period's end t0 + T along that slope (t_u may lie after it: a receiver
// channel's epoch that ended before the driver's period).
Eigen::Vector2d period_signal_offset(double replica_range_start_m, double replica_rate_mps, double replica_t_start_s,
                                     double period_s, double t_update_s, double signal_range_m, double signal_rate_mps,
                                     double signal_rate_slope_mps2);

// The prior 1-sigma (chips) of the period's mean code error: sqrt(h P h') / chip length with h the mean-range row
// of M(span) J_rep. P: the 17-state covariance (units of ins_error_state.hpp).
double prior_code_sigma_chips(const ReplicaErrors17& replica, const StateMatrix<17>& P, double span_s);

// The prompt sits on the correlation peak, where R(tau) has a kink: its local slope (+-A) would claim to measure
// tau with the sign of the current guess. Statistical linearisation over the prior tau ~ N(guess, sigma^2): the
// expected slope is the local one times erf(|guess| / (sqrt 2 sigma)), the weight returned (1 when sigma <= 0).
double prompt_code_slope_weight(double code_error_chips, double prior_code_sigma_chips);

// Where the period's replica stands and what else the I&Q form's noise holds.
struct IqPeriodOptions {
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();  // period_signal_offset (m, m/s)
  double span_s = 0.0;                               // period_span_s
  double prior_code_sigma_chips = 0.0;               // > 0: the prompt's code slope weighted (prompt_code_slope_weight)
  // Receiver-clock frequency noise within the period (m^2/s^2), in R along the taps' rate derivative g:
  // R += var g g' (the ultra-tight driver keeps it in P instead and passes 0).
  double clock_rate_var_m2ps2 = 0.0;
  double start_phase_rad = 0.0;       // the replica's carrier phase error at t0 (signal minus replica)
  double start_phase_var_rad2 = 0.0;  // its variance: R += var g g' with g the taps' phase derivative
};

// One satellite's I&Q over the period. z: the measured taps (I_E, I_P, I_L, Q_E, Q_P, Q_L); h(dx): expected_iq of
// the period errors p(dx); H(dx) = iq_jacobian(p(dx)) diag(1 / chip, 1 / lambda) M J_rep, the prompt rows' code
// column times prompt_code_slope_weight; R = iq_noise_covariance + the clock and start-phase terms at dx = 0.
class PeriodIqMeasurement {
 public:
  static constexpr int kMeasurementSize = kIqRowsPerChannel;
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  PeriodIqMeasurement(const NominalState& nominal, const SatelliteObservable& sat, const Eigen::Vector3d& lever_arm_b,
                      const Eigen::Vector3d& w_ib_b, const IqSettings& settings, const IqTaps& measured,
                      const IqPeriodOptions& period);
  const Vector6& z() const { return z_; }
  Vector6 h(const StateVector<17>& dx) const;
  MeasurementJacobian<17> H(const StateVector<17>& dx) const;
  const Eigen::Matrix<double, 6, 6>& R() const { return R_; }
  // The tracking errors (code chips, frequency Hz, start phase rad) the taps see under dx.
  TrackingErrors errors(const StateVector<17>& dx) const;

 private:
  ReplicaErrors17 replica_;
  IqSettings s_;
  Eigen::Vector2d offset_;
  Eigen::Matrix2d M_;
  Vector6 z_;
  Eigen::Matrix<double, 6, 6> R_;
  double code_sigma_ = 0.0;
  double start_phase_ = 0.0;
};

// The discriminator form's measurement z (m, m/s): the code discriminator (NELP) times the chip length, and the
// frequency discriminator (the prompt's mean phase over pi T) with the start phase taken off, times lambda.
Eigen::Vector2d period_discriminator_errors(const IqTaps& taps, const IqSettings& settings, double start_phase_rad);
// Variance (m^2/s^2) of that rate for a start phase of variance var_rad2: (lambda / (pi T))^2 var.
double start_phase_rate_variance(double start_phase_var_rad2, double period_s);

// One satellite's discriminators over the period: z (range error m, rate error m/s, replica minus signal), h(dx) =
// p(dx) (linear: M e(dx) + offset), H = M J_rep; R = diag(range sigma^2, rate sigma^2 + clock_rate_var +
// start_phase_rate_var) (m^2, m^2/s^2).
class PeriodDiscriminatorMeasurement {
 public:
  PeriodDiscriminatorMeasurement(const NominalState& nominal, const SatelliteObservable& sat,
                                 const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b,
                                 const Eigen::Vector2d& offset, double span_s, const Eigen::Vector2d& measured,
                                 const DiscriminatorNoise& noise, double clock_rate_var_m2ps2,
                                 double start_phase_rate_var_m2ps2);
  Eigen::VectorXd z() const { return z_; }
  Eigen::VectorXd h(const StateVector<17>& dx) const { return M_ * replica_.errors(dx) + offset_; }
  MeasurementJacobian<17> H(const StateVector<17>&) const { return M_ * replica_.jacobian(); }
  Eigen::MatrixXd R() const { return R_; }

 private:
  ReplicaErrors17 replica_;
  Eigen::Vector2d offset_;
  Eigen::Matrix2d M_;
  Eigen::VectorXd z_;
  Eigen::MatrixXd R_;
};

}  // namespace ultratrack::fusion
