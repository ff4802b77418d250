// SPDX-License-Identifier: GPL-3.0-or-later
// No gate lock-out: a GNSS/INS filter whose state has drifted away from its measurements rejects every fix at the
// innovation gate, and then nothing can bring it back (a MEMS unit after an outage, a bad start, a burst of bad
// fixes that got in). LockoutMonitor watches the updates of one measurement stream and says when the filter must
// re-open: a run of consecutive rejections spanning some time, or a windowed NIS far above its chi-square band
// (fusion/windowed_nis.hpp: the state is wrong although each update just passes the gate). inflate_for_recovery then
// opens the covariance of what the measurements observe (position, velocity, attitude, and the clock in tight mode) so
// the next update is accepted and pulls the state back; biases and their correlations are kept. Units SI; error state
// layout of fusion/ins_error_state.hpp.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "fusion/windowed_nis.hpp"

namespace ultratrack::fusion {

struct LockoutRecoveryOptions {
  bool enabled = true;
  int consecutive_rejections = 5;        // fixes (loose) or all-rejected epochs (tight) in a row ...
  double min_span_s = 2.0;               // ... spanning at least this long
  int nis_window = 20;                   // updates in the windowed NIS test (0: no window test)
  double nis_window_probability = 1e-6;  // re-open when the window's NIS sum passes this upper-tail quantile
  // After a recovery the attitude 1-sigma is at least this (north, east, down psi angles) [rad].
  Eigen::Vector3d attitude_sigma_rad{0.035, 0.035, 0.35};

  bool IsValid(std::string* why = nullptr) const;
};

// Why the monitor asked for a recovery.
struct RecoveryEvent {
  double t_s = 0.0;
  std::string reason;  // "5 consecutive rejections over 2.4 s" | "windowed NIS 812 over 20 updates (limit 131)"
};

class LockoutMonitor {
 public:
  explicit LockoutMonitor(const LockoutRecoveryOptions& options);

  // One update (or, tight, one epoch: accepted when any satellite was) at t_s with its NIS and dof. Returns the
  // event when the filter must re-open now; the monitor then starts afresh.
  std::optional<RecoveryEvent> observe(double t_s, bool accepted, double nis, int dof);
  void reset();

 private:
  LockoutRecoveryOptions opt_;
  int rejections_ = 0;
  double first_rejection_t_s_ = 0.0;
  WindowedNis window_;  // nis_window updates (one when the test is off), each NIS capped at 100 dof
};

// Opens P (n x n, n >= 9) for a recovery: position variances at least 4 innovation^2 per NED axis (pos_innovation;
// zero where unknown) plus 1 m^2, velocity at least 4 vel_innovation^2 (or (2 |pos_innovation| / span_s)^2 when no
// velocity was measured) plus 1 (m/s)^2, attitude at least options.attitude_sigma_rad^2; the cross-covariances of
// these nine states with everything are cleared. Tight (a clock innovation given: the mean pseudorange innovation;
// n >= 17): the clock bias like a position axis, the drift like velocity. Other states (biases, and what a filter
// appends after them) keep their variances.
Eigen::MatrixXd inflate_for_recovery(const Eigen::MatrixXd& P, const Eigen::Vector3d& pos_innovation_ned_m,
                                     const std::optional<Eigen::Vector3d>& vel_innovation_ned_mps, double span_s,
                                     const LockoutRecoveryOptions& options,
                                     std::optional<double> clock_innovation_m = std::nullopt);

}  // namespace ultratrack::fusion
