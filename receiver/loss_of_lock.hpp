// SPDX-License-Identifier: GPL-3.0-or-later
// The loss-of-lock test of a scalar channel (ScalarTrackingOptions, lock detection): the time a loss condition
// (low C/N0, low PLI) has held, against loss_of_lock_time_s; and, for a filter-driven channel (ultra-tight),
// the presence test on its 20 ms epochs (receiver/presence_test.hpp), whose absent run is the loss and whose
// present run ends coasting. ScalarTracking forms the conditions and acts on the verdicts. Units: seconds.
#pragma once

#include <complex>

#include "receiver/presence_test.hpp"
#include "receiver/scalar_tracking_options.hpp"

namespace ultratrack::receiver {

class LossOfLockTest final {
 public:
  explicit LossOfLockTest(const ScalarTrackingOptions& options);

  // One 20 ms epoch for the presence test while `run` (filter-driven, bit-synced or coasting); otherwise the
  // test restarts. A completed window sets presence_absent() (bit_synced: its run of absent windows is a loss)
  // or presence_found() (coasting: the signal is back); both are false after any other epoch.
  void presence_epoch(bool run, bool bit_synced, bool coasting, std::complex<float> prompt, std::complex<float> noise,
                      double t_s);
  bool presence_absent() const { return presence_absent_; }
  bool presence_found() const { return presence_found_; }
  void reset_presence() { presence_.reset(); }
  void clear_presence_absent() { presence_absent_ = false; }
  // The C/N0 of the latest completed presence window (dB-Hz; -100 before the first or without signal).
  double presence_cn0_dbhz() const { return presence_.last_cn0_dbhz(); }
  // The absent windows a loss needs at the channel's current level (PresenceMonitor).
  int presence_required_windows() const { return presence_.required_windows(); }

  // An epoch of t_s with or without a loss condition: true (and the timer restarted) once the conditions held
  // loss_of_lock_time_s. by_presence (a filter-driven bit-synced channel): the presence test decides instead.
  bool epoch_lost(bool loss_condition, bool by_presence, double t_s);
  // A long coherent update of t_s: true once the conditions held max(loss_of_lock_time_s, min_time_s) (the
  // timer is kept); by_presence: never (the presence test runs on the 20 ms epochs).
  bool long_update_lost(bool loss_condition, bool by_presence, double t_s, double min_time_s);
  void restart() { loss_time_s_ = 0.0; }

 private:
  ScalarTrackingOptions opt_;
  double loss_time_s_ = 0.0;
  PresenceMonitor presence_;
  bool presence_absent_ = false;  // the latest completed presence window ended a run of absent ones: lost
  bool presence_found_ = false;   // ... ended a run of present ones (re-lock while coasting)
};

}  // namespace ultratrack::receiver
