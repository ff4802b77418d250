// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/common_clock_loop.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "receiver/loop_filters.hpp"

namespace ultratrack::receiver {

CommonClockLoop::CommonClockLoop(const CommonClockLoopOptions& options) : opt_(options) {
  if (!(opt_.period_s > 0.0) || !(opt_.bandwidth_hz > 0.0) || !(opt_.bandwidth_hz * opt_.period_s <= 0.25))
    throw std::invalid_argument("common clock loop: bandwidth_hz must be in (0, 0.25 / period_s], period_s > 0");
  if (opt_.min_channels < 1) throw std::invalid_argument("common clock loop: min_channels must be at least 1");
  w0_rad_s_ = opt_.bandwidth_hz / kSecondOrderBnPerW0;
}

double CommonClockLoop::update(std::span<const ChannelPrompt> prompts) {
  double sum_i = 0.0, sum_q = 0.0, sum_a2 = 0.0;
  int used = 0;
  for (const ChannelPrompt& p : prompts) {
    if (!std::isfinite(p.i) || !std::isfinite(p.q) || !std::isfinite(p.cn0_dbhz)) continue;
    const double a2 = 2.0 * std::pow(10.0, p.cn0_dbhz / 10.0) * opt_.period_s;  // A^2 of a 20 ms prompt
    const double a = std::sqrt(a2);
    const double bit = p.bit_sign != 0 ? p.bit_sign : (p.i >= 0.0 ? 1.0 : -1.0);
    sum_i += a * bit * p.i;
    sum_q += a * bit * p.q;
    sum_a2 += a2;
    ++used;
  }
  channels_used_ = used;
  if (used < opt_.min_channels || !(sum_a2 > 0.0)) return frequency_hz_;
  mean_phase_rad_ = std::atan2(sum_q, sum_i);
  mean_phase_sigma_rad_ = std::sqrt(1.0 / sum_a2);
  constexpr double kZeta = std::numbers::sqrt2 / 2.0;
  integrator_rad_s_ += w0_rad_s_ * w0_rad_s_ * opt_.period_s * mean_phase_rad_;
  frequency_hz_ = (integrator_rad_s_ + 2.0 * kZeta * w0_rad_s_ * mean_phase_rad_) / (2.0 * std::numbers::pi);
  ++updates_;
  return frequency_hz_;
}

}  // namespace ultratrack::receiver
