// SPDX-License-Identifier: GPL-3.0-or-later
// Closed-loop GNSS/INS integration driver ([OhAttINS] feedback filter; [ChoUKF] 17-state tight model).
// Feed IMU increments and GNSS data in time order at any rates and times: the INS (ins::Strapdown, raw IMU
// samples compensated by the estimated biases) runs through every IMU interval; a GNSS measurement at time t
// inside an interval splits that interval at t (increments shared in proportion to time), so it is applied at
// its exact time, never at the nearest IMU sample. After each update the estimated errors are fed back
// (position, velocity, attitude via ins/nav_correction; biases into the IMU compensation; clock) and the error
// state reset to zero. Fallback: whatever part of an epoch is present is used (position without velocity,
// pseudoranges without Doppler, fewer than four satellites in tight mode); nothing present = pure INS.
// GPS attitude (multi-antenna receiver, [OhAttINS]) is a third measurement type in either coupling, applied at
// its own time: epochs with attitude, position/velocity, or both; without attitude the update falls back to
// position/velocity only (counted: fixes_without_attitude). At equal times attitude goes first.
// A filter locked out by its own gate re-opens (fusion/lockout_recovery.hpp): a rejected fix can never make every
// later fix rejected.
// Tight mode, optionally: height aiding (fusion/height_aiding.hpp) in epochs with fewer than 4 satellites.
// Loose: 15 states, GnssFix. Tight: 17 states, ObservationEpoch + ephemerides; with height aiding 18 (+ the
// terrain height). With odometer aiding: 19 loose, 21 tight (+ VMS delay, misalignment, scale factor; [KimVMS]),
// odometer speeds through add_odometer, gated by fusion/vms_measurement.hpp's rule. Loose with Gauss-Markov fix errors:
// + 3 NED fix-error states after all others (18, or 22 with the odometer; fusion/fix_error_model.hpp). EKF or UKF.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fusion/attitude_bias_correlation.hpp"
#include "fusion/attitude_measurement.hpp"
#include "fusion/coupling.hpp"
#include "fusion/ekf.hpp"
#include "fusion/fix_error_model.hpp"
#include "fusion/height_aiding.hpp"
#include "fusion/ins_error_model.hpp"
#include "fusion/ins_error_state.hpp"
#include "fusion/lockout_recovery.hpp"
#include "fusion/loose_measurements.hpp"
#include "fusion/nhc_measurement.hpp"
#include "fusion/odometer_error_model.hpp"
#include "fusion/tight_measurements.hpp"
#include "fusion/ukf.hpp"
#include "fusion/vms_measurement.hpp"
#include "ins/nav_state.hpp"
#include "ins/strapdown.hpp"
#include "receiver/observables.hpp"
#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::fusion {

enum class FilterKind { Ekf, Ukf };

struct IntegrationOptions {
  Coupling coupling = Coupling::kLoose;  // kLoose or kTight
  FilterKind filter = FilterKind::Ekf;
  InsErrorModelOptions model;                             // error_model_from_preset(...) is a good start
  Eigen::Vector3d lever_arm_b = Eigen::Vector3d::Zero();  // IMU -> antenna, body axes [m]
  // Initial 1-sigma of the nav errors (biases and clock: from `model`).
  Eigen::Vector3d sigma_pos_ned_m = Eigen::Vector3d::Constant(10.0);
  Eigen::Vector3d sigma_vel_n_mps = Eigen::Vector3d::Constant(1.0);
  Eigen::Vector3d sigma_att_rad = Eigen::Vector3d::Constant(0.01);
  // IMU biases already estimated (a stationary alignment), body axes (m/s^2, rad/s): the nominal starts from them;
  // with their 1-sigma given, those replace `model`'s turn-on bias sigmas in the initial covariance.
  Eigen::Vector3d initial_accel_bias_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d initial_gyro_bias_b = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> sigma_initial_accel_bias_b, sigma_initial_gyro_bias_b;
  // An alignment's attitude error per unit of IMU bias (fusion/attitude_bias_correlation.hpp): sigma_att_rad is
  // then the part independent of the biases, and the initial covariance correlates attitude and biases. Zero: none.
  AttitudePerBias attitude_per_bias = AttitudePerBias::Zero();
  GateOptions gate;
  // No gate lock-out: a run of rejected fixes (loose) or of epochs with every satellite rejected (tight), or a
  // windowed NIS far above its band, re-opens the covariance of position, velocity, attitude (and clock) and
  // re-applies the measurement (fusion/lockout_recovery.hpp).
  LockoutRecoveryOptions recovery;
  // Loose: fixes closer than this to the last fix used are skipped (a decorrelating interval: fixes whose errors
  // are correlated in time, from receiver smoothing or multipath, are then about independent; 0: every fix).
  double fix_min_interval_s = 0.0;
  // Loose: the correlation time of the fixes' position errors (first-order Gauss-Markov; 0: white). Their
  // variance is inflated by 1 + 2 tau / dt (dt: the time since the previous fix), the factor by which the variance
  // of a mean of correlated errors exceeds that of white ones, so the filter does not average them down.
  // Honest but it discards most of each fix; fix_error carries the correlated part as states instead (not both).
  double fix_error_correlation_s = 0.0;
  // Loose: the fixes' position errors as three Gauss-Markov states in NED (fusion/fix_error_model.hpp; off by
  // default).
  FixErrorOptions fix_error;
  // Land vehicles: non-holonomic constraints (fusion/nhc_measurement.hpp), off by default.
  LandVehicleOptions land;
  // Land vehicles: odometer (VMS) aiding, [KimVMS] (loose or tight; not with height aiding; off by default).
  OdometerAidingOptions odometer;
  UkfParameters ukf;
  Discretisation discretisation = Discretisation::SecondOrderSeries;
  // The error covariance is propagated over intervals of about this length (F at the interval's end,
  // specific force averaged over it), and always up to each measurement time. 0: every IMU interval.
  double propagation_interval_s = 0.05;
  ins::StrapdownOptions strapdown;
  TightOptions tight;
  // Tight mode: terrain-height state and height aids in epochs with fewer than 4 usable satellites (off by
  // default).
  HeightAidingOptions height_aiding;
  AttitudeAidingOptions attitude;  // GPS attitude: array-to-IMU mounting, pitch limit
  // Tight mode: GPS time at t_s = 0 of the run's time line. A receive time T (receiver clock) is applied at
  // t = (T - gps_time_origin) - clock_bias / c.
  signals::GpsTime gps_time_origin;
  // Tight mode: initial receiver clock (c * offset, c * drift) for the nominal.
  double initial_clock_bias_m = 0.0;
  double initial_clock_drift_mps = 0.0;

  // Every field in range (sigmas positive, probabilities in (0, 1), ...); why says the first that is not.
  bool IsValid(std::string* why) const;
};

// The solution after each IMU interval (and after each measurement update).
struct IntegrationOutput {
  ins::NavState nav;  // IMU position/velocity/attitude at nav.t_s
  Eigen::Vector3d sigma_pos_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_vel_n_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_att_rad = Eigen::Vector3d::Zero();  // psi north, east, down
  Eigen::Vector3d accel_bias_b = Eigen::Vector3d::Zero();   // current estimates (m/s^2, rad/s)
  Eigen::Vector3d gyro_bias_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_accel_bias_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_gyro_bias_b = Eigen::Vector3d::Zero();
  double clock_bias_m = 0.0, clock_drift_mps = 0.0;  // tight mode (else 0)
  double sigma_clock_bias_m = 0.0, sigma_clock_drift_mps = 0.0;
  double terrain_height_m = 0.0, sigma_terrain_height_m = 0.0;  // tight with height aiding (else 0)
  OdometerEstimate odometer;                                    // odometer aiding (else 0)
  // Gauss-Markov fix-error states (else 0): the estimate of the fixes' current position error, NED [m].
  Eigen::Vector3d fix_error_ned_m = Eigen::Vector3d::Zero(), sigma_fix_error_ned_m = Eigen::Vector3d::Zero();
};

// The INS part of an output (navigation state, bias estimates, the sigmas of the 15 INS error states) from a filter's
// nominal and the square roots of its covariance diagonal (any state count N >= 15, INS states first).
template <int N>
void set_ins_output(IntegrationOutput& o, const NominalState& nominal, const StateVector<N>& sd) {
  o.nav = nominal.nav;
  o.sigma_pos_ned_m = sd.template segment<3>(ix::kPos);
  o.sigma_vel_n_mps = sd.template segment<3>(ix::kVel);
  o.sigma_att_rad = sd.template segment<3>(ix::kAtt);
  o.accel_bias_b = nominal.accel_bias_b;
  o.gyro_bias_b = nominal.gyro_bias_b;
  o.sigma_accel_bias_b = sd.template segment<3>(ix::kAccelBias);
  o.sigma_gyro_bias_b = sd.template segment<3>(ix::kGyroBias);
}

struct IntegrationCounters {
  long long imu_steps = 0;
  long long epochs = 0;    // GNSS fixes / observation epochs applied
  long long accepted = 0;  // measurement updates (a satellite, or a fix) passed by the gate
  long long rejected = 0;  // refused by the gate
  long long late = 0;      // GNSS data older than the INS time when it came (dropped)
  long long satellites_missing_ephemeris = 0;
  long long invalid = 0;  // ignored: non-finite IMU increments or fixes, IMU times not increasing
  // Per measurement type (the totals above include them). Loose fixes: one update each.
  long long fix_accepted = 0, fix_rejected = 0;
  long long attitude_epochs = 0;  // GPS attitudes applied at their time (accepted + rejected + unusable)
  long long attitude_accepted = 0;
  long long attitude_rejected = 0;  // refused by the innovation gate
  long long attitude_unusable = 0;  // refused before the gate: near vertical (Euler sigmas degenerate)
  long long attitude_late = 0;      // older than the INS time when it came (dropped)
  // Fallback ([OhAttINS]): fixes / observation epochs with no accepted attitude since the previous one.
  long long fixes_without_attitude = 0;
  // Tight mode: epochs with fewer than height_aiding.min_satellites usable satellites, and the height
  // pseudo-measurements applied there (accepted / refused by the gate; none before a height is known).
  long long epochs_few_satellites = 0;
  long long height_accepted = 0, height_rejected = 0;
  long long recoveries = 0;                      // lock-out recoveries (recovery_events() says when and why)
  long long nhc_accepted = 0, nhc_rejected = 0;  // non-holonomic constraint updates
  long long fixes_skipped = 0;                   // loose: within fix_min_interval_s of the last fix used
  OdometerCounters odometer;                     // odometer windows (fusion/vms_measurement.hpp)
};

// Per-update diagnostics (for NIS / consistency logs).
struct UpdateRecord {
  double t_s = 0.0;
  int prn = 0;  // tight: satellite; loose: 0; GPS attitude: -1; height aiding: -2; non-holonomic: -3; odometer: -4
  UpdateResult result;
};

class GnssInsIntegration {
 public:
  // initial: the INS state at its time (alignment is the caller's: ins/coarse_alignment or a config).
  // Throws std::invalid_argument for inconsistent options (non-positive sigmas, bad UKF parameters).
  GnssInsIntegration(const ins::NavState& initial, const IntegrationOptions& options);
  ~GnssInsIntegration();
  GnssInsIntegration(GnssInsIntegration&&) noexcept;
  GnssInsIntegration& operator=(GnssInsIntegration&&) noexcept;

  // Queue GNSS data; applied when the IMU reaches its time (or at once if the INS is exactly there).
  // Loose mode only. Throws std::logic_error in tight mode.
  void add_fix(const GnssFix& fix);
  // Tight mode only: an epoch with the ephemeris sets to choose from (select_ephemeris per satellite).
  void add_observations(const receiver::ObservationEpoch& epoch, const std::vector<signals::Ephemeris>& ephemerides,
                        const signals::KlobucharParameters& iono = {});
  // Either coupling: a GPS attitude (array frame, options().attitude.q_ba to the IMU) at attitude.t_s.
  // Non-finite values or non-positive sigmas: ignored and counted (counters().invalid).
  void add_attitude(const GnssAttitude& attitude);
  // Odometer aiding only (options().odometer.enabled; else std::logic_error): the VMS speed over
  // (speed.t_s - speed.window_s, speed.t_s], applied at speed.t_s. Non-finite values: ignored (counters().invalid).
  void add_odometer(const OdometerSpeed& speed);

  // One raw IMU increment covering (output().nav.t_s, inc.t_s]. Pending GNSS data with times inside the
  // interval are applied at their exact times. Increments not later than the current time, or with non-finite
  // values, are ignored and counted (counters().invalid).
  void add_imu(const ins::ImuIncrement& inc);

  const IntegrationOutput& output() const;
  // Current nominal (nav + bias estimates + clock) and the error covariance (15 x 15 or 17 x 17; with height
  // aiding the terrain state is left out: output().sigma_terrain_height_m; likewise the odometer and fix-error states).
  NominalState nominal() const;
  Eigen::MatrixXd covariance() const;
  const IntegrationCounters& counters() const;
  // Every lock-out recovery so far, in time order.
  const std::vector<RecoveryEvent>& recovery_events() const;
  // Updates since the last call (cleared by the call; at most 8192 are kept, the oldest half dropped first).
  std::vector<UpdateRecord> take_update_records();
  const IntegrationOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ultratrack::fusion
