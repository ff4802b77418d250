// SPDX-License-Identifier: GPL-3.0-or-later
// Releases of the channels a vector or ultra-tight filter steers, when the filter's own innovations say its
// prediction of a channel is wrong: each channel's windowed NIS (fusion/windowed_nis.hpp) over its last `window`
// updates against margin x the chi-square upper quantile of the window's summed dof at `probability`. A channel far
// outside that band is released (the loop hands it back to its scalar loops, then re-acquisition, instead of
// steering it with a prediction its correlations contradict). The whole filter is tested first: the pooled windows
// (the sum of every full window's NIS against margin x the quantile of their summed dof, at least
// min_filter_channels windows). One contradicted channel cannot pass that alone (it adds at most W x the cap below
// to a pool of n - 1 clean windows); when most channels rise together the pool passes first (its quantile is the
// tighter, relative to its dof): the filter, not the channels, is wrong: one filter event once the pool has stayed
// outside filter_persistence evaluations in a row (the loop re-opens or resets the filter), and no channel is blamed
// while the pool stays outside; another filter event only after the pool
// has come back inside its band (re-opening cures a wrong state, not a wrong noise model: a filter whose NIS stays
// high after it is logged once). ReleaseLog records every release of a loop with its time, PRN and reason and counts
// them per reason (summary.json).
// Each update's NIS enters capped at the filter's own gate threshold for its dof (an update the gate rejects counts
// as one at the gate), so one outlier (a single wrong data bit at 45 dB-Hz: NIS ~5000) costs a bounded share of the
// budget: from a window of clean updates (mean NIS m0 per update), k consecutive updates at the cap c trip it once
// k > (limit - W m0) / (c - m0), and a run of W updates each above limit / W trips it within W updates whatever came
// before. margin: a real filter's NIS is not exactly chi-square (the ultra-tight I&Q NIS at 45 dB-Hz averages 1.05-
// 1.2 x its dof and its 1 s sums reach 1.9 x it; after a step to 22 dB-Hz on a signal with an unmodelled TCXO every
// channel's 1 s sum reaches 2.9 x: a noise model, not a state, that is wrong: docs/validation.md 10.6), so the band is
// the quantile of margin x chi-square(W dof). With margin 3 and the 0.9999 gate (cap 4.6 x dof for the I&Q form's 6
// dof) a 1 s window passes it only when ~45 of its 50 updates are at the gate: the filter has stopped believing the
// channel's correlations but still steers it.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "fusion/windowed_nis.hpp"

namespace ultratrack::fusion {

struct NisReleaseOptions {
  bool enabled = true;
  int window = 50;                   // a channel's updates per window (50 x 20 ms = 1 s), >= 1
  double probability = 1e-6;         // false-alarm probability of one full window of a consistent filter, (0, 1)
  double margin = 3.0;               // the band is margin x the chi-square quantile, >= 1
  double gate_probability = 0.9999;  // an update's NIS counts at most the gate threshold of its dof at this, (0, 1)
  int min_filter_channels = 3;       // the pooled test needs at least this many full windows, >= 1
  // The pool must stay out of its band this many evaluations in a row (50: 1 s of the loop's epochs) before the
  // filter event: a wrong state stays wrong, while a C/N0 step (the channels' C/N0 estimates, hence the I&Q noise
  // model, lag the signal for a second or so) passes. Meanwhile no channel is blamed. >= 1.
  int filter_persistence = 50;
  bool IsValid(std::string* why = nullptr) const;
};

// What one evaluation found.
struct NisVerdict {
  bool filter = false;               // the pooled windows out of band: the filter (no channel released)
  std::vector<int> released;         // PRNs released (filter false)
  std::vector<std::string> reasons;  // per released PRN (or one, for the filter): "windowed NIS 812 over 50 ..."
};

class NisReleaseMonitor final {
 public:
  // Throws std::invalid_argument for invalid options.
  explicit NisReleaseMonitor(const NisReleaseOptions& options);

  // One update of a channel (prn 1-32) in the current epoch.
  void add(int prn, double nis, int dof);
  // After an epoch's updates (the channels updated in it are tested): the filter, or which channels are far outside
  // their band. The windows of the channels named (all of them, for a filter event) restart. Disabled: nothing.
  NisVerdict evaluate();
  // A channel released, lost or out of the filter: its window restarts.
  void forget(int prn);
  void reset();
  // The limit of a full window (or pool) of `dof` summed degrees of freedom (margin x quantile).
  double limit(int dof) const;
  // The pooled windows are outside their band since the last filter event (channels are not blamed meanwhile).
  bool filter_out() const { return filter_out_; }
  const NisReleaseOptions& options() const { return opt_; }

 private:
  double gate_cap(int dof) const;

  NisReleaseOptions opt_;
  std::vector<WindowedNis> windows_;           // by PRN (0-32)
  std::array<bool, 33> touched_{};             // updated since the last evaluation
  mutable std::array<double, 8> gate_caps_{};  // by dof (1-7); 0: not computed yet
  mutable int pool_dof_ = -1;                  // the last pooled limit's dof, and the limit
  mutable double pool_limit_ = 0.0;
  bool filter_out_ = false;
  int pool_out_evaluations_ = 0;  // consecutive evaluations with the pool out of its band
};

// The releases of one loop: every release with its time, PRN (0: the whole filter) and reason, and the count per
// reason. Reasons are short keys ("channel_nis", "filter_nis", "jump", "coast", "runaway", "lost", ...).
class ReleaseLog final {
 public:
  void add(double t_s, int prn, const std::string& reason, const std::string& detail = "");
  long long count(const std::string& reason) const;
  long long total() const { return static_cast<long long>(events_.size()); }
  // JSON members (no braces around them): "releases_by_reason": {...}, "release_log": [{"t_s", "prn", "reason",
  // "detail"}, ...] (every key in the order first seen).
  std::string json_members() const;

  struct Event {
    double t_s = 0.0;
    int prn = 0;
    std::string reason, detail;
  };
  const std::vector<Event>& events() const { return events_; }

 private:
  std::vector<Event> events_;
  std::vector<std::pair<std::string, long long>> counts_;
};

}  // namespace ultratrack::fusion
