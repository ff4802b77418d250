// SPDX-License-Identifier: GPL-3.0-or-later
// Correlation-level simulator for the ultra-tight tests: a true trajectory (ins trajectory simulator, IMU with
// an ins/imu_error_model preset), a true receiver clock (bias/drift random walks) and the nominal constellation
// give each satellite's true pseudorange over every integration period (fusion_sim's simulate_epoch at its
// start, middle and end, a quadratic between); the E/P/L I&Q of the replica the filter commanded are the
// correlation of that signal with the replica summed over 20 sub-intervals (triangle code correlation times
// the carrier phase error integrated over the period, NCO phase realigned at the period's start) plus
// Gaussian noise correlated across the taps at the given C/N0. The truth never goes through the filter's model.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "fusion/ultratight_integration.hpp"

namespace ultratrack::fusion::test {

struct CorrelationSimConfig {
  std::string profile = "circle";  // [ChoUKF] circle: 500 km/h
  double duration_s = 10.0;
  double imu_rate_hz = 100.0;
  std::string imu_preset = "hg1700ae";
  std::uint64_t seed = 1;
  Eigen::Vector3d lever_arm_b{1.0, 0.3, -1.2};
  double integration_time_s = 0.020;
  double cn0_dbhz = 45.0;
  int max_satellites = 8;                                  // highest elevation first
  double blockage_start_s = 1e9, blockage_length_s = 0.0;  // every signal absent in [start, start + length)
  FilterKind filter = FilterKind::Ekf;
  UltraTightForm form = UltraTightForm::Iq;
  // Initial errors drawn with these 1-sigma, and told to the filter.
  Eigen::Vector3d sigma0_pos_m{3.0, 3.0, 3.0};
  Eigen::Vector3d sigma0_vel_mps{0.1, 0.1, 0.1};
  Eigen::Vector3d sigma0_att_rad{1e-3, 1e-3, 5e-3};
  double sigma0_clock_bias_m = 3.0, sigma0_clock_drift_mps = 0.1;
  // Receiver clock (truth and filter model alike). Default white FM h0 = 2e-22 (OCXO class): a TCXO's h0 = 2e-19
  // (fusion's default, 0.009 m^2/s) averages to ~1 m/s (5 Hz) of frequency noise over 20 ms, which the I&Q
  // model (frequency error constant within T, equal to the drift state) does not represent.
  double clock_bias_psd_m2_per_s = 9e-6;
  double clock_drift_psd_m2_per_s3 = 0.0355;
  bool troposphere = true;  // in the signal and in the filter's model alike
  // A receiver channel whose Costas PLL stays closed starts each period with its residual phase error instead of
  // the realigned phase: drawn N(0, sigma^2) per satellite and period (0: realigned); told to the driver as
  // ChannelCorrelation::start_phase_var_rad2 when tell_start_phase.
  double start_phase_sigma_rad = 0.0;
  bool tell_start_phase = true;
  // > 0: each channel's carrier runs on continuously (no realignment) and a closed 2nd-order PLL of this noise
  // bandwidth (zeta 0.707) on the prompt's mean phase adds a frequency correction to the commanded replica, as a
  // receiver channel whose Costas PLL stays closed; the replica that ran is given to the driver (has_replica).
  // ChannelCorrelation::continuous_carrier = tell_continuous_carrier.
  double pll_bw_hz = 0.0;
  bool tell_continuous_carrier = true;
};

struct CorrelationRunResult {
  std::vector<double> t_s;                   // end of every period (after its update)
  std::vector<Eigen::Vector3d> pos_err_m;    // IMU position error, NED
  std::vector<Eigen::Vector3d> sigma_pos_m;  // filter's 1-sigma, NED
  std::vector<double> nees;                  // 17-state NEES
  std::vector<double> max_code_err_chips;    // over the satellites, true error of the replica at mid-period
  std::vector<double> max_freq_err_hz;
  std::vector<int> coasting;                            // satellites reported coasting at the period's start
  std::vector<double> nis;                              // every satellite update's NIS (accepted or not), in order
  Eigen::Matrix<double, 17, 1> last_error, last_sigma;  // error state and filter 1-sigma at the end
  int satellites = 0;
  double cpu_s = 0.0;  // filter time (start/finish_period + IMU)
  UltraTightCounters counters;
};

CorrelationRunResult run_correlation_simulation(const CorrelationSimConfig& cfg);

// E/P/L taps (normalised) of a signal whose code error (signal minus replica, chips) and carrier phase error
// (rad, 0 at the start) are given at the midpoints of M equal sub-intervals, amplitude A = sqrt(2 C/N0 T).
IqTaps ideal_correlation(const std::vector<double>& code_err_chips, const std::vector<double>& phase_err_rad,
                         double amplitude, double tap_offset_chips);

}  // namespace ultratrack::fusion::test
