// SPDX-License-Identifier: GPL-3.0-or-later
// A tracking channel's carrier against a navigation filter's prediction: the mean, in Hz, of (the channel's carrier
// frequency - the predicted Doppler) over an averaging time. A weak channel whose PLL sits on a false lock (25 Hz
// off: half a cycle per 20 ms epoch) or runs away from its signal shows it as a mean far from zero; a locked one
// keeps it within the PLL's noise and the prediction's error. The vector filter (fusion/vector_tracking.hpp) and the
// ultra-tight loop (pipelines/ultratight_loop.hpp) both judge their weak channels with it, each with its own
// averaging and thresholds:
//   kRunning  an exponential mean, weight min(1, step / average_s) per epoch, always current: the vector filter
//             leaves a channel's Doppler rows out while it is off and steps its aiding once it has averaged long
//             enough (epochs() x step)
//   kBlock    means of consecutive blocks of average_s: add() says when one completes (one verdict per block);
//             recent_hz() is the mean of the last kRecent epochs (where the PLL is now: a runaway drifts by up to
//             10-25 Hz/s, so a block mean lags it by several Hz)
// reset(settle) starts afresh (after a step of the aiding, a re-lock), skipping the next `settle` epochs (a command
// that reaches the channel a period late). Non-finite offsets are ignored.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

namespace ultratrack::fusion {

class FalseLockMonitor {
 public:
  enum class Averaging { kRunning, kBlock };
  static constexpr int kRecent = 5;

  explicit FalseLockMonitor(Averaging averaging = Averaging::kBlock, double average_s = 1.0)
      : averaging_(averaging), average_s_(average_s) {}

  // One epoch's offset (Hz) lasting step_s (> 0). kRunning: true when taken in; kBlock: true when a block completes.
  bool add(double offset_hz, double step_s) {
    if (!std::isfinite(offset_hz)) return false;
    if (settle_ > 0) {
      --settle_;
      return false;
    }
    ++n_;
    recent_[static_cast<std::size_t>(next_++ % kRecent)] = offset_hz;
    if (averaging_ == Averaging::kRunning) {
      mean_hz_ += std::min(1.0, step_s / average_s_) * (offset_hz - mean_hz_);
      return true;
    }
    sum_ += offset_hz;
    if (static_cast<double>(n_) * step_s < average_s_ - 1e-9) return false;
    mean_hz_ = sum_ / n_;
    sum_ = 0.0;
    n_ = 0;
    return true;
  }
  void reset(int settle = 0) {
    if (averaging_ == Averaging::kRunning) mean_hz_ = 0.0;
    sum_ = 0.0;
    n_ = 0;
    next_ = 0;
    settle_ = settle;
  }
  // kRunning: the running mean; kBlock: the last completed block's mean (0 before the first).
  double mean_hz() const { return mean_hz_; }
  // Epochs taken in since the last reset (kRunning) or in the open block (kBlock).
  int epochs() const { return n_; }
  // The mean of the last kRecent epochs since the last reset (mean_hz() when there are none).
  double recent_hz() const {
    const int n = std::min(next_, kRecent);
    double s = 0.0;
    for (int k = 0; k < n; ++k) s += recent_[static_cast<std::size_t>(k)];
    return n > 0 ? s / n : mean_hz_;
  }

 private:
  Averaging averaging_;
  double average_s_;
  double sum_ = 0.0, mean_hz_ = 0.0;
  std::array<double, kRecent> recent_{};
  int n_ = 0, settle_ = 0, next_ = 0;
};

}  // namespace ultratrack::fusion
