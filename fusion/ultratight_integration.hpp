// SPDX-License-Identifier: GPL-3.0-or-later
// Closed-loop ultra-tight GPS/INS driver ([ChoUKF]): the INS (ins::Strapdown on bias-compensated IMU samples) and
// the 17-state error filter (EKF or UKF) predict every satellite's replica for each integration period T
// (code phase/rate, carrier frequency, running carrier phase: the "INS-predicted replica", as NcoCommands), then
// update from the E/P/L correlations measured over that period, either the seed's I&Q model directly (eqs.
// 11-17) or the discriminator ("pre-filtered") form, with noise from the measured C/N0; the estimated errors
// are fed back to the INS, the IMU compensation and the clock. Satellites without a usable measurement (blocked,
// C/N0 below the threshold) keep being predicted and are reported as coasting.
// Time line: t_s of the IMU samples (GPS time minus gps_time_origin). Metres, m/s, chips, Hz, cycles.
// Model assumption (iq_measurements.hpp): data bits known/wiped off, carrier NCO phase realigned at the start
// of every period (the phase error inside a period is 2 pi df s), or its error at the start given as a variance
// (ChannelCorrelation::start_phase_var_rad2: a closed PLL's residual, taken as noise in R). Over a period the taps see
// the mean range error and the rate error at a third of the period (period_replica_errors). The receiver clock's
// frequency within the period differs from the drift state by a noise e common to the period's satellites (from
// options.model.clock): the period's updates run on x' = x + u e (u the drift axis), after which e is conditioned out
// (exact for a linear measurement; no 18th state). A continuous-carrier channel
// (ChannelCorrelation::continuous_carrier) starts each period with the phase its previous epoch ended with.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "fusion/gnss_ins_integration.hpp"
#include "fusion/iq_measurements.hpp"
#include "fusion/odometer_error_model.hpp"
#include "fusion/vms_measurement.hpp"
#include "receiver/nco_command.hpp"
#include "signals/ephemeris.hpp"

namespace ultratrack::fusion {

enum class UltraTightForm { Iq, Discriminator };

struct UltraTightOptions {
  FilterKind filter = FilterKind::Ekf;
  UltraTightForm form = UltraTightForm::Iq;
  InsErrorModelOptions model;
  Eigen::Vector3d lever_arm_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_pos_ned_m = Eigen::Vector3d::Constant(3.0);
  Eigen::Vector3d sigma_vel_n_mps = Eigen::Vector3d::Constant(0.1);
  Eigen::Vector3d sigma_att_rad = Eigen::Vector3d::Constant(0.01);
  GateOptions gate;
  UkfParameters ukf;
  Discretisation discretisation = Discretisation::SecondOrderSeries;
  ins::StrapdownOptions strapdown;
  TightOptions tight;  // elevation mask, troposphere, ionosphere (with `iono`)
  // Satellites between tight.elevation_mask_rad (above it: predicted, a replica command every period) and this
  // mask are commanded but never update the filter ("aided only"): a low satellite's INS-predicted replica keeps
  // its channel on the signal, while its measurements (multipath, troposphere mapping, fast line-of-sight
  // geometry in a 10 g turn) stay out of the filter. -inf: every predicted satellite updates.
  double measurement_mask_rad = -std::numeric_limits<double>::infinity();
  signals::KlobucharParameters iono;  // broadcast ionosphere (default: invalid, no ionospheric delay)
  double tap_offset_chips = 0.5;      // early/late offset d
  // true: the taps' code correlation is the C/A code's own (its one-chip autocorrelation, IqSettings::
  // code_lag1_correlation: E and L 3.1 % of A higher for PRN 7, 15, 17, 21, 24 at d = 0.5); false: the ideal
  // triangle (the correlation-level simulator's truth).
  bool ca_code_correlation = false;
  double coast_cn0_dbhz = 14.0;  // below: no update, the channel coasts on the INS (on a ~1 s C/N0)
  // A carrier-phase rate (ChannelCorrelation::has_carrier_rate) whose innovation alone lies beyond this many of its
  // sigmas (a PLL that slipped or lets go) is left out of the period's carrier-rate update.
  double carrier_rate_screen_sigma = 4.0;
  // Added to each carrier-phase rate's phase-noise variance (as a 1-sigma, m/s): the PLL's phase lag moves within a
  // window as its aiding error and the line-of-sight dynamics change (a 0.5 Hz aiding step moves a 10 Hz loop's
  // phase by ~0.3 rad, 0.05 m/s over 0.2 s), which the thermal jitter leaves out.
  double carrier_rate_floor_mps = 0.05;
  signals::GpsTime gps_time_origin;
  double initial_clock_bias_m = 0.0, initial_clock_drift_mps = 0.0;
  // IMU biases already estimated (e.g. by the tight filter the receiver hands over from); the filter's bias
  // states are errors of these.
  Eigen::Vector3d initial_accel_bias_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d initial_gyro_bias_b = Eigen::Vector3d::Zero();
  // Land vehicles: odometer (VMS) aiding ([KimVMS], fusion/vms_measurement.hpp; off by default): the odometer's four
  // states after the clock's (21 states), speeds through add_odometer. Their nominal at the start (e.g. the tight
  // filter's estimates at the hand-over) and 1-sigma (a field <= 0: the options' initial sigma).
  OdometerAidingOptions odometer;
  OdometerNominal initial_odometer;
  OdometerNominal sigma_initial_odometer;

  // Sigmas positive, tap offset in (0, 0.5] chip, gate probability in (0, 1), thresholds not NaN; why says which.
  bool IsValid(std::string* why) const;
};

// The replica of one satellite for the period starting at t_start_s, held constant-rate over the period.
struct ReplicaCommand {
  int prn = 0;
  double t_start_s = 0.0;
  receiver::NcoCommand nco;           // code rate (with code Doppler) and carrier frequency (Doppler)
  double pseudorange_m = 0.0;         // replica code phase at t_start as a pseudorange (chips = m / chip length)
  double range_rate_mps = 0.0;        // replica pseudorange rate (= -lambda * carrier frequency)
  double carrier_phase_cycles = 0.0;  // running replica carrier phase at t_start (continuous, integral of nco)
  double elevation_rad = 0.0;
  bool coasting = false;    // no accepted measurement in the last period
  bool aided_only = false;  // below measurement_mask_rad: commanded, never used to update
};

// Measured correlations of one satellite over one period (normalised: unit noise variance per I or Q).
struct ChannelCorrelation {
  int prn = 0;
  IqTaps taps;
  double cn0_dbhz = 0.0;  // the channel's C/N0 estimate
  double integration_time_s = 0.020;
  bool data_wiped = true;  // false: this period is not used (sign ambiguity)
  // The replica that actually ran, when it was not the commanded one (a receiver channel whose carrier follows
  // its own PLL, whose correlation epoch is not the driver's period): its start time (s), its code pseudorange
  // at that start and its constant carrier range rate. has_replica false: the ReplicaCommand of this PRN.
  bool has_replica = false;
  double replica_t_start_s = 0.0, replica_pseudorange_m = 0.0, replica_range_rate_mps = 0.0;
  // Variance (rad^2) of the replica's carrier phase error at the period's start. 0: the NCO phase is realigned at
  // every start, as the seed model assumes. A channel whose Costas PLL stays closed starts each period with the
  // PLL's residual phase error (thermal jitter Bn / (C/N0) (1 + 1 / (2 T C/N0))): the taps turn by it, which the
  // model takes as noise along the phase direction (iq_phase_derivative), the frequency discriminator as a rate
  // error of variance (lambda / (pi T))^2 times it.
  double start_phase_var_rad2 = 0.0;
  // The replica's carrier phase runs on continuously from this channel's previous 20 ms epoch (a closed PLL that
  // changes only the NCO frequency): the period then starts with the phase error the previous one ended with,
  // which in dynamics is not zero (in steady state the PLL holds the mean phase at zero, so under a line-of-sight
  // acceleration a the start phase is -pi a T^2 / 6 / lambda, 0.11 rad in a 10 g turn). With the previous epoch
  // of the same channel adjacent (its replica ended where this one starts), the driver takes as the start phase
  // that epoch's measured mean phase atan2(Q_P, I_P) plus its end-minus-mean phase pi T f(2 T / 3) from the
  // filter's rate-error profile after its update, with the measured phase's thermal variance (1 + 1 / A^2) / A^2
  // in place of start_phase_var_rad2. Otherwise (first epoch, a gap, false) start_phase_var_rad2 as above.
  bool continuous_carrier = false;
  // The carrier-phase rate over a window ending at this epoch (fusion/carrier_rate_measurement.hpp): the channel's
  // replica (its PLL closed, its NCO phase never jumped) ran through -range / lambda cycles over the window; its mean
  // range rate (m/s), the window's middle (s, this time line) and length (s), and that rate's variance from the
  // PLL's jitter at both ends (m^2/s^2). Used once per window, with the period's other windows in one update.
  bool has_carrier_rate = false;
  double carrier_rate_mps = 0.0, carrier_rate_t_mid_s = 0.0, carrier_rate_window_s = 0.0;
  double carrier_rate_var_m2ps2 = 0.0;
};

// One satellite's update in the latest finish_period (for logs): the filter's innovation (Iq: I_E, I_P, I_L,
// Q_E, Q_P, Q_L, unit-noise units; Discriminator: range m, range rate m/s) and its normalised square.
struct UltraTightSatelliteUpdate {
  int prn = 0;
  bool accepted = false;
  double nis = 0.0;
  Eigen::VectorXd innovation;
};

struct UltraTightCounters {
  long long periods = 0;
  long long updates = 0, accepted = 0, rejected = 0;
  long long coasting = 0;    // satellite-periods without a usable measurement
  long long aided_only = 0;  // satellite-periods below the measurement mask (commanded, not used)
  // Carrier-phase rates (fusion/carrier_rate_measurement.hpp): updates (one per window, all satellites), their
  // accepted ones, the rows used and the rows screened out (carrier_rate_screen_sigma).
  long long rate_updates = 0, rate_accepted = 0, rate_rows = 0, rate_screened = 0;
  OdometerCounters odometer;  // odometer windows (add_odometer; fusion/vms_measurement.hpp)
};

class UltraTightIntegration {
 public:
  // Throws std::invalid_argument for bad options (sigmas, tap offset, gate probability).
  UltraTightIntegration(const ins::NavState& initial, std::vector<signals::Ephemeris> ephemerides,
                        const UltraTightOptions& options);
  ~UltraTightIntegration();
  UltraTightIntegration(UltraTightIntegration&&) noexcept;
  UltraTightIntegration& operator=(UltraTightIntegration&&) noexcept;

  // One IMU increment over (current t, inc.t_s]; non-finite or non-increasing ones are ignored.
  void add_imu(const ins::ImuIncrement& inc);
  // Ephemerides received after the start (a satellite's first set, a new IODE): from the next start_period on,
  // each satellite is predicted from the set valid at its transmit time (signals::select_ephemeris) among all
  // held; a set already held (same PRN, IODE, IODC, toe, toc) is ignored.
  void add_ephemerides(const std::vector<signals::Ephemeris>& ephemerides);
  // Predict the replicas of every satellite above the mask for the period [now, now + T), 1 ms <= T <= 20 ms
  // (std::invalid_argument otherwise). Channels keep their running carrier phase.
  const std::vector<ReplicaCommand>& start_period(double integration_time_s);
  // The correlations of the period opened by start_period; call when the INS has reached its end (t_start + T).
  // Satellites missing from `correlations`, with C/N0 below the threshold or data not wiped: coasting.
  void finish_period(const std::vector<ChannelCorrelation>& correlations);

  const std::vector<ReplicaCommand>& replicas() const;
  const IntegrationOutput& output() const;
  NominalState nominal() const;
  Eigen::MatrixXd covariance() const;  // 17 x 17 (the INS and clock states; with the odometer's, their block)
  // Replaces the error covariance (17 x 17, symmetric positive definite; std::invalid_argument otherwise): a loop
  // re-opening a filter its measurements contradict (fusion/lockout_recovery.hpp's inflate_for_recovery). The
  // state and the replicas of the open period are kept.
  void set_covariance(const Eigen::MatrixXd& P);
  // One odometer window ending at the current INS time (options.odometer enabled; std::logic_error otherwise): the
  // gate of [KimVMS] eqs. 16-17, then the VMS/NHC update. Non-finite speeds count as unusable.
  void add_odometer(const OdometerSpeed& speed);
  const UltraTightCounters& counters() const;
  // The updates of the latest finish_period (satellites with a usable measurement), in replica order.
  const std::vector<UltraTightSatelliteUpdate>& last_updates() const;
  const UltraTightOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ultratrack::fusion
