// SPDX-License-Identifier: GPL-3.0-or-later
// Signal-presence test for a channel whose replica an external filter drives (ultra-tight): over non-overlapping
// windows of n epochs, the prompt's power against the noise tap's, SNR_hat = sum|P|^2 / sum|N|^2 - 1 (per epoch);
// "absent" when SNR_hat < 10^(threshold_dbhz / 10) T. Energy only (no phase lock needed: the filter, not the
// PLL, keeps the replica on the signal). Exact error rates: docs/validation.md (Poisson mixture of beta laws).
// PresenceMonitor turns window verdicts into a loss (a run of absent windows whose length follows the channel's
// C/N0) and a re-lock (a run of windows above a higher threshold).
#pragma once

#include <complex>
#include <optional>

namespace ultratrack::receiver {

class SignalPresenceTest final {
 public:
  // window_epochs >= 1; threshold in dB-Hz (converted with each epoch's length t_s).
  SignalPresenceTest(int window_epochs, double threshold_dbhz);
  // One epoch's prompt and noise-tap sums (same scale). Returns the verdict when a window completes (true:
  // present), nothing otherwise. Epochs of another length (by more than 1 %: the sample count of one length varies
  // with the code Doppler) than the window's first restart the window.
  std::optional<bool> add(std::complex<float> prompt, std::complex<float> noise, double t_s);
  void reset() {
    n_ = 0;
    prompt_power_ = noise_power_ = 0.0;
    t_s_ = 0.0;
  }
  // The latest completed window's SNR per epoch, as C/N0 (dB-Hz; -inf-like -100 when not positive).
  double last_cn0_dbhz() const { return last_cn0_dbhz_; }
  int window_epochs() const { return window_; }

 private:
  int window_;
  double threshold_dbhz_;
  int n_ = 0;
  double prompt_power_ = 0.0, noise_power_ = 0.0, t_s_ = 0.0;
  double last_cn0_dbhz_ = -100.0;
};

// Exact probability that a window of n epochs of length t_s says "absent" for a signal at cn0_dbhz (below -50:
// no signal): sum_j Pois(j; n rho) I_x(n + j, n), rho = C/N0 t_s, x = (1 + r) / (2 + r), r = 10^(thr/10) t_s.
double presence_absent_probability(double cn0_dbhz, int n, double t_s, double threshold_dbhz);
// Probability of at least one run of k consecutive successes in `trials` independent trials of probability p.
double run_probability(double p, int k, int trials);

struct PresenceMonitorOptions {
  int window_epochs = 50;        // one window (50 x 20 ms = 1 s)
  double epoch_s = 0.020;        // the epochs' length, for the error rates
  double threshold_dbhz = 12.0;  // a window below this says absent
  // Loss: k consecutive absent windows, k the smallest in [1, max_windows] whose probability of a false loss in
  // a minute (run_probability of the exact per-window rate) at the channel's level less margin_db is at most
  // false_loss_per_min. The level: the C/N0 of the present windows before the run that read at least
  // relock_threshold_dbhz (the mean SNR of the last three, or the latest alone when lower: a step down counts at
  // once); none yet: one window.
  int max_windows = 5;
  double false_loss_per_min = 1e-3;
  double margin_db = 2.0;
  // Re-lock (found): relock_windows consecutive windows at or above relock_threshold_dbhz.
  double relock_threshold_dbhz = 15.0;
  int relock_windows = 2;
};

class PresenceMonitor final {
 public:
  explicit PresenceMonitor(const PresenceMonitorOptions& options);
  // One epoch; returns the window's verdict (true: present) when one completes.
  std::optional<bool> add(std::complex<float> prompt, std::complex<float> noise, double t_s);
  // The window just completed ends a loss run (lost) / a re-lock run (found); both false between windows.
  bool lost() const { return lost_; }
  bool found() const { return found_; }
  // The absent windows a loss needs at the current level (see PresenceMonitorOptions).
  int required_windows() const { return required_; }
  double last_cn0_dbhz() const { return test_.last_cn0_dbhz(); }
  // Restarts the window and both runs (keeps the level).
  void reset();

 private:
  int windows_for_level(double cn0_dbhz) const;

  PresenceMonitorOptions opt_;
  SignalPresenceTest test_;
  double recent_snr_[3] = {0.0, 0.0, 0.0};
  int recent_count_ = 0;
  int required_ = 1;
  int absent_run_ = 0, relock_run_ = 0;
  bool lost_ = false, found_ = false;
};

}  // namespace ultratrack::receiver
