// SPDX-License-Identifier: GPL-3.0-or-later
// Carrier-phase attitude of a rigid antenna array (2..4 antennas, antenna 0 the master) from AntennaPhaseEpochs:
// double differences between antennas and satellites, integer ambiguities by LAMBDA with the known baseline
// lengths and angles as constraints, ratio and difference tests (on one epoch, or on the summed fits of several
// when one is not enough), attitude by a Wahba (SVD) fit of the fixed baselines, and the fixed ambiguities kept
// across epochs. Units: m, rad, cycles of L1; body frame x forward, y right, z down; C_nb
// is body to the local NED frame at the master antenna (WGS-84); Euler angles z-y-x (yaw, pitch, roll).
//
// Sign convention (RINEX, phase grows with range): for satellite s with unit line of sight u_s (master -> sat, ECEF)
// and baseline b_k (master -> antenna k, ECEF), carrier_phase_cycles[k] - carrier_phase_cycles[0]
//   = -(u_s . b_k) / lambda + N_k^s + line bias_k + noise.
// (The comment in antenna_phase.hpp writes +; the physics of a phase that grows with range gives -.)
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "receiver/antenna_phase.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::receiver {

struct AntennaArray {
  // Phase centre of each antenna in the body frame, m; [0] is the master. 3..kMaxAntennas entries, the baselines
  // (lever_arm_body_m[k] - lever_arm_body_m[0]) at least 0.1 m long and at least two of them not collinear (a full
  // attitude needs two directions).
  std::vector<Eigen::Vector3d> lever_arm_body_m;
};

struct AttitudeSolverOptions {
  AntennaArray array;
  double phase_sigma_m = 0.003;  // carrier noise of one antenna's phase (1 sigma, uniform over elevation), m
  double elevation_mask_rad = 0.17453292519943295;  // 10 deg; satellites below it are left out
  int min_satellites = 5;                           // satellites (reference included) needed on a baseline to resolve
  // Validation of a new fix, both tests on the rigid-fit chi-square of the best and second-best candidates: ratio
  // test J2 / J1 >= ratio_threshold (Euler & Schaffrin 1991) and difference test J2 - J1 >= difference_threshold
  // (Tiberius & de Jonge 1995). The difference test is what keeps wrong fixes rare at 5 satellites, where a wrong
  // candidate can fit almost as well as the right one (15: no wrong fix in 12000 simulated 5-satellite epochs).
  double ratio_threshold = 2.0;
  double difference_threshold = 15.0;
  // true: per-baseline LAMBDA candidates filtered by the baseline lengths, then pairs by the angle between
  // baselines and ranked by the rigid-array fit of all DDs (the constrained method). false: plain LAMBDA on each
  // baseline's float (weak length prior only), best candidate + ratio test: kept to measure what constraints buy.
  bool use_length_constraint = true;
  // Acceptance gates, in standard deviations of the quantity tested (length, angle, normalised DD residual).
  double constraint_gate_sigma = 4.0;
  // Length tolerance added to the statistical gate (antenna phase-centre survey error), m.
  double length_tolerance_m = 0.01;
  // Residual check of carried ambiguities each epoch: chi-square of the rigid fit, as a false-alarm probability.
  double residual_test_pfa = 1e-4;
  int max_candidates_per_baseline = 4000;  // LAMBDA enumeration cap (keeps the search bounded at 5 satellites)
  // Multi-epoch resolution (constrained method), while no single epoch validates: the integer candidates of the
  // rigid array that fit the first epoch within 60 of the best (at most 40) are scored again on every following
  // epoch with the same satellites and no slip flag (the DD integers stay the same while the phases are
  // continuous; the attitude is free per epoch), their chi-squares summed. The best sum is fixed when it passes the
  // chi-square test of all those epochs and the second best sum exceeds it by multi_epoch_difference_threshold
  // (a difference test on all the epochs: twice the log likelihood ratio of the two hypotheses). The threshold is
  // twice the single-epoch one because epoch-to-epoch correlated phase noise (e.g. multipath, a 0.1 s
  // Gauss-Markov at 10 Hz) makes the summed chi-squares overstate the evidence. At most multi_epoch_max_epochs.
  bool multi_epoch = true;
  double multi_epoch_difference_threshold = 30.0;
  int multi_epoch_max_epochs = 600;

  // True when the options fit together; otherwise false and *why (when given) says which setting and why.
  bool IsValid(std::string* why) const;
};

// One fixed single-difference ambiguity: antenna k (>= 1) minus master, satellite prn, integer cycles. The integers
// of one antenna share an arbitrary datum (the integer part of the line bias): only differences between two
// satellites (the DD ambiguities) are physical.
struct SdAmbiguity {
  int antenna = 0;
  int prn = 0;
  long cycles = 0;
};

struct AttitudeSolution {
  signals::GpsTime time;
  bool valid = false;    // an attitude is given (only from validated integer ambiguities)
  bool fixed = false;    // the ambiguities used this epoch are fixed and passed this epoch's checks
  bool new_fix = false;  // resolved from scratch this epoch (false: carried from earlier epochs)
  // Ratio test value (J2 / J1) of the fix in use, from the epoch it was resolved; 1e9 when no rival candidate passed
  // the constraints; when not fixed, the value that failed (0 if no candidate at all).
  double ratio = 0.0;
  int num_sats = 0;                                           // satellites in the attitude fit (reference included)
  double roll_rad = 0.0, pitch_rad = 0.0, yaw_rad = 0.0;      // yaw in [0, 2 pi)
  Eigen::Matrix3d covariance_rad2 = Eigen::Matrix3d::Zero();  // (roll, pitch, yaw), from the DD covariance
  Eigen::Matrix3d C_nb = Eigen::Matrix3d::Identity();
  std::vector<Eigen::Vector3d> baseline_n_m;  // fitted baselines master -> antenna k (k >= 1), NED, m
  double residual_chi2 = 0.0;                 // weighted DD residual sum of squares of the rigid fit
  int residual_dof = 0;
  // Calibrated between-antenna single-difference line bias (antenna k minus master, cycles in [-0.5, 0.5)) and
  // its 1-sigma; [0] = 0. NaN for an antenna until a fix. Averaged over the fixed epochs since the last restart.
  std::vector<double> line_bias_cycles;
  std::vector<double> line_bias_sigma_cycles;
  std::vector<SdAmbiguity> ambiguities;  // the fixed ambiguities used this epoch
  std::vector<int> slipped_prns;         // satellites whose ambiguity restarted this epoch (flag or check)
};

// Stateful: keeps the fixed ambiguities (per antenna and satellite) from epoch to epoch. Each epoch: drop the
// ambiguities of flagged slips, check the rest by the rigid-fit residuals (a failed check restarts them all), add
// newly seen satellites by rounding against the fitted attitude and the calibrated line bias, and resolve from
// scratch (LAMBDA + constraints + ratio test) when too few fixed ambiguities remain. No attitude is output from a
// fix that failed a check: valid = fixed = false then.
class AttitudeSolver {
 public:
  // Throws std::invalid_argument when the options are not valid (IsValid).
  explicit AttitudeSolver(AttitudeSolverOptions options);

  // An epoch without a usable master position (not finite, or nearer the geocentre than 1000 km) has no NED frame:
  // valid = false, and the ambiguities are kept for the next epoch.
  AttitudeSolution update(const AntennaPhaseEpoch& epoch);
  // Forget every fixed ambiguity and the line-bias calibration.
  void reset();

  const AttitudeSolverOptions& options() const { return options_; }

 private:
  AttitudeSolverOptions options_;
  std::vector<SdAmbiguity> fixed_;           // carried SD ambiguities
  std::vector<double> bias_mean_, bias_m2_;  // running line-bias calibration per antenna (Welford)
  std::vector<int> bias_count_;
  double last_ratio_ = 0.0;
  // Multi-epoch resolution in progress: the candidates' summed chi-squares, and the DD rows they were formed on.
  struct Hypothesis {
    Eigen::VectorXd integers;
    double chi2_sum = 0.0;
  };
  struct RowKey {
    int antenna = 0, prn = 0, ref_prn = 0;
    bool operator==(const RowKey&) const = default;
  };
  std::vector<Hypothesis> pending_;
  std::vector<RowKey> pending_rows_;
  int pending_epochs_ = 0, pending_dof_ = 0;
  bool have_attitude_ = false;
  Eigen::Matrix3d last_R_eb_ = Eigen::Matrix3d::Identity();
};

}  // namespace ultratrack::receiver
