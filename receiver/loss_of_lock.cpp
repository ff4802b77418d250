// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/loss_of_lock.hpp"

#include <algorithm>
#include <cmath>

namespace ultratrack::receiver {
namespace {

constexpr double kBitPeriod_s = 0.02;
// The 1 s estimate's spread at 16-18 dB-Hz is ~1.5 dB (the level averages up to three): 2 dB of margin.
constexpr double kPresenceMarginDb = 2.0;
constexpr int kPresenceRelockWindows = 2;

int epochs_in(double window_s, double t_s) { return std::max(1, static_cast<int>(std::lround(window_s / t_s))); }

PresenceMonitorOptions presence_options(const ScalarTrackingOptions& o) {
  PresenceMonitorOptions p;
  p.window_epochs = epochs_in(o.presence_window_s, kBitPeriod_s);
  p.epoch_s = kBitPeriod_s;
  p.threshold_dbhz = o.presence_threshold_dbhz;
  p.max_windows = o.presence_max_windows;
  p.false_loss_per_min = o.presence_false_loss_per_min;
  p.margin_db = kPresenceMarginDb;
  p.relock_threshold_dbhz = o.presence_relock_dbhz;
  p.relock_windows = kPresenceRelockWindows;
  return p;
}

}  // namespace

LossOfLockTest::LossOfLockTest(const ScalarTrackingOptions& options)
    : opt_(options), presence_(presence_options(options)) {}

void LossOfLockTest::presence_epoch(bool run, bool bit_synced, bool coasting, std::complex<float> prompt,
                                    std::complex<float> noise, double t_s) {
  presence_absent_ = presence_found_ = false;
  if (!run) {
    presence_.reset();
    return;
  }
  if (presence_.add(prompt, noise, t_s)) {
    presence_absent_ = bit_synced && presence_.lost();
    presence_found_ = coasting && presence_.found();
  }
}

bool LossOfLockTest::epoch_lost(bool loss_condition, bool by_presence, double t_s) {
  loss_time_s_ = loss_condition ? loss_time_s_ + t_s : 0.0;
  if (by_presence) loss_time_s_ = presence_absent_ ? opt_.loss_of_lock_time_s : 0.0;
  if (loss_time_s_ < opt_.loss_of_lock_time_s) return false;
  loss_time_s_ = 0.0;
  return true;
}

bool LossOfLockTest::long_update_lost(bool loss_condition, bool by_presence, double t_s, double min_time_s) {
  loss_time_s_ = loss_condition ? loss_time_s_ + t_s : 0.0;
  if (by_presence) loss_time_s_ = 0.0;
  return loss_time_s_ >= std::max(opt_.loss_of_lock_time_s, min_time_s);
}

}  // namespace ultratrack::receiver
