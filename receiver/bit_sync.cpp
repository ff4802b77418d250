#include "receiver/bit_sync.hpp"

#include <algorithm>
#include <cmath>

namespace ultratrack::receiver {

void BitSynchronizer::add(std::int64_t code_period, std::complex<float> prompt) {
  if (synchronised_) return;
  ++periods_;
  if (have_previous_ && code_period == previous_period_ + 1) {
    const double dot = static_cast<double>(prompt.real()) * previous_.real() + static_cast<double>(prompt.imag()) * previous_.imag();
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
    return std::nullopt;
  }
  sum_ += std::complex<double>(epoch.master().prompt);
  periods_ += epoch.num_code_periods;
  if (periods_ < 20) return std::nullopt;
  active_ = false;
  if (periods_ > 20) return std::nullopt;
  const double magnitude = std::abs(sum_);
  amplitude_ = amplitude_ == 0.0 ? magnitude : amplitude_ + 0.05 * (magnitude - amplitude_);
  current_.value = sum_.real() >= 0.0 ? 1 : -1;
  current_.soft = amplitude_ > 0.0 ? static_cast<float>(sum_.real() / amplitude_) : 0.0f;
  return current_;
}

}  // namespace ultratrack::receiver
