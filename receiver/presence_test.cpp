// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/presence_test.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace ultratrack::receiver {

SignalPresenceTest::SignalPresenceTest(int window_epochs, double threshold_dbhz)
    : window_(std::max(1, window_epochs)), threshold_dbhz_(threshold_dbhz) {}

std::optional<bool> SignalPresenceTest::add(std::complex<float> prompt, std::complex<float> noise, double t_s) {
  // Epochs of one length vary by a sample with the code Doppler (20 code periods): 1 % tells another length.
  if (n_ > 0 && std::abs(t_s - t_s_) > 0.01 * t_s_) reset();
  t_s_ = t_s;
  prompt_power_ += std::norm(std::complex<double>(prompt));
  noise_power_ += std::norm(std::complex<double>(noise));
  if (++n_ < window_) return std::nullopt;
  const double snr = noise_power_ > 0.0 ? prompt_power_ / noise_power_ - 1.0 : 0.0;
  last_cn0_dbhz_ = snr > 0.0 && t_s > 0.0 ? 10.0 * std::log10(snr / t_s) : -100.0;
  const bool present = t_s > 0.0 && snr >= std::pow(10.0, threshold_dbhz_ / 10.0) * t_s;
  reset();
  t_s_ = t_s;
  return present;
}

double presence_absent_probability(double cn0_dbhz, int n, double t_s, double threshold_dbhz) {
  n = std::max(1, n);
  const double rho = cn0_dbhz < -50.0 ? 0.0 : std::pow(10.0, cn0_dbhz / 10.0) * t_s;
  const double r = std::pow(10.0, threshold_dbhz / 10.0) * t_s;
  const double x = (1.0 + r) / (2.0 + r);
  const double lx = std::log(x), l1x = std::log1p(-x);
  // I_x(n, n) = P(Binomial(2n - 1, x) >= n), then I_x(a + 1, n) = I_x(a, n) - Gamma(a + n) / (Gamma(a + 1)
  // Gamma(n)) x^a (1 - x)^n for a = n, n + 1, ...
  const int m = 2 * n - 1;
  double ibeta = 0.0;
  for (int k = n; k <= m; ++k)
    ibeta += std::exp(std::lgamma(m + 1.0) - std::lgamma(k + 1.0) - std::lgamma(m - k + 1.0) + k * lx + (m - k) * l1x);
  const double mean = n * rho;
  double p = 0.0;
  for (int j = 0;; ++j) {
    const double w = mean > 0.0 ? std::exp(-mean + j * std::log(mean) - std::lgamma(j + 1.0)) : (j == 0 ? 1.0 : 0.0);
    if (w < 1e-18 && j > mean) break;
    p += w * std::max(0.0, ibeta);
    const int a = n + j;
    ibeta -= std::exp(std::lgamma(a + n + 0.0) - std::lgamma(a + 1.0) - std::lgamma(n + 0.0) + a * lx + n * l1x);
  }
  return std::clamp(p, 0.0, 1.0);
}

double run_probability(double p, int k, int trials) {
  if (k <= 0) return 1.0;
  // state i < k: the current run has length i; state k: a run of k has occurred (absorbing)
  std::vector<double> state(static_cast<std::size_t>(k) + 1, 0.0), next(state.size());
  state[0] = 1.0;
  for (int t = 0; t < trials; ++t) {
    std::fill(next.begin(), next.end(), 0.0);
    for (int i = 0; i < k; ++i) {
      next[0] += state[static_cast<std::size_t>(i)] * (1.0 - p);
      next[static_cast<std::size_t>(i) + 1] += state[static_cast<std::size_t>(i)] * p;
    }
    next[static_cast<std::size_t>(k)] += state[static_cast<std::size_t>(k)];
    state.swap(next);
  }
  return state[static_cast<std::size_t>(k)];
}

PresenceMonitor::PresenceMonitor(const PresenceMonitorOptions& options)
    : opt_(options), test_(options.window_epochs, options.threshold_dbhz) {}

void PresenceMonitor::reset() {
  test_.reset();
  absent_run_ = relock_run_ = 0;
  lost_ = found_ = false;
}

int PresenceMonitor::windows_for_level(double cn0_dbhz) const {
  const int max_windows = std::max(1, opt_.max_windows);
  // Above 25 dB-Hz one window's false-absent probability is below 1e-20 (n = 50, 12 dB-Hz): no formula needed.
  if (cn0_dbhz - opt_.threshold_dbhz >= 13.0) return 1;
  const double p = presence_absent_probability(cn0_dbhz, opt_.window_epochs, opt_.epoch_s, opt_.threshold_dbhz);
  const int per_minute = std::max(1, static_cast<int>(std::lround(60.0 / (opt_.window_epochs * opt_.epoch_s))));
  for (int k = 1; k < max_windows; ++k)
    if (run_probability(p, k, per_minute) <= opt_.false_loss_per_min) return k;
  return max_windows;
}

std::optional<bool> PresenceMonitor::add(std::complex<float> prompt, std::complex<float> noise, double t_s) {
  lost_ = found_ = false;
  const auto present = test_.add(prompt, noise, t_s);
  if (!present) return present;
  const double cn0 = test_.last_cn0_dbhz();
  if (*present) {
    absent_run_ = 0;
    // The level comes from windows that read at least the re-lock threshold: one that only just passes the
    // presence threshold is as likely noise (8.5 % of noise windows pass 12 dB-Hz, 0.75 % pass 15), and a
    // tunnel's channels would then wait for a weak signal's longer run.
    if (cn0 >= opt_.relock_threshold_dbhz) {
      recent_snr_[recent_count_ % 3] = std::pow(10.0, cn0 / 10.0);  // per second (the level's unit)
      ++recent_count_;
    }
  } else {
    if (absent_run_ == 0) {
      // The run's length: from the level of the present windows before it (none yet: one window).
      required_ = 1;
      if (recent_count_ > 0) {
        const int count = std::min(recent_count_, 3);
        double mean = 0.0;
        for (int i = 0; i < count; ++i) mean += recent_snr_[i];
        mean /= count;
        const double latest = recent_snr_[(recent_count_ - 1) % 3];
        required_ = windows_for_level(10.0 * std::log10(std::min(mean, latest)) - opt_.margin_db);
      }
    }
    lost_ = ++absent_run_ >= required_;
    if (lost_) absent_run_ = 0;
  }
  relock_run_ = cn0 >= opt_.relock_threshold_dbhz ? relock_run_ + 1 : 0;
  found_ = relock_run_ >= opt_.relock_windows;
  if (found_) relock_run_ = 0;
  return present;
}

}  // namespace ultratrack::receiver
