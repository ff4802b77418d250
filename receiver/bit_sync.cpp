// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/bit_sync.hpp"

#include <algorithm>
#include <cmath>

namespace ultratrack::receiver {

void BitSynchronizer::add_energy(std::int64_t code_period, std::complex<float> prompt) {
  const bool consecutive = have_previous_ && code_period == previous_period_ + 1;
  if (!consecutive) {  // a gap: windows across it are meaningless, and so is the current set
    consecutive_ = 0;
    window_count_ = 0;
    have_previous_set_ = false;
  }
  ring_[static_cast<std::size_t>(((code_period % 20) + 20) % 20)] = std::complex<double>(prompt);
  if (++consecutive_ < 20) return;
  consecutive_ = 20;
  std::complex<double> sum{};
  for (const auto& p : ring_) sum += p;
  // the window ends at code_period: it starts at code_period - 19, offset (code_period + 1) mod 20
  const auto c = static_cast<std::size_t>((((code_period + 1) % 20) + 20) % 20);
  if (window_count_ == 0 && c != 0) return;  // sets run from offset 0 to 19
  window_[c] = std::norm(sum);
  if (++window_count_ < 20) return;
  window_count_ = 0;
  ++energy_sets_;
  for (std::size_t j = 0; j < 20; ++j) {
    energy_[j] += window_[j];
    for (std::size_t k = j; k < 20; ++k) cross_[j][k] += window_[j] * window_[k];
  }
  if (have_previous_set_) {
    ++lag_sets_;
    for (std::size_t j = 0; j < 20; ++j)
      for (std::size_t k = 0; k < 20; ++k) lag_[j][k] += previous_window_[j] * window_[k];
  }
  previous_window_ = window_;
  have_previous_set_ = true;
}

bool BitSynchronizer::energy_decides(int* best) const {
  if (energy_sets_ < options_.min_energy_bits) return false;
  const auto b = static_cast<std::size_t>(std::max_element(energy_.begin(), energy_.end()) - energy_.begin());
  const double n = energy_sets_;
  const auto cross = [&](std::size_t j, std::size_t k) { return j <= k ? cross_[j][k] : cross_[k][j]; };
  if (lag_sets_ < 1) return false;
  const double m = lag_sets_;
  for (std::size_t k = 0; k < 20; ++k) {
    if (k == b) continue;
    const double d = energy_[b] - energy_[k];
    // variance of the summed difference per set: that of window_b - window_k within a set plus twice its
    // covariance with the next set's (Newey-West with one lag: windows more than one set apart do not overlap)
    const double mean = d / n;
    const double var0 = (cross(b, b) - 2.0 * cross(b, k) + cross(k, k)) / n - mean * mean;
    const double cov1 = (lag_[b][b] - lag_[b][k] - lag_[k][b] + lag_[k][k]) / m - mean * mean;
    const double var = var0 + 2.0 * cov1;
    if (!(d > options_.min_energy_sigma * std::sqrt(std::max(var, 0.0) * n))) return false;
  }
  *best = static_cast<int>(b);
  return true;
}

void BitSynchronizer::add(std::int64_t code_period, std::complex<float> prompt) {
  if (synchronised_) return;
  ++periods_;
  if (options_.energy_test) {
    add_energy(code_period, prompt);
    int best = 0;
    if (energy_decides(&best)) {
      synchronised_ = true;
      edge_ = best;
      return;
    }
  }
  if (have_previous_ && code_period == previous_period_ + 1) {
    const double dot =
        static_cast<double>(prompt.real()) * previous_.real() + static_cast<double>(prompt.imag()) * previous_.imag();
    if (dot < 0.0) ++bins_[static_cast<std::size_t>(((code_period % 20) + 20) % 20)];
  }
  have_previous_ = true;
  previous_period_ = code_period;
  previous_ = prompt;

  const auto best = std::max_element(bins_.begin(), bins_.end());
  if (*best < options_.min_edges) return;
  int runner_up = 0;
  for (auto it = bins_.begin(); it != bins_.end(); ++it)
    if (it != best) runner_up = std::max(runner_up, *it);
  const bool ratio = *best >= options_.min_ratio * std::max(runner_up, 1);
  const bool lead = *best - runner_up >= options_.min_lead_sigma * std::sqrt(static_cast<double>(*best + runner_up));
  if (ratio || lead) {
    synchronised_ = true;
    edge_ = best - bins_.begin();  // period index modulo 20 at which bits start
  }
}

std::optional<NavBit> BitAssembler::add(const CorrelationEpoch& epoch) {
  const std::int64_t p = epoch.first_code_period;
  const std::int64_t phase = ((p - edge_) % 20 + 20) % 20;
  if (phase == 0) {  // a bit starts here
    active_ = true;
    current_ = NavBit{epoch.first_sample, p, 0, 0.0f};
    sum_ = {};
    periods_ = 0;
  }
  if (!active_) return std::nullopt;
  if (phase != periods_) {  // a gap or misaligned epoch: drop the partial bit
    active_ = false;
    have_previous_ = false;
    return std::nullopt;
  }
  sum_ += std::complex<double>(epoch.master().prompt);
  periods_ += epoch.num_code_periods;
  if (periods_ < 20) return std::nullopt;
  active_ = false;
  if (periods_ > 20) {
    have_previous_ = false;
    return std::nullopt;
  }
  // A bit that does not follow the previous one (a bit start missed) breaks the differential chain.
  const bool follows = have_previous_ && current_.first_code_period == previous_period_ + 20;
  const double magnitude = std::abs(sum_);
  amplitude_ = amplitude_ == 0.0 ? magnitude : amplitude_ + 0.05 * (magnitude - amplitude_);
  const double previous_magnitude = std::abs(previous_sum_);
  if (differential_ && follows && previous_magnitude > 0.0) {
    const double projection = (sum_ * std::conj(previous_sum_)).real() / previous_magnitude;  // on the previous bit
    current_.value = previous_value_ * (projection >= 0.0 ? 1 : -1);
    current_.soft = amplitude_ > 0.0 ? static_cast<float>(previous_value_ * projection / amplitude_) : 0.0f;
  } else {
    current_.value = sum_.real() >= 0.0 ? 1 : -1;
    current_.soft = amplitude_ > 0.0 ? static_cast<float>(sum_.real() / amplitude_) : 0.0f;
  }
  previous_sum_ = sum_;
  previous_value_ = current_.value;
  previous_period_ = current_.first_code_period;
  have_previous_ = true;
  return current_;
}

}  // namespace ultratrack::receiver
