// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/clock_model.hpp"

#include <numbers>

#include "signals/gps_constants.hpp"

namespace ultratrack::fusion {

ClockNoiseModel clock_noise_from_allan(const OscillatorAllan& allan, const ClockNoiseModel& base) {
  constexpr double kC2 = signals::kSpeedOfLight_mps * signals::kSpeedOfLight_mps;
  ClockNoiseModel out = base;
  out.bias_psd_m2_per_s = kC2 * allan.h0 / 2.0;
  out.drift_psd_m2_per_s3 = kC2 * 2.0 * std::numbers::pi * std::numbers::pi * allan.h_minus2;
  return out;
}

Eigen::Matrix2d clock_process_noise(const ClockNoiseModel& clock, double dt) {
  const double sb = clock.bias_psd_m2_per_s, sd = clock.drift_psd_m2_per_s3;
  Eigen::Matrix2d q;
  q << sb * dt + sd * dt * dt * dt / 3.0, sd * dt * dt / 2.0, sd * dt * dt / 2.0, sd * dt;
  return q;
}

}  // namespace ultratrack::fusion
