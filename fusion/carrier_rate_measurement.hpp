// SPDX-License-Identifier: GPL-3.0-or-later
// The ultra-tight filter's carrier-phase rate measurement: a closed PLL's replica carrier phase, accumulated over a
// window of W seconds (a few hundred ms), gives the signal's mean range rate over it to the PLL's phase jitter at
// the two ends, sqrt(2) sigma_phi lambda / (2 pi W): 0.05 m/s (0.27 Hz) at 20 dB-Hz for W = 0.2 s, where one 20 ms
// period's taps tell the frequency only to ~12 Hz. The satellites' rates share the receiver clock's frequency, so
// this is what lets the filter follow a TCXO's frequency wander (1 Hz / sqrt(s) at L1) on weak signals, where the
// taps alone leave the common drift seconds behind and every PLL then carries it (docs/validation.md, section 6).
//
// Rows, one per satellite: z_i = the nominal's predicted range rate at the update time minus the measured one (m/s;
// "replica minus signal", as the discriminator form's rate row); h(dx) = ReplicaErrors17's rate row, H its Jacobian.
// R = diag(phase-noise variance of each window) + v 1 1' (v: the receiver clock's frequency wander between the
// windows and the update time, common to every row: the random-walk FM's S_d (t_u - t_end + W / 3), m^2/s^2).
// State and units as fusion/ultratight_measurement_models.hpp (17 states, m, m/s).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fusion/filter_types.hpp"
#include "fusion/ins_error_state.hpp"
#include "fusion/iq_measurements.hpp"
#include "fusion/tight_measurements.hpp"

namespace ultratrack::fusion {

// One satellite's window: its mean range rate -lambda (phi_end - phi_start) / W (m/s) carried to the update time
// along the predicted line-of-sight rate slope, the nominal's predicted range rate there (m/s), and the variance of
// the measured rate from the PLL's phase jitter (m^2/s^2).
struct CarrierRateRow {
  SatelliteObservable sat;
  double rate_at_update_mps = 0.0;
  double predicted_rate_mps = 0.0;
  double phase_noise_var_m2ps2 = 0.0;
};

// Variance (m^2/s^2) of a window's mean rate from the phase jitter at its two ends (rad^2 each), over window_s.
double carrier_rate_phase_variance(double start_phase_var_rad2, double end_phase_var_rad2, double window_s);

class CarrierRateMeasurement {
 public:
  CarrierRateMeasurement(const NominalState& nominal, const std::vector<CarrierRateRow>& rows,
                         const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b,
                         double common_clock_var_m2ps2);
  Eigen::VectorXd z() const { return z_; }
  Eigen::VectorXd h(const StateVector<17>& dx) const;
  MeasurementJacobian<17> H(const StateVector<17>&) const { return H_; }
  Eigen::MatrixXd R() const { return R_; }

 private:
  ReplicaErrors17 replica_;
  Eigen::VectorXd z_;
  MeasurementJacobian<17> H_;
  Eigen::MatrixXd R_;
};

}  // namespace ultratrack::fusion
