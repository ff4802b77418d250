// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/receiver_clock.hpp"

#include <cmath>

#include "signals/synth_kernels.hpp"

namespace ultratrack::signals {

ReceiverClock::ReceiverClock(ReceiverClockModel model, std::uint64_t seed)
    : model_(model),
      noisy_(model.bias_noise_s_per_sqrt_s > 0.0 || model.drift_noise_sps_per_sqrt_s > 0.0),
      rng_(synth::seeded_engine(seed, 1)) {
  grid_.push_back({model_.bias_s, model_.drift_sps});
}

void ReceiverClock::grow_to(std::size_t node) {
  if (node < grid_.size()) return;
  if (node >= grid_.capacity()) grid_.reserve(node + 65536);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double h = kGridStep_s;
  const double sb = model_.bias_noise_s_per_sqrt_s * std::sqrt(h);
  const double sd = model_.drift_noise_sps_per_sqrt_s * std::sqrt(h);
  while (grid_.size() <= node) {
    const auto& p = grid_.back();
    const double drift = p.drift_sps + sd * gauss(rng_);
    const double bias = p.bias_s + 0.5 * (p.drift_sps + drift) * h + sb * gauss(rng_);
    grid_.push_back({bias, drift});
  }
}

ReceiverClockState ReceiverClock::at(double tau_s) {
  if (!noisy_) return {model_.bias_s + model_.drift_sps * tau_s, model_.drift_sps};
  if (tau_s < 0.0) tau_s = 0.0;
  const double x = tau_s / kGridStep_s;
  const auto i = static_cast<std::size_t>(x);
  grow_to(i + 1);
  const double u = x - static_cast<double>(i);
  const auto& a = grid_[i];
  const auto& b = grid_[i + 1];
  // Between nodes b is linear, so its rate there is the chord slope (it includes the white-FM step).
  return {a.bias_s + u * (b.bias_s - a.bias_s), (b.bias_s - a.bias_s) / kGridStep_s};
}

}  // namespace ultratrack::signals
