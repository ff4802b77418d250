// SPDX-License-Identifier: GPL-3.0-or-later
// Ultra-tight measurements ([ChoUKF] eqs. 5-8, 11-17): the early/prompt/late in-phase and quadrature correlator
// outputs of one channel as functions of the 17-state error, and the "pre-filtered" alternative (code and
// frequency discriminators turned into range and range-rate errors), both with closed-form noise from C/N0.
// Units: correlator outputs normalised so that the noise of each I or Q is N(0, 1) ([ChoUKF] eq. 16); the
// signal amplitude is then A = sqrt(2 C/N0 T) (C/N0 in Hz, T the coherent integration in s). Code errors in
// chips, frequency errors in Hz, range errors in m, range-rate errors in m/s. Navigation data bits known or
// wiped off (no sign ambiguity); the carrier NCO phase is realigned at the start of every integration, so the
// phase error inside an interval is 2 pi df s, s in [0, T) (the absolute carrier phase, with its integer
// ambiguity, is not a state of the 17-state model and is not used).
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "fusion/filter_types.hpp"
#include "fusion/ins_error_state.hpp"
#include "fusion/tight_measurements.hpp"

namespace ultratrack::fusion {

struct IqSettings {
  double cn0_dbhz = 45.0;
  double integration_time_s = 0.020;  // coherent T (bits known / wiped off)
  double tap_offset_chips = 0.5;      // d: early / late replicas d chips ahead / behind (E-L spacing 2 d), 0 < d <= 0.5
  // Seed 001 eq. 8b read literally: the phase error at the interval's start is 2 pi (range error) / lambda, i.e.
  // the absolute carrier phase is a range measurement with a known integer ambiguity (an idealisation: the
  // 17-state model has no ambiguity states). Default off: the NCO phase is realigned every interval.
  bool absolute_carrier_phase = false;
  // The code's periodic autocorrelation at one chip, R1 (C/A codes: -1/1023 for most PRNs, +63/1023 for 7, 15, 17,
  // 21, 24, -65/1023 for 8, 22: ca_code_lag1_correlation). With rectangular chips the correlation between lags 0
  // and 1 chip is 1 - |x| (1 - R1) instead of the ideal triangle (0: the triangle, as the seed model). |R1| < 1.
  double code_lag1_correlation = 0.0;
};

// Signal minus replica, as receiver/discriminators.hpp: positive code error = the signal leads the replica.
struct TrackingErrors {
  double code_chips = 0.0;
  double frequency_hz = 0.0;
  double phase_rad = 0.0;  // carrier phase error at the interval's start (0 with the NCO realigned)
};

// Correlator taps in the order early, prompt, late; I and Q normalised (unit noise variance).
struct IqTaps {
  std::array<double, 3> i{}, q{};
};
inline constexpr int kIqRowsPerChannel = 6;  // I_E, I_P, I_L, Q_E, Q_P, Q_L

double iq_amplitude(const IqSettings& s);  // sqrt(2 C/N0 T)

// Ideal (infinite-bandwidth) C/A code autocorrelation: R(x) = 1 - |x| for |x| < 1 chip, 0 beyond.
double triangle_correlation(double x_chips);
// dR/dx, with the mean of the one-sided slopes at the corners (0 at the peak, -+1/2 at +-1 chip).
double triangle_slope(double x_chips);

// Correlation of a rectangular-chip code with itself shifted by x chips, from its periodic autocorrelation at 0
// (1) and one chip (lag1): 1 - |x| (1 - lag1) within one chip, lag1 (2 - |x|) between one and two (the two-chip
// value taken as 0), 0 beyond; lag1 = 0 is triangle_correlation. Slope: as triangle_slope (mean of the one-sided
// slopes at the corners).
double code_correlation(double x_chips, double lag1);
double code_correlation_slope(double x_chips, double lag1);
// R1 of the GPS C/A code of a PRN (1..32; 0 for others), from signals::ca_code.
double ca_code_lag1_correlation(int prn);

// Replica errors from the range and range-rate errors of the replica (replica minus signal, m and m/s):
// code = e_rho / chip length, frequency = e_rhodot / L1 wavelength.
TrackingErrors tracking_errors(double range_error_m, double range_rate_error_mps);

// What the I&Q of one period see of a replica held at constant range rate against a signal whose range rate
// varies linearly over the period [0, L] (from signal_rate_start to signal_rate_end, signal range signal_range_end
// at L). The code taps average the range error over the period: (replica minus signal) mean range. The prompt's
// phase is the mean of the carrier phase error, (1 / L) int_0^L (L - u) (rate error at u) du, i.e. the rate error
// at u = L / 3 (not at mid-period): that is the rate error a linear phase must have to give the same taps.
// Returns (range error m, rate error m/s), replica minus signal, for tracking_errors.
Eigen::Vector2d period_replica_errors(double replica_range_start_m, double replica_rate_mps, double signal_range_end_m,
                                      double signal_rate_start_mps, double signal_rate_end_mps, double period_s);

// E[I], E[Q] of the early/prompt/late taps: with x = pi df T and phi the start phase,
// I_k = A R(tau - o_k) sinc(x) cos(phi + x), Q_k = A R(tau - o_k) sinc(x) sin(phi + x), o = (+d, 0, -d) for E, P, L
// (the early replica runs d chips ahead, so a leading signal, tau > 0, raises the early tap)
// ([ChoUKF] eq. 7 with the phase error zero at the interval's start; its I and Q are swapped by its sin/cos
// replica convention).
IqTaps expected_iq(const TrackingErrors& e, const IqSettings& s);
// Jacobian of (I_E, I_P, I_L, Q_E, Q_P, Q_L) with respect to (code chips, frequency Hz), and to the start phase.
Eigen::Matrix<double, 6, 2> iq_jacobian(const TrackingErrors& e, const IqSettings& s);
Eigen::Matrix<double, 6, 1> iq_phase_derivative(const TrackingErrors& e, const IqSettings& s);
// Noise covariance of the six outputs: unit variance; taps o_j, o_k share R(o_j - o_k) (white noise through
// the same replica shifted by the tap spacing); I and Q independent.
Eigen::Matrix<double, 6, 6> iq_noise_covariance(const IqSettings& s);

// Discriminators on one interval's taps. Code: normalised early-minus-late envelope (receiver::dll_nelp_chips),
// tau in chips within +-d. Frequency: the prompt's phase (its mean over the interval, which is pi df T when the
// phase starts at zero) over pi T, atan2(Q_P, I_P) / (pi T) Hz, within +-1 / T.
double code_discriminator_chips(const IqTaps& taps, const IqSettings& s);
double frequency_discriminator_hz(const IqTaps& taps, const IqSettings& s);

// Closed-form variances of one interval's discriminator outputs (thermal noise, one-sided noise bandwidth of
// an integrate-and-dump B = 1 / (2 T) in the loop formulas of Kaplan & Hegarty, Understanding GPS, 2nd ed.,
// sec. 5.6 (thermal-noise jitter): DLL sigma^2 = B D / (2 C/N0) chips^2 with D = 2 d the E-L spacing (the
// coherent early-minus-late form, also Betz & Kolodziejski 2009 for an ideal front end; the normalised NELP
// has no squaring-loss bracket to within the Monte Carlo's 0.7 % at 35 dB-Hz, unlike the unnormalised E-L
// power's [1 + 2 / ((2 - D) T C/N0)]); PLL sigma^2 = B / (C/N0) [1 + 1 / (2 T C/N0)] rad^2 (with known data the
// bracket is atan2's second-order term E[(n_Q / (A + n_I))^2] - ... = (1 + 1 / A^2) / A^2), frequency = phase /
// (pi T). First order: code d / A^2 chips^2, phase 1 / A^2 rad^2, frequency 1 / (A pi T)^2 Hz^2, the inverse of
// the linearised I&Q information (iq_jacobian' R^-1 iq_jacobian) at zero error. squaring_loss = false: first
// order only. Off zero error the amplitude drops (sinc, R(tau)): evaluate at the correspondingly lower C/N0.
struct DiscriminatorNoise {
  double code_var_chips2 = 0.0;
  double frequency_var_hz2 = 0.0;
  double range_sigma_m = 0.0;   // sqrt(code var) * chip length
  double rate_sigma_mps = 0.0;  // sqrt(frequency var) * L1 wavelength
};
DiscriminatorNoise discriminator_noise(const IqSettings& s, bool squaring_loss = true);

// Replica range and range-rate errors (replica minus signal) of every satellite for a hypothesised error state
// dx: the replica follows the nominal, the signal the nominal corrected by dx (fusion::corrected).
class ReplicaErrors17 {
 public:
  ReplicaErrors17(const NominalState& nominal, const std::vector<SatelliteObservable>& sats,
                  const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b);
  int size() const { return static_cast<int>(rows_.size()); }
  // Rows 2 i, 2 i + 1: range error (m), range-rate error (m/s) of satellite i.
  Eigen::VectorXd errors(const StateVector<17>& dx) const;
  Eigen::Vector2d errors(int satellite, const StateVector<17>& dx) const;  // rows 2 i, 2 i + 1 only
  MeasurementJacobian<17> jacobian() const;  // d errors / d dx (independent of dx to first order)

 private:
  std::vector<SatelliteMeasurement17> rows_;
  Eigen::VectorXd nominal_;  // predicted pseudorange and rate at the nominal
};

// The seed's I&Q measurement of all satellites of an epoch (6 rows per satellite: I_E, I_P, I_L, Q_E, Q_P, Q_L):
// h(dx) = expected_iq(tracking_errors(replica errors(dx))); z = the measured (normalised) taps; R block-diagonal
// iq_noise_covariance. H is the chain rule with iq_jacobian at dx (corners: triangle_slope's convention).
class IqEpochMeasurement17 {
 public:
  IqEpochMeasurement17(const NominalState& nominal, const std::vector<SatelliteObservable>& sats,
                       const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b, const IqSettings& settings,
                       const std::vector<IqTaps>& measured);

  Eigen::VectorXd z() const { return z_; }
  Eigen::VectorXd h(const StateVector<17>& dx) const;
  MeasurementJacobian<17> H(const StateVector<17>& dx) const;
  Eigen::MatrixXd R() const { return R_; }
  int size() const { return static_cast<int>(z_.size()); }

 private:
  TrackingErrors errors_of(const Eigen::VectorXd& replica_errors, int satellite) const;
  ReplicaErrors17 replica_;
  IqSettings settings_;
  Eigen::VectorXd z_;
  Eigen::MatrixXd R_;
};

// The pre-filtered form: per satellite the code discriminator as a range error (m) and the frequency
// discriminator as a range-rate error (m/s) (2 rows per satellite, or 1 without rates): h(dx) = replica errors.
class DiscriminatorEpochMeasurement17 {
 public:
  // measured: range and rate errors per satellite (rows as ReplicaErrors17::errors); sigmas per measurement.
  DiscriminatorEpochMeasurement17(const NominalState& nominal, const std::vector<SatelliteObservable>& sats,
                                  const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b,
                                  const Eigen::VectorXd& measured, double range_sigma_m, double rate_sigma_mps,
                                  bool use_rate);

  Eigen::VectorXd z() const { return z_; }
  Eigen::VectorXd h(const StateVector<17>& dx) const;
  MeasurementJacobian<17> H(const StateVector<17>& dx) const;
  Eigen::MatrixXd R() const { return R_; }
  int size() const { return static_cast<int>(z_.size()); }

 private:
  Eigen::VectorXd select(const Eigen::VectorXd& both) const;
  ReplicaErrors17 replica_;
  bool rate_ = true;
  Eigen::VectorXd z_;
  Eigen::MatrixXd R_;
};

}  // namespace ultratrack::fusion
